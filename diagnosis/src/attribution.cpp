#include "drapegen/diagnosis/attribution.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <numeric>
#include <optional>
#include <utility>

#include <fmt/ranges.h>

#include "drapegen/diagnosis/fold_repeatability.hpp"
#include "drapegen/diagnosis/work_sharing.hpp"
#include "drapegen/renderer/random.hpp"
#include "drapegen/sim/logging.hpp"
#include "drapegen/sim/measures.hpp"

namespace drapegen::diagnosis {
namespace {

/// The directions of a misaligned setup's drift tried on a later placement (where the specimen lies off centre by the
/// same distance in a direction of its own): 0, 45, 90 and 135 degrees from the warp. The bending is orthotropic and
/// the specimen square, so a drift at theta + 180 degrees drapes as one at theta turned by 180 degrees (which the
/// outline turn absorbs): these four cover every direction to within 22.5 degrees.
constexpr int kDriftDirections = 4;

/// `setup`'s drapes `on` the capture scored against another placement, from `states` (those of `on`):
/// - a yielding setup is laid again there with the plastic set its best drape left (kept by evaluate) and simulated
///   from `states`;
/// - a misaligned setup (drift) is placed off centre by the same distance in the best of kDriftDirections directions
///   (each simulated from the state of the best drape on `on`, scored by the fit score), then simulated from `states`;
/// - an edge-curled setup laid on another face than on `on` is simulated there from `states` (its curl turns over);
/// - any other setup's drapes are scored again (turned to the placement's outline; turned over, an orthotropic fabric
///   without a rest shape is the same fabric).
/// `placed` receives the setup as placed there, `drift_direction` the chosen direction (misaligned setups only).
sim::Expected<Evaluation> on_next_placement(ForwardModel& next, const ModelSetup& setup, const Evaluation& on,
                                            const std::vector<sim::InitialStateSpec>& states, ModelSetup& placed,
                                            std::optional<double>* drift_direction = nullptr) {
  const sim::InitialStateSpec& best_state = states.at(static_cast<std::size_t>(on.best.state));
  if (setup.effects.bending_yield_curvature) {
    // The set its best drape left, kept by evaluate (a yielding setup's drapes are always simulated, never rescored).
    if (on.best.left.rest_angles.size() == 0) return sim::Error{"yield candidate laid again: no plastic set kept"};
    placed = ForwardModel::laid_again(setup, on.best);
    return next.evaluate(placed, states);
  }
  if (setup.drift.squaredNorm() > 0.0) {
    const double distance = setup.drift.norm();
    double best = std::numeric_limits<double>::infinity(), best_direction = 0.0;
    // The best direction's drape from the best state: evaluate scores it again rather than simulating it again.
    ForwardModel::Simulated simulated;
    simulated.state = static_cast<std::size_t>(on.best.state);
    placed = setup;
    for (int k = 0; k < kDriftDirections; ++k) {
      const double direction = M_PI * k / kDriftDirections;
      placed.drift = distance * Eigen::Vector2d(std::cos(direction), std::sin(direction));
      bool converged = true;
      auto mesh = next.simulate(placed, best_state, &converged);
      if (!mesh) return mesh.error();
      auto scored = next.score(*mesh, placed);
      if (!scored) return scored.error();
      if (scored->fit_score < best) {
        best = scored->fit_score, best_direction = direction;
        simulated.mesh = std::move(*mesh), simulated.converged = converged;
      }
    }
    placed.drift = distance * Eigen::Vector2d(std::cos(best_direction), std::sin(best_direction));
    if (drift_direction) *drift_direction = best_direction;
    return next.evaluate(placed, states, &simulated);
  }
  placed = setup;
  if (setup.effects.edge_curl && !on.states.empty() &&
      sim::lies_face_down(on.states.front().mesh) != next.capture().face_down) {
    return next.evaluate(setup, states);
  }
  std::vector<sim::ClothMesh> meshes;
  for (const auto& d : on.states) meshes.push_back(d.mesh);
  return next.rescore(meshes, setup);
}

/// The refits' range of the ln bending scale, which always holds the fit itself (0).
std::pair<double, double> bending_scale_bounds(const AttributionSettings& settings) {
  return {std::min(0.0, settings.bending_scale_lower), std::max(0.0, settings.bending_scale_upper)};
}

/// `setup` with its bending's alpha and beta times exp(ln_scale).
ModelSetup scaled_bending(ModelSetup setup, double ln_scale) {
  setup.bending = scaled(setup.bending, std::exp(ln_scale));
  return setup;
}

/// The largest rest angle of a setup's plastic set (unset for a setup that does not yield).
std::optional<double> largest_set(const ModelSetup& setup) {
  if (!setup.effects.bending_yield_curvature) return std::nullopt;
  const Eigen::VectorXd& set = setup.plastic_set.rest_angles;
  return set.size() > 0 ? set.cwiseAbs().maxCoeff() : 0.0;
}

/// `setup` from the validation states on the capture (or, given `rescored`, that evaluation's drapes re-scored: the
/// sensor candidate re-renders the baseline's), then on the other placements in turn (the second, then the held-out
/// one), each from the last: fills c.validated, c.second, c.held_out and c.setup.
sim::Status validate(ForwardModel& model, ForwardModel* second, ForwardModel* held_out, const ModelSetup& setup,
                     const Evaluation* rescored, const AttributionSettings& settings, CandidateResult& c) {
  std::vector<sim::ClothMesh> fresh;
  if (rescored)
    for (const auto& s : rescored->states) fresh.push_back(s.mesh);
  const std::vector<sim::InitialStateSpec> states = validation_states(settings);
  auto validated = rescored ? model.rescore(fresh, setup) : model.evaluate(setup, states);
  if (!validated) return validated.error();
  ModelSetup laid = setup;
  const Evaluation* last = &*validated;
  std::optional<Evaluation> on_second;
  for (ForwardModel* next : {second, held_out}) {
    if (!next) continue;
    ModelSetup again;
    std::optional<double> direction;
    auto e = on_next_placement(*next, laid, *last, states, again, &direction);
    if (!e) return sim::Error{std::string(next == second ? "second" : "held-out") + " capture: " + e.error().message};
    OtherPlacement placement{e->best, largest_set(again), direction, e->all_scores()};
    if (next == second) {
      c.second = std::move(placement);
      on_second = std::move(*e);
      last = &*on_second;
    } else {
      c.held_out = std::move(placement);
    }
    laid = std::move(again);
  }
  c.validated = validated->best;
  c.setup = setup;
  c.placement_folds =
      placement_fold_correlations(c.validated, c.second ? &c.second->best : nullptr, c.held_out_drape());
  c.drape_folds = drape_fold_correlations(sine_drapes(*validated, states));
  return {};
}

/// Refits `effect` with the bending scale free, or with no effect (the bar) the bending scale alone, on the fit
/// states (and the second capture, if given); then evaluates the refitted setup from the validation states on the
/// capture and on the other placements.
sim::Expected<CandidateResult> refit(ForwardModel& model, ForwardModel* second, ForwardModel* held_out,
                                     std::optional<Effect> effect, const ModelSetup& baseline, const Evaluation& fit,
                                     const Evaluation& baseline_validated, const AttributionSettings& settings) {
  const auto start = std::chrono::steady_clock::now();
  const bool bar = !effect;
  const EffectSpace space = bar ? EffectSpace{} : effect_space(*effect);
  CandidateResult c;
  c.effect = effect.value_or(Effect::kYield);
  c.names = space.names;
  std::vector<double> x0, step, lo, hi;
  const bool sim = bar || needs_simulation(*effect);
  if (sim) {  // the bending scale stays free: an effect may trade off against stiffness (and the bar refits it alone)
    const auto [lower, upper] = bending_scale_bounds(settings);
    // The first step goes up (the NelderMead reflects it down at the upper bound); a quarter of the range at most.
    x0.push_back(0.0), step.push_back(std::min(0.25, 0.25 * (upper - lower))), lo.push_back(lower), hi.push_back(upper);
  }
  const std::size_t first = x0.size();
  x0.insert(x0.end(), space.start.begin(), space.start.end());
  step.insert(step.end(), space.step.begin(), space.step.end());
  if (effect == Effect::kMisalignment) {
    // Start from the centre offset that the baseline lacks: the fit views' first harmonics of the hem radius and of
    // the hem's height against angle (only their sizes: the turn makes the direction arbitrary). The extra cloth on
    // the long side of an off-centre specimen both reaches out and hangs down, so both harmonics carry the offset;
    // the radius alone often shows none of it (the start was then 0, the baseline itself, which no refit with a
    // multistable objective and 14 evaluations beat). Still an underestimate (the far side's skirt takes up part of
    // it): a start, not an estimate.
    const auto& captured = model.target().shape.fit.off_centre;
    const auto& modelled = fit.best.shape.fit.off_centre;
    if (captured.size() >= 2 && modelled.size() >= 2) {
      const double radial = std::max(0.0, captured[0] - modelled[0]);
      const double vertical = std::max(0.0, captured[1] - modelled[1]);
      x0[first] = std::clamp(std::hypot(radial, vertical) * 1e3, 0.0, space.upper[0]);
    }
    sim::logger()->debug("refit misalignment: start drift {:.1f} mm (before any scan)", x0[first]);
  }
  lo.insert(lo.end(), space.lower.begin(), space.lower.end());
  hi.insert(hi.end(), space.upper.begin(), space.upper.end());
  if (effect == Effect::kSensor && settings.sensor_start) {
    // The camera pose the rigid surfaces show (rotation in mrad, translation in mm: effect_space's first six).
    const renderer::SensorError& start = *settings.sensor_start;
    for (int k = 0; k < 3; ++k) {
      const std::size_t r = first + static_cast<std::size_t>(k), t = r + 3;
      x0[r] = std::clamp(start.rotation[k] * 1e3, lo[r], hi[r]);
      x0[t] = std::clamp(start.translation[k] * 1e3, lo[t], hi[t]);
    }
    if (settings.sensor_held) {
      // The camera as the rigid surfaces show it, no depth bias or slope: a box of one value holds each (nelder_mead).
      const std::size_t gain = x0.size() - 1;  // multipath_mm, effect_space's last
      for (std::size_t k = first; k < gain; ++k) {
        if (k >= first + 6) x0[k] = 0.0;
        lo[k] = hi[k] = x0[k];
      }
    }
    sim::logger()->debug("refit sensor: start from the rigid surfaces' pose {}{}", fmt::join(x0, ", "),
                         settings.sensor_held ? " (held; the multipath gain alone is refitted)" : "");
  }

  std::vector<sim::ClothMesh> meshes;
  if (!sim)
    for (const auto& s : fit.states) meshes.push_back(s.mesh);
  std::optional<sim::Error> error;
  double best = std::numeric_limits<double>::infinity();
  auto scaled = [&](double ln_scale) { return scaled_bending(baseline, ln_scale); };
  auto setup_of = [&](const std::vector<double>& x) {
    ModelSetup setup = sim ? scaled(x[0]) : baseline;
    if (!bar)
      apply_effect(*effect, std::vector<double>(x.begin() + static_cast<std::ptrdiff_t>(first), x.end()), setup);
    return setup;
  };
  // The scan's best point, which the simplex evaluates first: its value is known (evaluations are deterministic).
  std::optional<std::pair<std::vector<double>, double>> known;
  // The refit's objective of a setup: its fit score, or the mean of it and the second capture's (where a yielding
  // setup is laid again from its best drape); `drape` receives its best drape on the capture.
  auto objective_of = [&](const ModelSetup& setup, ScoredDrape& drape, bool simulate) -> sim::Expected<double> {
    auto e = simulate ? model.evaluate(setup) : model.rescore(meshes, setup);
    if (!e) return e.error();
    double value = e->best.fit_score;
    if (second) {
      ModelSetup placed;
      auto e2 = on_next_placement(*second, setup, *e, model.initial_states(), placed);
      if (!e2) return sim::Error{"second capture: " + e2.error().message};
      value = 0.5 * (value + e2->best.fit_score);
    }
    drape = std::move(e->best);
    return value;
  };
  auto f = [&](const std::vector<double>& x) -> double {
    if (error) return std::numeric_limits<double>::infinity();
    if (known && known->first == x) return known->second;
    ScoredDrape drape;
    auto value = objective_of(setup_of(x), drape, sim);
    if (!value) {
      error = value.error();
      return std::numeric_limits<double>::infinity();
    }
    sim::logger()->debug("refit {}: {} -> {:.3f} mm (state {}, shape {:.2f})", bar ? "bending" : effect_name(*effect),
                         fmt::join(x, ", "), *value * 1e3, drape.state, drape.shape_fit);
    if (*value < best) {
      best = *value;
      c.drape = std::move(drape);
    }
    return *value;
  };
  NelderMeadOptions options = settings.optimiser;
  if (!sim) options.max_evaluations = settings.sensor_evaluations;
  // A scan before the simplex (the simplex refines from its best point): points and the axes the simplex then steps
  // along by a third of the scan's spacing, towards the range's middle.
  std::vector<std::vector<double>> scan;
  std::vector<std::size_t> scanned_axes;
  double spacing = 0.0;
  const int room = options.max_evaluations - AttributionSettings::kSimplexAfterScan;
  const bool one_parameter = sim && !bar && space.start.size() == 1;
  // A trade of a stiffer bending against a weaker effect (AttributionSettings::yield_trade_levels, shear_trade_levels):
  // `levels` points, the bending scale from x1 to e^reach evenly in ln, the effect's parameter at each anchor - power x
  // the ln scale. The yield trade reaches kYieldScaleRange or a known bending's box (no room to trade when the fit is
  // at its edge), beyond the other refits' bound; the shear trade reaches that bound.
  // Several anchors: one such line each (AttributionSettings::yield_trade_curvatures).
  struct Trade {
    int levels = 0;
    double reach = 0.0;
    std::vector<double> anchors;
    double power = 1.0;
  };
  // `n` levels of one axis over its whole range (both ends included), the other parameters at x0.
  auto scan_evenly = [&](std::size_t axis, int n) {
    spacing = (hi[axis] - lo[axis]) / (n - 1);
    for (int k = 0; k < n; ++k) {
      std::vector<double> x = x0;
      x[axis] = k + 1 == n ? hi[axis] : lo[axis] + spacing * k;
      scan.push_back(std::move(x));
    }
    scanned_axes = {axis};
  };
  std::optional<Trade> trade;
  if (one_parameter && effect == Effect::kYield) {
    std::vector<double> anchors;
    for (double k : settings.yield_trade_curvatures) anchors.push_back(std::log(k));
    trade = Trade{settings.yield_trade_levels,
                  settings.bending_scale_known ? hi[0] : AttributionSettings::kYieldScaleRange, std::move(anchors),
                  1.0};
  } else if (one_parameter && effect == Effect::kShear) {
    trade = Trade{settings.shear_trade_levels, hi[0], {std::log(AttributionSettings::kShearTradeStiffness)},
                  AttributionSettings::kShearTradePower};
  }
  const int trade_points = trade ? trade->levels * static_cast<int>(trade->anchors.size()) : 0;
  if (trade && trade->levels >= 2 && trade_points <= room && trade->reach > 0.01) {
    const int n = trade->levels;
    hi[0] = trade->reach;
    spacing = hi[0] / (n - 1);
    for (double anchor : trade->anchors) {
      for (int k = 0; k < n; ++k) {
        std::vector<double> x = x0;
        x[0] = k + 1 == n ? hi[0] : spacing * k;
        x[first] = std::clamp(anchor - trade->power * x[0], lo[first], hi[first]);
        scan.push_back(std::move(x));
      }
    }
    scanned_axes = {0, first};
  } else if (one_parameter && settings.scan_levels >= 2 && settings.scan_levels <= room) {
    // The strength over its range, the bending as fitted. A simplex from one fixed start rarely moved the strength
    // within the budget (docs/DIAGNOSIS_RESULTS.md, session 10).
    scan_evenly(first, settings.scan_levels);
  } else if (effect == Effect::kSensor && settings.sensor_gain_levels >= 2 && settings.sensor_gain_levels <= room) {
    // The multipath gain over its range (AttributionSettings::sensor_gain_levels), the camera at its start.
    scan_evenly(x0.size() - 1, settings.sensor_gain_levels);  // multipath_mm, effect_space's last
  } else if (effect == Effect::kMisalignment && settings.drift_scan_levels >= 1 &&
             settings.drift_scan_levels <= room) {
    // Drift sizes along the warp (AttributionSettings::drift_scan_levels), no turn, the bending as fitted.
    const int n = settings.drift_scan_levels;
    spacing = hi[first] / (n + 1);
    for (int k = 1; k <= n; ++k) {
      std::vector<double> x = x0;
      x[first] = spacing * k;  // x0 holds the fitted bending (scale 0) and no drift across
      scan.push_back(std::move(x));
    }
    scanned_axes = {first};
  }
  const int scanned = static_cast<int>(scan.size());
  if (scanned > 0) {
    double best_value = std::numeric_limits<double>::infinity();
    for (const auto& x : scan) {
      const double value = f(x);
      if (error) return *error;
      // The scanned parameter (the effect's; the sensor's multipath gain) and the bending scale (x1: re-rendered).
      c.scan.push_back({x[scanned_axes.back()], sim ? std::exp(x[0]) : 1.0, value});
      if (value < best_value) best_value = value, known = {x, value};
    }
    x0 = known->first;
    for (std::size_t axis : scanned_axes)
      step[axis] = (x0[axis] < 0.5 * (lo[axis] + hi[axis]) ? 1.0 : -1.0) * spacing / 3.0;
    // The simplex's first evaluation, the best point, is known: the budget of simulations stays the same.
    options.max_evaluations -= scanned - 1;
  }
  NelderMeadResult r = nelder_mead(f, x0, step, lo, hi, options);
  if (error) return *error;
  if (scanned > 0) r.evaluations += scanned - 1;
  ModelSetup refitted = setup_of(r.x);
  double ln_scale = sim ? r.x[0] : 0.0;
  if (effect == Effect::kSensor && settings.sensor_bending) {
    // The bending refitted under the camera the render-only refit found (AttributionSettings::sensor_bending).
    const std::size_t gain = r.x.size() - 1;  // multipath_mm, effect_space's last
    const std::size_t rendered = c.scan.size();  // the render-only scan's levels (sensor_gain_levels), if any
    auto under_camera = [&](double s, double g) {
      ModelSetup setup = scaled(s);
      std::vector<double> camera = r.x;
      camera[gain] = g;
      apply_effect(Effect::kSensor, camera, setup);
      return setup;
    };
    double stage_best = std::numeric_limits<double>::infinity();
    ScoredDrape stage_drape;
    auto g = [&](const std::vector<double>& y) -> double {
      if (error) return std::numeric_limits<double>::infinity();
      ScoredDrape drape;
      auto value = objective_of(under_camera(y[0], y[1]), drape, true);
      if (!value) {
        error = value.error();
        return std::numeric_limits<double>::infinity();
      }
      sim::logger()->debug("refit sensor, bending under its camera: scale x{:.2f}, multipath {:.1f} mm -> {:.3f} mm",
                           std::exp(y[0]), y[1], *value * 1e3);
      c.scan.push_back({y[1], std::exp(y[0]), *value});
      if (*value < stage_best) stage_best = *value, stage_drape = std::move(drape);
      return *value;
    };
    const auto [lower, upper] = bending_scale_bounds(settings);
    const double gain_hi = hi[first + gain];
    std::vector<double> y_best;
    for (const auto& y : sensor_bending_grid(lower, upper, gain_hi, settings.optimiser.max_evaluations)) {
      if (const double v = g(y); y_best.empty() || v <= stage_best) y_best = y;
      if (error) return *error;
    }
    const int grid = static_cast<int>(c.scan.size() - rendered);
    NelderMeadOptions refine = settings.optimiser;
    refine.max_evaluations = std::max(1, refine.max_evaluations - grid + 1);  // its first point is the grid's best
    const std::vector<double> known_y = y_best;
    const double known_value = stage_best;
    auto g_known = [&](const std::vector<double>& y) { return y == known_y ? known_value : g(y); };
    const std::vector<double> y_step{y_best[0] < 0.5 * (lower + upper) ? 0.25 : -0.25,
                                     y_best[1] < 0.5 * gain_hi ? 5.0 : -5.0};
    NelderMeadResult q = nelder_mead(g_known, y_best, y_step, {lower, 0.0}, {upper, gain_hi}, refine);
    if (error) return *error;
    const int simulated = static_cast<int>(c.scan.size() - rendered);
    // Its ablation: the same bending scale seen by the same camera without multipath.
    ScoredDrape ablation_drape;
    auto ablation = objective_of(under_camera(q.x[0], 0.0), ablation_drape, true);
    if (!ablation) return ablation.error();
    c.scan.push_back({0.0, std::exp(q.x[0]), *ablation});
    r.evaluations += simulated + 1;
    sim::logger()->debug("refit sensor, bending under its camera: x{:.2f}, {:.1f} mm -> {:.3f} mm (render-only "
                         "{:.3f}, without multipath {:.3f})",
                         std::exp(q.x[0]), q.x[1], stage_best * 1e3, best * 1e3, *ablation * 1e3);
    if (stage_best < best && stage_best < *ablation) {
      best = stage_best;
      c.drape = std::move(stage_drape);
      r.x[gain] = q.x[1];
      ln_scale = q.x[0];
      refitted = under_camera(q.x[0], q.x[1]);
      c.bending_under_sensor = true;
    }
  }
  // The refitted setup from the validation states (the sensor candidate re-renders the baseline's drapes from them,
  // unless it refitted the bending under its camera).
  const bool rerendered = !sim && !c.bending_under_sensor;
  if (sim::Status s = validate(model, second, held_out, refitted, rerendered ? &baseline_validated : nullptr, settings,
                               c);
      !s) {
    return s.error();
  }
  if (settings.ablation && sim && !bar) {
    // The same bending scale without the effect (the bar's shape at the candidate's scale).
    CandidateResult off;
    off.effect = c.effect;
    off.alpha_scale = std::exp(r.x[0]);
    const ModelSetup switched_off = scaled(r.x[0]);
    auto objective = objective_of(switched_off, off.drape, true);  // where the bar would rank it
    if (!objective) return objective.error();
    off.objective = *objective;
    if (sim::Status s = validate(model, second, held_out, switched_off, nullptr, settings, off); !s) return s.error();
    c.ablated = std::make_shared<const CandidateResult>(std::move(off));
  }
  c.alpha_scale = std::exp(ln_scale);
  c.parameters.assign(r.x.begin() + static_cast<std::ptrdiff_t>(first), r.x.end());
  c.evaluations = r.evaluations;
  c.objective = best;
  c.fit_score = c.drape.fit_score;
  c.held_out_score = c.drape.held_out_score;
  c.all_score = c.drape.all_score;
  c.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  sim::logger()->info("attribution: {} refitted, objective {:.2f} mm after {} evaluations ({:.0f} s)",
                      bar ? "the bending alone" : effect_name(*effect), c.objective * 1e3, c.evaluations, c.seconds);
  return c;
}

}  // namespace

std::vector<sim::InitialStateSpec> validation_states(const AttributionSettings& settings) {
  return fit_initial_states(settings.validation_states, settings.validation_seed);
}

std::vector<std::vector<double>> sensor_bending_grid(double lower, double upper, double gain_hi, int budget) {
  std::vector<std::vector<double>> points;
  for (double s : AttributionSettings::kSensorBendingScales) {
    for (double m : AttributionSettings::kSensorBendingGains) {
      std::vector<double> y{std::clamp(s, lower, upper), std::min(m, gain_hi)};
      if (std::find(points.begin(), points.end(), y) == points.end()) points.push_back(std::move(y));
    }
  }
  points.resize(std::min(points.size(), static_cast<std::size_t>(std::max(1, budget))));
  return points;
}

double confirmation_score(const ScoredDrape& drape, const ScoredDrape* held_out_capture) {
  return held_out_capture ? held_out_capture->all_score : drape.held_out_score;
}

std::optional<CommonBending> common_bending(const std::vector<CandidateResult>& candidates, const Floors& floors,
                                            int at_least) {
  CommonBending shared;
  std::vector<double> ln_scales;
  for (const auto& c : candidates) {
    if (c.confirmed() && c.validated_excess(floors) == 0.0) {
      shared.effects.push_back(c.effect);
      ln_scales.push_back(std::log(c.alpha_scale));
    }
  }
  if (at_least <= 0 || static_cast<int>(ln_scales.size()) < at_least) return std::nullopt;
  std::sort(ln_scales.begin(), ln_scales.end());
  const std::size_t n = ln_scales.size();
  shared.ln_scale = 0.5 * (ln_scales[(n - 1) / 2] + ln_scales[n / 2]);
  return shared;
}

bool promote_first(std::vector<CandidateResult>& ranked, Effect effect, double significant) {
  const auto it = std::find_if(ranked.begin(), ranked.end(), [&](const CandidateResult& c) {
    return c.effect == effect && c.confirmed() && c.shrinkage >= significant;
  });
  if (it == ranked.end() || it == ranked.begin()) return false;
  std::rotate(ranked.begin(), it, it + 1);
  return true;
}

bool ranks_before(const CandidateResult& x, const CandidateResult& y) {
  if (x.confirmed() != y.confirmed()) return x.confirmed();
  if (x.shrinkage != y.shrinkage) return x.shrinkage > y.shrinkage;
  if (needs_simulation(x.effect) != needs_simulation(y.effect)) return needs_simulation(x.effect);
  if (x.objective != y.objective) return x.objective < y.objective;
  return x.held_out_shrinkage > y.held_out_shrinkage;
}

bool near_ties_first(std::vector<CandidateResult>& ranked, double margin, double significant) {
  if (ranked.empty() || !ranked.front().confirmed() || margin <= 0.0) return false;
  // A first tied exactly keeps ranks_before's order (a physical effect before the sensor error).
  if (ranked.size() > 1 && ranked[1].confirmed() && ranked[1].shrinkage == ranked.front().shrinkage) return false;
  const double from = ranked.front().shrinkage - margin;
  auto best = ranked.begin();
  for (auto it = ranked.begin() + 1; it != ranked.end(); ++it) {
    if (it->confirmed() && it->shrinkage >= significant && it->shrinkage >= from && it->objective < best->objective)
      best = it;
  }
  if (best == ranked.begin()) return false;  // (every other candidate it may pick is significant)
  std::rotate(ranked.begin(), best, best + 1);
  return true;
}

bool confirms(double held_out_after, double held_out_before, double tolerance) {
  return held_out_after <= (1.0 + tolerance) * held_out_before;
}

Confirmation confirmation(double held_out_after, double held_out_before, const ScoredDrape* held_out_capture,
                          const Floors& floors, const AttributionSettings& settings) {
  if (confirms(held_out_after, held_out_before, settings.held_out_tolerance)) return Confirmation::kScore;
  if (settings.confirm_within_floors && held_out_capture &&
      excess_above_floors(gap_terms(*held_out_capture), floors) == 0.0) {
    return Confirmation::kWithinFloors;
  }
  return Confirmation::kNone;
}

double gap_shrinkage(double excess_before, double excess_after) {
  return excess_before > 0.0 ? 1.0 - excess_after / excess_before : 0.0;
}

double bootstrap_confidence(const ForwardModel& model, const ScoredDrape& a, const ScoredDrape& b, int samples,
                            int tile_px, std::uint64_t seed, bool all_views) {
  const auto& fit_views = model.settings().fit_views;
  std::vector<double> d;  // per tile: b's energy - a's energy
  for (std::size_t v = 0; v < a.views.size() && v < b.views.size(); ++v) {
    if (!all_views && std::find(fit_views.begin(), fit_views.end(), static_cast<int>(v)) != fit_views.end()) continue;
    const auto& img = model.capture().views[v].depth;
    const int W = img.width, H = img.height;
    for (int ty = 0; ty < H; ty += tile_px) {
      for (int tx = 0; tx < W; tx += tile_px) {
        double ea = 0.0, eb = 0.0;
        bool any = false;
        for (int y = ty; y < std::min(H, ty + tile_px); ++y) {
          for (int x = tx; x < std::min(W, tx + tile_px); ++x) {
            const std::size_t i = static_cast<std::size_t>(y) * W + x;
            const float ra = a.views[v].residual[i], rb = b.views[v].residual[i];
            if (std::isfinite(ra)) ea += static_cast<double>(ra) * ra, any = true;
            if (std::isfinite(rb)) eb += static_cast<double>(rb) * rb, any = true;
          }
        }
        if (any) d.push_back(eb - ea);
      }
    }
  }
  if (d.empty() || samples <= 0) return 0.5;
  renderer::Rng rng(seed);
  int wins = 0;
  for (int s = 0; s < samples; ++s) {
    double sum = 0.0;
    for (std::size_t k = 0; k < d.size(); ++k)
      sum += d[std::min(d.size() - 1, static_cast<std::size_t>(rng.uniform() * d.size()))];
    wins += sum > 0.0;
  }
  return static_cast<double>(wins) / samples;
}

sim::Expected<Attribution> attribute(ForwardModel& model, const ModelSetup& baseline, const Evaluation& fit,
                                     const Evaluation& validated, const Floors& floors,
                                     const AttributionSettings& given, const ModelFactory& make_model,
                                     const OtherCaptures& others) {
  AttributionSettings settings = given;
  if (settings.multipath_first && others.views_imply_multipath) settings.sensor_bending = true;
  // Tasks: the candidates, then the bar (no effect: the baseline's bending scale refitted with the same budget).
  const std::size_t tasks = settings.candidates.size() + 1;
  auto task_effect = [&](std::size_t k) -> std::optional<Effect> {
    return k < settings.candidates.size() ? std::optional<Effect>(settings.candidates[k]) : std::nullopt;
  };
  std::vector<std::optional<sim::Expected<CandidateResult>>> results(tasks);
  const int jobs = std::max(1, std::min<int>(settings.jobs, static_cast<int>(tasks)));
  if (jobs == 1 || !make_model) {
    for (std::size_t k = 0; k < tasks; ++k) {
      results[k] = refit(model, others.second.model, others.held_out.model, task_effect(k), baseline, fit, validated,
                         settings);
    }
  } else {
    std::mutex mutex;
    std::optional<sim::Error> error;
    // Each thread takes the next task when it is free: the refits differ in length several times over (a
    // misalignment refit can take as long as three others), so a fixed share per thread left one idle. The longest
    // go first: those that simulate before those that re-render, the most parameters first.
    std::vector<std::size_t> order(tasks);
    std::iota(order.begin(), order.end(), std::size_t{0});
    auto cost = [&](std::size_t k) {
      const std::optional<Effect> e = task_effect(k);
      const bool simulates = !e || needs_simulation(*e);
      return std::pair(simulates, e ? effect_space(*e).names.size() : 0);
    };
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return cost(a) > cost(b); });
    WorkQueue queue(tasks);
    run_on_threads(jobs, [&](int j) {
      // Thread 0 uses the given models, every other thread its own of each capture.
      std::vector<std::unique_ptr<ForwardModel>> own;
      auto model_of = [&](ForwardModel* given) -> ForwardModel* {
        if (j == 0 || !given) return given;
        auto created = make_model(given->capture());
        if (!created) {
          std::lock_guard lock(mutex);
          error = created.error();
          return nullptr;
        }
        own.push_back(std::move(*created));
        return own.back().get();
      };
      ForwardModel* m = model_of(&model);
      ForwardModel* second = model_of(others.second.model);
      ForwardModel* held_out = model_of(others.held_out.model);
      if (!m || (others.second && !second) || (others.held_out && !held_out)) return;
      while (const auto n = queue.take()) {
        const std::size_t k = order[*n];
        auto r = refit(*m, second, held_out, task_effect(k), baseline, fit, validated, settings);
        std::lock_guard lock(mutex);
        results[k] = std::move(r);
      }
    });
    if (error) return *error;
  }
  for (auto& r : results)
    if (!r || !*r) return r ? r->error() : sim::Error{"candidate refit did not run"};
  // The gate's terms of a candidate (or the reference): its validation drape's, or the mean of it and the paired
  // capture's (gap_terms). The baseline's drapes against the other placements are scored, not simulated again.
  const ScoredDrape* baseline_paired = others.paired().baseline;
  const ScoredDrape* baseline_held_out = others.held_out.baseline;
  // Shrinkage: of the excess above the floors that made the gate fire (the same two tests), once the candidate is
  // added, measured from the validation states against the reference: the better (smaller excess) of the baseline
  // and the bar. So an effect counts only for what it adds beyond refitting the bending alone. The held-out view (not
  // in any refit), or the held-out capture, must confirm it: its score there at most (1 + held_out_tolerance) times
  // the reference's, a tolerance for the noise of choosing the best validation drape there (confirms); with
  // confirm_within_floors, also where its drape on the held-out capture is within the floors.
  Attribution a;
  a.held_out_tolerance = settings.held_out_tolerance;
  a.confirm_within_floors = settings.confirm_within_floors;
  a.significant_shrinkage = settings.significant_shrinkage;
  a.bar = std::move(results.back()->value());
  const double baseline_excess = excess_above_floors(gap_terms(validated.best, baseline_paired), floors);
  const double bar_excess = a.bar.validated_excess(floors);
  a.bar.shrinkage = gap_shrinkage(baseline_excess, bar_excess);
  a.bar_within_floors = bar_excess == 0.0;
  const bool bar_is_reference = a.bar.shrinkage > 0.0;
  const ScoredDrape& reference = bar_is_reference ? a.bar.validated : validated.best;
  const ScoredDrape* reference_held_out = bar_is_reference ? a.bar.held_out_drape() : baseline_held_out;
  const double h0 = confirmation_score(reference, reference_held_out);
  const double excess0 = bar_is_reference ? bar_excess : baseline_excess;
  for (std::size_t k = 0; k + 1 < tasks; ++k) {
    CandidateResult c = std::move(results[k]->value());
    const double h = confirmation_score(c.validated, c.held_out_drape());
    double from = excess0, against = h0;  // with an ablation, the smaller of the reference's and its own
    if (c.ablated) {
      from = std::min(from, c.ablated->validated_excess(floors));
      against = std::min(against, confirmation_score(c.ablated->validated, c.ablated->held_out_drape()));
    }
    c.shrinkage = gap_shrinkage(from, c.validated_excess(floors));
    c.held_out_shrinkage = against > 0.0 ? 1.0 - h / against : 0.0;
    c.confirmation = confirmation(h, against, c.held_out_drape(), floors, settings);
    a.candidates.push_back(std::move(c));
  }
  std::stable_sort(a.candidates.begin(), a.candidates.end(), ranks_before);
  a.tie_margin = settings.tie_margin;
  a.common_bending_effects = settings.common_bending_effects;
  a.sensor_held = settings.sensor_held && settings.sensor_start.has_value() &&
                  std::find(settings.candidates.begin(), settings.candidates.end(), Effect::kSensor) !=
                      settings.candidates.end();
  a.near_tie_promoted = near_ties_first(a.candidates, settings.tie_margin, settings.significant_shrinkage);
  if (a.near_tie_promoted)
    sim::logger()->info("attribution: {} within {:.2f} of the first's shrinkage; named first as a tie",
                        effect_name(a.candidates[0].effect), settings.tie_margin);
  a.curl_promoted =
      others.fold_unlike_model && promote_first(a.candidates, Effect::kCurl, settings.significant_shrinkage);
  if (a.curl_promoted)
    sim::logger()->info("attribution: the placements fold less alike than the fitted model's drapes; curl first");
  a.multipath_first = settings.multipath_first;
  a.sensor_promoted = settings.multipath_first && others.views_imply_multipath &&
                      promote_first(a.candidates, Effect::kSensor, settings.significant_shrinkage);
  if (a.sensor_promoted)
    sim::logger()->info("attribution: every placement's views imply multipath; the sensor error first");
  if (const auto shared = common_bending(a.candidates, floors, settings.common_bending_effects);
      shared && !a.bar_within_floors) {
    // Unlike effects each within the floors: the bending scale they share, validated as the bar is.
    CandidateResult common;
    common.alpha_scale = std::exp(shared->ln_scale);
    if (sim::Status s = validate(model, others.second.model, others.held_out.model,
                                 scaled_bending(baseline, shared->ln_scale), nullptr, settings, common);
        !s) {
      return s.error();
    }
    const double common_excess = common.validated_excess(floors);
    common.shrinkage = gap_shrinkage(baseline_excess, common_excess);
    a.common_within_floors = common_excess == 0.0;
    a.common_effects = shared->effects;
    sim::logger()->info("attribution: {} effects within the floors; the bending alone at x{:.2f} {}",
                        shared->effects.size(), common.alpha_scale, a.common_within_floors ? "is as well" : "is not");
    a.common_bending = std::move(common);
  }
  if (!a.candidates.empty()) {
    a.named = !a.bending_within_floors() && a.candidates[0].confirmed() &&
              a.candidates[0].shrinkage >= settings.significant_shrinkage;
    a.confidence = 1.0;
    if (a.candidates.size() > 1) {
      const CandidateResult &best = a.candidates[0], &runner_up = a.candidates[1];
      a.confidence = others.held_out
                         ? bootstrap_confidence(*others.held_out.model, *best.held_out_drape(),
                                                *runner_up.held_out_drape(), settings.bootstrap_samples,
                                                settings.tile_px, 0xB007, true)
                         : bootstrap_confidence(model, best.validated, runner_up.validated, settings.bootstrap_samples,
                                                settings.tile_px, 0xB007);
    }
  }
  return a;
}

}  // namespace drapegen::diagnosis
