#include "drapegen/diagnosis/diagnosis.hpp"

#include <algorithm>
#include <chrono>
#include <ctime>
#include <filesystem>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>
#include <nlohmann/json.hpp>

#include <fmt/format.h>

#include "drapegen/diagnosis/bending_json.hpp"
#include "drapegen/diagnosis/hem_profile.hpp"
#include "drapegen/diagnosis/shape_features.hpp"
#include "drapegen/sim/logging.hpp"

namespace drapegen::diagnosis {
namespace {

double since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

/// CPU seconds this process has used so far, all threads.
double process_cpu_seconds() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

ModelSetup baseline_setup(const ReducedBending& x) {
  ModelSetup s;
  s.bending = from_reduced(x);
  return s;
}

/// The initial guess: the drape coefficient of the capture's outline against that of isotropic drapes at a few
/// stiffness levels (flat start; alpha 1500 .. 100000 at 300 g/m^2, scaled with the density), interpolated in
/// ln(alpha).
sim::Expected<ReducedBending> initial_guess(ForwardModel& model, int levels) {
  const HemProfile& outline = model.outline();
  const double target = drape_coefficient(outline, model.capture().specimen);
  const double density = model.capture().specimen.density;
  const ReducedBending lo = reduced_lower(density), hi = reduced_upper(density);
  const double scale = stiffness_scale(density);
  const double a0 = std::log(1500.0 * scale), a1 = std::log(100000.0 * scale);
  std::vector<std::pair<double, double>> samples;  // (ln alpha, drape coefficient)
  for (int k = 0; k < levels; ++k) {
    const double la = levels > 1 ? a0 + (a1 - a0) * k / (levels - 1) : 0.5 * (a0 + a1);
    ReducedBending x{la, 0.0, 0.0, 2.5};
    auto mesh = model.simulate(baseline_setup(x), model.initial_states().front());
    if (!mesh) return mesh.error();
    samples.emplace_back(la, drape_coefficient(hem_profile_from_mesh(*mesh), model.capture().specimen));
  }
  double la = samples.front().first;
  if (target <= samples.front().second) {
    la = samples.front().first;
  } else if (target >= samples.back().second) {
    la = samples.back().first;
  } else {
    for (std::size_t k = 0; k + 1 < samples.size(); ++k) {
      const auto& [x0, d0] = samples[k];
      const auto& [x1, d1] = samples[k + 1];
      if ((target - d0) * (target - d1) <= 0.0 && d1 != d0) {
        la = x0 + (x1 - x0) * (target - d0) / (d1 - d0);
        break;
      }
    }
  }
  for (const auto& [x, d] : samples) {
    sim::logger()->debug("initial guess: alpha {:.0f} -> drape coefficient {:.3f}", std::exp(x), d);
  }
  sim::logger()->debug("initial guess: the capture's drape coefficient {:.3f} -> alpha {:.0f}", target, std::exp(la));
  return ReducedBending{std::clamp(la, lo[0], hi[0]), 0.0, 0.0, 2.5};
}

nlohmann::json view_json(const ScoredDrape& d) {
  nlohmann::json views = nlohmann::json::array();
  for (std::size_t k = 0; k < d.views.size(); ++k) {
    const auto& v = d.views[k];
    views.push_back({{"score_mm", v.score * 1e3},
                     {"stable_rms_mm", v.stable_rms * 1e3},
                     {"stable_px", v.stable_pixels},
                     {"depth_rms_mm", v.depth_rms * 1e3},
                     {"silhouette_mismatch", v.silhouette},
                     {"fold_rms_deg", v.fold_rms_deg},
                     {"overlap_px", v.overlap}});
  }
  return views;
}

nlohmann::json groups_json(const std::vector<double>& d) {
  nlohmann::json g = nlohmann::json::object();
  for (std::size_t k = 0; k < d.size() && k < static_cast<std::size_t>(kFeatureGroupCount); ++k) {
    g[std::string(feature_group_name(kFeatureGroups[k]))] = d[k] < 0.0 ? -1.0 : d[k] * 1e3;
  }
  return g;
}

nlohmann::json spread_json(const ValidationSpread& s) {
  nlohmann::json capture_groups = nlohmann::json::array(), pair_groups = nlohmann::json::array();
  for (const auto& d : s.capture_groups) capture_groups.push_back(groups_json(d));
  for (std::size_t i = 0; i < s.pairwise_groups.size(); ++i) {
    for (std::size_t j = i + 1; j < s.pairwise_groups[i].size(); ++j) {
      pair_groups.push_back({{"i", i}, {"j", j}, {"groups_mm", groups_json(s.pairwise_groups[i][j])}});
    }
  }
  return {{"capture_shape", s.capture_distance},
          {"capture_groups_mm", capture_groups},
          {"pairwise_shape", s.pairwise},
          {"nearest_other_shape", s.nearest_other},
          {"pairwise_groups_mm", pair_groups}};
}

nlohmann::json multipath_json(const MultipathTest& t, const std::vector<DiagnosisResult::Placement>& placements) {
  nlohmann::json each = nlohmann::json::array();
  for (std::size_t k = 0; k < t.placements.size(); ++k) {
    const ViewConsistency& c = t.placements[k];
    each.push_back({{"role", k < placements.size() ? placements[k].role : ""},
                    {"gain_mm", c.gain * 1e3},
                    {"standard_error_mm", c.standard_error * 1e3},
                    {"offset_mm", c.offset * 1e3},
                    {"rms_mm", c.rms * 1e3},
                    {"pixels", c.pixels}});
  }
  return {{"placements", each},
          {"smallest_gain_mm", t.smallest_gain() * 1e3},
          {"threshold_mm", t.threshold * 1e3},
          {"multipath", t.detected()}};
}

nlohmann::json repeatability_json(const FoldRepeatability& f) {
  auto least = [](const std::vector<double>& v) {
    return v.empty() ? nlohmann::json(nullptr) : nlohmann::json(*std::min_element(v.begin(), v.end()));
  };
  return {{"capture_pairs", f.capture}, {"capture_min", least(f.capture)}, {"model_pairs", f.model},
          {"model_min", least(f.model)}, {"model_placement_pairs", f.model_placements},
          {"folds_less_alike", folds_less_alike(f)}};
}

/// Lengths in metres as a JSON array of millimetres.
nlohmann::json millimetres(const std::vector<double>& metres) {
  nlohmann::json mm = nlohmann::json::array();
  for (double x : metres) mm.push_back(x * 1e3);
  return mm;
}

/// A setup's validation drapes against another placement (null without one): the best (chosen by that capture's fit
/// views) and every drape's all-views score (`all_scores`, m; validation states' order).
nlohmann::json placement_json(const ScoredDrape* best, const std::vector<double>& all_scores) {
  if (!best) return nullptr;
  return {{"stable_mm", best->stable_all * 1e3},
          {"shape", best->shape_all},
          {"all_views_score_mm", best->all_score * 1e3},
          {"best_validation_state", best->state},
          {"validation_all_views_scores_mm", millimetres(all_scores)},
          {"drape_coefficient", best->capture_drape_coefficient},
          {"model_drape_coefficient", best->median_drape_coefficient}};
}
nlohmann::json placement_json(const std::optional<Evaluation>& e) {
  return e ? placement_json(&e->best, e->all_scores()) : nullptr;
}
nlohmann::json placement_json(const std::optional<OtherPlacement>& p) {
  return p ? placement_json(&p->best, p->all_scores) : nullptr;
}

/// A refitted candidate (or the bar) from the validation states: its drape against the capture, against the other
/// placements if any (with the plastic set a yielding candidate starts from there), and the gate's excess.
nlohmann::json validated_json(const CandidateResult& c, const Floors& floors) {
  auto set_json = [](const std::optional<OtherPlacement>& p) {
    return p && p->plastic_set ? nlohmann::json(*p->plastic_set) : nlohmann::json(nullptr);
  };
  auto direction_json = [](const std::optional<OtherPlacement>& p) {
    return p && p->drift_direction ? nlohmann::json(*p->drift_direction * 180.0 / M_PI) : nlohmann::json(nullptr);
  };
  return {{"stable_mm", c.validated.stable_all * 1e3},
          {"shape", c.validated.shape_all},
          {"model_drape_coefficient", c.validated.median_drape_coefficient},
          {"held_out_score_mm", c.validated.held_out_score * 1e3},
          {"second_capture", placement_json(c.second)},
          {"second_plastic_set_rad", set_json(c.second)},
          {"second_drift_direction_deg", direction_json(c.second)},
          {"held_out_capture", placement_json(c.held_out)},
          {"held_out_plastic_set_rad", set_json(c.held_out)},
          {"held_out_drift_direction_deg", direction_json(c.held_out)},
          {"excess_above_floors", c.validated_excess(floors)}};
}

/// How a candidate was confirmed (null: not at all).
nlohmann::json confirmed_by_json(Confirmation how) {
  switch (how) {
    case Confirmation::kScore:
      return "held_out_score";
    case Confirmation::kWithinFloors:
      return "held_out_within_floors";
    case Confirmation::kNone:
      break;
  }
  return nullptr;
}

/// A candidate's ablation (null without one): validated as the candidate is, with its refit objective (where the bar's
/// search would rank that bending scale).
nlohmann::json ablated_json(const CandidateResult& c, const Floors& floors) {
  if (!c.ablated) return nullptr;
  nlohmann::json j = validated_json(*c.ablated, floors);
  j["objective_mm"] = c.ablated->objective * 1e3;
  return j;
}

/// The common bending of unlike effects each within the floors (null where fewer did): their effects, the median
/// scale and its validation.
nlohmann::json common_bending_json(const Attribution& a, const Floors& floors) {
  if (!a.common_bending) return nullptr;
  nlohmann::json effects = nlohmann::json::array();
  for (Effect e : a.common_effects) effects.push_back(effect_name(e));
  return {{"effects", effects},
          {"alpha_scale", a.common_bending->alpha_scale},
          {"validated", validated_json(*a.common_bending, floors)},
          {"shrinkage", a.common_bending->shrinkage},
          {"within_floors", a.common_within_floors}};
}

/// `drape` (scored against the capture) localised against `floors`, with the camera error the rigid surfaces show
/// (`camera_moved`, m): the baseline's gap and each refit's alike.
Localisation localise_drape(const ForwardModel& model, const ScoredDrape& drape, const Floors& floors,
                            double camera_moved) {
  Localisation l = localise(model, drape);
  l.camera_moved = camera_moved;
  localise_against_floors(l, floors.region_floor());
  localise_features(l, drape, model.target(), floors.group_floor(), floors.stable_floor());
  return l;
}

/// A refit's validated drape localised as the baseline's gap is (unset where it has no pixel residuals).
std::optional<Localisation> localise_refit(const ForwardModel& model, const DiagnosisResult& r,
                                           const ScoredDrape& drape) {
  if (drape.views.empty()) return std::nullopt;
  return localise_drape(model, drape, r.floors, r.localisation.camera_moved);
}

/// Where a refit leaves the gap (null: not localised): the region place_gap says, what leads, and each feature
/// group's, the stable term's and each region's ratio to its floor.
nlohmann::json refit_localisation_json(const std::optional<Localisation>& l) {
  if (!l) return nullptr;
  nlohmann::json groups = nlohmann::json::object(), regions = nlohmann::json::object();
  for (std::size_t k = 0; k < l->group_ratio.size(); ++k)
    groups[std::string(feature_group_name(kFeatureGroups[k]))] = l->group_ratio[k];
  for (const auto& s : l->regions) regions[std::string(region_name(s.region))] = s.floor_ratio;
  return {{"region", region_name(l->dominant)},
          {"dominant_feature",
           l->dominant_feature.empty() ? nlohmann::json(nullptr) : nlohmann::json(l->dominant_feature)},
          {"stable_ratio", l->stable_ratio},
          {"group_ratios", groups},
          {"region_floor_ratios", regions},
          {"floor_region", region_name(l->floor_region)}};
}

}  // namespace

DiagnosisSettings DiagnosisSettings::quick() {
  DiagnosisSettings s;
  s.fit.resolution = 16;
  s.fit.initial_states = 2;
  s.fit.max_newton_iterations = 150;
  s.baseline_optimiser.max_evaluations = 20;
  s.guess_levels = 3;
  s.floors.noise_seeds = 2;
  s.floors.extra_states = 3;
  s.attribution.optimiser.max_evaluations = 14;
  s.attribution.sensor_evaluations = 100;
  s.attribution.bootstrap_samples = 400;
  return s;
}

DiagnosisSettings DiagnosisSettings::fine() {
  DiagnosisSettings s = quick();
  s.fit.resolution = kFineResolution;
  s.floors.shape_threshold = kFineShapeFloor;
  s.held_out_shape_threshold = kFineHeldOutShapeFloor;
  s.turn_over_yield = kFineTurnOverYield;
  return s;
}

sim::Status check_same_specimen(const Capture& capture, const Capture& other, std::string_view role) {
  const SpecimenFacts &a = capture.specimen, &b = other.specimen;
  auto differs = [](double x, double y) { return std::abs(x - y) > 1e-9 * std::max(1.0, std::abs(x)); };
  if (differs(a.size_x, b.size_x) || differs(a.size_y, b.size_y) || differs(a.density, b.density) ||
      differs(a.cylinder_diameter, b.cylinder_diameter)) {
    return sim::Error{fmt::format("{} {}: another specimen or tester ({}x{} mm, {} g/m^2, cylinder {} mm; "
                                  "the capture: {}x{} mm, {} g/m^2, cylinder {} mm)",
                                  role, other.directory, b.size_x * 1e3, b.size_y * 1e3, b.density,
                                  b.cylinder_diameter * 1e3, a.size_x * 1e3, a.size_y * 1e3, a.density,
                                  a.cylinder_diameter * 1e3)};
  }
  std::error_code ec;
  if (std::filesystem::equivalent(capture.directory, other.directory, ec) && !ec) {
    return sim::Error{fmt::format("{} {}: the capture itself (it must be another placement)", role, other.directory)};
  }
  // A copy of the capture: every view's depth the same (a re-placement, even re-captured, differs in its noise).
  const auto same_depth = [](const CaptureView& x, const CaptureView& y) { return x.depth.depth == y.depth.depth; };
  const bool copy = capture.views.size() == other.views.size() &&
                    std::equal(capture.views.begin(), capture.views.end(), other.views.begin(), same_depth);
  if (copy) {
    return sim::Error{fmt::format("{} {}: the same depth in every view as the capture (a copy of it; it must be "
                                  "another placement)",
                                  role, other.directory)};
  }
  return {};
}

namespace {

// The diagnosis on settings.fit.resolution's mesh (diagnose() adds the confirming mesh's).
sim::Expected<DiagnosisResult> diagnose_on_mesh(const Capture& capture, const DiagnosisSettings& settings,
                                                const OtherPlacements& others) {
  const auto start = std::chrono::steady_clock::now();
  const double cpu_start = process_cpu_seconds();
  if (others.second) {
    if (sim::Status s = check_same_specimen(capture, *others.second, "second capture"); !s) return s.error();
  }
  if (others.held_out) {
    if (sim::Status s = check_same_specimen(capture, *others.held_out); !s) return s.error();
    std::error_code ec;
    if (others.second && std::filesystem::equivalent(others.second->directory, others.held_out->directory, ec) && !ec) {
      return sim::Error{fmt::format("held-out capture {}: the second capture too (data in a fit is not held out)",
                                    others.held_out->directory)};
    }
  }
  auto created = ForwardModel::create(capture, settings.fit);
  if (!created) return created.error();
  ForwardModel& model = **created;
  std::unique_ptr<ForwardModel> second_model, held_out_model;
  for (auto [placement, made] :
       {std::pair{others.second, &second_model}, std::pair{others.held_out, &held_out_model}}) {
    if (!placement) continue;
    auto m = ForwardModel::create(*placement, settings.fit);
    if (!m) return m.error();
    *made = std::move(*m);
  }
  // Until the refits (which run settings.attribution.jobs at a time, each simulating on refit_state_threads threads),
  // every evaluation simulates its initial states on attribution.jobs threads.
  const auto set_threads = [&](int threads) {
    for (ForwardModel* m : {&model, second_model.get(), held_out_model.get()})
      if (m != nullptr) m->set_threads(threads);
  };
  set_threads(settings.attribution.jobs);
  DiagnosisResult r;
  r.placements.push_back({"capture", capture.directory, capture.face_down});
  if (others.second) r.placements.push_back({"second_capture", others.second->directory, others.second->face_down});
  if (others.held_out) {
    r.placements.push_back({"held_out_capture", others.held_out->directory, others.held_out->face_down});
  }
  r.budgets = {settings.fit.resolution, settings.fit.initial_states, settings.baseline_optimiser.max_evaluations,
               settings.attribute};
  // 0. The camera from the rigid surfaces (no simulation): the sensor candidate's start.
  if (auto pose = estimate_rigid_pose(capture, RigidSurfaces::for_specimen(capture.specimen))) {
    r.rigid_pose = *pose;
  } else {
    r.rigid_pose_error = pose.error().message;
    sim::logger()->warn("{}: the sensor candidate starts from the recorded camera", r.rigid_pose_error);
  }

  // 1. Baseline fit in the reduced space, from the drape-coefficient guess (or the given start, or the capture's
  // measured bending).
  ReducedBending lo = reduced_lower(capture.specimen.density), hi = reduced_upper(capture.specimen.density);
  sim::Expected<ReducedBending> guess = ReducedBending{};
  std::optional<BendingParameters> fit_start = settings.start;
  double start_box = settings.start_box;
  r.initial_guess_from = "given start";
  if (!fit_start && settings.use_measured_bending && capture.specimen.measured_bending) {
    fit_start = capture.specimen.measured_bending->bending;
    start_box = capture.specimen.measured_bending->within_factor;
    r.initial_guess_from = "measured bending";
  }
  if (fit_start) {
    *guess = to_reduced(*fit_start);
    if (start_box > 1.0) {  // the box narrowed to the start's neighbourhood: reduced_box
      const auto [near_lo, near_hi] = reduced_box(*guess, start_box);
      for (std::size_t k = 0; k < guess->size(); ++k) {
        lo[k] = std::max(lo[k], near_lo[k]), hi[k] = std::min(hi[k], near_hi[k]);
        // A bending known to that precision with no bending of the search range near it is in other units (SI
        // moduli are 1e9 times smaller), not a fabric to fit: clamped, it started a fit 60 times too soft.
        if (!(lo[k] <= hi[k])) {
          static constexpr const char* kCoordinate[] = {"the mean alpha", "warp over weft", "the bias's alpha",
                                                        "the softening -beta/alpha"};
          return sim::Error{fmt::format(
              "the {} ({}) lies beyond the fit's range even within its factor {:g}: {} is off (alpha in "
              "g*mm^2/s^2 and beta in g*mm^3/s^2, the paper's units?)",
              r.initial_guess_from == "measured bending" ? "capture's measured bending" : "given start",
              fmt::format("alpha {:g},{:g},{:g}, beta {:g},{:g},{:g}", fit_start->alpha.warp, fit_start->alpha.bias,
                          fit_start->alpha.weft, fit_start->beta.warp, fit_start->beta.bias, fit_start->beta.weft),
              start_box, kCoordinate[k])};
        }
      }
      r.search_within_factor = start_box;
    }
    for (std::size_t k = 0; k < guess->size(); ++k) (*guess)[k] = std::clamp((*guess)[k], lo[k], hi[k]);
  } else {
    guess = initial_guess(model, std::max(1, settings.guess_levels));
    if (!guess) return guess.error();
    r.initial_guess_from = "drape coefficient";
  }
  r.initial_guess = from_reduced(*guess);
  std::optional<sim::Error> error;
  double best = std::numeric_limits<double>::infinity();
  std::optional<std::pair<std::vector<double>, double>> known_start;  // a point scored already, and its score
  auto objective = [&](const std::vector<double>& x) -> double {
    if (error) return std::numeric_limits<double>::infinity();
    if (known_start && x == known_start->first) return known_start->second;
    auto e = model.evaluate(baseline_setup({x[0], x[1], x[2], x[3]}));
    if (!e) {
      error = e.error();
      return std::numeric_limits<double>::infinity();
    }
    const double value = e->best.fit_score;
    sim::logger()->debug("baseline fit: ({:.3f}, {:.3f}, {:.3f}, {:.3f}) -> {:.3f} mm (state {}, shape {:.2f})", x[0],
                         x[1], x[2], x[3], value * 1e3, e->best.state, e->best.shape_fit);
    if (value < best) {
      best = value;
      r.fit = std::move(*e);
    }
    return value;
  };
  std::vector<double> steps{0.35, 0.4, 0.4, 1.0};
  for (std::size_t k = 0; k < steps.size(); ++k) steps[k] = std::min(steps[k], 0.5 * (hi[k] - lo[k]));  // a narrow box
  const auto simplex = [&](const ReducedBending& from) {
    return nelder_mead(objective, {from.begin(), from.end()}, steps, {lo.begin(), lo.end()}, {hi.begin(), hi.end()},
                       settings.baseline_optimiser);
  };
  // The simplex from the drape-coefficient guess; then, if a start of the grid scores better than where that simplex
  // ended, a second simplex from the best start, and the better of the two fits counts (so the fit is never worse
  // than the guess's alone).
  r.start = *guess;
  NelderMeadResult nm = simplex(*guess);
  if (error) return *error;
  r.baseline_evaluations = nm.evaluations;
  r.baseline_history = nm.history;
  if (settings.start_levels > 0) {
    std::vector<double> levels{(*guess)[0]};
    for (int k = 0; k < settings.start_levels; ++k) {
      levels.push_back(lo[0] + (hi[0] - lo[0]) * (k + 0.5) / settings.start_levels);
    }
    double best_start = std::numeric_limits<double>::infinity();
    ReducedBending best_x{};
    for (double la : levels) {
      for (double ratio : settings.start_ratios_mm) {
        const ReducedBending x{la, std::clamp(0.0, lo[1], hi[1]), std::clamp(0.0, lo[2], hi[2]),
                               std::clamp(ratio, lo[3], hi[3])};
        const double value = objective({x.begin(), x.end()});
        if (error) return *error;
        ++r.start_evaluations;
        if (value < best_start) {
          best_start = value;
          best_x = x;
        }
      }
    }
    r.best_start_score = best_start;
    if (best_start < nm.f) {
      // Its minimum includes its start, so it ends below the first simplex's: it is the fit.
      known_start = {{best_x.begin(), best_x.end()}, best_start};  // not simulated again
      nm = simplex(best_x);
      if (error) return *error;
      r.baseline_evaluations += nm.evaluations;
      r.baseline_history.insert(r.baseline_history.end(), nm.history.begin(), nm.history.end());
      r.restarted = true;
      r.start = best_x;
    }
  }
  r.fitted_reduced = {nm.x[0], nm.x[1], nm.x[2], nm.x[3]};
  r.fitted = from_reduced(r.fitted_reduced);
  r.seconds_fit = since(start);
  sim::logger()->info("diagnosis: baseline fit {:.2f} mm after {} evaluations ({:.0f} s); floors next",
                      nm.f * 1e3, r.baseline_evaluations, r.seconds_fit);
  const ModelSetup fitted = baseline_setup(r.fitted_reduced);

  // 2. Floors and the gap.
  const auto floors_start = std::chrono::steady_clock::now();
  FloorSettings floor_settings = settings.floors;
  if ((others.second || others.held_out) && settings.held_out_shape_threshold > 0.0) {
    floor_settings.shape_threshold = settings.held_out_shape_threshold;
  }
  if (!others.second && !others.held_out) floor_settings.placement_shape_threshold = 0.0;  // one placement: no test
  auto floors = measure_floors(model, fitted, r.fit, floor_settings);
  if (!floors) return floors.error();
  r.floors = *floors;
  // The gap: the fitted parameters simulated from fresh initial states (the fit's best score is biased low).
  auto validated = model.evaluate(fitted, validation_states(settings.attribution));
  if (!validated) return validated.error();
  r.validated = std::move(*validated);
  std::vector<sim::ClothMesh> meshes;  // the same drapes against the other placements (if any)
  if (second_model || held_out_model)
    for (const auto& d : r.validated.states) meshes.push_back(d.mesh);
  for (auto [m, into] : {std::pair{second_model.get(), &r.validated_second},
                         std::pair{held_out_model.get(), &r.validated_held_out}}) {
    if (!m) continue;
    auto e = m->rescore(meshes, fitted);
    if (!e) return e.error();
    *into = std::move(*e);
  }
  if (settings.floors.placement_drape_coefficient && (second_model || held_out_model)) {
    r.floors.placement_dc = settings.floors.placement_drape_floor > 0.0
                                ? settings.floors.placement_drape_floor
                                : placement_dc_floor(r.validated, r.floors.margin);
    if (settings.floors.placement_drape_when_seen && !(r.gap().placement_dc > r.floors.placement_dc))
      r.floors.placement_dc = 0.0;  // the captures show no change beyond the floor: no test
  }
  r.validation_spread = validation_spread(r.validated.states, model.target().shape.all);
  {  // Does the specimen drape the same way on every placement, as often as the fitted model does?
    std::vector<HemProfile> placements{specimen_frame(hem_profile_from_capture(capture), capture.face_down)};
    for (const Capture* other : {others.second, others.held_out})
      if (other) placements.push_back(specimen_frame(hem_profile_from_capture(*other), other->face_down));
    r.fold_repeatability =
        fold_repeatability(placements, sine_drapes(r.validated, validation_states(settings.attribution)));
    r.fold_repeatability.model_placements = placement_fold_correlations(
        r.validated.best, r.validated_second ? &r.validated_second->best : nullptr,
        r.validated_held_out ? &r.validated_held_out->best : nullptr);
  }
  {  // Do the four views describe one surface on every placement? (A multipath error breaks that; the cloth cannot.)
    r.multipath.threshold = settings.view_consistency.multipath_gain;
    for (const Capture* c : {&capture, others.second, others.held_out})
      if (c) r.multipath.placements.push_back(view_consistency(*c, settings.view_consistency));
  }
  const ScoredDrape& gap = r.gap_drape();
  for (std::size_t v = 0; v < gap.views.size(); ++v) {
    if (gap.views[v].stable_pixels > 0 || gap.views[v].captured_stable_pixels == 0) continue;
    sim::logger()->warn("view {}: no pixel where both the capture and the fitted drape see the platform top or the "
                        "bare cylinder (is the view's world_to_camera in capture.json right?): its stable term counts "
                        "the most a pixel can, {:.0f} mm",
                        v, gap.views[v].stable_rms * 1e3);
  }
  r.gap_all = gap.all_score;
  r.gap_fit = gap.fit_score;
  r.gap_held_out = gap.held_out_score;
  // Within the floors: neither the stable-region term (sensor errors) nor the shape distance (physical effects)
  // exceeds what sensor noise and other stable drapes of the fitted fabric produce. The attribution's shrinkage is
  // measured on the same excess.
  const GapTerms gate = r.gap();
  r.within_floors = excess_above_floors(gate, r.floors) == 0.0;
  r.seconds_floors = since(floors_start);
  sim::logger()->info("diagnosis: stable term {:.2f} mm (floor {:.2f}), shape distance {:.2f} (floor {:.2f}): {} "
                      "({:.0f} s){}",
                      gate.stable * 1e3, r.floors.stable * 1e3, gate.shape, r.floors.shape,
                      r.within_floors ? "within the floors" : "above the floors", r.seconds_floors,
                      r.within_floors || !settings.attribute
                          ? ""
                          : fmt::format("; refitting {} candidates and the bending alone",
                                        settings.attribution.candidates.size()));

  // 3. Where the gap sits.
  r.localisation = localise_drape(model, gap, r.floors,
                                  r.rigid_pose ? platform_displacement(r.rigid_pose->pose, capture) : 0.0);
  if (settings.multipath_region && r.multipath.detected()) place_sensor_gap(r.localisation);
  r.fit_target = model.target().shape;

  // 4. Which effect explains it (not when the gap is within the floors).
  const auto attribution_start = std::chrono::steady_clock::now();
  if (r.within_floors) {
    r.verdict = "none";
  } else if (!settings.attribute) {
    r.verdict = "not attributed";
  } else {
    const FitSettings fit_settings = settings.fit;
    const int state_threads = std::max(1, settings.refit_state_threads);
    auto make_model = [fit_settings, state_threads](const Capture& c) {
      auto m = ForwardModel::create(c, fit_settings);
      if (m) (*m)->set_threads(state_threads);
      return m;
    };
    OtherCaptures other_captures;
    if (second_model) other_captures.second = {second_model.get(), &r.validated_second->best};
    if (held_out_model) other_captures.held_out = {held_out_model.get(), &r.validated_held_out->best};
    other_captures.fold_unlike_model = folds_less_alike(r.fold_repeatability);
    other_captures.views_imply_multipath = r.multipath.detected();
    AttributionSettings attribution_settings = settings.attribution;
    if (r.search_within_factor > 1.0) {
      // A known bending's box (a measured bending or --start-box) bounds the refits too: the bending scale moves only
      // ln mean alpha (the ratios and -beta/alpha stay), so the refits reach from the fit to either end of the box's
      // ln mean alpha, however far the fit sits from the box's middle.
      attribution_settings.bending_scale_lower = lo[0] - r.fitted_reduced[0];
      attribution_settings.bending_scale_upper = hi[0] - r.fitted_reduced[0];
      attribution_settings.bending_scale_known = true;
    }
    if (r.rigid_pose) {
      attribution_settings.sensor_start = r.rigid_pose->pose;
      attribution_settings.sensor_held =
          settings.hold_sensor && r.localisation.camera_moved < kCameraMovedAtPlatform;
    }
    r.refit_scale_lower = attribution_settings.bending_scale_lower;
    r.refit_scale_upper = attribution_settings.bending_scale_upper;
    set_threads(state_threads);
    auto attribution = attribute(model, fitted, r.fit, r.validated, r.floors, attribution_settings, make_model,
                                 other_captures);
    if (!attribution) return attribution.error();
    r.attribution = std::move(*attribution);
    const auto& c = r.attribution.candidates;
    r.bar_localisation = localise_refit(model, r, r.attribution.bar.validated);
    for (const auto& candidate : c) r.candidate_localisations.push_back(localise_refit(model, r, candidate.validated));
    if (r.attribution.bending_within_floors()) {
      r.verdict = "none";  // within the floors once the bending is refitted: the gap was the baseline fit's
    } else {
      r.verdict = r.attribution.named ? std::string(effect_name(c[0].effect)) : "unexplained";
      if (c.size() > 1) r.runner_up = effect_name(c[r.attribution.named ? 1 : 0].effect);
    }
  }
  r.seconds_attribution = since(attribution_start);
  // The simulations of every placement's own model (their helper threads' too; not the refit threads' models).
  r.simulations = model.simulations();
  for (const auto& m : {second_model.get(), held_out_model.get()})
    if (m) r.simulations += m->simulations();
  r.seconds = since(start);
  r.cpu_seconds = process_cpu_seconds() - cpu_start;
  r.jobs = settings.attribution.jobs;
  sim::logger()->info("diagnosis: verdict {} in {:.1f} s", r.verdict, r.seconds);
  return r;
}

/// `reported` takes on `other`'s runtime too (both diagnoses together); returns `other`, whole, to keep beside it.
std::shared_ptr<const DiagnosisResult> runtimes_together(DiagnosisResult& reported, DiagnosisResult&& other) {
  reported.seconds += other.seconds;
  reported.cpu_seconds += other.cpu_seconds;
  reported.simulations += other.simulations;
  return std::make_shared<const DiagnosisResult>(std::move(other));
}

/// The diagnosis on the settings' mesh, and with DiagnosisSettings::confirm_resolution its confirmation on the other.
sim::Expected<DiagnosisResult> diagnose_confirming_mesh(const Capture& capture, const DiagnosisSettings& settings,
                                                        const OtherPlacements& others) {
  auto first = diagnose_on_mesh(capture, settings, others);
  const int confirm = settings.confirm_resolution;  // the confirming mesh's vertices per side
  if (!first || confirm <= 0 || confirm == settings.fit.resolution || first->within_floors || !settings.attribute) {
    return first;
  }
  sim::logger()->info("diagnosis: the gap above the floors on the {0}x{0} mesh; diagnosing again on {1}x{1}",
                      settings.fit.resolution, confirm);
  DiagnosisSettings confirming = settings;
  confirming.fit.resolution = confirm;
  confirming.confirm_resolution = 0;
  auto second = diagnose_on_mesh(capture, confirming, others);
  if (!second) return second.error();
  const bool gap_found = !second->within_floors;
  sim::logger()->info("diagnosis: the {0}x{0} mesh {1}: the verdict {2}", confirm,
                      gap_found ? "finds the gap too" : "leaves it within its floors", gap_found ? second->verdict
                                                                                                : first->verdict);
  DiagnosisResult reported = std::move(gap_found ? *second : *first);
  auto other = runtimes_together(reported, std::move(gap_found ? *first : *second));
  reported.mesh_confirmation = DiagnosisResult::MeshConfirmation{confirm, gap_found, std::move(other)};
  return reported;
}

/// The verdict "none" or "unexplained": the refits name no effect.
bool names_no_effect(const DiagnosisResult& r) { return r.verdict == "none" || r.verdict == "unexplained"; }

/// The second capture's drape coefficient less the capture's where the second lay on the other face (laid after the
/// capture, turned over); nothing otherwise.
std::optional<double> turn_over_rise(const Capture& capture, const OtherPlacements& others) {
  if (!others.second || others.second->face_down == capture.face_down) return std::nullopt;
  return drape_coefficient(*others.second) - drape_coefficient(capture);
}

/// The diagnosis with DiagnosisSettings::confirm_resolution's and confirm_placement_rise's confirmations.
sim::Expected<DiagnosisResult> diagnose_confirming_placement(const Capture& capture, const DiagnosisSettings& settings,
                                                              const OtherPlacements& others) {
  auto first = diagnose_confirming_mesh(capture, settings, others);
  const double floor = settings.confirm_placement_rise;
  if (!first || floor <= 0.0 || settings.floors.placement_drape_coefficient || !names_no_effect(*first)) return first;
  const std::optional<double> rise_or = turn_over_rise(capture, others);
  if (!rise_or || !(*rise_or >= floor)) return first;
  const double rise = *rise_or;
  sim::logger()->info("diagnosis: verdict {} but the turned placement drapes {:.4f} stiffer (drape coefficient); "
                      "diagnosing again with the placement drape test at {:g}",
                      first->verdict, rise, floor);
  DiagnosisSettings tested = settings;
  tested.confirm_placement_rise = 0.0;
  tested.floors.placement_drape_coefficient = true;
  tested.floors.placement_drape_floor = floor;
  tested.floors.placement_drape_when_seen = true;
  auto second = diagnose_confirming_mesh(capture, tested, others);
  if (!second) return second.error();
  sim::logger()->info("diagnosis: with the placement drape test, the verdict {}", second->verdict);
  DiagnosisResult reported = std::move(*second);
  auto other = runtimes_together(reported, std::move(*first));
  reported.placement_confirmation = DiagnosisResult::PlacementConfirmation{rise, floor, std::move(other)};
  return reported;
}

/// DiagnosisSettings::turn_over_yield (rule U): yield where the refits name no effect and the turned placement
/// drapes at least budgets.turn_over_yield stiffer.
void name_yield_from_turn_over(DiagnosisResult& r, const Capture& capture, const OtherPlacements& others) {
  const double floor = r.budgets.turn_over_yield;
  if (floor <= 0.0 || !names_no_effect(r) || !others.second) return;
  const std::optional<double> rise = turn_over_rise(capture, others);
  if (!rise) {
    sim::logger()->info("diagnosis: the second capture lies on the capture's face: no turn-over to name yield by");
    return;
  }
  if (!(*rise >= floor)) return;
  sim::logger()->info("diagnosis: verdict {} but the turned placement drapes {:.4f} stiffer (drape coefficient, at "
                      "least {:g}): yield, from the turn-over",
                      r.verdict, *rise, floor);
  r.turn_over = DiagnosisResult::TurnOverYield{*rise, floor, r.verdict};
  r.verdict = "yield";
  r.runner_up.clear();  // the refits ranked no yield first: nothing stands second to the turn-over
}

/// The turn-over's alternation: the second capture's drape coefficient less the mean of the capture's and the held-out
/// capture's, where the second lies on the other face and the held-out one on the capture's; nothing otherwise.
std::optional<double> turn_over_alternation(const Capture& capture, const OtherPlacements& others) {
  const std::optional<double> rise = turn_over_rise(capture, others);
  if (!rise || !others.held_out || others.held_out->face_down != capture.face_down) return std::nullopt;
  return *rise - 0.5 * (drape_coefficient(*others.held_out) - drape_coefficient(capture));
}

/// DiagnosisSettings::turn_over_alternation (rule A), after the turn-over's rule U: yield where no effect is named
/// and the alternation reaches budgets.turn_over_alternation; the refits' yield withdrawn ("unexplained") where it
/// does not, unless the first turn-over alone reaches budgets.turn_over_yield (rule U would name it again).
void weigh_yield_by_alternation(DiagnosisResult& r, const Capture& capture, const OtherPlacements& others) {
  const double floor = r.budgets.turn_over_alternation;
  const bool refits_yield = r.verdict == "yield" && !r.turn_over;
  if (floor <= 0.0 || !(names_no_effect(r) || refits_yield)) return;
  const std::optional<double> alternation = turn_over_alternation(capture, others);
  if (!alternation) {
    sim::logger()->info("diagnosis: no turned second capture between two placements on the capture's face: no "
                        "alternation to weigh yield by");
    return;
  }
  if (names_no_effect(r) && *alternation >= floor) {
    sim::logger()->info("diagnosis: verdict {} but the turned placement drapes {:.4f} stiffer than the mean of the "
                        "others (drape coefficient, at least {:g}): yield, from the turn-over's alternation",
                        r.verdict, *alternation, floor);
    r.alternation = DiagnosisResult::TurnOverAlternation{*alternation, floor, r.verdict};
    r.verdict = "yield";
    r.runner_up.clear();
    return;
  }
  const std::optional<double> rise = turn_over_rise(capture, others);
  const bool turn_over_names = r.budgets.turn_over_yield > 0.0 && *rise >= r.budgets.turn_over_yield;
  if (!refits_yield || !(*alternation < floor) || turn_over_names) return;
  sim::logger()->info("diagnosis: the refits name yield but the turned placement drapes {:.4f} against the mean of "
                      "the others (drape coefficient, under {:g}): unexplained, the yield withdrawn",
                      *alternation, floor);
  r.alternation = DiagnosisResult::TurnOverAlternation{*alternation, floor, r.verdict};
  r.verdict = "unexplained";
  r.runner_up = "yield";  // the best candidate, as with the refits' own "unexplained"
}

/// DiagnosisSettings::off_centre_misalignment and off_centre_mm (rules E and D): misalignment where no effect is named
/// (after the turn-over and its alternation) and the hem's centre lies at least budgets.off_centre_misalignment times
/// its floor, or budgets.off_centre_mm mm, off the fitted drape's; with off_centre_mm_over_yield (rule D2) also by the
/// offset where the refits named yield and the turn-over would not.
void name_misalignment_from_off_centre(DiagnosisResult& r, const Capture& capture, const OtherPlacements& others) {
  const auto& b = r.budgets;
  constexpr auto kOffCentre = static_cast<std::size_t>(FeatureGroup::kOffCentre);
  const auto& L = r.localisation;
  if (L.group_ratio.size() <= kOffCentre || L.group_difference.size() <= kOffCentre) return;
  // In mm as report.json gives it, which the rules were registered on.
  const double ratio = L.group_ratio[kOffCentre], offset_mm = L.group_difference[kOffCentre] * 1e3;
  const bool ratio_reaches = b.off_centre_misalignment > 0.0 && ratio >= b.off_centre_misalignment;
  const bool offset_reaches = b.off_centre_mm > 0.0 && offset_mm >= b.off_centre_mm;
  const std::optional<double> rise = turn_over_rise(capture, others);
  const bool turn_over_names = b.turn_over_yield > 0.0 && rise && *rise >= b.turn_over_yield;
  const bool refits_yield = r.verdict == "yield" && !r.turn_over && !r.alternation && !turn_over_names;
  const bool fires = names_no_effect(r) ? ratio_reaches || offset_reaches
                                        : offset_reaches && b.off_centre_mm_over_yield && refits_yield;
  if (!fires) return;
  const bool by_offset = !(ratio_reaches && names_no_effect(r));
  r.off_centre = DiagnosisResult::OffCentreMisalignment{ratio,          b.off_centre_misalignment, offset_mm,
                                                        b.off_centre_mm, by_offset,                 r.verdict};
  sim::logger()->info("diagnosis: verdict {} but the hem's order-1 harmonic differs from the fitted drape's by {}: "
                      "misalignment, from the hem's centre",
                      r.verdict, r.off_centre->difference());
  r.verdict = "misalignment";
  r.runner_up.clear();  // the refits ranked no misalignment first: nothing stands second to the hem's centre
}

/// The hem's tilt of one placement (mm): the first harmonic of its height against the angle about the axis, from all
/// its views; nothing where it saw too little of the skirt.
std::optional<double> hem_tilt_mm(const Capture& placement) {
  std::vector<int> views(placement.views.size());
  std::iota(views.begin(), views.end(), 0);
  const ShapeFeatures f = shape_features(placement, views);
  if (!f.valid || f.off_centre.size() < 2) return std::nullopt;
  return f.off_centre[1] * 1e3;
}

/// The hem's tilt on the capture, the second and the held-out capture, as many as were given and read; empty if any
/// given one saw too little of the skirt (the rule needs every placement).
std::vector<double> placement_hem_tilts(const Capture& capture, const OtherPlacements& others) {
  std::vector<double> tilts;
  for (const Capture* placement : {&capture, others.second, others.held_out}) {
    if (!placement) continue;
    const std::optional<double> tilt = hem_tilt_mm(*placement);
    if (!tilt) return {};
    tilts.push_back(*tilt);
  }
  return tilts;
}

/// DiagnosisSettings::hem_tilt_misalignment (rule H), after the other signatures: misalignment, whatever the verdict,
/// where the capture, the second and the held-out capture each tilt by at least budgets.hem_tilt_misalignment.
void name_misalignment_from_hem_tilt(DiagnosisResult& r, const OtherPlacements& others) {
  const double floor = r.budgets.hem_tilt_misalignment;
  const auto& tilts = r.placement_hem_tilt_mm;
  if (floor <= 0.0 || r.verdict == "misalignment" || !others.second || !others.held_out || tilts.size() != 3) return;
  const double smallest = *std::ranges::min_element(tilts);
  if (!(smallest >= floor)) return;
  sim::logger()->info("diagnosis: verdict {} but the hem tilts by {:.2f} mm or more on each of the three placements "
                      "(at least {:g} mm): misalignment, from the hem's tilt",
                      r.verdict, smallest, floor);
  r.hem_tilt = DiagnosisResult::HemTiltMisalignment{smallest, floor, r.verdict};
  r.verdict = "misalignment";
  r.runner_up.clear();  // whatever stood first, the tilt of every placement names the effect
}

}  // namespace

sim::Expected<DiagnosisResult> diagnose(const Capture& capture, const DiagnosisSettings& settings,
                                        const OtherPlacements& others) {
  auto result = diagnose_confirming_placement(capture, settings, others);
  if (!result) return result;
  // A screening run names no effect, so no signature names one there.
  result->budgets.turn_over_yield = settings.attribute ? settings.turn_over_yield : 0.0;
  result->budgets.turn_over_alternation = settings.attribute ? settings.turn_over_alternation : 0.0;
  result->budgets.off_centre_misalignment = settings.attribute ? settings.off_centre_misalignment : 0.0;
  result->budgets.off_centre_mm = settings.attribute ? settings.off_centre_mm : 0.0;
  result->budgets.off_centre_mm_over_yield =
      settings.attribute && settings.off_centre_mm > 0.0 && settings.off_centre_mm_over_yield;
  name_yield_from_turn_over(*result, capture, others);
  weigh_yield_by_alternation(*result, capture, others);
  name_misalignment_from_off_centre(*result, capture, others);
  result->budgets.hem_tilt_misalignment = settings.attribute ? settings.hem_tilt_misalignment : 0.0;
  result->placement_hem_tilt_mm = placement_hem_tilts(capture, others);
  name_misalignment_from_hem_tilt(*result, others);
  return result;
}

const CandidateResult* DiagnosisResult::refit(Effect effect) const {
  const auto found = std::ranges::find(attribution.candidates, effect, &CandidateResult::effect);
  return found == attribution.candidates.end() ? nullptr : &*found;
}

std::string DiagnosisResult::OffCentreMisalignment::difference() const {
  return by_offset ? fmt::format("{:.2f} mm (at least {:g} mm)", offset_mm, offset_floor_mm)
                   : fmt::format("{:.2f} times its floor (at least {:g})", ratio, floor);
}

const std::string& DiagnosisResult::refits_verdict() const {
  if (turn_over) return turn_over->refits_verdict;
  if (alternation) return alternation->refits_verdict;
  if (off_centre) return off_centre->refits_verdict;
  if (hem_tilt) return hem_tilt->refits_verdict;
  return verdict;
}

const CandidateResult* DiagnosisResult::named_refit() const {
  if (signature_set()) {
    const std::optional<Effect> named = parse_effect(verdict);
    return named ? refit(*named) : nullptr;
  }
  return attribution.named && !attribution.candidates.empty() ? &attribution.candidates.front() : nullptr;
}

double DiagnosisResult::named_shrinkage() const {
  if (signature_set() && !names_no_effect(*this)) {
    const CandidateResult* named = named_refit();
    return named ? named->shrinkage : 0.0;
  }
  // Without a named effect, the best candidate's (an "unexplained" verdict's, below the bar).
  return attribution.candidates.empty() ? 0.0 : attribution.candidates.front().shrinkage;
}

nlohmann::json to_json(const DiagnosisResult& r, const Capture& capture) {
  nlohmann::json j;
  j["capture"] = capture.directory;
  nlohmann::json placements = nlohmann::json::array();
  for (const auto& p : r.placements)
    placements.push_back({{"role", p.role}, {"directory", p.directory}, {"face", p.face_down ? "down" : "up"}});
  j["placements"] = std::move(placements);
  j["verdict"] = r.verdict;
  j["runner_up"] = r.runner_up;
  j["confidence"] =
      r.signature_set() ? nlohmann::json(nullptr) : nlohmann::json(r.attribution.confidence);
  j["within_floors"] = r.within_floors;
  j["within_floors_after_bending_refit"] = r.attribution.bending_within_floors();
  j["gap_mm"] = {
      {"all_views", r.gap_all * 1e3}, {"fit_views", r.gap_fit * 1e3}, {"held_out_view", r.gap_held_out * 1e3}};
  nlohmann::json states = nlohmann::json::array();
  for (const auto& d : r.validated.states) {
    states.push_back({{"state", d.state}, {"stable_mm", d.stable_all * 1e3}, {"shape", d.shape_all},
                      {"fit_score_mm", d.fit_score * 1e3}, {"converged", d.converged}});
  }
  // The gate's terms (with a paired capture, the second else the held-out one: the mean of both captures'), then each
  // capture's own.
  const GapTerms gap = r.gap();
  j["gap_tests"] = {{"stable_mm", gap.stable * 1e3},
                    {"stable_floor_mm", r.floors.stable * 1e3},
                    {"shape", gap.shape},
                    {"shape_floor", r.floors.shape},
                    {"shape_max", gap.shape_max},
                    {"placement_shape_floor", r.floors.placement_shape},
                    {"placement_dc", gap.placement_dc},
                    {"placement_dc_floor", r.floors.placement_dc},
                    {"excess_above_floors", excess_above_floors(gap, r.floors)},
                    {"paired_with", r.validated_second     ? nlohmann::json("second_capture")
                                    : r.validated_held_out ? nlohmann::json("held_out_capture")
                                                           : nlohmann::json(nullptr)},
                    {"capture",
                     {{"stable_mm", r.gap_drape().stable_all * 1e3},
                      {"shape", r.gap_drape().shape_all},
                      {"drape_coefficient", r.gap_drape().capture_drape_coefficient},
                      {"model_drape_coefficient", r.gap_drape().median_drape_coefficient}}},
                    {"second_capture", placement_json(r.validated_second)},
                    {"held_out_capture", placement_json(r.validated_held_out)},
                    {"validation_states", r.validated.states.size()},
                    {"best_validation_state", r.gap_drape().state},
                    {"validation_spread", spread_json(r.validation_spread)},
                    {"fold_repeatability", repeatability_json(r.fold_repeatability)},
                    {"view_consistency", multipath_json(r.multipath, r.placements)},
                    {"validation_drapes", states},
                    {"fit_states", {{"stable_mm", r.fit.best.stable_all * 1e3},
                                    {"shape", r.fit.best.shape_all},
                                    {"excess_above_floors", excess_above_floors(r.fit.best, r.floors)}}}};
  nlohmann::json floors = {{"all_views_mm", r.floors.all * 1e3},
                           {"held_out_view_mm", r.floors.held_out * 1e3},
                           {"margin", r.floors.margin},
                           {"stable_mm", r.floors.stable * 1e3},
                           {"shape", r.floors.shape},
                           {"shape_margin", r.floors.shape_margin},
                           {"typical_all_views_mm", r.floors.typical_all * 1e3},
                           {"typical_held_out_view_mm", r.floors.typical_held_out * 1e3},
                           {"noise_shape", r.floors.noise.shape},
                           {"multistability_shape", r.floors.multistability.shape},
                           {"noise_all_mm", millimetres(r.floors.noise.all)},
                           {"noise_held_out_mm", millimetres(r.floors.noise.held_out)},
                           {"multistability_all_mm", millimetres(r.floors.multistability.all)},
                           {"multistability_held_out_mm", millimetres(r.floors.multistability.held_out)}};
  j["floors"] = floors;
  if (r.rigid_pose) {
    const RigidPose& p = *r.rigid_pose;
    j["rigid_surfaces"] = {{"rotation_mrad", {p.pose.rotation.x() * 1e3, p.pose.rotation.y() * 1e3,
                                              p.pose.rotation.z() * 1e3}},
                           {"translation_mm", {p.pose.translation.x() * 1e3, p.pose.translation.y() * 1e3,
                                               p.pose.translation.z() * 1e3}},
                           {"top_lift_mm", p.top_lift * 1e3},
                           {"rms_recorded_mm", p.rms_recorded * 1e3},
                           {"rms_estimated_mm", p.rms_estimated * 1e3},
                           {"top_pixels", p.top_pixels},
                           {"side_pixels", p.side_pixels}};
  } else {
    j["rigid_surfaces"] = {{"error", r.rigid_pose_error}};
  }
  j["baseline"] = {{"initial_guess", bending_json(r.initial_guess)},
                   {"initial_guess_from", r.initial_guess_from},
                   {"search_within_factor", r.search_within_factor > 1.0 ? nlohmann::json(r.search_within_factor)
                                                                        : nlohmann::json(nullptr)},
                   {"fitted", bending_json(r.fitted)},
                   {"fitted_reduced", r.fitted_reduced},
                   {"evaluations", r.baseline_evaluations},
                   {"start_evaluations", r.start_evaluations},
                   {"start_reduced", r.start},
                   {"restarted", r.restarted},
                   {"best_start_score_mm", std::isfinite(r.best_start_score) ? nlohmann::json(r.best_start_score * 1e3)
                                                                             : nlohmann::json(nullptr)},
                   {"fit_score_mm", r.fit.best.fit_score * 1e3},
                   {"best_state", r.fit.best.state},
                   {"turn_deg", r.fit.best.angle * 180.0 / M_PI},
                   {"converged", r.fit.best.converged},
                   {"stable_mm", {{"fit_views", r.fit.best.stable_fit * 1e3},
                                  {"held_out_view", r.fit.best.stable_held_out * 1e3},
                                  {"all_views", r.fit.best.stable_all * 1e3}}},
                   {"shape_distance", {{"fit_views", r.fit.best.shape_fit},
                                       {"held_out_view", r.fit.best.shape_held_out},
                                       {"all_views", r.fit.best.shape_all}}},
                   {"views", view_json(r.fit.best)}};
  const auto& L = r.localisation;
  nlohmann::json regions = nlohmann::json::array();
  for (const auto& s : L.regions) {
    regions.push_back({{"region", region_name(s.region)},
                       {"energy_share", s.energy_share},
                       {"pixel_share", s.pixel_share},
                       {"enrichment", s.enrichment},
                       {"rms_mm", s.rms * 1e3},
                       {"mean_mm", s.mean * 1e3},
                       {"view_mean_mm", millimetres(s.view_mean)},
                       {"floor_ratio", s.floor_ratio}});
  }
  nlohmann::json harmonics = nlohmann::json::array();
  for (const auto& h : L.hem_difference) {
    if (h.order == 0) continue;
    harmonics.push_back({{"order", h.order}, {"amplitude_mm", h.amplitude * 1e3}, {"phase_rad", h.phase}});
  }
  nlohmann::json groups = nlohmann::json::object();
  // The gap drape's differences, localise_features's (before session 67 the fit's best drape's).
  const auto floor = r.floors.group_floor();
  for (std::size_t k = 0; k < L.group_ratio.size(); ++k) {
    groups[std::string(feature_group_name(kFeatureGroups[k]))] = {
        {"difference_mm", L.group_difference.at(k) * 1e3},
        {"floor_mm", floor[k] * 1e3},
        {"ratio_floor_mm", group_ratio_floor(k, floor) * 1e3},
        {"ratio", L.group_ratio[k]}};
  }
  j["localisation"] = {{"region", region_name(L.dominant)},
                       {"dominant_feature", L.dominant_feature.empty() ? nlohmann::json(nullptr)
                                                                       : nlohmann::json(L.dominant_feature)},
                       {"moved_to_hem", L.moved_to_hem},
                       {"moved_by_offset", L.moved_by_offset},
                       {"placed_by_views", L.placed_by_views},
                       {"feature_groups", groups},
                       {"stable_ratio", L.stable_ratio},
                       {"camera_moved_mm", L.camera_moved * 1e3},
                       {"pixel_region", region_name(L.pixel_region)},
                       {"floor_region", region_name(L.floor_region)},
                       {"regions", regions},
                       {"view_share", L.view_share},
                       {"hem_difference_harmonics", harmonics},
                       {"folds", {{"capture", L.capture_folds}, {"model", L.model_folds}}},
                       {"fold_phase_rad", {{"capture", L.capture_fold_phase}, {"model", L.model_fold_phase}}},
                       {"drape_coefficient",
                        {{"capture", L.capture_drape_coefficient}, {"model", L.model_drape_coefficient}}}};
  const bool ran = !r.within_floors && r.verdict != "not attributed";
  nlohmann::json candidates = nlohmann::json::array();
  for (std::size_t i = 0; i < r.attribution.candidates.size(); ++i) {
    const CandidateResult& c = r.attribution.candidates[i];
    nlohmann::json params = nlohmann::json::object();
    for (std::size_t k = 0; k < c.names.size() && k < c.parameters.size(); ++k) params[c.names[k]] = c.parameters[k];
    nlohmann::json scan = nlohmann::json::array();
    for (const auto& l : c.scan) {
      scan.push_back({{"parameter", l.parameter}, {"alpha_scale", l.alpha_scale}, {"objective_mm", l.objective * 1e3}});
    }
    candidates.push_back({{"effect", effect_name(c.effect)},
                          {"parameters", params},
                          {"alpha_scale", c.alpha_scale},
                          {"fit_score_mm", c.fit_score * 1e3},
                          {"objective_mm", c.objective * 1e3},
                          {"held_out_score_mm", c.held_out_score * 1e3},
                          {"all_views_score_mm", c.all_score * 1e3},
                          {"stable_mm", c.drape.stable_all * 1e3},
                          {"shape", c.drape.shape_all},
                          {"excess_above_floors", excess_above_floors(c.drape, r.floors)},
                          {"validated", validated_json(c, r.floors)},
                          {"ablated", ablated_json(c, r.floors)},
                          {"shrinkage", c.shrinkage},
                          {"held_out_shrinkage", c.held_out_shrinkage},
                          {"confirmed", c.confirmed()},
                          {"confirmed_by", confirmed_by_json(c.confirmation)},
                          {"evaluations", c.evaluations},
                          {"fold_repeatability",
                           {{"placement_pairs", c.placement_folds}, {"drape_pairs", c.drape_folds}}},
                          {"scan", scan},
                          {"bending_under_sensor", c.bending_under_sensor},
                          {"localisation", refit_localisation_json(i < r.candidate_localisations.size()
                                                                       ? r.candidate_localisations[i]
                                                                       : std::nullopt)},
                          {"seconds", c.seconds}});
  }
  j["attribution"] = {{"ran", ran},
                      {"curl_first", r.attribution.curl_promoted},
                      {"sensor_first", ran ? nlohmann::json{{"multipath_first", r.attribution.multipath_first},
                                                            {"promoted", r.attribution.sensor_promoted}}
                                           : nlohmann::json(nullptr)},
                      {"near_tie", ran ? nlohmann::json{{"margin", r.attribution.tie_margin},
                                                        {"promoted", r.attribution.near_tie_promoted}}
                                       : nlohmann::json(nullptr)},
                      {"sensor_held", ran ? nlohmann::json(r.attribution.sensor_held) : nullptr},
                      {"confirmed_on", r.validated_held_out ? "held_out_capture" : "held_out_view"},
                      {"held_out_tolerance", ran ? nlohmann::json(r.attribution.held_out_tolerance) : nullptr},
                      {"confirm_within_floors", ran ? nlohmann::json(r.attribution.confirm_within_floors) : nullptr},
                      {"significant_shrinkage", ran ? nlohmann::json(r.attribution.significant_shrinkage) : nullptr},
                      {"refitted_on", r.validated_second ? "capture_and_second_capture" : "capture"},
                      {"alpha_scale_bounds", ran ? nlohmann::json::array({std::exp(r.refit_scale_lower),
                                                                           std::exp(r.refit_scale_upper)})
                                                 : nlohmann::json(nullptr)},
                      {"mean_alpha_bounds",  // the same as the refits' range of the geometric mean alpha
                       ran ? nlohmann::json::array({std::exp(r.fitted_reduced[0] + r.refit_scale_lower),
                                                    std::exp(r.fitted_reduced[0] + r.refit_scale_upper)})
                           : nlohmann::json(nullptr)},
                      {"bending_refit_bar",
                       {{"alpha_scale", r.attribution.bar.alpha_scale},
                        {"bending", bending_json(r.attribution.bar.setup.bending)},
                        {"evaluations", r.attribution.bar.evaluations},
                        {"fit_score_mm", r.attribution.bar.fit_score * 1e3},
                        {"objective_mm", r.attribution.bar.objective * 1e3},
                        {"validated", ran ? validated_json(r.attribution.bar, r.floors) : nlohmann::json(nullptr)},
                        {"localisation", refit_localisation_json(r.bar_localisation)},
                        {"shrinkage", r.attribution.bar.shrinkage}}},
                      {"common_bending", common_bending_json(r.attribution, r.floors)},
                      {"common_bending_effects", ran ? nlohmann::json(r.attribution.common_bending_effects) : nullptr},
                      {"named", r.attribution.named},
                      {"confidence", r.attribution.confidence},
                      {"candidates", candidates}};
  j["shrinkage"] = r.named_shrinkage();
  j["settings"] = {{"resolution", r.budgets.resolution},
                   {"initial_states", r.budgets.initial_states},
                   {"max_baseline_evaluations", r.budgets.max_baseline_evaluations},
                   {"attribution", r.budgets.attribution},
                   {"turn_over_yield", r.budgets.turn_over_yield},
                   {"turn_over_alternation", r.budgets.turn_over_alternation},
                   {"off_centre_misalignment", r.budgets.off_centre_misalignment},
                   {"off_centre_mm", r.budgets.off_centre_mm},
                   {"off_centre_mm_over_yield", r.budgets.off_centre_mm_over_yield},
                   {"hem_tilt_misalignment", r.budgets.hem_tilt_misalignment}};
  if (const auto& m = r.mesh_confirmation) {
    j["mesh_confirmation"] = {{"resolution", m->resolution},
                              {"gap_found", m->gap_found},
                              {"reported", m->gap_found ? "confirming mesh" : "first mesh"},
                              {"other", m->other ? to_json(*m->other, capture) : nlohmann::json(nullptr)}};
  }
  if (const auto& p = r.placement_confirmation) {
    j["placement_confirmation"] = {{"rise", p->rise},
                                   {"floor", p->floor},
                                   {"other", p->other ? to_json(*p->other, capture) : nlohmann::json(nullptr)}};
  }
  if (const auto& t = r.turn_over) {
    j["turn_over"] = {{"rise", t->rise}, {"floor", t->floor}, {"refits_verdict", t->refits_verdict}};
  }
  if (const auto& a = r.alternation) {
    j["alternation"] = {{"alternation", a->alternation}, {"floor", a->floor}, {"refits_verdict", a->refits_verdict}};
  }
  if (const auto& o = r.off_centre) {
    j["off_centre"] = {{"ratio", o->ratio},
                       {"floor", o->floor},
                       {"offset_mm", o->offset_mm},
                       {"offset_floor_mm", o->offset_floor_mm},
                       {"by", o->by_offset ? "offset" : "ratio"},
                       {"refits_verdict", o->refits_verdict}};
  }
  j["placement_hem_tilt_mm"] = r.placement_hem_tilt_mm;
  if (const auto& h = r.hem_tilt) {
    j["hem_tilt"] = {{"smallest_mm", h->smallest_mm}, {"floor_mm", h->floor_mm}, {"refits_verdict", h->refits_verdict}};
  }
  j["runtime"] = {{"seconds", r.seconds},
                  {"cpu_seconds", r.cpu_seconds},
                  {"jobs", r.jobs},
                  {"fit_seconds", r.seconds_fit},
                  {"floors_seconds", r.seconds_floors},
                  {"attribution_seconds", r.seconds_attribution},
                  {"simulations_main_thread", r.simulations}};
  return j;
}

}  // namespace drapegen::diagnosis
