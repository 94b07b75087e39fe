// How a specimen's placements differ in their drape coefficient. An elastic specimen lifted, turned over and laid
// again drapes from the same distribution of stable states each time; a yielding one carries the creases of its
// earlier drapes into the next (turned over, they stand against the drape), and a curled edge rolls to the other face.
// Prints each case's drape coefficient (Cusick's, from the capture's back-projected outline: hem_profile_from_capture)
// on its three placements (NAME, NAME.p1, NAME.p2) and the truth's where a truth file is there; with --model, the
// spread an elastic specimen's drape coefficient has over stable states: the diagnosis's fitted bending (its report's
// baseline) draped from the attribution's validation states, each drape's coefficient measured as the diagnosis
// measures it (from the outline its noisy renders show, ForwardModel::views_drape_coefficient). Reads
// the truth files only to print the family and the true coefficients: a benchmark tool (docs/DIAGNOSIS_RESULTS.md,
// "Session 73").
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fmt/format.h>
#include <iostream>
#include <optional>

#include "drapegen/diagnosis/attribution.hpp"
#include "drapegen/diagnosis/bending_json.hpp"
#include "drapegen/diagnosis/capture.hpp"
#include "drapegen/diagnosis/diagnosis.hpp"
#include "drapegen/diagnosis/forward_model.hpp"
#include "drapegen/diagnosis/hem_profile.hpp"
#include "drapegen/sim/blas_kernels.hpp"
#include "json_file.hpp"

namespace fs = std::filesystem;
using namespace drapegen;

namespace {

/// The drape coefficients of the report's fitted baseline draped from the attribution's validation states.
sim::Expected<std::vector<double>> model_coefficients(const diagnosis::Capture& capture, const fs::path& report_file) {
  const auto report = bench::read_json(report_file);
  if (!report) return report.error();
  const auto settings = diagnosis::DiagnosisSettings::fine();
  auto model = diagnosis::ForwardModel::create(capture, settings.fit);
  if (!model) return model.error();
  auto fitted = diagnosis::bending_from_json(report->at("baseline").at("fitted"), "report baseline.fitted");
  if (!fitted) return fitted.error();
  diagnosis::ModelSetup setup;
  setup.bending = *fitted;
  std::vector<double> dc;
  for (const auto& state : diagnosis::validation_states(settings.attribution)) {
    auto mesh = (*model)->simulate(setup, state);
    if (!mesh) return mesh.error();
    auto scored = (*model)->score(*mesh, setup);
    if (!scored) return scored.error();
    dc.push_back(scored->drape_coefficient);
  }
  return dc;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Drape coefficients of every placement of benchmark captures (docs/DIAGNOSIS_RESULTS.md, "
               "\"Session 73\")."};
  std::vector<std::string> runs;
  sim::relaunch_with_blas_kernels(argv);  // the kernels drapegen runs on (blas_kernels.hpp)
  int placements = 3;
  std::string model_reports;
  app.add_option("runs", runs, "benchmark run directories (captures/ and truth/ inside)")->required();
  app.add_option("--placements", placements, "placements per case (NAME, NAME.p1, ...)")
      ->capture_default_str()
      ->check(CLI::Range(1, 9));
  app.add_option("--model", model_reports, "the runs' folder of diagnosis reports: print the fitted model's drape "
                                           "coefficients over the validation states (simulates)");
  CLI11_PARSE(app, argc, argv);

  fmt::print("{:<6} {:<18} {:<13}", "run", "case", "family");
  for (int p = 0; p < placements; ++p) fmt::print(" {:>7} {:>7}", fmt::format("dc{}", p), fmt::format("true{}", p));
  if (!model_reports.empty()) fmt::print(" {:>7} {:>7} {:>7}  model", "m_min", "m_max", "m_sd");
  fmt::print("\n");
  for (const std::string& run : runs) {
    std::vector<fs::path> dirs;
    for (const auto& e : fs::directory_iterator(fs::path(run) / "captures"))
      if (e.is_directory() && e.path().extension().empty()) dirs.push_back(e.path());
    std::sort(dirs.begin(), dirs.end());
    for (const fs::path& dir : dirs) {
      std::string family = "none";
      fmt::memory_buffer row;
      std::optional<diagnosis::Capture> first;  // placement 0: the one the report's fit was made on
      for (int p = 0; p < placements; ++p) {
        const std::string name = dir.filename().string() + (p > 0 ? fmt::format(".p{}", p) : "");
        const auto capture = diagnosis::read_capture((dir.parent_path() / name).string());
        if (!capture) {
          std::cerr << capture.error().message << "\n";
          return 1;
        }
        const double dc = diagnosis::drape_coefficient(*capture);
        double truth = std::nan("");
        if (const auto t = bench::read_json(fs::path(run) / "truth" / (name + ".json"))) {
          family = t->value("family", "none");
          truth = t->value("drape_coefficient", std::nan(""));
        }
        fmt::format_to(std::back_inserter(row), " {:>7.4f} {:>7.4f}", dc, truth);
        if (p == 0) first = *capture;
      }
      if (!model_reports.empty()) {
        const auto report = fs::path(run) / model_reports / (dir.filename().string() + ".json");
        const auto dc = model_coefficients(*first, report);
        if (!dc || dc->empty()) {
          std::cerr << dir.string() << ": " << (dc ? std::string("no validation states") : dc.error().message)
                    << "\n";
          continue;
        }
        double mean = 0.0, sq = 0.0;
        for (double x : *dc) mean += x / static_cast<double>(dc->size());
        for (double x : *dc) sq += (x - mean) * (x - mean) / std::max<double>(1.0, dc->size() - 1.0);
        fmt::format_to(std::back_inserter(row), " {:>7.4f} {:>7.4f} {:>7.4f} ",
                       *std::min_element(dc->begin(), dc->end()), *std::max_element(dc->begin(), dc->end()),
                       std::sqrt(sq));
        for (double x : *dc) fmt::format_to(std::back_inserter(row), " {:.4f}", x);
      }
      fmt::print("{:<6} {:<18} {:<13}{}\n", fs::path(run).filename().string(), dir.filename().string(), family,
                 fmt::to_string(row));
      std::fflush(stdout);
    }
  }
  return 0;
}
