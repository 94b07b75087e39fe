// Whether a specimen's placements remember where it folded: the hem outlines of placements 0, 1, 2 of benchmark
// captures (drapegen_diagnosis_bench --placements 3), their fold content (orders above kOrientationOrders) turned into
// the cloth's own frame with the truth's orientation, and correlated pair by pair. A yielding specimen is laid again
// with the creases its earlier drapes left (docs/CAPTURE.md, "A second capture"); an elastic one keeps nothing. Also
// the blind statistic a diagnosis could compute: the best correlation over every turn (the orientation unknown).
// Reads truth files: a probe of the generator, never part of a diagnosis.

#include <CLI/CLI.hpp>
#include <cmath>
#include <filesystem>
#include <optional>
#include <algorithm>
#include <nlohmann/json.hpp>

#include <fmt/core.h>

#include "json_file.hpp"
#include "drapegen/diagnosis/bending_json.hpp"
#include "drapegen/diagnosis/capture.hpp"
#include "drapegen/diagnosis/diagnosis.hpp"
#include "drapegen/diagnosis/fold_repeatability.hpp"
#include "drapegen/diagnosis/forward_model.hpp"
#include "drapegen/diagnosis/hem_profile.hpp"
#include "drapegen/sim/median.hpp"

namespace dg = drapegen::diagnosis;

namespace {

double correlation(const dg::HemProfile& a, const dg::HemProfile& b) {
  double ab = 0, aa = 0, bb = 0;
  for (int k = 0; k < a.bins(); ++k) {
    if (!std::isfinite(a.radius[k]) || !std::isfinite(b.radius[k])) continue;
    ab += a.radius[k] * b.radius[k], aa += a.radius[k] * a.radius[k], bb += b.radius[k] * b.radius[k];
  }
  return aa > 0 && bb > 0 ? ab / std::sqrt(aa * bb) : 0.0;
}

/// The model's own repeatability: the elastic setup (the truth's fabric without its effect, or the diagnosis's fit)
/// draped from sine states at the fine fitting mesh (those of the validation: seeds 2001..); every pair's
/// fold_correlation. Returns min, median.
std::pair<double, double> model_repeatability(const dg::Capture& capture, const dg::BendingParameters& bending,
                                              int states) {
  dg::FitSettings fit = dg::DiagnosisSettings::fine().fit;
  auto model = dg::ForwardModel::create(capture, fit);
  if (!model) return {NAN, NAN};
  dg::ModelSetup setup;
  setup.bending = bending;
  const std::vector<drapegen::sim::InitialStateSpec> all = dg::fit_initial_states(states + 1, 2000);
  const std::vector<drapegen::sim::InitialStateSpec> sine(all.begin() + 1, all.end());
  std::vector<drapegen::sim::ClothMesh> drapes;
  for (const auto& st : sine) {
    auto mesh = (*model)->simulate(setup, st);
    if (!mesh) return {NAN, NAN};
    drapes.push_back(std::move(*mesh));
  }
  std::vector<double> c = dg::fold_repeatability({}, drapes).model;
  std::sort(c.begin(), c.end());
  return {c.front(), drapegen::sim::median(c)};
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Fold memory between a specimen's placements (a probe of the reality generator; reads truth files)"};
  std::vector<std::string> runs;
  app.add_option("runs", runs, "Benchmark directories (captures/NAME{,.p1,.p2}, truth/NAME{,.p1,.p2}.json)")
      ->required();
  std::string setup = "none";
  int states = 6;
  app.add_option("--model", setup,
                 "Also the elastic model's repeatability: none, truth (the true fabric without its effect) or fitted "
                 "(diagnoses/NAME.json's baseline fit)")
      ->check(CLI::IsMember({"none", "truth", "fitted"}));
  app.add_option("--states", states, "Sine states of the model (default 6)")->check(CLI::Range(2, 50));
  CLI11_PARSE(app, argc, argv);
  fmt::print("{:<28} {:>8} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7}\n", "case", "set_rad", "true01", "true02",
             "true12", "blind01", "blind02", "blind12", "mod_min", "mod_med");
  for (const std::string& run : runs) {
    for (const auto& entry : std::filesystem::directory_iterator(run + "/captures")) {
      const std::string name = entry.path().filename().string();
      if (name.find(".p") != std::string::npos) continue;
      std::vector<dg::HemProfile> cloth, world;
      std::optional<dg::Capture> first;
      std::optional<dg::BendingParameters> bending;
      double set = 0.0;
      bool ok = true;
      for (const std::string suffix : {"", ".p1", ".p2"}) {
        auto capture = dg::read_capture(run + "/captures/" + name + suffix);
        const auto truth_file = drapegen::bench::read_json(run + "/truth/" + name + suffix + ".json");
        if (!capture || !truth_file) {
          fmt::print(stderr, "memory_probe: {}/{}{} skipped: {}\n", run, name, suffix,
                     !capture ? capture.error().message : truth_file.error().message);
          ok = false;
          break;
        }
        const nlohmann::json& truth = *truth_file;
        const nlohmann::json::json_pointer turn("/initial_state/rotation_rad");
        if (!truth.contains(turn) || !truth[turn].is_number()) {
          fmt::print(stderr, "memory_probe: {}/{}{} skipped: its truth file has no initial_state.rotation_rad\n", run,
                     name, suffix);
          ok = false;
          break;
        }
        const double rotation = truth[turn].get<double>();
        if (!first) {
          first = *capture;
          if (setup == "truth") {
            auto b = dg::bending_from_json(truth, "truth");
            if (b)
              bending = *b;
            else
              fmt::print(stderr, "memory_probe: {}/{}: no true model: {}\n", run, name, b.error().message);
          }
          if (setup == "fitted") {
            const auto report = drapegen::bench::read_json(run + "/diagnoses/" + name + ".json");
            if (!report)
              fmt::print(stderr, "memory_probe: {}/{}: no fitted model: {}\n", run, name, report.error().message);
            else if (auto fitted = dg::bending_from_json(
                         report->value(nlohmann::json::json_pointer("/baseline/fitted"), nlohmann::json::object()),
                         "fitted"))
              bending = *fitted;
          }
        }
        if (truth.contains("plastic_set")) set = truth["plastic_set"].value("largest_rest_angle_rad", NAN);
        const dg::HemProfile f = dg::hem_profile_from_capture(*capture);
        world.push_back(f);
        cloth.push_back(dg::fold_content(dg::rotate(f, -rotation)));
      }
      if (!ok) continue;
      auto blind = [&](int i, int j) { return dg::fold_correlation(world[i], world[j]); };
      const auto [mod_min, mod_med] =
          bending ? model_repeatability(*first, *bending, states) : std::pair<double, double>{NAN, NAN};
      fmt::print("{:<28} {:>8.2f} {:>7.2f} {:>7.2f} {:>7.2f} {:>7.2f} {:>7.2f} {:>7.2f} {:>7.2f} {:>7.2f}\n",
                 std::filesystem::path(run).filename().string() + "/" + name, set, correlation(cloth[0], cloth[1]),
                 correlation(cloth[0], cloth[2]), correlation(cloth[1], cloth[2]), blind(0, 1), blind(0, 2),
                 blind(1, 2), mod_min, mod_med);
    }
  }
  return 0;
}
