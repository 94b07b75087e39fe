// Does the baseline fit absorb an effect, or does the coarse fitting mesh hide it? For each diagnosed capture of a
// benchmark run, the capture is scored (as the diagnosis scores its gap: the validation states, --fine's forward
// model) against three setups:
//   fitted  the diagnosis's fitted bending, no effect (reproduces the reported gap);
//   truth   the true bending (truth file), no effect;
//   oracle  the true bending with the true effect (simulated effects only: yield, shear, curl, friction).
// If "truth" is far above the floor and "fitted" within it, the fit absorbed the effect into the bending parameters;
// if even "oracle" is not below "fitted", the fitting mesh and the multistability hide the effect from any refit.
// Each cell also gives (after "m") the captures' mean shape features (placements 0 and 1 / placement 0 alone) against
// the mean over the validation drapes. For a yield capture with a second placement, a second line scores that
// placement against the truth, the oracle laid again unloaded and the oracle laid again with its plastic set (and a
// third line the held-out placement captures/NAME.p2, with the set of both earlier placements), and
// with --yield-levels the true bending at each yield curvature against both placements. With --curl-levels, a curl
// capture with a held-out placement (captures/NAME.p2) is scored at each edge curvature with the true bending and the
// curl refit's, against the capture, the second placement (the refit's objective) and the held-out one.
// --resolution changes the forward model's mesh (default --fine's).
// Reads the truth files, so it is a benchmark tool, never part of the diagnosis.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fmt/format.h>
#include <iostream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>

#include "drapegen/diagnosis/bending_json.hpp"
#include "drapegen/diagnosis/candidate_effect.hpp"
#include "drapegen/diagnosis/diagnosis.hpp"
#include "drapegen/diagnosis/forward_model.hpp"
#include "drapegen/sim/blas_kernels.hpp"
#include "drapegen/sim/median.hpp"
#include "json_file.hpp"

namespace fs = std::filesystem;
using namespace drapegen;
using nlohmann::json;

namespace {

using bench::read_json;

/// The truth file's (first) effect: its name and strength; none for a control.
std::optional<std::pair<std::string, double>> first_effect(const json& truth) {
  if (!truth.contains("effects") || truth.at("effects").empty()) return std::nullopt;
  const json& e = truth.at("effects").at(0);
  return std::pair{e.at("name").get<std::string>(), e.at("strength").get<double>()};
}

/// The true effect in the refit's parameters (effect_space), for the effects a simulation carries.
std::optional<std::pair<diagnosis::Effect, std::vector<double>>> true_effect(const json& truth) {
  const auto effect = first_effect(truth);
  if (!effect) return std::nullopt;
  const auto& [name, s] = *effect;
  if (name == "yield") return std::pair{diagnosis::Effect::kYield, std::vector<double>{std::log(s)}};
  if (name == "shear") return std::pair{diagnosis::Effect::kShear, std::vector<double>{std::log(s)}};
  if (name == "curl") return std::pair{diagnosis::Effect::kCurl, std::vector<double>{s}};
  if (name == "friction") return std::pair{diagnosis::Effect::kFriction, std::vector<double>{std::log(s)}};
  return std::nullopt;
}

struct Scores {
  double best_shape = 0.0, best_stable = 0.0, median_shape = 0.0;
  /// The mean features of the captures (placements 0 and 1, or 0 alone) against the mean over the states' drapes.
  double mean_shape = 0.0, mean_shape_p0 = 0.0;
  int best_state = 0;  // index into the states of the best drape
};

/// Entry by entry mean of feature vectors (entries missing or NaN in one are left out of that entry's mean).
std::vector<double> mean_entries(const std::vector<const std::vector<double>*>& v) {
  std::size_t n = 0;
  for (const auto* x : v) n = std::max(n, x->size());
  std::vector<double> m(n, std::numeric_limits<double>::quiet_NaN());
  for (std::size_t i = 0; i < n; ++i) {
    double sum = 0.0;
    int count = 0;
    for (const auto* x : v) {
      if (i < x->size() && std::isfinite((*x)[i])) {
        sum += (*x)[i];
        ++count;
      }
    }
    if (count > 0) m[i] = sum / count;
  }
  return m;
}

diagnosis::ShapeFeatures mean_features(const std::vector<const diagnosis::ShapeFeatures*>& f) {
  diagnosis::ShapeFeatures m;
  const auto field = [&](auto member) {
    std::vector<const std::vector<double>*> v;
    for (const auto* x : f) v.push_back(&(x->*member));
    return mean_entries(v);
  };
  m.harmonics = field(&diagnosis::ShapeFeatures::harmonics);
  m.off_centre = field(&diagnosis::ShapeFeatures::off_centre);
  m.sorted_radii = field(&diagnosis::ShapeFeatures::sorted_radii);
  m.hem_height = field(&diagnosis::ShapeFeatures::hem_height);
  m.skirt_height = field(&diagnosis::ShapeFeatures::skirt_height);
  m.skirt_spread = field(&diagnosis::ShapeFeatures::skirt_spread);
  m.valid = true;
  for (const auto* x : f) {
    m.folds += x->folds / static_cast<double>(f.size());
    m.valid = m.valid && x->valid;
  }
  return m;
}

sim::Expected<Scores> score(diagnosis::ForwardModel& model, const diagnosis::ModelSetup& setup,
                            const std::vector<sim::InitialStateSpec>& states,
                            const diagnosis::ShapeFeatures* second_capture) {
  auto e = model.evaluate(setup, states);
  if (!e) return e.error();
  std::vector<double> shapes;
  std::vector<const diagnosis::ShapeFeatures*> drapes;
  for (const auto& s : e->states) {
    shapes.push_back(s.shape_all);
    drapes.push_back(&s.shape.all);
  }
  const auto model_mean = mean_features(drapes);
  const auto scales = diagnosis::default_feature_scales();
  const auto& first = model.target().shape.all;
  Scores r{e->best.shape_all, e->best.stable_all * 1e3, sim::median(shapes)};
  r.best_state = e->best.state;
  r.mean_shape_p0 = diagnosis::feature_distance(first, model_mean, scales);
  r.mean_shape = second_capture
                     ? diagnosis::feature_distance(mean_features({&first, second_capture}), model_mean, scales)
                     : r.mean_shape_p0;
  return r;
}

/// A yielding specimen's second placement (captures/NAME.p1: the diagnosis's second capture, fitted with the first
/// under the three-placement protocol) against the true bending without the effect, the
/// oracle as if the specimen were laid again unloaded, and the oracle laid again with the plastic set that its best
/// drape against the capture (`oracle_best_state`) left: what the diagnosis's yield candidate does. The set comes
/// from `model`, the capture's own (its face: a set made on the second placement's face would not fight a
/// turned-over drape; before session 63 it was, and the oracle looked unable to reproduce a turned placement).
/// With `third` (captures/NAME.p2, the diagnosis's held-out capture), the same three setups there, the oracle laid
/// again with the set its best drape on the second placement left (after the capture's): what the yield candidate's
/// validation on the held-out capture does.
sim::Status probe_yield_second(diagnosis::ForwardModel& model, diagnosis::ForwardModel& second,
                               diagnosis::ForwardModel* third, const diagnosis::ModelSetup& elastic,
                               const std::vector<sim::InitialStateSpec>& states, const diagnosis::ModelSetup& oracle,
                               int oracle_best_state) {
  auto laid = model.laid_again(oracle, states.at(static_cast<std::size_t>(oracle_best_state)));
  if (!laid) return laid.error();
  const diagnosis::ModelSetup& creased = *laid;
  // The three setups' best drapes on `on`, as cells; the last one's evaluation (the creased oracle's).
  std::string cells;
  const auto score_three = [&](diagnosis::ForwardModel& on,
                               const diagnosis::ModelSetup& last) -> sim::Expected<diagnosis::Evaluation> {
    cells.clear();
    sim::Expected<diagnosis::Evaluation> e = sim::Error{"no setup"};
    for (const diagnosis::ModelSetup* setup : {&elastic, &oracle, &last}) {
      e = on.evaluate(*setup, states);
      if (!e) return e.error();
      cells += fmt::format(" {:.2f} [{:.2f}]", e->best.shape_all, e->best.stable_all * 1e3);
    }
    return e;
  };
  auto on_second = score_three(second, creased);
  if (!on_second) return on_second.error();
  std::cout << fmt::format("  second placement: truth, oracle unloaded, oracle with its set (largest {:.2f} rad):{}\n",
                           creased.plastic_set.rest_angles.cwiseAbs().maxCoeff(), cells)
            << std::flush;
  if (third == nullptr) return {};
  // The set after the capture and the second placement.
  const diagnosis::ModelSetup creased_twice = diagnosis::ForwardModel::laid_again(creased, on_second->best);
  if (auto on_third = score_three(*third, creased_twice); !on_third) return on_third.error();
  std::cout << fmt::format("  third placement ({}): truth, oracle unloaded, oracle with both sets (largest {:.2f} "
                           "rad):{}\n",
                           third->capture().face_down ? "face down" : "face up",
                           creased_twice.plastic_set.rest_angles.cwiseAbs().maxCoeff(), cells)
            << std::flush;
  return {};
}

/// Is the yield curvature observable on the two placements? The true bending with yield curvature K, for each K:
/// its best drape against the capture, and laid again with that drape's set, its best against the second placement.
sim::Status probe_yield_levels(diagnosis::ForwardModel& model, diagnosis::ForwardModel& second,
                               const diagnosis::ModelSetup& elastic, const std::vector<sim::InitialStateSpec>& states,
                               const std::vector<double>& levels) {
  for (const double k : levels) {
    diagnosis::ModelSetup setup = elastic;
    setup.effects.bending_yield_curvature = k;
    auto first = model.evaluate(setup, states);
    if (!first) return first.error();
    // The set its best drape on the capture left (evaluate keeps it), as the diagnosis's yield candidate lays it.
    const diagnosis::ModelSetup laid = diagnosis::ForwardModel::laid_again(setup, first->best);
    auto on_second = second.evaluate(laid, states);
    if (!on_second) return on_second.error();
    std::cout << fmt::format("  yield {:>6.1f} /m: capture {:.2f}, second placement {:.2f}, mean {:.2f}\n", k,
                             first->best.shape_all, on_second->best.shape_all,
                             0.5 * (first->best.shape_all + on_second->best.shape_all))
              << std::flush;
  }
  return {};
}

/// The fold counts of an evaluation's drapes, in state order.
std::string fold_counts(const diagnosis::Evaluation& e) {
  std::string counts;
  for (const auto& d : e.states) counts += fmt::format("{}{:.0f}", counts.empty() ? "" : " ", d.shape.all.folds);
  return counts;
}

/// Does the curl's curvature decide which stable drapes a placement can reach? For each curvature K, the `bending`
/// with edge curl K from the validation states: its best drape against the capture and against the held-out
/// placement (placement 2), the curl refit's objective over the same states (the mean of the best fit scores on the
/// capture and on the second placement; the refit itself uses the fit's fewer states), and every drape's fold count.
/// On a placement that lies on the capture's face the capture's drapes are re-scored; on the other face, simulated
/// there (the curl turns over).
sim::Status probe_curl_levels(diagnosis::ForwardModel& model, diagnosis::ForwardModel* second,
                              diagnosis::ForwardModel& held_out, const diagnosis::ModelSetup& bending,
                              const std::string& label, const std::vector<sim::InitialStateSpec>& states,
                              const std::vector<double>& levels) {
  for (const double k : levels) {
    diagnosis::ModelSetup setup = bending;
    if (k != 0.0) diagnosis::apply_effect(diagnosis::Effect::kCurl, {k}, setup);
    auto first = model.evaluate(setup, states);
    if (!first) return first.error();
    std::vector<sim::ClothMesh> meshes;
    for (const auto& d : first->states) meshes.push_back(d.mesh);
    const auto on = [&](diagnosis::ForwardModel& placement) {
      return placement.capture().face_down == model.capture().face_down ? placement.rescore(meshes, setup)
                                                                          : placement.evaluate(setup, states);
    };
    auto other = on(held_out);
    if (!other) return other.error();
    std::string objective;
    if (second) {
      auto on_second = on(*second);
      if (!on_second) return on_second.error();
      objective = fmt::format(" objective {:.2f} mm (second {:.2f}, folds {});",
                              0.5e3 * (first->best.fit_score + on_second->best.fit_score),
                              on_second->best.fit_score * 1e3, fold_counts(*on_second));
    }
    std::cout << fmt::format("  {} curl {:>6.1f} /m:{} capture shape {:.2f} all {:.2f} mm; held-out shape {:.2f} all "
                             "{:.2f} mm; folds {} | {}\n",
                             label, k, objective, first->best.shape_all, first->best.all_score * 1e3,
                             other->best.shape_all, other->best.all_score * 1e3, fold_counts(*first),
                             fold_counts(*other))
              << std::flush;
  }
  return {};
}

/// The forward model of the capture in `directory`.
sim::Expected<std::unique_ptr<diagnosis::ForwardModel>> open_model(const fs::path& directory,
                                                                  const diagnosis::FitSettings& fit) {
  auto capture = diagnosis::read_capture(directory.string());
  if (!capture) return capture.error();
  return diagnosis::ForwardModel::create(*capture, fit);
}

/// One row: the capture against its fitted (if diagnosed), true and oracle setups.
sim::Status probe_case(const fs::path& run, const std::string& name, const diagnosis::DiagnosisSettings& settings,
                       const std::vector<sim::InitialStateSpec>& states, const std::vector<double>& yield_levels,
                       const std::vector<double>& curl_levels) {
  const auto truth = read_json(run / "truth" / (name + ".json"));
  if (!truth) return truth.error();
  // Without a diagnosis (captures generated only), the fitted column stays empty.
  const auto report = read_json(run / "diagnoses" / (name + ".json"));
  auto model = open_model(run / "captures" / name, settings.fit);
  if (!model) return model.error();
  // The second placement, if the run has one: its shape features (in its own cameras).
  std::optional<diagnosis::ShapeFeatures> second;
  std::unique_ptr<diagnosis::ForwardModel> held_out;
  if (fs::exists(run / "captures" / (name + ".p1"))) {
    auto m1 = open_model(run / "captures" / (name + ".p1"), settings.fit);
    if (!m1) return m1.error();
    held_out = std::move(*m1);
    second = held_out->target().shape.all;
  }
  const diagnosis::ShapeFeatures* p1 = second ? &*second : nullptr;
  const auto cell = [](const sim::Expected<Scores>& s) {
    return s ? fmt::format("{:.2f} [{:.2f}] {:.1f} m{:.2f}/{:.2f}", s->best_shape, s->median_shape, s->best_stable,
                           s->mean_shape, s->mean_shape_p0)
             : std::string("error");
  };
  std::string fitted = "-", reported = "-";
  if (report) {
    diagnosis::ModelSetup setup;
    auto fitted_bending = diagnosis::bending_from_json(report->at("baseline").at("fitted"), "report baseline.fitted");
    if (!fitted_bending) return fitted_bending.error();
    setup.bending = *fitted_bending;
    fitted = cell(score(**model, setup, states, p1));
    reported = fmt::format("{:.2f}", report->at("gap_tests").at("capture").at("shape").get<double>());
  }
  diagnosis::ModelSetup truth_setup;
  auto true_bending = diagnosis::bending_from_json(*truth, "truth");
  if (!true_bending) return true_bending.error();
  truth_setup.bending = *true_bending;
  const auto without = score(**model, truth_setup, states, p1);
  if (!without) return without.error();
  std::string oracle = "-";
  diagnosis::ModelSetup with = truth_setup;
  std::optional<sim::Expected<Scores>> with_scores;
  if (const auto simulated = true_effect(*truth)) {
    diagnosis::apply_effect(simulated->first, simulated->second, with);
    with_scores = score(**model, with, states, p1);
    oracle = cell(*with_scores);
  }
  const auto effect = first_effect(*truth);
  const double strength = effect ? effect->second : 0.0;
  std::cout << fmt::format("{:<16} {:>8.3g} {:>34} {:>34} {:>34} {:>9}\n", name, strength, fitted, cell(without),
                           oracle, reported)
            << std::flush;
  const bool yield_probe = held_out && effect && effect->first == "yield" && with_scores && *with_scores;
  const bool curl_probe = effect && effect->first == "curl" && !curl_levels.empty();
  // The held-out placement, if the run has one and a probe below reads it.
  std::unique_ptr<diagnosis::ForwardModel> third;
  if (const fs::path p2 = run / "captures" / (name + ".p2"); (yield_probe || curl_probe) && fs::exists(p2)) {
    auto m2 = open_model(p2, settings.fit);
    if (!m2) return m2.error();
    third = std::move(*m2);
  }
  if (yield_probe) {
    if (sim::Status s = probe_yield_second(**model, *held_out, third.get(), truth_setup, states, with,
                                           (*with_scores)->best_state);
        !s) {
      return s;
    }
    if (sim::Status s = probe_yield_levels(**model, *held_out, truth_setup, states, yield_levels); !s) return s;
  }
  if (curl_probe && third) {
    std::cout << fmt::format("  folds: capture {:.0f}, held-out placement {:.0f} ({})\n",
                             (*model)->target().shape.all.folds, third->target().shape.all.folds,
                             third->capture().face_down ? "face down" : "face up");
    // Placement 1 (`held_out` above, the yield probe's second placement) is the diagnosis's second capture here.
    diagnosis::ForwardModel* second_placement = held_out.get();
    if (sim::Status s =
            probe_curl_levels(**model, second_placement, *third, truth_setup, "truth ", states, curl_levels);
        !s) {
      return s;
    }
    // The diagnosis's curl refit's bending: the fitted bending times the curl candidate's scale.
    if (report) {
      for (const json& c : report->at("attribution").at("candidates")) {
        if (c.at("effect") != "curl") continue;
        diagnosis::ModelSetup refitted;
        auto fitted_bending =
            diagnosis::bending_from_json(report->at("baseline").at("fitted"), "report baseline.fitted");
        if (!fitted_bending) return fitted_bending.error();
        const double scale = c.at("alpha_scale").get<double>();
        refitted.bending = diagnosis::scaled(*fitted_bending, scale);
        const std::string label = fmt::format("refit x{:.2f}", scale);
        if (sim::Status s = probe_curl_levels(**model, second_placement, *third, refitted, label, states, curl_levels);
            !s) {
          return s;
        }
      }
    }
  }
  return {};
}

}  // namespace

int main(int argc, char** argv) {
  drapegen::sim::relaunch_with_blas_kernels(argv);  // the kernels drapegen runs on (blas_kernels.hpp)
  CLI::App app{"drapegen absorption probe: a capture against its fitted, true and true-with-effect setups"};
  std::string run;
  std::vector<std::string> cases;
  app.add_option("--run", run, "A drapegen_diagnosis_bench output (captures/, truth/, diagnoses/)")->required();
  app.add_option("--cases", cases, "Case names (default: every placement-0 capture with a truth file)");
  auto settings = diagnosis::DiagnosisSettings::fine();
  app.add_option("--resolution", settings.fit.resolution,
                 "Vertices per side of the forward model's mesh (default: --fine's)")
      ->check(CLI::Range(8, 200));
  std::vector<double> yield_levels;
  app.add_option("--yield-levels", yield_levels,
                 "For yield captures with a second placement: the true bending with each of these yield curvatures "
                 "(1/m), scored against the capture and, laid again with its set, against the second placement")
      ->check(CLI::PositiveNumber);
  std::vector<double> curl_levels;
  app.add_option("--curl-levels", curl_levels,
                 "For curl captures with a held-out placement (captures/NAME.p2): the true bending, and the curl "
                 "refit's if diagnosed, with each of these edge curvatures (1/m; 0: none) from the validation states, "
                 "against the capture and the held-out placement, with every drape's fold count");
  CLI11_PARSE(app, argc, argv);
  if (cases.empty()) {
    // Every placement-0 capture that has a truth file (captures/NAME.pK are other placements).
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(fs::path(run) / "captures", ec)) {
      const std::string name = entry.path().filename().string();
      if (entry.is_directory() && name.find('.') == std::string::npos &&
          fs::exists(fs::path(run) / "truth" / (name + ".json"))) {
        cases.push_back(name);
      }
    }
    if (ec) {
      std::cerr << "absorption_probe: error: " << ec.message() << ": " << run << "/captures\n";
      return 1;
    }
    std::sort(cases.begin(), cases.end());
  }
  const auto states = diagnosis::validation_states(settings.attribution);
  std::cout << "shape distance over all views (best of " << states.size()
            << " validation states, median in brackets), stable term mm; forward model ("
            << settings.fit.resolution << "x" << settings.fit.resolution << ")\n";
  std::cout << fmt::format("{:<16} {:>8} {:>34} {:>34} {:>34} {:>9}\n", "case", "strength", "fitted", "truth", "oracle",
                           "reported");
  int failed = 0;
  for (const auto& name : cases) {
    try {
      if (sim::Status s = probe_case(fs::path(run), name, settings, states, yield_levels, curl_levels); !s) {
        std::cerr << "absorption_probe: " << name << ": " << s.error().message << "\n";
        ++failed;
      }
    } catch (const json::exception& e) {  // a truth or report file without the expected fields
      std::cerr << "absorption_probe: " << name << ": " << e.what() << "\n";
      ++failed;
    }
  }
  if (failed > 0) std::cerr << "absorption_probe: " << failed << " of " << cases.size() << " cases failed\n";
  return failed > 0 ? 1 : 0;
}
