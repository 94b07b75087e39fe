// drapegen sample: parameter vectors from the VAE subspace and their initial-state recipes (paper Sections 5.1.3 and
// 5.2.1), or, with --report, how well the sampler covers the measured fabrics.
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <vector>
#include <nlohmann/json.hpp>

#include <fmt/format.h>

#include "commands.hpp"
#include "failure.hpp"
#include "drapegen/sampler/coverage.hpp"
#include "drapegen/sampler/fabric_data.hpp"
#include "drapegen/sampler/parameter_sampler.hpp"
#include "drapegen/sampler/recipe_generator.hpp"
#include "drapegen/sampler/scatter_plot.hpp"
#include "drapegen/storage/atomic_file.hpp"
#include "drapegen/storage/json_text.hpp"
#include "parse.hpp"

namespace drapegen::cli {
namespace {

struct SampleOptions {
  int n = 6000;
  std::uint64_t seed = 0;
  std::string out;
  std::string model;
  bool json = false;
  std::string recipes;
  int states = 8;
  double max_drift_mm = 3.0;
  double range_margin = 0.1;
  double duplicate_distance = 1e-3;
  bool report = false;
  std::string data = sampler::default_fabric_data_path();
  std::string plot = "coverage.png";
  std::string plot_x = "alpha_warp";
  std::string plot_y = "beta_warp";
  int iw_samples = 1000;
  bool no_plot = false;
};

const Failure fail{"sample"};

int feature_index(const std::string& name) {
  for (int i = 0; i < sampler::kFeatureCount; ++i) {
    if (name == sampler::kFeatureNames[i]) return i;
  }
  return -1;
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// The parameters as CSV text (written whole, atomically: a failed write leaves the old file, not half a table).
std::string parameters_csv(const sampler::SampledParameters& s) {
  std::string out = "sample";
  for (const char* name : sampler::kFeatureNames) out += fmt::format(",{}", name);
  out += "\n";
  for (std::size_t i = 0; i < s.vectors.size(); ++i) {
    const auto& v = s.vectors[i];
    out += fmt::format("{},{},{},{},{},{},{}\n", i, v.alpha.warp, v.alpha.bias, v.alpha.weft, v.beta.warp,
                       v.beta.bias, v.beta.weft);
  }
  return out;
}

int run_sample(const SampleOptions& o, const sampler::VaeModel& model, const std::string& model_path) {
  if (o.out.empty()) return fail("--out FILE is required (or use --report)");
  sampler::RecipeOptions recipe_options;
  recipe_options.seed = o.seed;
  recipe_options.states_per_sample = o.states;
  recipe_options.max_drift_mm = o.max_drift_mm;
  if (sim::Status s = sampler::validate(recipe_options); !s) return fail(s.error().message);
  // An output over an input would destroy it (the model read, then replaced by a CSV).
  if (!o.model.empty()) {
    for (const auto& [name, path] : {std::pair{"--out", o.out}, {"--recipes", o.recipes}}) {
      if (!path.empty() && same_file(path, o.model)) return fail(fmt::format("{} {} is the model file", name, path));
    }
  }
  if (sim::Status s = check_writable(o.out); !s) return fail(s.error().message, kExitIo);
  if (!o.recipes.empty()) {
    if (same_file(o.out, o.recipes)) return fail("--out and --recipes name the same file");
    if (sim::Status s = check_writable(o.recipes); !s) return fail(s.error().message, kExitIo);
  }
  const auto start = std::chrono::steady_clock::now();
  sampler::SamplerOptions options;
  options.count = o.n;
  options.seed = o.seed;
  options.range_margin = o.range_margin;
  options.duplicate_distance = o.duplicate_distance;
  auto sampled = sampler::sample_parameters(model, options);
  if (!sampled) return fail(sampled.error().message);
  const double sample_seconds = seconds_since(start);
  std::int64_t kinds[3] = {0, 0, 0};
  std::string recipes;
  for (int i = 0; !o.recipes.empty() && i < o.n; ++i) {
    for (const auto& r : sampler::make_recipes_in_order(recipe_options, i)) {
      ++kinds[static_cast<int>(r.kind)];
      recipes += sampler::to_text(r) + "\n";
    }
  }
  // Both files as one set: a failed write leaves both as they were (no new recipes beside old parameters).
  const std::string parameters = parameters_csv(*sampled);
  std::vector<storage::FileBytes> files{{o.out, parameters}};
  if (!o.recipes.empty()) files.push_back({o.recipes, recipes});
  if (sim::Status s = storage::write_files_atomic(files); !s) return fail(s.error().message, kExitIo);
  nlohmann::json summary{{"samples", o.n},
                         {"seed", o.seed},
                         {"model", model_path},
                         {"candidates", sampled->candidates},
                         {"rejected_outside_range", sampled->rejected_range},
                         {"rejected_near_duplicate", sampled->rejected_duplicate},
                         {"parameters", o.out},
                         {"units", "alpha g*mm^2/s^2, beta g*mm^3/s^2, at 300 g/m^2 (multiply by rho/300)"},
                         {"sampling_seconds", sample_seconds}};
  if (!o.recipes.empty()) {
    summary["recipes"] = o.recipes;
    summary["recipes_per_sample"] = o.states;
    summary["recipe_kinds"] = {{"sine", kinds[0]}, {"fold", kinds[1]}, {"drape", kinds[2]}};
  }
  std::ostream& out = summary_stream({o.out, o.recipes});  // not over a file written to standard output
  if (o.json) {
    out << storage::json_text(summary) << "\n";
  } else {
    out << fmt::format("sampled {} parameter vectors (seed {}) from {} candidates: {} outside the range, {} "
                             "near-duplicates; written to {}\n",
                             o.n, o.seed, sampled->candidates, sampled->rejected_range, sampled->rejected_duplicate,
                             o.out);
    if (!o.recipes.empty()) {
      out << fmt::format("  {} initial-state recipes ({} sine, {} fold, {} drape) written to {}\n",
                               o.n * o.states, kinds[0], kinds[1], kinds[2], o.recipes);
    }
  }
  return kExitOk;
}

int run_report(const SampleOptions& o, const sampler::VaeModel& model, const std::string& model_path) {
  const int x = feature_index(o.plot_x), y = feature_index(o.plot_y);
  if (x < 0 || y < 0) {
    return fail("--plot-x/--plot-y must name a feature: alpha_warp, alpha_bias, alpha_weft, beta_warp, beta_bias, "
                "beta_weft");
  }
  if (o.iw_samples < 3 || o.iw_samples > 100000) return fail("--iw-samples must be 3..100000");
  auto fabrics = sampler::read_fabric_csv(o.data);
  if (!fabrics) return fail(fabrics.error().message);
  const auto data = sampler::distinct_features(*fabrics);
  if (o.n < static_cast<int>(data.size())) {
    return fail(fmt::format("--n must be at least the number of distinct fabrics ({}) for the Wasserstein distance",
                            data.size()));
  }
  if (!o.plot.empty()) {
    if (same_file(o.plot, o.data)) return fail(fmt::format("--plot {} is the --data file", o.plot));
    if (!o.model.empty() && same_file(o.plot, o.model)) return fail(fmt::format("--plot {} is the model file", o.plot));
    if (sim::Status s = check_writable(o.plot); !s) return fail(s.error().message, kExitIo);
  }
  struct Row {
    std::string name;
    sampler::SamplerOptions options;
    sampler::WassersteinResult w;
    sampler::SampledParameters samples;
  };
  std::vector<Row> rows(3);
  rows[0].name = "prior N(0,1), decoder means, no rejection";
  rows[0].options.latent = sampler::LatentSampling::kPrior;
  rows[0].options.reject = false;
  rows[1].name = "paper's widened sampling, no rejection";
  rows[1].options.reject = false;
  rows[2].name = "sampler output (widened, range and duplicate rejection)";
  rows[2].options.range_margin = o.range_margin;
  rows[2].options.duplicate_distance = o.duplicate_distance;
  for (Row& row : rows) {
    row.options.count = o.n;
    row.options.seed = o.seed;
    auto s = sampler::sample_parameters(model, row.options);
    if (!s) return fail(s.error().message);
    row.samples = std::move(s).value();
    row.w = sampler::wasserstein_exact(row.samples.features, data);
  }
  const double ll = sampler::mean_log_likelihood(model, data, o.iw_samples, o.seed);
  std::string plot_caption;
  if (!o.plot.empty()) {
    sampler::ScatterPlotSpec spec;
    spec.x_feature = x;
    spec.y_feature = y;
    if (sim::Status s = sampler::write_scatter_png(o.plot, spec, rows[2].samples.features, data); !s) {
      return fail(s.error().message, kExitIo);
    }
    plot_caption = fmt::format("{}: x = sign(k) ln|k| of {}, y = of {} (k normalised to 300 g/m^2, paper units); "
                               "blue: the {} sampler output vectors, orange: the {} distinct measured fabrics",
                               o.plot, o.plot_x, o.plot_y, o.n, data.size());
  }
  if (o.json) {
    nlohmann::json j{{"model", model_path},
                     {"data", o.data},
                     {"fabric_rows", fabrics->size()},
                     {"distinct_fabrics", data.size()},
                     {"seed", o.seed},
                     {"generated", o.n},
                     {"space", "sign(k) ln|k| of alpha (g*mm^2/s^2) and beta (g*mm^3/s^2) at 300 g/m^2"},
                     {"log_likelihood", {{"value", ll},
                                         {"estimator", fmt::format("importance sampling, K = {} draws from 1/3 q(z|x) "
                                                                   "+ 1/3 q(z|x) widened 3x + 1/3 N(0,I), mean over "
                                                                   "the distinct fabrics, nats/fabric",
                                                                   o.iw_samples)}}}};
    for (const Row& row : rows) {
      j["wasserstein"].push_back({{"sampling", row.name},
                                  {"w1", row.w.mean},
                                  {"w1_std_over_chunks", row.w.stddev},
                                  {"chunks", row.w.chunks},
                                  {"candidates", row.samples.candidates},
                                  {"rejected_outside_range", row.samples.rejected_range},
                                  {"rejected_near_duplicate", row.samples.rejected_duplicate}});
    }
    j["wasserstein_solver"] = "exact W1, Euclidean cost, optimal assignment per chunk of generated vectors the size of "
                              "the data, mean over the disjoint chunks";
    if (!plot_caption.empty()) j["plot"] = plot_caption;
    std::cout << storage::json_text(j) << "\n";
    return kExitOk;
  }
  std::cout << fmt::format("coverage of {} distinct fabrics ({} rows of {}) by {}, seed {}, {} generated vectors\n",
                           data.size(), fabrics->size(), o.data, model_path, o.seed, o.n);
  std::cout << "space: sign(k) ln|k| of alpha (g*mm^2/s^2) and beta (g*mm^3/s^2), normalised to 300 g/m^2\n\n";
  std::cout << fmt::format("{:<66} {:>9}\n", "metric", "value");
  std::cout << fmt::format("{:<66} {:>9.3f}\n",
                           fmt::format("log-likelihood, importance sampling K={}, nats/fabric", o.iw_samples), ll);
  for (const Row& row : rows) {
    std::cout << fmt::format("{:<66} {:>9.3f}  (+- {:.3f} over {} chunks)\n", "W1 exact: " + row.name, row.w.mean,
                             row.w.stddev, row.w.chunks);
  }
  std::cout << fmt::format("\nsampler output: {} candidates, {} outside the range (data range widened by {:.0f}% per "
                           "side), {} near-duplicates (closer than {} in standardised features)\n",
                           rows[2].samples.candidates, rows[2].samples.rejected_range, 100 * o.range_margin,
                           rows[2].samples.rejected_duplicate, o.duplicate_distance);
  if (!plot_caption.empty()) std::cout << "plot: " << plot_caption << "\n";
  return kExitOk;
}

int run(const SampleOptions& o) {
  if (o.n <= 0) return fail(fmt::format("--n must be positive, got {}", o.n));
  if (o.n > 10'000'000) return fail("--n must be at most 10000000");
  if (!(o.range_margin >= 0.0 && o.range_margin <= 10.0)) return fail("--range-margin must be 0..10");
  if (!(o.duplicate_distance == 0.0 || (o.duplicate_distance >= 1e-6 && o.duplicate_distance <= 10.0)))
    return fail("--duplicate-distance must be 0 (off) or 1e-6..10");
  if (o.states < 1 || o.states > sampler::kMaxStatesPerSample) {
    return fail(fmt::format("--states must be 1..{}, got {}", sampler::kMaxStatesPerSample, o.states));
  }
  if (!(o.max_drift_mm >= 0.0 && o.max_drift_mm <= sampler::kMaxDriftMm)) {
    return fail(fmt::format("--max-drift must be 0..{} (mm)", sampler::kMaxDriftMm));
  }
  const std::string model_path = o.model.empty() ? "built-in (sampler/models/vae3.dgvae)" : o.model;
  auto model = o.model.empty() ? sampler::builtin_vae_model() : sampler::load_vae_model(o.model);
  if (!model) return fail(model.error().message);
  return o.report ? run_report(o, *model, model_path) : run_sample(o, *model, model_path);
}

}  // namespace

Runner add_sample_command(CLI::App& app) {
  auto o = std::make_shared<SampleOptions>();
  app.add_option("--n", o->n, "Number of parameter vectors")->capture_default_str();
  app.add_option("--seed", o->seed, "Seed of the latents and the recipes (0 is a seed like any other)")
      ->check(kSeed)
      ->capture_default_str();
  auto* out = app.add_option("--out", o->out,
                             "Write the parameter vectors to this CSV file (paper units at 300 g/m^2)");
  app.add_option("--model", o->model,
                 "VAE model file (default: the committed sampler/models/vae3.dgvae, built into the program)");
  app.add_flag("--json", o->json, "Print the summary (or the report) as JSON");
  auto* recipes =
      app.add_option("--recipes", o->recipes, "Write the initial-state recipes, one line each, to this file");
  app.add_option("--states", o->states, "Initial states per parameter vector")->capture_default_str();
  app.add_option("--max-drift", o->max_drift_mm, "Largest drift of the specimen centre, mm")->capture_default_str();
  app.add_option("--range-margin", o->range_margin, "Widen the data range by this fraction per side")
      ->capture_default_str();
  app.add_option("--duplicate-distance", o->duplicate_distance,
                 "Reject vectors closer than this to an accepted one (standardised features)")
      ->capture_default_str();
  auto* report = app.add_flag("--report", o->report, "Report the coverage of the measured fabrics instead of sampling");
  // The report writes no samples, and its own options mean nothing without it: given in the wrong mode, an error
  // rather than silently ignored.
  out->excludes(report);
  recipes->excludes(report);
  app.add_option("--data", o->data, "--report: the measured fabrics (fabrics618.csv)")
      ->capture_default_str()
      ->needs(report);
  app.add_option("--plot", o->plot, "--report: scatter plot PNG")->capture_default_str()->needs(report);
  app.add_flag("--no-plot", o->no_plot, "--report: no scatter plot")->needs(report);
  app.add_option("--plot-x", o->plot_x, "--report: feature on the plot's x axis")->capture_default_str()->needs(report);
  app.add_option("--plot-y", o->plot_y, "--report: feature on the plot's y axis")->capture_default_str()->needs(report);
  app.add_option("--iw-samples", o->iw_samples, "--report: importance samples per fabric")
      ->capture_default_str()
      ->needs(report);
  return [o] {
    if (o->no_plot) o->plot.clear();
    return run(*o);
  };
}

}  // namespace drapegen::cli
