#include "drapegen/coordinator/stats.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fmt/format.h>
#include <map>

#include "drapegen/coordinator/run_config.hpp"
#include "drapegen/sampler/fabric_data.hpp"
#include "drapegen/sampler/parameters.hpp"
#include "drapegen/sampler/vae_model.hpp"
#include "drapegen/storage/atomic_file.hpp"
#include "drapegen/storage/manifest_reader.hpp"

namespace drapegen::coordinator {
namespace {

struct Data {
  nlohmann::json stats;
  std::vector<double> dc, folds, seconds;
  std::vector<std::vector<double>> run_features, measured_features;  // [feature][value]
};

/// The q-quantile of `sorted` (ascending, not empty), linear between neighbours.
double quantile(const std::vector<double>& sorted, double q) {
  const double pos = q * static_cast<double>(sorted.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(pos));
  const auto hi = std::min(lo + 1, sorted.size() - 1);
  return sorted[lo] + (pos - static_cast<double>(lo)) * (sorted[hi] - sorted[lo]);
}

nlohmann::json summary(std::vector<double> v) {
  if (v.empty()) return {{"count", 0}};
  std::sort(v.begin(), v.end());
  double sum = 0.0;
  for (double x : v) sum += x;
  return {{"count", v.size()},
          {"min", v.front()},
          {"p05", quantile(v, 0.05)},
          {"median", quantile(v, 0.5)},
          {"mean", sum / static_cast<double>(v.size())},
          {"p95", quantile(v, 0.95)},
          {"max", v.back()}};
}

std::string default_fabrics() { return sampler::default_fabric_data_path(); }

sim::Expected<Data> gather(const std::string& manifest_path, const StatsOptions& options) {
  auto reader = storage::ManifestReader::open(manifest_path);
  if (!reader) return reader.error();

  // Every table is read a row at a time and only what the figures need is kept (a run's manifest can hold millions
  // of file rows), all in one read transaction: a run in progress commits meanwhile, and the figures must all be of
  // one commit.
  Data d;
  storage::RunRecord run;
  std::map<std::string, std::int64_t> by_state, by_reason, attempts_by_reason;
  for (const auto& state : {"pending", "done", "failed"}) by_state[state] = 0;
  struct WorkerStats {
    std::int64_t jobs = 0;
    double busy = 0.0;
  };
  std::map<std::string, WorkerStats> workers;
  double first_start = 1e300, last_finish = 0.0;
  std::vector<std::pair<double, double>> attempts;  // the recorded attempts' [start, end]
  std::vector<double> iterations;
  std::int64_t failed_attempts = 0, files = 0, bytes = 0, mesh_bytes = 0, exr_bytes = 0;
  d.run_features.assign(sampler::kFeatureCount, {});

  const sim::Status read = reader->in_one_snapshot([&]() -> sim::Status {
    auto run_record = reader->run();
    if (!run_record) return run_record.error();
    run = std::move(run_record).value();
    // Parameters in the sampler's feature space (sign(k) ln|k| at 300 g/m^2), to set against the measured fabrics.
    if (sim::Status s = reader->for_each_sample([&](const storage::SampleRecord& smp) {
          const sampler::ParameterVector v{{smp.alpha[0], smp.alpha[1], smp.alpha[2]},
                                           {smp.beta[0], smp.beta[1], smp.beta[2]}};
          const auto f = sampler::to_features(sampler::normalise_density(v, smp.density_g_per_m2));
          for (int i = 0; i < sampler::kFeatureCount; ++i) d.run_features[i].push_back(f[i]);
        });
        !s) {
      return s;
    }
    if (sim::Status s = reader->for_each_job([&](const storage::JobRecord& j) {
          ++by_state[std::string(storage::to_string(j.state))];
          if (j.state == storage::JobState::kFailed) ++by_reason[j.failure_reason];
          if (j.state == storage::JobState::kPending || !(j.finished_at >= j.started_at) || j.started_at <= 0.0) {
            return;
          }
          // A failed job's last attempt counts as busy time too (often the longest: a solve to its iteration
          // limit); earlier failed attempts are not timed in the manifest (a failure row has its end only).
          const double seconds = j.finished_at - j.started_at;
          auto& w = workers[j.worker];
          w.busy += seconds;
          attempts.emplace_back(j.started_at, j.finished_at);
          if (j.state == storage::JobState::kDone) {
            d.seconds.push_back(seconds);
            ++w.jobs;
            first_start = std::min(first_start, j.started_at);
            last_finish = std::max(last_finish, j.finished_at);
          }
        });
        !s) {
      return s;
    }
    if (sim::Status s = reader->for_each_result([&](const storage::ResultRecord& r) {
          if (r.outcome == "noop") return;
          d.dc.push_back(r.drape_coefficient);
          d.folds.push_back(r.folds);
          iterations.push_back(r.iterations);
        });
        !s) {
      return s;
    }
    if (sim::Status s = reader->for_each_file([&](const storage::FileRecord& f) {
          ++files;
          bytes += f.bytes;
          (f.kind == "mesh" ? mesh_bytes : exr_bytes) += f.bytes;
        });
        !s) {
      return s;
    }
    return reader->for_each_failure([&](const storage::FailureRecord& f) {
      ++attempts_by_reason[f.reason];
      ++failed_attempts;
    });
  });
  if (!read) return read.error();

  nlohmann::json& s = d.stats;
  s["manifest"] = manifest_path;
  s["run"] = {{"seed", run.seed}, {"state", run.state}, {"code_version", run.code_version},
              {"total_jobs", run.total_jobs}, {"samples", d.run_features[0].size()}};
  // The stored configuration was validated when the run was planned; one that no longer parses (a manifest of
  // another version) leaves the model unnamed rather than guessed.
  const auto config = parse_run_config(run.config_toml, manifest_path);
  s["run"]["bending_model"] = config ? config->bending_model : std::string("unknown");

  // Time with an attempt in flight: the union of the attempts' spans. A run stopped and resumed later does not count
  // the time between (the first lease to the last result did).
  std::sort(attempts.begin(), attempts.end());
  double active = 0.0, covered_to = -1e300;
  for (const auto& [start, end] : attempts) {
    if (end <= covered_to) continue;
    active += end - std::max(start, covered_to);
    covered_to = end;
  }
  s["jobs"] = {{"by_state", by_state}, {"failed_by_reason", by_reason},
               {"failed_attempts_by_reason", attempts_by_reason}, {"failed_attempts", failed_attempts}};

  const double wall = last_finish > first_start ? last_finish - first_start : 0.0;
  nlohmann::json per_worker = nlohmann::json::object();
  for (const auto& [name, w] : workers) {
    per_worker[name] = {{"jobs", w.jobs},
                        {"busy_seconds", w.busy},
                        {"jobs_per_hour_busy", w.busy > 0 ? 3600.0 * static_cast<double>(w.jobs) / w.busy : 0.0}};
  }
  const auto done = by_state["done"];
  s["throughput"] = {{"wall_seconds_first_lease_to_last_result", wall},
                     {"active_seconds", active},
                     {"jobs_per_hour", active > 0 ? 3600.0 * static_cast<double>(done) / active : 0.0},
                     {"per_worker", per_worker}};
  s["seconds_per_job"] = summary(d.seconds);
  s["drape_coefficient"] = summary(d.dc);
  s["folds"] = summary(d.folds);
  s["newton_iterations"] = summary(iterations);

  std::error_code ec;
  std::int64_t manifest_bytes = 0;
  for (const char* suffix : {"", "-wal"}) {
    const auto size = std::filesystem::file_size(manifest_path + suffix, ec);
    if (!ec) manifest_bytes += static_cast<std::int64_t>(size);
  }
  s["storage"] = {{"files", files}, {"bytes", bytes}, {"mesh_bytes", mesh_bytes},
                  {"exr_bytes", exr_bytes}, {"manifest_bytes", manifest_bytes}};

  const std::string csv = options.fabrics_csv.empty() ? default_fabrics() : options.fabrics_csv;
  nlohmann::json params = nlohmann::json::object();
  auto fabrics = csv.empty() ? sim::Expected<std::vector<sampler::MeasuredFabric>>(sim::Error{"no fabric data"})
                             : sampler::read_fabric_csv(csv);
  if (!fabrics && !options.fabrics_csv.empty()) return sim::Error{"the measured fabrics: " + fabrics.error().message};
  if (fabrics) {
    d.measured_features.assign(sampler::kFeatureCount, {});
    for (const auto& f : sampler::distinct_features(*fabrics)) {
      for (int i = 0; i < sampler::kFeatureCount; ++i) d.measured_features[i].push_back(f[i]);
    }
    s["measured_fabrics"] = {{"file", csv}, {"distinct", d.measured_features[0].size()}};
  } else {
    s["measured_fabrics"] = {{"file", csv}, {"error", fabrics.error().message}};
  }
  for (int i = 0; i < sampler::kFeatureCount; ++i) {
    nlohmann::json entry = {{"run", summary(d.run_features[i])}};
    if (!d.measured_features.empty()) entry["measured"] = summary(d.measured_features[i]);
    params[sampler::kFeatureNames[i]] = entry;
  }
  s["parameters_sign_log"] = params;
  return d;
}

std::string histogram_svg(const std::string& title, const std::string& x_label,
                          const std::vector<std::pair<std::string, std::vector<double>>>& series) {
  double lo = 1e300, hi = -1e300;
  for (const auto& [name, v] : series) {
    for (double x : v) {
      if (!std::isfinite(x)) continue;
      lo = std::min(lo, x);
      hi = std::max(hi, x);
    }
  }
  const int width = 640, height = 400, left = 60, right = 20, top = 40, bottom = 60;
  std::string svg = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{}\" height=\"{}\" font-family=\"sans-serif\" "
      "font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
      "<text x=\"{}\" y=\"22\" font-size=\"15\" text-anchor=\"middle\">{}</text>\n",
      width, height, width / 2, title);
  if (lo > hi) {
    return svg + fmt::format("<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">no data</text>\n</svg>\n", width / 2,
                             height / 2);
  }
  if (hi - lo < 1e-12) {
    lo -= 0.5;
    hi += 0.5;
  }
  constexpr int bins = 20;
  const double bin_width = (hi - lo) / bins;
  std::vector<std::vector<double>> density;
  double peak = 0.0;
  for (const auto& [name, v] : series) {
    std::vector<double> h(bins, 0.0);
    int n = 0;
    for (double x : v) {
      if (!std::isfinite(x)) continue;
      h[std::min(bins - 1, static_cast<int>((x - lo) / bin_width))] += 1.0;
      ++n;
    }
    for (double& c : h) c = n > 0 ? c / n : 0.0;  // fraction per bin: series of different sizes compare
    for (double c : h) peak = std::max(peak, c);
    density.push_back(std::move(h));
  }
  const double plot_w = width - left - right, plot_h = height - top - bottom;
  const char* colours[] = {"#1f77b4", "#ff7f0e", "#2ca02c"};
  for (std::size_t k = 0; k < density.size(); ++k) {
    for (int b = 0; b < bins; ++b) {
      const double h = peak > 0 ? density[k][b] / peak * plot_h : 0.0;
      svg += fmt::format("<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"{:.1f}\" height=\"{:.1f}\" fill=\"{}\" "
                         "fill-opacity=\"0.55\"/>\n",
                         left + b * plot_w / bins, top + plot_h - h, plot_w / bins - 1, h, colours[k % 3]);
    }
    svg += fmt::format("<rect x=\"{}\" y=\"{}\" width=\"12\" height=\"12\" fill=\"{}\" fill-opacity=\"0.55\"/>"
                       "<text x=\"{}\" y=\"{}\">{} (n = {})</text>\n",
                       width - 230, top + 4 + 18 * k, colours[k % 3], width - 212, top + 15 + 18 * k,
                       series[k].first, series[k].second.size());
  }
  svg += fmt::format("<line x1=\"{0}\" y1=\"{1}\" x2=\"{2}\" y2=\"{1}\" stroke=\"black\"/>\n", left, top + plot_h,
                     left + plot_w);
  svg += fmt::format("<line x1=\"{0}\" y1=\"{1}\" x2=\"{0}\" y2=\"{2}\" stroke=\"black\"/>\n", left, top,
                     top + plot_h);
  for (int t = 0; t <= 4; ++t) {
    const double x = lo + (hi - lo) * t / 4.0;
    svg += fmt::format("<text x=\"{:.1f}\" y=\"{}\" text-anchor=\"middle\">{:.3g}</text>\n",
                       left + plot_w * t / 4.0, top + plot_h + 18, x);
  }
  svg += fmt::format("<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">{}</text>\n", left + plot_w / 2, height - 15,
                     x_label);
  svg += fmt::format("<text x=\"15\" y=\"{}\" transform=\"rotate(-90 15 {})\" text-anchor=\"middle\">fraction per "
                     "bin (tallest = {:.2f})</text>\n",
                     top + plot_h / 2, top + plot_h / 2, peak);
  return svg + "</svg>\n";
}

std::string fmt_number(const nlohmann::json& j, const char* key, const char* format = "{:.3g}") {
  if (!j.contains(key) || !j[key].is_number()) return "-";
  return fmt::format(fmt::runtime(format), j[key].get<double>());
}

}  // namespace

namespace {

/// The histograms of `d` as SVG files in `directory` (created); the files written.
sim::Expected<std::vector<std::string>> write_plots(const Data* d, const std::string& directory) {
  std::error_code ec;
  std::filesystem::create_directories(directory, ec);
  if (ec) return sim::Error{fmt::format("cannot create {}: {}", directory, ec.message()), /*io=*/true};
  std::vector<std::pair<std::string, std::string>> plots = {
      {"drape_coefficient.svg", histogram_svg("Drape coefficient", "Cusick drape coefficient", {{"run", d->dc}})},
      {"folds.svg", histogram_svg("Folds", "folds (nodes of the hem)", {{"run", d->folds}})},
      {"job_seconds.svg", histogram_svg("Time per job", "seconds (lease to result)", {{"run", d->seconds}})},
  };
  for (int i = 0; i < sampler::kFeatureCount; ++i) {
    std::vector<std::pair<std::string, std::vector<double>>> series = {{"run", d->run_features[i]}};
    if (!d->measured_features.empty()) series.emplace_back("measured fabrics", d->measured_features[i]);
    plots.emplace_back(fmt::format("param_{}.svg", sampler::kFeatureNames[i]),
                       histogram_svg(fmt::format("{} (run vs measured)", sampler::kFeatureNames[i]),
                                     "sign(k) ln|k| at 300 g/m^2", series));
  }
  std::vector<std::string> written;
  for (const auto& [name, svg] : plots) {
    const std::string path = (std::filesystem::path(directory) / name).string();
    if (sim::Status s = storage::write_file_atomic(path, svg); !s) return s.error();
    written.push_back(path);
  }
  return written;
}

}  // namespace

sim::Expected<nlohmann::json> compute_stats(const std::string& manifest_path, const StatsOptions& options) {
  auto d = gather(manifest_path, options);
  if (!d) return d.error();
  if (!options.plots_directory.empty()) {
    auto written = write_plots(&*d, options.plots_directory);
    if (!written) return written.error();
    d->stats["plots"] = *written;
  }
  return d->stats;
}

std::string format_stats(const nlohmann::json& s) {
  std::string out;
  const auto& states = s["jobs"]["by_state"];
  out += fmt::format("manifest {} (run {}, seed {}, bending model {}): {} jobs: {} done, {} failed, {} pending\n",
                     s["manifest"].get<std::string>(), s["run"]["state"].get<std::string>(),
                     s["run"]["seed"].get<std::uint64_t>(), s["run"]["bending_model"].get<std::string>(),
                     s["run"]["total_jobs"].get<std::int64_t>(),
                     states["done"].get<std::int64_t>(), states["failed"].get<std::int64_t>(),
                     states["pending"].get<std::int64_t>());
  if (!s["jobs"]["failed_by_reason"].empty() || s["jobs"]["failed_attempts"].get<std::int64_t>() > 0) {
    std::string reasons;
    for (const auto& [reason, count] : s["jobs"]["failed_by_reason"].items()) {
      reasons += fmt::format("{}{} {}", reasons.empty() ? "" : ", ", count.get<std::int64_t>(), reason);
    }
    std::string attempts;
    for (const auto& [reason, count] : s["jobs"]["failed_attempts_by_reason"].items()) {
      attempts += fmt::format("{}{} {}", attempts.empty() ? "" : ", ", count.get<std::int64_t>(), reason);
    }
    out += fmt::format("  failed jobs by reason: {}; failed attempts: {}\n", reasons.empty() ? "none" : reasons,
                       attempts.empty() ? "none" : attempts);
  }
  const auto& t = s["throughput"];
  out += fmt::format("  throughput: {:.0f} jobs/hour over {:.1f} s with attempts in flight ({:.1f} s from the first "
                     "lease to the last result); seconds per job: median {}, p95 {}\n",
                     t["jobs_per_hour"].get<double>(), t["active_seconds"].get<double>(),
                     t["wall_seconds_first_lease_to_last_result"].get<double>(),
                     fmt_number(s["seconds_per_job"], "median"), fmt_number(s["seconds_per_job"], "p95"));
  for (const auto& [name, w] : t["per_worker"].items()) {
    out += fmt::format("    worker {}: {} jobs, {:.1f} s busy, {:.0f} jobs/hour busy\n", name,
                       w["jobs"].get<std::int64_t>(), w["busy_seconds"].get<double>(),
                       w["jobs_per_hour_busy"].get<double>());
  }
  const auto& dc = s["drape_coefficient"];
  out += fmt::format("  drape coefficient: median {}, p05 {}, p95 {}; folds: median {}, range {}..{}\n",
                     fmt_number(dc, "median"), fmt_number(dc, "p05"), fmt_number(dc, "p95"),
                     fmt_number(s["folds"], "median"), fmt_number(s["folds"], "min"), fmt_number(s["folds"], "max"));
  out += "  parameters, sign(k) ln|k| at 300 g/m^2, median [p05, p95] of the run vs the measured fabrics:\n";
  for (const auto& [name, p] : s["parameters_sign_log"].items()) {
    out += fmt::format("    {:<10} run {} [{}, {}]", name, fmt_number(p["run"], "median", "{:.2f}"),
                       fmt_number(p["run"], "p05", "{:.2f}"), fmt_number(p["run"], "p95", "{:.2f}"));
    if (p.contains("measured")) {
      out += fmt::format("   measured {} [{}, {}]", fmt_number(p["measured"], "median", "{:.2f}"),
                         fmt_number(p["measured"], "p05", "{:.2f}"), fmt_number(p["measured"], "p95", "{:.2f}"));
    }
    out += "\n";
  }
  const auto& st = s["storage"];
  out += fmt::format("  storage: {} files, {:.2f} MB (meshes {:.2f} MB, EXR {:.2f} MB), manifest {:.2f} MB\n",
                     st["files"].get<std::int64_t>(), st["bytes"].get<double>() / 1e6,
                     st["mesh_bytes"].get<double>() / 1e6, st["exr_bytes"].get<double>() / 1e6,
                     st["manifest_bytes"].get<double>() / 1e6);
  return out;
}


}  // namespace drapegen::coordinator
