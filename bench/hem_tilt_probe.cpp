// The hem's tilt on every placement of benchmark captures. A specimen laid off the cylinder's axis hangs more cloth on
// one side, so its hem hangs lower there: the hem's height against the angle about the axis has a first harmonic of
// the order of the offset, on each placement however the specimen was turned (the offset's direction differs, its
// size does not). A centred elastic specimen's hem tilts only as far as its folds do. Prints, per capture and
// placement (NAME, NAME.p1, NAME.p2), that amplitude and the outline's own first harmonic (its centre off the axis),
// both as shape_features measures them from all views (ShapeFeatures::off_centre), as CSV rows. Reads the captures
// only, no report and no truth file: scripts/hem_tilt_rule.py lays the rule it suggests on the reports
// (docs/DIAGNOSIS_RESULTS.md, "Session 90").
#include <CLI/CLI.hpp>
#include <algorithm>
#include <filesystem>
#include <fmt/format.h>
#include <iostream>
#include <numeric>
#include <regex>
#include <string>
#include <vector>

#include "drapegen/diagnosis/capture.hpp"
#include "drapegen/diagnosis/shape_features.hpp"

namespace fs = std::filesystem;
using namespace drapegen;

int main(int argc, char** argv) {
  CLI::App app{"The hem's tilt (its height's first harmonic, mm) on every placement of benchmark captures, as CSV "
               "(docs/DIAGNOSIS_RESULTS.md, \"Session 90\")."};
  std::vector<std::string> sets;
  app.add_option("sets", sets, "benchmark sets (scripts/diagnosis_set.sh): each SET/captures/NAME[.pK] is read")
      ->required()
      ->check(CLI::ExistingDirectory);
  CLI11_PARSE(app, argc, argv);

  const std::regex later_placement(R"(.*\.p[0-9]+$)");
  std::cout << "set,capture,placement,hem_tilt_mm,outline_offset_mm\n";
  int failures = 0;
  for (const auto& set : sets) {
    const fs::path captures = fs::path(set) / "captures";
    if (!fs::is_directory(captures)) {
      fmt::print(stderr, "hem_tilt_probe: {} has no captures/ directory\n", set);
      return 2;
    }
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(captures)) {
      const std::string name = entry.path().filename().string();
      if (entry.is_directory() && !std::regex_match(name, later_placement)) names.push_back(name);
    }
    std::sort(names.begin(), names.end());
    for (const auto& name : names) {
      for (int placement = 0; placement < 3; ++placement) {
        const fs::path dir = captures / (placement == 0 ? name : fmt::format("{}.p{}", name, placement));
        if (!fs::is_directory(dir)) continue;  // a set of one placement: the capture alone
        const auto capture = diagnosis::read_capture(dir.string());
        if (!capture) {
          fmt::print(stderr, "hem_tilt_probe: {}: {}\n", dir.string(), capture.error().message);
          ++failures;
          continue;
        }
        std::vector<int> views(capture->views.size());
        std::iota(views.begin(), views.end(), 0);
        const auto f = diagnosis::shape_features(*capture, views);
        if (!f.valid || f.off_centre.size() != 2) {
          fmt::print(stderr, "hem_tilt_probe: {}: too little of the skirt seen for the whole outline\n", dir.string());
          ++failures;
          continue;
        }
        std::cout << fmt::format("{},{},{},{:.3f},{:.3f}\n", fs::path(set).filename().string(), name, placement,
                                 1e3 * f.off_centre[1], 1e3 * f.off_centre[0]);
      }
    }
  }
  return failures == 0 ? 0 : 1;
}
