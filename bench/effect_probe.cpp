// Can the reality generator's effects be seen at all? For a few fabrics, captures with each effect and without
// (several seeds: initial state, orientation, noise) are reduced to the fold-placement-invariant shape features
// (shape_features.hpp); per feature group, the median difference between an effect capture and a control of the same
// fabric is printed beside the median difference between two controls (the multistability + noise spread). An
// effect whose differences do not exceed the controls' cannot be detected by any method that fits the fabric.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <filesystem>
#include <fmt/format.h>
#include <iostream>

#include "drapegen/diagnosis/reality.hpp"
#include "drapegen/diagnosis/shape_features.hpp"
#include "drapegen/sampler/fabric_data.hpp"
#include "drapegen/sim/blas_kernels.hpp"
#include "drapegen/sim/median.hpp"

namespace fs = std::filesystem;
using namespace drapegen;

int main(int argc, char** argv) {
  drapegen::sim::relaunch_with_blas_kernels(argv);  // the kernels drapegen runs on (blas_kernels.hpp)
  CLI::App app{"drapegen effect probe: effect vs control differences of the shape features"};
  std::string fabrics_path = DRAPEGEN_FABRIC_DATA_DEFAULT, work = "out/effect_probe";
  std::vector<int> fabric_rows{0, 2};
  std::vector<std::string> effects{"yield=15", "shear=0.5", "curl=40", "friction=0.05", "misalign=20", "stiff=0.7",
                                   "stiff=1.4"};
  int seeds = 4, resolution = 30;
  app.add_option("--fabrics", fabrics_path)->capture_default_str();
  app.add_option("--rows", fabric_rows, "Fabric rows of the CSV")->capture_default_str();
  app.add_option("--effects", effects,
                 "NAME=STRENGTH, A+B for several in one capture (stiff=S: no effect, bending scaled by S)")
      ->capture_default_str();
  app.add_option("--seeds", seeds)->capture_default_str();
  app.add_option("--resolution", resolution)->capture_default_str();
  app.add_option("--work", work)->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  const auto fabrics = sampler::read_fabric_csv(fabrics_path);
  if (!fabrics) {
    std::cerr << "effect_probe: error: " << fabrics.error().message << "\n";
    return 1;
  }

  std::cout << "group differences in mm (folds: count); control: median over control pairs, effect: median over "
               "(effect, control) pairs\n";
  std::cout << fmt::format("{:>6} {:>16}", "fabric", "config");
  for (auto g : diagnosis::kFeatureGroups) std::cout << fmt::format(" {:>12}", diagnosis::feature_group_name(g));
  std::cout << "\n";
  for (int row : fabric_rows) {
    if (row < 0 || row >= static_cast<int>(fabrics->size())) {
      std::cerr << "effect_probe: error: no fabric row " << row << "\n";
      return 1;
    }
    const auto& fabric = (*fabrics)[static_cast<std::size_t>(row)];
    const diagnosis::BendingParameters bending{fabric.moduli.alpha, fabric.moduli.beta};
    const double density = fabric.density_g_per_m2;
    auto features_of = [&](const std::string& effect, int seed) -> diagnosis::ShapeFeatures {
      diagnosis::RealitySpec spec;
      spec.bending = bending;
      spec.density = density;
      spec.resolution = resolution;
      spec.seed = static_cast<std::uint64_t>(seed);
      if (effect.rfind("stiff=", 0) == 0) {
        spec.bending = diagnosis::scaled(spec.bending, std::stod(effect.substr(6)));
      } else {
        // A+B: several effects in one capture (e.g. friction=0.02+misalign=10: friction with a placement drift).
        for (std::size_t from = 0; from < effect.size();) {
          const std::size_t plus = std::min(effect.find('+', from), effect.size());
          auto e = diagnosis::parse_reality_effect(effect.substr(from, plus - from));
          if (!e) throw std::runtime_error(e.error().message);
          spec.effects.push_back(*e);
          from = plus + 1;
        }
      }
      const std::string dir = fmt::format("{}/f{}_{}_{}", work, row, effect.empty() ? "none" : effect, seed);
      auto r = diagnosis::generate_reality(spec, dir);
      if (!r) throw std::runtime_error(r.error().message);
      auto c = diagnosis::read_capture(dir);
      if (!c) throw std::runtime_error(c.error().message);
      return diagnosis::shape_features(*c, {0, 1, 2, 3});
    };
    std::vector<diagnosis::ShapeFeatures> controls;
    for (int s = 1; s <= seeds; ++s) controls.push_back(features_of("", s));
    auto print = [&](const std::string& name, const std::vector<std::vector<double>>& diffs) {
      std::cout << fmt::format("{:>6} {:>16}", row, name);
      for (int g = 0; g < diagnosis::kFeatureGroupCount; ++g) {
        std::vector<double> v;
        for (const auto& d : diffs)
          if (d[g] >= 0.0) v.push_back(d[g]);
        const double m = sim::median(v);
        const double unit = g == static_cast<int>(diagnosis::FeatureGroup::kFolds) ? diagnosis::kFoldScale : 1e-3;
        std::cout << fmt::format(" {:>12.2f}", m / unit);
      }
      std::cout << "\n" << std::flush;
    };
    std::vector<std::vector<double>> cc;
    for (int i = 0; i < seeds; ++i)
      for (int j = i + 1; j < seeds; ++j) cc.push_back(diagnosis::group_differences(controls[i], controls[j]));
    print("control", cc);
    for (const auto& e : effects) {
      std::vector<std::vector<double>> ec;
      for (int s = 1; s <= seeds; ++s) {
        const auto f = features_of(e, 100 + s);
        for (const auto& c : controls) ec.push_back(diagnosis::group_differences(f, c));
      }
      print(e, ec);
    }
  }
  return 0;
}
