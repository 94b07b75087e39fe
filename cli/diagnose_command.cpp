// drapegen diagnose: where the sim-to-real gap of a capture lies and which unmodelled effect explains it (issue 6).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <tuple>
#include <utility>
#include <vector>
#include <nlohmann/json.hpp>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "commands.hpp"
#include "failure.hpp"
#include "drapegen/coordinator/logging.hpp"
#include "drapegen/coordinator/simulation_fleet.hpp"
#include "drapegen/diagnosis/capture.hpp"
#include "drapegen/diagnosis/diagnosis.hpp"
#include "drapegen/diagnosis/report.hpp"
#include "drapegen/sim/logging.hpp"
#include "drapegen/storage/atomic_file.hpp"
#include "drapegen/storage/json_text.hpp"
#include "parse.hpp"
#include "usable_cpus.hpp"

namespace drapegen::cli {
namespace {

struct DiagnoseOptions {
  std::string capture;
  std::string held_out;
  std::string second;
  std::string report;
  bool json = false;
  bool quick = false;
  bool fine = false;
  // Unset options keep the settings' value (default, --quick or --fine).
  std::optional<int> resolution;
  int confirm_resolution = 0;
  double confirm_placement_rise = 0.0;
  std::optional<double> turn_over_yield;
  std::optional<double> turn_over_alternation;
  std::optional<double> off_centre_misalignment;
  std::optional<double> off_centre_mm;
  std::optional<bool> off_centre_mm_over_yield;  // unset: the settings' (off)
  std::optional<double> hem_tilt_misalignment;
  std::optional<int> states;
  std::optional<int> evaluations;
  std::optional<int> refit_evaluations;
  std::optional<int> sensor_evaluations;
  std::optional<int> refit_scan;
  std::optional<int> yield_trade;
  std::vector<double> yield_trade_at;  // empty: the default lines (AttributionSettings::yield_trade_curvatures)
  std::optional<int> shear_trade;
  std::optional<int> drift_scan;
  std::vector<std::string> candidates;  // empty: every effect
  std::optional<int> starts;
  std::string start_alpha, start_beta;  // empty: the drape-coefficient guess
  std::optional<double> start_box;      // unset: the whole box
  bool ignore_measured_bending = false;
  std::optional<int> jobs;  // unset: one per CPU this process may run on, with a fleet --fleet-workers (run_diagnose)
  std::optional<double> shape_floor;
  double placement_shape_floor = 0.0;
  bool placement_drape_test = false;
  double placement_drape_floor = 0.0;
  bool placement_drape_when_seen = false;
  bool gap_only = false;
  bool ablation = false;
  bool confirm_within_floors = false;
  bool sensor_bending = false;
  bool multipath_first = diagnosis::AttributionSettings{}.multipath_first;
  bool multipath_region = diagnosis::DiagnosisSettings{}.multipath_region;
  std::optional<int> sensor_gain_scan;
  bool free_sensor = false;
  std::optional<int> common_bending;
  double tie_margin = diagnosis::AttributionSettings{}.tie_margin;
  double held_out_tolerance = diagnosis::AttributionSettings{}.held_out_tolerance;
  bool verbose = false;
  bool quiet = false;
  std::string fleet;  // empty: the drapes are computed here
  int fleet_workers = 1;
  double fleet_wait = coordinator::FleetOptions{}.wait_s;
  std::string fleet_endpoint_file;
  std::string fleet_server_key, fleet_authorized_keys;  // CurveZMQ
};

const Failure fail{"diagnose"};
constexpr int kMaxJobs = 64;

int run_diagnose(const DiagnoseOptions& o) {
  if (o.jobs && (*o.jobs < 1 || *o.jobs > kMaxJobs)) return fail(fmt::format("--jobs must be 1 .. {}", kMaxJobs));
  // By default one thread per CPU here; with a fleet, as many refits in flight as workers are asked for.
  const int jobs = o.jobs.value_or(std::clamp(o.fleet.empty() ? usable_cpus() : o.fleet_workers, 1, kMaxJobs));
  if (o.fleet.empty() && !(o.fleet_endpoint_file.empty() && o.fleet_server_key.empty() &&
                           o.fleet_authorized_keys.empty())) {
    return fail("--fleet-endpoint-file, --fleet-server-key and --fleet-authorized-keys need --fleet");
  }
  if (o.fleet_workers < 0 || o.fleet_workers > 10000) return fail("--fleet-workers must be 0 .. 10000");
  if (!(o.fleet_wait > 0.0 && o.fleet_wait <= 86400.0)) return fail("--fleet-wait must be > 0 .. 86400 s");
  const auto outside = [](const std::optional<int>& value, int lo, int hi) {
    return value && (*value < lo || *value > hi);
  };
  // A scan of N levels: 0 (off) or 2 .. hi (one level is no scan).
  const auto bad_scan = [&](const std::optional<int>& value, int hi) { return outside(value, 0, hi) || value == 1; };
  if (outside(o.resolution, 6, 60)) return fail("--resolution must be 6 .. 60");
  if (o.confirm_resolution != 0 && outside(o.confirm_resolution, 6, 60)) {
    return fail("--confirm-resolution must be 0 (off) or 6 .. 60");
  }
  if (outside(o.states, 1, 16)) return fail("--states must be 1 .. 16");
  for (auto [value, option] : {std::pair{&o.evaluations, "--evaluations"},
                               std::pair{&o.refit_evaluations, "--refit-evaluations"},
                               std::pair{&o.sensor_evaluations, "--sensor-evaluations"}}) {
    if (outside(*value, 1, 10000)) return fail(fmt::format("{} must be 1 .. 10000", option));
  }
  if (o.shape_floor && !(*o.shape_floor >= 0.0 && *o.shape_floor <= 100.0)) {
    return fail("--shape-floor must be 0 (from the floor samples) .. 100");
  }
  if (!(o.placement_shape_floor >= 0.0 && o.placement_shape_floor <= 100.0)) {
    return fail("--placement-shape-floor must be 0 (no such test) .. 100");
  }
  if (o.placement_shape_floor > 0.0 && o.second.empty() && o.held_out.empty()) {
    return fail("--placement-shape-floor tests two placements: give --second-capture or --held-out-capture");
  }
  if (o.placement_drape_test && o.second.empty() && o.held_out.empty()) {
    return fail("--placement-drape-test tests two placements: give --second-capture or --held-out-capture");
  }
  if (!(o.placement_drape_floor >= 0.0 && o.placement_drape_floor < 1.0)) {
    return fail("--placement-drape-floor must be 0 (the model's range) .. 1 (a drape-coefficient difference)");
  }
  if (!(o.confirm_placement_rise >= 0.0 && o.confirm_placement_rise < 1.0)) {
    return fail("--confirm-placement-rise must be 0 (off) .. 1 (a drape-coefficient difference)");
  }
  if (o.confirm_placement_rise > 0.0 && o.second.empty()) {
    return fail("--confirm-placement-rise compares the turned placement with the capture: give --second-capture");
  }
  if (o.confirm_placement_rise > 0.0 && o.placement_drape_test) {
    return fail("--confirm-placement-rise diagnoses again with the placement drape test: leave out "
                "--placement-drape-test");
  }
  if (o.turn_over_yield && !(*o.turn_over_yield >= 0.0 && *o.turn_over_yield < 1.0)) {
    return fail("--turn-over-yield must be 0 (off) .. 1 (a drape-coefficient difference)");
  }
  if (o.turn_over_yield.value_or(0.0) > 0.0 && o.second.empty()) {
    return fail("--turn-over-yield compares the turned placement with the capture: give --second-capture");
  }
  if (o.turn_over_alternation && !(*o.turn_over_alternation >= 0.0 && *o.turn_over_alternation < 1.0)) {
    return fail("--turn-over-alternation must be 0 (off) .. 1 (a drape-coefficient difference)");
  }
  if (o.turn_over_alternation.value_or(0.0) > 0.0 && (o.second.empty() || o.held_out.empty())) {
    return fail("--turn-over-alternation compares the turned placement with the two on the capture's face: give "
                "--second-capture and --held-out-capture");
  }
  if (o.off_centre_misalignment && !(*o.off_centre_misalignment >= 0.0)) {
    return fail("--off-centre-misalignment must be 0 (off) or more (a ratio to the off-centre floor)");
  }
  if (o.off_centre_mm && !(*o.off_centre_mm >= 0.0)) return fail("--off-centre-mm must be 0 (off) or more (mm)");
  if (o.off_centre_mm_over_yield.value_or(false) && !(o.off_centre_mm.value_or(0.0) > 0.0)) {
    return fail("--off-centre-mm-over-yield weighs the refits' yield by the hem's centre: give --off-centre-mm "
                "above 0");
  }
  if (o.hem_tilt_misalignment && !(*o.hem_tilt_misalignment >= 0.0)) {
    return fail("--hem-tilt-misalignment must be 0 (off) or more (mm)");
  }
  if (o.hem_tilt_misalignment.value_or(0.0) > 0.0 && (o.second.empty() || o.held_out.empty())) {
    return fail("--hem-tilt-misalignment reads the hem's tilt on three placements: give --second-capture and "
                "--held-out-capture");
  }
  if (!(o.held_out_tolerance >= 0.0 && o.held_out_tolerance <= 1.0)) return fail("--held-out-tolerance must be 0 .. 1");
  if (outside(o.starts, 0, 100)) return fail("--starts must be 0 (the guess alone) .. 100");
  if (bad_scan(o.refit_scan, 100)) return fail("--refit-scan must be 0 (off) or 2 .. 100");
  if (bad_scan(o.common_bending, 6)) return fail("--common-bending must be 0 (off) or 2 .. 6");
  if (!(o.tie_margin >= 0.0 && o.tie_margin <= 1.0)) return fail("--tie-margin must be 0 (exact ties only) .. 1");
  if (bad_scan(o.sensor_gain_scan, 1000)) return fail("--sensor-gain-scan must be 0 (off) or 2 .. 1000");
  if (bad_scan(o.yield_trade, 100)) return fail("--yield-trade must be 0 (off) or 2 .. 100");
  // Within the yield candidate's box (effect_space: ln of the curvature), where the refit would clamp it anyway.
  const diagnosis::EffectSpace yield_box = diagnosis::effect_space(diagnosis::Effect::kYield);
  const double yield_lo = std::exp(yield_box.lower[0]), yield_hi = std::exp(yield_box.upper[0]);
  for (double k : o.yield_trade_at) {
    if (!(k >= yield_lo * (1 - 1e-9) && k <= yield_hi * (1 + 1e-9))) {
      return fail(fmt::format("--yield-trade-at: each curvature must be {:g} .. {:g} /m", yield_lo, yield_hi));
    }
  }
  if (!o.yield_trade_at.empty() && o.yield_trade.value_or(diagnosis::AttributionSettings{}.yield_trade_levels) == 0) {
    return fail("--yield-trade-at places the lines of --yield-trade, which is off");
  }
  if (bad_scan(o.shear_trade, 100)) return fail("--shear-trade must be 0 (off) or 2 .. 100");
  if (outside(o.drift_scan, 0, 100)) return fail("--drift-scan must be 0 (off) .. 100");
  std::optional<diagnosis::BendingParameters> start;
  if (o.start_alpha.empty() != o.start_beta.empty()) return fail("--start-alpha and --start-beta go together");
  if (!o.start_alpha.empty()) {
    const auto alpha = parse_directional(o.start_alpha, "--start-alpha");
    if (!alpha) return fail(alpha.error().message);
    const auto beta = parse_directional(o.start_beta, "--start-beta");
    if (!beta) return fail(beta.error().message);
    if (!(alpha->warp > 0 && alpha->bias > 0 && alpha->weft > 0)) return fail("--start-alpha must be positive");
    start = diagnosis::BendingParameters{.alpha = *alpha, .beta = *beta};
  }
  if (o.start_box && (!start || !(*o.start_box > 1.0 && *o.start_box <= 100.0))) {
    return fail("--start-box must be 1 .. 100 (exclusive of 1) and needs --start-alpha/--start-beta");
  }
  std::vector<diagnosis::Effect> candidates;
  for (const auto& name : o.candidates) {
    // `drapegen reality`'s name of the misalignment effect, taken here too.
    const auto effect = diagnosis::parse_effect(name == "misalign" ? "misalignment" : name);
    if (!effect) return fail(fmt::format("--candidates: unknown effect '{}' (yield, shear, curl, friction, "
                                         "misalignment or misalign, sensor)", name));
    if (std::find(candidates.begin(), candidates.end(), *effect) != candidates.end()) {
      return fail(fmt::format("--candidates: '{}' given twice", name));
    }
    candidates.push_back(*effect);
  }
  // Each stage's end by default (a diagnosis takes minutes); every evaluation with --verbose; warnings with --quiet.
  const auto level = o.verbose ? spdlog::level::debug : o.quiet ? spdlog::level::warn : spdlog::level::info;
  sim::logger()->set_level(level);
  coordinator::logger()->set_level(level);  // the fleet's
  auto capture = diagnosis::read_capture(o.capture);
  if (!capture) return fail(capture.error().message);
  if (const double half_mm = 500.0 * std::min(capture->specimen.size_x, capture->specimen.size_y);
      o.off_centre_mm && *o.off_centre_mm > half_mm) {
    return fail(fmt::format("--off-centre-mm {:g}: more than half the specimen's side ({:g} mm)", *o.off_centre_mm,
                            half_mm));
  }
  std::optional<diagnosis::Capture> held_out, second;
  for (auto [path, into, role] : {std::tuple{&o.held_out, &held_out, "held-out capture"},
                                  std::tuple{&o.second, &second, "second capture"}}) {
    if (path->empty()) continue;
    auto read = diagnosis::read_capture(*path);
    if (!read) return fail(std::string(role) + ": " + read.error().message);
    *into = std::move(*read);
  }
  if (!o.report.empty()) {
    // Not into a capture: a capture made again there (drapegen reality --out) would sit beside the old report.
    std::error_code ec;
    if (std::filesystem::exists(std::filesystem::path(o.report) / "capture.json", ec)) {
      return fail(fmt::format("--report {}: a capture's directory (it holds capture.json); write the report to "
                              "another directory",
                              o.report));
    }
    if (sim::Status s = prepare_output_directory(o.report, "report.json"); !s) return fail(s.error().message, kExitIo);
  }
  diagnosis::DiagnosisSettings settings = o.fine    ? diagnosis::DiagnosisSettings::fine()
                                          : o.quick ? diagnosis::DiagnosisSettings::quick()
                                                    : diagnosis::DiagnosisSettings{};
  if (o.resolution) settings.fit.resolution = *o.resolution;
  settings.confirm_resolution = o.confirm_resolution;
  settings.confirm_placement_rise = o.confirm_placement_rise;
  if (o.turn_over_yield) settings.turn_over_yield = *o.turn_over_yield;
  if (o.turn_over_alternation) settings.turn_over_alternation = *o.turn_over_alternation;
  if (o.off_centre_misalignment) settings.off_centre_misalignment = *o.off_centre_misalignment;
  if (o.off_centre_mm) settings.off_centre_mm = *o.off_centre_mm;
  if (o.off_centre_mm_over_yield) settings.off_centre_mm_over_yield = *o.off_centre_mm_over_yield;
  if (o.hem_tilt_misalignment) settings.hem_tilt_misalignment = *o.hem_tilt_misalignment;
  if (o.states) settings.fit.initial_states = *o.states;
  if (o.evaluations) settings.baseline_optimiser.max_evaluations = *o.evaluations;
  if (o.refit_evaluations) settings.attribution.optimiser.max_evaluations = *o.refit_evaluations;
  if (o.sensor_evaluations) settings.attribution.sensor_evaluations = *o.sensor_evaluations;
  settings.attribution.sensor_bending = o.sensor_bending;
  settings.attribution.multipath_first = o.multipath_first;
  settings.multipath_region = o.multipath_region;
  if (o.sensor_gain_scan) settings.attribution.sensor_gain_levels = *o.sensor_gain_scan;
  settings.hold_sensor = !o.free_sensor;
  if (o.common_bending) settings.attribution.common_bending_effects = *o.common_bending;
  settings.attribution.tie_margin = o.tie_margin;
  if (o.refit_scan) settings.attribution.scan_levels = *o.refit_scan;
  if (o.yield_trade) settings.attribution.yield_trade_levels = *o.yield_trade;
  if (!o.yield_trade_at.empty()) settings.attribution.yield_trade_curvatures = o.yield_trade_at;
  if (o.shear_trade) settings.attribution.shear_trade_levels = *o.shear_trade;
  if (o.drift_scan) settings.attribution.drift_scan_levels = *o.drift_scan;
  if (!candidates.empty()) settings.attribution.candidates = candidates;
  if (o.starts) settings.start_levels = *o.starts;
  settings.start = start;
  settings.start_box = o.start_box.value_or(0.0);
  settings.use_measured_bending = !o.ignore_measured_bending;
  // A scan asked for must leave the refit's simplex its room; a default one that does not is skipped by the refit.
  constexpr int kKeep = diagnosis::AttributionSettings::kSimplexAfterScan;
  const std::optional<int> yield_points = o.yield_trade || !o.yield_trade_at.empty()
                                              ? std::optional<int>(settings.attribution.yield_trade_points())
                                              : std::nullopt;
  for (auto [levels, option] :
       {std::pair{o.refit_scan, "--refit-scan"}, std::pair{yield_points, "--yield-trade (points over its lines)"},
        std::pair{o.shear_trade, "--shear-trade"}, std::pair{o.drift_scan, "--drift-scan"}}) {
    if (levels && *levels > 0 &&
        *levels > settings.attribution.optimiser.max_evaluations - kKeep) {  // 0: off, nothing to fit
      return fail(fmt::format("{} ({}) must leave the refit's simplex {} of its {} evaluations", option, *levels, kKeep,
                              settings.attribution.optimiser.max_evaluations));
    }
  }
  if (o.sensor_gain_scan && *o.sensor_gain_scan > 0 &&  // 0: off, nothing to fit
      *o.sensor_gain_scan > settings.attribution.sensor_evaluations - kKeep) {
    return fail(fmt::format("--sensor-gain-scan ({}) must leave the sensor refit's simplex {} of its {} evaluations",
                            *o.sensor_gain_scan, kKeep, settings.attribution.sensor_evaluations));
  }
  settings.attribution.jobs = jobs;
  settings.attribute = !o.gap_only;
  settings.attribution.ablation = o.ablation;
  settings.attribution.confirm_within_floors = o.confirm_within_floors;
  settings.attribution.held_out_tolerance = o.held_out_tolerance;
  if (o.shape_floor) settings.floors.shape_threshold = settings.held_out_shape_threshold = *o.shape_floor;
  settings.floors.placement_shape_threshold = o.placement_shape_floor;
  settings.floors.placement_drape_coefficient = o.placement_drape_test;
  settings.floors.placement_drape_floor = o.placement_drape_floor;
  settings.floors.placement_drape_when_seen = o.placement_drape_when_seen;
  // The fleet: the drapes go to workers; the renders, scores and the search stay here.
  std::unique_ptr<coordinator::SimulationFleet> fleet;
  if (!o.fleet.empty()) {
    auto started = coordinator::SimulationFleet::start({.bind = o.fleet,
                                                        .server_secret_key = o.fleet_server_key,
                                                        .authorized_keys = o.fleet_authorized_keys,
                                                        .wait_s = o.fleet_wait});
    if (!started) return fail(started.error().message);
    fleet = std::move(started).value();
    const std::string& endpoint = fleet->endpoint();
    if (!o.fleet_endpoint_file.empty()) {
      if (sim::Status s = storage::write_file_atomic(o.fleet_endpoint_file, endpoint + "\n"); !s) {
        return fail(s.error().message, kExitIo);
      }
    }
    sim::logger()->info("fleet: serving drapes at {}; waiting for {} worker(s) (drapegen worker --connect {})",
                        endpoint, o.fleet_workers, endpoint);
    if (fleet->wait_for_workers(o.fleet_workers, o.fleet_wait) < o.fleet_workers) {
      return fail(fmt::format("fleet: fewer than {} worker(s) connected to {} within {} s", o.fleet_workers, endpoint,
                              o.fleet_wait));
    }
    coordinator::SimulationFleet* f = fleet.get();
    settings.fit.simulator = [f](const sim::DrapeConfig& config) { return f->simulate(config); };
    settings.refit_state_threads = jobs;
  }
  auto result = diagnosis::diagnose(
      *capture, settings, {.second = second ? &*second : nullptr, .held_out = held_out ? &*held_out : nullptr});
  if (!result) return fail(result.error().message);
  if (fleet) {
    const auto c = fleet->counters();
    sim::logger()->info("fleet: {} drapes on {} worker(s) ({} attempts lost with a worker)", c.simulated,
                        c.workers_seen, c.lost_attempts);
    settings.fit.simulator = {};
    fleet.reset();  // the workers are told to shut down
  }
  if (!o.report.empty()) {
    diagnosis::FitSettings fit = settings.fit;  // the reported diagnosis's mesh (--confirm-resolution's, maybe)
    fit.resolution = result->budgets.resolution;
    auto model = diagnosis::ForwardModel::create(*capture, fit);
    if (!model) return fail(model.error().message);
    if (sim::Status s = diagnosis::write_report(o.report, *result, *capture, **model); !s) {
      return fail(s.error().message, kExitIo);
    }
  }
  const nlohmann::json j = diagnosis::to_json(*result, *capture);
  if (o.json) {
    std::cout << storage::json_text(j) << "\n";
  } else {
    const auto& r = *result;
    std::cout << fmt::format("diagnose: {} in {:.0f} s\n", o.capture, r.seconds);
    // The verdict's tests first: the scores' own floors are for reference (report.md, "Gap and floors").
    const diagnosis::GapTerms gap = r.gap();
    std::cout << fmt::format("  tests: stable term {:.2f} mm against its floor {:.2f} mm; shape distance {:.2f} "
                             "against its floor {:.2f}\n",
                             gap.stable * 1e3, r.floors.stable * 1e3, gap.shape, r.floors.shape);
    if (r.floors.placement_shape > 0.0) {
      std::cout << fmt::format("  placement test: the larger placement's shape distance {:.2f} against its floor "
                               "{:.2f}\n",
                               gap.shape_max, r.floors.placement_shape);
    }
    if (r.floors.placement_dc > 0.0) {
      std::cout << fmt::format("  placement drape test: the placements' drape-coefficient difference less the "
                               "model's {:.4f} against its floor {:.4f}\n",
                               gap.placement_dc, r.floors.placement_dc);
    }
    std::cout << fmt::format("  score {:.2f} mm (all views), {:.2f} mm (held-out view); the scores' floors {:.2f} / "
                             "{:.2f} mm\n",
                             r.gap_all * 1e3, r.gap_held_out * 1e3, r.floors.all * 1e3, r.floors.held_out * 1e3);
    std::cout << fmt::format("  localised: {}\n", diagnosis::region_name(r.localisation.dominant));
    if (const auto& m = r.mesh_confirmation) {
      const int first = m->gap_found ? m->other->budgets.resolution : r.budgets.resolution;
      std::cout << (m->gap_found ? fmt::format("  mesh confirmation: the {0}x{0} mesh finds the gap too: its diagnosis "
                                               "here (the {1}x{1} mesh's verdict: {2})\n",
                                               m->resolution, first, m->other->verdict)
                                 : fmt::format("  mesh confirmation: the {0}x{0} mesh leaves the gap within its "
                                               "floors: the {1}x{1} mesh's diagnosis here\n",
                                               m->resolution, first));
    }
    if (const auto& p = r.placement_confirmation) {
      std::cout << fmt::format("  placement confirmation: the verdict {} without the placement drape test, but the "
                               "turned placement drapes {:.4f} stiffer (at least {:g}): the diagnosis with the test "
                               "here\n",
                               p->other->verdict, p->rise, p->floor);
    }
    // A signature of its own set the verdict (rules U, A, E, D and H): what it read, the refits' verdict, the named
    // refit.
    const auto named_by = [&r](std::string_view effect, const std::string& reading) {
      const diagnosis::CandidateResult* refit = r.named_refit();
      std::cout << fmt::format("  verdict: {}, {}; the refits' verdict {}; {}\n", effect, reading, r.refits_verdict(),
                               refit ? fmt::format("the {} refit's shrinkage {:.0f}%", effect, 100 * refit->shrinkage)
                                     : fmt::format("no {} refit ran", effect));
    };
    if (const auto& h = r.hem_tilt) {
      named_by("misalignment", fmt::format("from the hem's tilt: it hangs lower on one side by {:.2f} mm or more on "
                                           "each of the three placements (at least {:g} mm)",
                                           h->smallest_mm, h->floor_mm));
    } else if (const auto& t = r.turn_over) {
      named_by("yield", fmt::format("from the turn-over: the turned placement drapes {:.4f} stiffer (at least {:g})",
                                    t->rise, t->floor));
    } else if (const auto& c = r.off_centre) {
      named_by("misalignment",
               "from the hem's centre: its order-1 harmonic differs from the fitted drape's by " + c->difference());
    } else if (const auto& a = r.alternation; a && !a->withdrew()) {
      named_by("yield", fmt::format("from the turn-over's alternation: the turned placement drapes {:.4f} stiffer than "
                                    "the mean of the others (at least {:g})",
                                    a->alternation, a->floor));
    } else if (a) {
      std::cout << fmt::format("  verdict: unexplained, the refits' yield withdrawn: the turned placement drapes "
                               "{:.4f} against the mean of the others (under {:g})\n",
                               a->alternation, a->floor);
    } else if (r.verdict == "none") {
      std::cout << fmt::format("  verdict: within the floors{} (no effect named)\n",
                               r.attribution.bending_within_floors() ? " once the bending is refitted" : "");
    } else if (r.verdict == "unexplained") {
      std::cout << "  verdict: above the floors, no candidate shrinks it significantly\n";
    } else if (r.verdict == "not attributed") {
      std::cout << "  verdict: above the floors (attribution not run: --gap-only)\n";
    } else {
      const std::string against =
          r.runner_up.empty() ? std::string("the only candidate refitted")
                              : fmt::format("confidence {:.2f}, runner-up {}", r.attribution.confidence, r.runner_up);
      std::cout << fmt::format("  verdict: {} ({}), shrinkage {:.0f}%\n", r.verdict, against,
                               100 * r.attribution.candidates[0].shrinkage);
    }
    if (!o.report.empty()) std::cout << "  report: " << o.report << "/report.md\n";
  }
  return kExitOk;
}

}  // namespace

Runner add_diagnose_command(CLI::App& app) {
  auto o = std::make_shared<DiagnoseOptions>();
  app.footer("Exit codes: 0 diagnosed (whatever the verdict); 1 bad input, a bad capture included (docs/CAPTURE.md), "
             "or a diagnosis that could not finish (a simulation's error, a fleet without workers): one line on "
             "stderr says why; 3 the report (--report, --fleet-endpoint-file) could not be written.");
  app.add_option("--capture", o->capture, "Capture directory (docs/CAPTURE.md)")->required();
  app.add_option("--held-out-capture", o->held_out,
                 "Another capture of the same specimen (another placement), used in no fit: every candidate is "
                 "confirmed on it; without --second-capture the gate tests the mean of both captures' terms too");
  app.add_option("--second-capture", o->second,
                 "Another capture of the same specimen (another placement, before the held-out one), in every "
                 "candidate refit (the mean of both captures' fit scores; a yielding candidate is laid again on it "
                 "with the plastic set its drape on the capture left) and in the gate (the mean of both captures' "
                 "terms); not in the baseline fit");
  app.add_option("--report", o->report,
                 "Write report.json, report.md, views.png and the residual PNGs into this directory (created; not a "
                 "capture's)")
      ->check([](const std::string& dir) { return dir.empty() ? std::string("--report needs a directory") : ""; });
  app.add_flag("--json", o->json, "Print the result as JSON");
  auto* quick = app.add_flag("--quick", o->quick, "Small budgets (16x16 mesh, 2 initial states, fewer evaluations)");
  app.add_flag("--fine", o->fine,
               fmt::format("--quick's budgets on a {0}x{0} fitting mesh, with the shape floor calibrated for it, "
                           "and --turn-over-yield {1:g}",
                           diagnosis::DiagnosisSettings::kFineResolution,
                           diagnosis::DiagnosisSettings::kFineTurnOverYield))
      ->excludes(quick);
  app.add_option("--resolution", o->resolution,
                 "Fitting mesh vertices per side (default 20; quick 16; fine " +
                     std::to_string(diagnosis::DiagnosisSettings::kFineResolution) + ")");
  app.add_option("--confirm-resolution", o->confirm_resolution,
                 "Where the gap is found above the floors, diagnose again on a fitting mesh of this many vertices per "
                 "side and report that diagnosis where it finds the gap too, else the first (both in report.json "
                 "\"mesh_confirmation\"; an experiment, default 0: off)")
      ->capture_default_str();
  app.add_option("--confirm-placement-rise", o->confirm_placement_rise,
                 "Where the verdict names no effect (none or unexplained) and the second capture, turned over, drapes "
                 "with a drape coefficient at least this much (F) above the capture's, diagnose again with "
                 "--placement-drape-test --placement-drape-floor F --placement-drape-when-seen and report that "
                 "diagnosis (both in report.json \"placement_confirmation\"; needs --second-capture; an experiment, "
                 "default 0: off)")
      ->capture_default_str();
  app.add_option("--turn-over-yield", o->turn_over_yield,
                 "Where the verdict names no effect (none or unexplained; after --confirm-placement-rise) and the "
                 "second capture, turned over, drapes with a drape coefficient at least this much above the "
                 "capture's, name yield, from the turn-over: a plastic set stiffens the turned drape, an elastic "
                 "specimen has no face (report.json \"turn_over\"; within the floors too; not with --gap-only; needs "
                 "--second-capture; default 0: off; --fine " +
                     fmt::format("{:g}", diagnosis::DiagnosisSettings::kFineTurnOverYield) + ")");
  app.add_option("--turn-over-alternation", o->turn_over_alternation,
                 "After --turn-over-yield, weigh yield by the turn-over's alternation (A: the turned second capture's "
                 "drape coefficient less the mean of the capture's and the held-out capture's, laid on the capture's "
                 "face): where the verdict names no effect and A is at least this, name yield; where the refits named "
                 "yield and A is below this (and the turn-over alone names no yield), unexplained (report.json "
                 "\"alternation\"; within the floors too; not with --gap-only; needs --second-capture and "
                 "--held-out-capture; default 0: off, --fine too: it left that preset in session 83)");
  app.add_option("--off-centre-misalignment", o->off_centre_misalignment,
                 "Where the verdict names no effect (none or unexplained; after --turn-over-alternation) and the "
                 "hem's centre lies at least this many times its floor off the fitted drape's (localisation."
                 "feature_groups.off_centre.ratio), name misalignment, from the hem's centre: a specimen laid off "
                 "centre hangs longer on one side (report.json \"off_centre\"; within the floors too; not with "
                 "--gap-only; default 0: off, --fine too: it left that preset in session 88, at 2.5 there since "
                 "session 82)");
  app.add_option("--off-centre-mm", o->off_centre_mm,
                 "Where the verdict names no effect (after --off-centre-misalignment) and the hem's centre lies at "
                 "least this many mm off the fitted drape's, whatever its floor (localisation.feature_groups."
                 "off_centre.difference_mm), name misalignment, from the hem's centre (report.json \"off_centre\", "
                 "\"by\": \"offset\"; within the floors too; not with --gap-only; default 0: off, --fine too: it "
                 "left that preset in session 85)");
  app.add_flag_function(
      "--off-centre-mm-over-yield,!--no-off-centre-mm-over-yield",
      [o](std::int64_t count) { o->off_centre_mm_over_yield = count > 0; },
      "With --off-centre-mm: also where the refits named yield and the turn-over does not (--turn-over-yield): a "
      "yield refit can stand in for an off-centre drape (default off; --no-off-centre-mm-over-yield: off; the last "
      "one given counts)")
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  app.add_option("--hem-tilt-misalignment", o->hem_tilt_misalignment,
                 "After the other signatures, where the hem's height has a first harmonic of at least this many mm on "
                 "each of the three placements (the capture, --second-capture, --held-out-capture; report.json "
                 "\"placement_hem_tilt_mm\"), name misalignment, from the hem's tilt, whatever the verdict: a "
                 "specimen laid off the axis hangs lower on one side however it is turned (report.json \"hem_tilt\"; "
                 "within the floors too; not with --gap-only; default 0: off, --fine too)");
  app.add_option("--states", o->states, "Initial states per evaluation (default 3; quick and fine 2)");
  app.add_option("--evaluations", o->evaluations,
                 "Baseline fit evaluations per simplex (default 40; quick and fine 20; a second one with --starts)");
  app.add_option("--starts", o->starts,
                 fmt::format("After the simplex from the drape-coefficient guess, score the guess's alpha and N levels "
                             "over the search box, each at {} softening ratios; if the best beats the first simplex's "
                             "end, a second simplex from it is the fit (default {}: the guess's simplex alone; "
                             "docs/DIAGNOSIS.md, \"A second start\")",
                             diagnosis::DiagnosisSettings{}.start_ratios_mm.size(),
                             diagnosis::DiagnosisSettings{}.start_levels));
  app.add_option("--start-alpha", o->start_alpha,
                 "Start the baseline fit here instead of at the drape-coefficient guess: linear bending moduli W,B,F, "
                 "g*mm^2/s^2 (e.g. a cantilever test's estimate; with --start-beta; the fit searches alpha's mean, two "
                 "ratios and one -beta/alpha shared by the directions, within its box)");
  app.add_option("--start-beta", o->start_beta,
                 "The start's quadratic bending moduli W,B,F, g*mm^3/s^2 (--start-beta=-... for a softening "
                 "fabric)");
  app.add_option("--start-box", o->start_box,
                 "With --start-alpha/--start-beta: each of the six parameters known to within this factor (e.g. 1.3 "
                 "for a test good to 30%): the fit searches only the bendings that allows, and the candidate refits "
                 "scale the bending only within that box, from the fit to either end of its mean alpha (default: the "
                 "whole box, and x0.22 .. x4.5)");
  app.add_flag("--ignore-measured-bending", o->ignore_measured_bending,
               "Diagnose as if the capture had no measured bending (capture.json specimen.measured_bending, "
               "docs/CAPTURE.md). Without this flag, a measured bending is the fit's start and its within_factor the "
               "fit's box (as --start-alpha/--start-beta/--start-box), unless --start-alpha/--start-beta is given");
  app.add_option("--refit-evaluations", o->refit_evaluations,
                 "Evaluations per candidate refit and of the bar, the bending scale refitted alone (default 14, also "
                 "with --quick and --fine)");
  app.add_option(
      "--sensor-evaluations", o->sensor_evaluations,
      "Evaluations of the sensor candidate's refit, which re-renders the baseline's drapes (default 200, 100 "
      "with --quick and --fine)");
  app.add_flag("--sensor-bending", o->sensor_bending,
               "The sensor candidate also refits the bending scale with a multipath gain under the camera it found, "
               "by simulation (a grid of 3 scales x 2 gains, a simplex within --refit-evaluations, the best without "
               "multipath), and keeps it if it beats both the re-rendering and that (off by default; "
               "docs/DIAGNOSIS_RESULTS.md, \"Session 29\")");
  app.add_flag("--multipath-first,!--no-multipath-first", o->multipath_first,
               fmt::format("Where the four views disagree as a multipath error makes them on every placement (the "
                           "cross-view slope at least {:g} mm on each; report.json gap_tests.view_consistency), the "
                           "sensor candidate refits the bending as with --sensor-bending and is named first where it "
                           "is confirmed and significant (on by default; --no-multipath-first: off; "
                           "docs/DIAGNOSIS_RESULTS.md, \"Session 68\")",
                           1e3 * diagnosis::ViewConsistencySettings{}.multipath_gain));
  app.add_flag("--multipath-region,!--no-multipath-region", o->multipath_region,
               "Where the multipath test fires (as for --multipath-first), the gap's region is the one whose pixel "
               "residuals stand furthest above their own floor, unless none does or the rigid surfaces put the "
               "camera off (a camera error: everywhere, as without it); report.json localisation.placed_by_views; on "
               "by default; --no-multipath-region: the shape features place it alone (docs/DIAGNOSIS_RESULTS.md, "
               "\"Session 69\")");
  app.add_option("--sensor-gain-scan", o->sensor_gain_scan,
                 fmt::format("Levels of the multipath gain (0 to 60 mm, evenly) the sensor candidate's re-rendering "
                             "scores before its simplex refines from the best (0: off, the simplex from no multipath; "
                             "1 is refused; levels count in --sensor-evaluations, which must leave {} for the simplex; "
                             "default {}, off where --sensor-evaluations leaves it no room; docs/DIAGNOSIS_RESULTS.md, "
                             "\"Session 67\")",
                             diagnosis::AttributionSettings::kSimplexAfterScan,
                             diagnosis::AttributionSettings{}.sensor_gain_levels));
  app.add_flag("--free-sensor", o->free_sensor,
               "Refit all nine parameters of the sensor candidate (camera pose, depth bias and slope, multipath) "
               "wherever the camera sits. By default, where the rigid surfaces show the camera as recorded (it "
               "moves the platform's centre less than 3 mm), the candidate keeps their camera, no depth bias or "
               "slope, and refits only the multipath gain, which they cannot see (docs/DIAGNOSIS_RESULTS.md, \"Session "
               "32\")");
  app.add_option("--common-bending", o->common_bending,
                 fmt::format("Where this many confirmed candidates or more each bring the gap within the floors, "
                             "validate the baseline's bending at the median of their scales, and within the floors "
                             "read the capture as the bending's (verdict none) (default {}; 0: off, as before session "
                             "29)",
                             diagnosis::AttributionSettings{}.common_bending_effects));
  app.add_option("--tie-margin", o->tie_margin,
                 "Candidates whose shrinkage is within this of the first's are tied: among the confirmed ones that "
                 "shrink the gap significantly, the smallest refit objective is named; a first tied exactly keeps "
                 "the exact-tie order, a physical effect before the sensor error (0: exact ties only; "
                 "docs/DIAGNOSIS_RESULTS.md, \"Session 31\")")
      ->capture_default_str();
  app.add_option("--refit-scan", o->refit_scan,
                 fmt::format("Refits of one-parameter effects (yield, shear, curl, friction) start with this many "
                             "strengths over the effect's range (bending as fitted), then refine from the best within "
                             "--refit-evaluations, which must leave {} for that (0: off; default {}; report.json lists "
                             "the scan per candidate)",
                             diagnosis::AttributionSettings::kSimplexAfterScan,
                             diagnosis::AttributionSettings{}.scan_levels));
  app.add_option("--yield-trade", o->yield_trade,
                 fmt::format("The yield refit starts with this many points along each line of the trade of a stiffer "
                             "bending (x1 .. x{:.0f}) against a lower yield curvature (--yield-trade-at / the scale), "
                             "then refines from the best within --refit-evaluations, which must leave {} for that; "
                             "replaces --refit-scan for yield (0: off; default {}, off where --refit-evaluations "
                             "leaves it no room; docs/DIAGNOSIS_RESULTS.md, \"Session 64\")",
                             std::exp(diagnosis::AttributionSettings::kYieldScaleRange),
                             diagnosis::AttributionSettings::kSimplexAfterScan,
                             diagnosis::AttributionSettings{}.yield_trade_levels));
  app.add_option("--yield-trade-at", o->yield_trade_at,
                 fmt::format("The yield trade's curvature at x1, /m: one line of --yield-trade points per value "
                             "(default {}; the points of all lines must leave the simplex its room)",
                             fmt::join(diagnosis::AttributionSettings{}.yield_trade_curvatures, ",")))
      ->delimiter(',');
  app.add_option(
      "--shear-trade", o->shear_trade,
      fmt::format("The shear refit starts with this many points along the trade of a stiffer bending (x1 "
                  ".. the refits' upper bound, x{:.1f} unless a known bending's box sets it) against a more "
                  "compliant membrane ({:.0f} kg/s^2 / the scale^{:.0f}), then refines from the best within "
                  "--refit-evaluations, which must leave {} for that; replaces --refit-scan for shear (0: "
                  "off; default {}, off where --refit-evaluations leaves it no room; docs/DIAGNOSIS_RESULTS.md, "
                  "\"Session 42\")",
                  std::exp(diagnosis::AttributionSettings{}.bending_scale_upper),
                  diagnosis::AttributionSettings::kShearTradeStiffness,
                  diagnosis::AttributionSettings::kShearTradePower, diagnosis::AttributionSettings::kSimplexAfterScan,
                  diagnosis::AttributionSettings{}.shear_trade_levels));
  app.add_option("--drift-scan", o->drift_scan,
                 fmt::format("The misalignment refit starts with this many drift sizes evenly spaced below its bound "
                             "(3: 10, 20 and 30 mm), bending as fitted, then refines from the best within "
                             "--refit-evaluations, which must leave {} for that (0: off, the start from the "
                             "hem's first harmonics; default {}, off where --refit-evaluations leaves it no room; "
                             "docs/DIAGNOSIS_RESULTS.md, \"Session 37\" and \"Session 39\")",
                             diagnosis::AttributionSettings::kSimplexAfterScan,
                             diagnosis::AttributionSettings{}.drift_scan_levels));
  app.add_option("--candidates", o->candidates,
                 "The candidate effects to refit, comma-separated (default: yield, shear, curl, friction, "
                 "misalignment, sensor; misalign for misalignment as drapegen reality names it)")
      ->delimiter(',');
  app.add_option(
      "--jobs", o->jobs,
      fmt::format("Threads: the fit's and the floors' initial states, then the candidate refits, in "
                  "parallel, fewer where there are fewer to share out (same result as --jobs 1; report.json: "
                  "runtime.jobs). Default: one per CPU this process may run on (taskset, a Slurm or "
                  "container CPU set; not a CPU quota), at most {}; with --fleet, --fleet-workers",
                  kMaxJobs));
  CLI::Option* fleet = app.add_option(
      "--fleet", o->fleet,
      "Compute the drapes on worker processes instead of here: bind this endpoint (e.g. tcp://127.0.0.1:5600; "
      "tcp://127.0.0.1:* picks a free port, logged and written by --fleet-endpoint-file) and serve every drape to "
      "`drapegen worker --connect ENDPOINT` processes, on this machine or others, as they come and go; the renders, "
      "scores and searches stay here. --jobs then counts refits in flight (default: --fleet-workers), and each refit "
      "simulates its initial states on --jobs threads too. The same result as without, where the workers run this "
      "build on the same BLAS kernels (docs/DIAGNOSIS.md, \"Refits on workers\"). An address other machines can reach "
      "(e.g. tcp://*:5600) needs --fleet-server-key and --fleet-authorized-keys");
  fleet->check(kEndpoint);
  app.add_option("--fleet-workers", o->fleet_workers,
                 "With --fleet: wait for this many workers before starting (more may join later)")
      ->capture_default_str()
      ->needs(fleet);
  app.add_option("--fleet-wait", o->fleet_wait,
                 "With --fleet: fail when the workers asked for have not all come within this many seconds, or a drape "
                 "has waited this long with no worker connected")
      ->capture_default_str()
      ->needs(fleet);
  app.add_option("--fleet-server-key", o->fleet_server_key,
                 "With --fleet: CurveZMQ, this side's secret key file (drapegen keygen; the workers connect with "
                 "--server-key and --key)");
  app.add_option("--fleet-authorized-keys", o->fleet_authorized_keys,
                 "With --fleet: CurveZMQ, the workers' public keys it admits, one per line");
  app.add_option("--fleet-endpoint-file", o->fleet_endpoint_file,
                 "With --fleet: also write the bound endpoint to this file (for job scripts that start the workers)");
  app.add_option("--shape-floor", o->shape_floor,
                 fmt::format("Shape-distance floor (default and quick: calibrated {:.2f}; fine: {:.2f}, with "
                             "--held-out-capture or --second-capture {:.2f}; 0: the largest floor sample)",
                             diagnosis::FloorSettings{}.shape_threshold, diagnosis::DiagnosisSettings::kFineShapeFloor,
                             diagnosis::DiagnosisSettings::kFineHeldOutShapeFloor));
  app.add_option("--placement-shape-floor", o->placement_shape_floor,
                 "With --second-capture or --held-out-capture: also test the larger of the two placements' shape "
                 "distances against this floor (0, the default: no such test; an experiment, docs/DIAGNOSIS.md, "
                 "\"Floors\")")
      ->capture_default_str();
  app.add_flag("--placement-drape-test", o->placement_drape_test,
               "With --second-capture or --held-out-capture: also test whether the two placements' drape coefficients "
               "differ by more than the model's (its stable drapes' range x the floors' margin): a yielding or "
               "curled specimen drapes otherwise once turned over (off by default; an experiment, docs/DIAGNOSIS.md, "
               "\"Floors\")");
  app.add_option("--placement-drape-floor", o->placement_drape_floor,
                 "With --placement-drape-test: its floor, a drape-coefficient difference (e.g. 0.02), instead of the "
                 "model's stable drapes' range x the floors' margin (0, the default: the range; an experiment, "
                 "docs/DIAGNOSIS_RESULTS.md, \"Session 74\")")
      ->needs("--placement-drape-test")
      ->capture_default_str();
  app.add_flag("--placement-drape-when-seen", o->placement_drape_when_seen,
               "With --placement-drape-test: the test counts only where the captures' own drape coefficients differ "
               "by more than its floor (report.json gap_tests.placement_dc_floor 0 elsewhere; an experiment, "
               "docs/DIAGNOSIS_RESULTS.md, \"Session 74\")")
      ->needs("--placement-drape-test");
  app.add_flag("--ablation", o->ablation,
               "Also validate each simulated candidate with its effect switched off at its refitted bending scale, and "
               "credit it only for what the effect adds beyond that (report.json: candidates' \"ablated\"; off by "
               "default; docs/DIAGNOSIS_RESULTS.md, \"Session 19\")");
  app.add_option("--held-out-tolerance", o->held_out_tolerance,
                 "A candidate is confirmed when its score on the held-out view or capture is at most (1 + this) "
                 "times the reference's (0: not worse at all; docs/DIAGNOSIS_RESULTS.md, \"Session 23\", "
                 "\"Session 74\")")
      ->capture_default_str();
  app.add_flag("--confirm-within-floors", o->confirm_within_floors,
               "Also confirm a candidate whose drape on the held-out capture is within the floors, however its score "
               "there compares with the reference's (report.json: candidates' \"confirmed_by\"; needs "
               "--held-out-capture; off by default: on fresh captures it changed no verdict; "
               "docs/DIAGNOSIS_RESULTS.md, \"Session 62\")")
      ->needs("--held-out-capture");
  CLI::Option* gap_only = app.add_flag(
      "--gap-only", o->gap_only,
      "Stop after the gap, floors and localisation (verdict \"not attributed\" above the floors); the attribution's "
      "options are refused with it");
  // What only the attribution reads would be ignored: refused instead.
  for (const char* name : {"--candidates", "--ablation", "--confirm-within-floors", "--sensor-bending", "--free-sensor",
                           "--tie-margin", "--held-out-tolerance", "--confirm-resolution", "--refit-evaluations",
                           "--sensor-evaluations", "--sensor-gain-scan", "--common-bending", "--refit-scan",
                           "--yield-trade", "--yield-trade-at", "--shear-trade", "--drift-scan"}) {
    gap_only->excludes(app.get_option(name));
  }
  app.add_flag("-v,--verbose", o->verbose, "Log every simulation of the fit and the refits on stderr (by default: "
                                           "each stage's end)");
  app.add_flag("-q,--quiet", o->quiet, "Log only warnings and errors on stderr")->excludes("--verbose");
  return [o] { return run_diagnose(*o); };
}

}  // namespace drapegen::cli
