#pragma once
// The whole diagnosis of one capture: baseline fit, floors, localisation, attribution (docs/DIAGNOSIS.md).

#include <nlohmann/json_fwd.hpp>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "drapegen/diagnosis/attribution.hpp"
#include "drapegen/diagnosis/floors.hpp"
#include "drapegen/diagnosis/fold_repeatability.hpp"
#include "drapegen/diagnosis/localisation.hpp"
#include "drapegen/diagnosis/rigid_pose.hpp"
#include "drapegen/diagnosis/validation_spread.hpp"
#include "drapegen/diagnosis/view_consistency.hpp"

namespace drapegen::diagnosis {

struct DiagnosisSettings {
  FitSettings fit;
  NelderMeadOptions baseline_optimiser{.max_evaluations = 40};
  int guess_levels = 4;        // simulations for the initial guess (drape coefficient against alpha)
  /// A second start of the baseline fit: after the simplex from the drape-coefficient guess, the guess's alpha and
  /// this many ln(alpha) levels evenly over the search box, each isotropic at every softening ratio -beta/alpha of
  /// start_ratios_mm, are scored by the fit objective; if the best of them beats where the simplex ended, a second
  /// simplex (the same budget) starts there and is the fit (its minimum includes its start, so its fit score is
  /// below the first's). The drape coefficient hardly changes with alpha for soft-looking drapes, and a strong
  /// softening (-beta/alpha) looks soft, so the guess alone can sit in another basin than the fabric. 0, the default:
  /// the guess's simplex alone. Off because on the evaluation set the better baseline fits absorbed shear and friction
  /// signatures: top-1 11/30 with 4 levels against 15/30 without, controls 5/5 against 4/5 (docs/DIAGNOSIS_RESULTS.md,
  /// "Session 12").
  int start_levels = 0;
  /// The baseline fit's start instead of the drape-coefficient guess (e.g. an estimate from a cantilever test or the
  /// network), clamped to the search box; its reduced coordinates (to_reduced) are all the fit can use of it.
  std::optional<BendingParameters> start;
  /// With a start: the fit searches only the bendings whose six parameters each lie within this factor of the
  /// start's (reduced_box), for a bending known from another test to that precision; the candidates' refits then
  /// scale the bending only within that box (from the fit to either end of its mean alpha, instead of
  /// AttributionSettings' x0.22 .. x4.5). 0: the whole box.
  double start_box = 0.0;
  /// Without a start: a capture's measured bending (SpecimenFacts::measured_bending) is the start and its
  /// within_factor the start_box. false: the capture's measured bending is not used (the fit starts at the
  /// drape-coefficient guess and searches the whole box).
  bool use_measured_bending = true;
  /// Where the rigid surfaces show the camera as recorded (within kCameraMovedAtPlatform at the platform), the sensor
  /// candidate refits only the multipath gain under their camera (AttributionSettings::sensor_held). false: its nine
  /// parameters are free wherever the camera sits (before session 32).
  bool hold_sensor = true;
  std::vector<double> start_ratios_mm{1.8, 3.6};  // about the 20% and 86% quantiles of fabrics618's -beta/alpha
  FloorSettings floors;
  /// The cross-view slope read off every placement and the multipath test on it (reported; it changes the verdict
  /// only with AttributionSettings::multipath_first, the region only with multipath_region).
  ViewConsistencySettings view_consistency;
  /// Where the multipath test fires, the gap's region is the pixels' (place_sensor_gap). false: place_gap's alone.
  bool multipath_region = true;
  AttributionSettings attribution;
  /// false: stop after the gap, floors and localisation (a capture above the floors gets the verdict
  /// "not attributed"): a screening run, or a calibration of the floors, at a fraction of the cost.
  bool attribute = true;
  /// The shape floor when the gate has a paired capture (a second or a held-out one: it then tests the mean of two
  /// captures' shape distances, which spreads less over controls than one capture's); 0: floors.shape_threshold.
  double held_out_shape_threshold = 0.0;
  /// Threads each refit simulates an evaluation's initial states on (the refits themselves run attribution.jobs at a
  /// time, and before them every evaluation simulates on attribution.jobs threads). 1: the refit's own thread alone,
  /// right where the drapes are computed on this machine. More pays where they are computed elsewhere
  /// (FitSettings::simulator: a fleet), so that up to attribution.jobs x this many are in flight. The result does not
  /// depend on it (ForwardModel::set_threads).
  int refit_state_threads = 1;
  /// Where the diagnosis on fit.resolution's mesh finds the gap above the floors, diagnose again on a mesh of this
  /// many vertices per side and report that diagnosis where it finds the gap too (the first one otherwise, the
  /// gate's verdict staying the first mesh's): a finer mesh refits the effects closer, while the floors are
  /// calibrated on the preset's (docs/DIAGNOSIS_RESULTS.md, "Session 76"). 0: off (an experiment, not the default).
  int confirm_resolution = 0;
  /// Where the verdict names no effect ("none" or "unexplained") and the second capture, laid turned over after the
  /// capture, drapes with a drape coefficient (of the outline its views see) at least this much above the capture's,
  /// diagnose again with the placement drape test at this floor where the captures show the change
  /// (FloorSettings::placement_drape_coefficient, placement_drape_floor, placement_drape_when_seen) and report that
  /// diagnosis: an elastic specimen has no face, while the plastic set a drape leaves opposes the turned placement's
  /// folds and stiffens its drape (rule Y, docs/DIAGNOSIS_RESULTS.md, "Session 77"). Skipped where the settings test
  /// the placements' drape coefficients already. 0: off (an experiment, not the default).
  double confirm_placement_rise = 0.0;
  /// Where the verdict (after confirm_placement_rise) names no effect ("none" or "unexplained") and the second
  /// capture, laid turned over after the capture, drapes with a drape coefficient at least this much above the
  /// capture's, name yield (DiagnosisResult::turn_over): a plastic set makes the specimen laid on its other face drape
  /// stiffer, an elastic one drapes alike on both faces up to its multistability (rule U,
  /// docs/preregistrations/session79.md). Within the floors too, where no refit ran; not with attribute false (a
  /// screening run names no effect). The refits stand as they ran. 0: off (the --fine preset: kFineTurnOverYield).
  double turn_over_yield = 0.0;
  /// The turn-over's alternation: the second capture, laid turned over after the capture, less the mean of the
  /// capture and the held-out capture (laid on the capture's face again), in drape coefficient. A plastic set stiffens
  /// the turned drape and eases on the first face again; an elastic fabric's three drapes differ by their noise. After
  /// turn_over_yield: where the verdict names no effect ("none" or "unexplained") and the alternation is at least
  /// this, name yield; where the refits named yield and the alternation is below this (and the first turn-over alone
  /// is below turn_over_yield, which would name yield again), withdraw it: "unexplained", the refits' yield kept in
  /// the report (DiagnosisResult::alternation; rule A, docs/preregistrations/session82.md: +1 -0 on fresh seeds
  /// 109-110). Needs a turned second capture and a held-out capture on the capture's face; not with attribute false.
  /// The refits stand as they ran. 0: off. Not in the --fine preset: there at 0.015 from session 82, it left in
  /// session 83 (fresh seeds 113-114: of the three verdicts it set, a control named yield and a yield the refits
  /// named right withdrawn; docs/DIAGNOSIS_RESULTS.md, "Session 84").
  double turn_over_alternation = 0.0;
  /// Where the verdict (after turn_over_alternation) names no effect ("none" or "unexplained") and the hem's centre
  /// lies at least this many times its floor off the fitted drape's (the off-centre feature group's ratio,
  /// Localisation::group_ratio, FeatureGroup::kOffCentre: the order-1 harmonic of the hem's radius and height), name
  /// misalignment (DiagnosisResult::off_centre): a specimen laid off centre hangs longer on one side, which no elastic
  /// fabric's drape on a centred specimen does (rule E, docs/preregistrations/session82.md: on seeds 101-108 the ratio
  /// reached 2.5 on 14 of 16 misalignments and on none of 36 controls, at most 1.77). Within the floors too, where no
  /// refit ran; not with attribute false. The refits stand as they ran. 0: off. Not in the --fine preset: there at
  /// 2.5 from session 82 (registered in session 81 for fresh seeds 109-110: +1 -0), it left in session 88 (fresh seeds
  /// 125-126, session 90's test: both verdicts it set wrong, two curls named misalignment; docs/DIAGNOSIS_RESULTS.md,
  /// "Session 90").
  double off_centre_misalignment = 0.0;
  /// mm. Where the verdict (after off_centre_misalignment) names no effect ("none" or "unexplained") and the hem's
  /// centre lies at least this many mm off the fitted drape's, whatever its floor (the off-centre feature group's
  /// difference, Localisation::group_difference, as report.json gives it), name misalignment
  /// (DiagnosisResult::off_centre): rule E reads the offset over its floor, which stayed under 2.5 on misalignments
  /// whose hem lay 4-9 mm off (rule D, docs/preregistrations/session85.md). Within the floors too; not with attribute
  /// false. The refits stand as they ran. 0: off. Not in the --fine preset: there at 6.5 mm with
  /// off_centre_mm_over_yield in session 85 only (fresh seeds 119-120: its one verdict wrong, a shear within the floors
  /// 6.98 mm off; docs/DIAGNOSIS_RESULTS.md, "Session 87").
  double off_centre_mm = 0.0;
  /// With off_centre_mm: also where the refits named yield and the turn-over does not (rule U off, no turned second
  /// capture, or its rise under turn_over_yield): a yield refit can stand in for an off-centre drape (rule D2,
  /// docs/preregistrations/session85.md).
  bool off_centre_mm_over_yield = false;
  /// mm. Where the hem's height has a first harmonic (its amplitude against the angle about the axis,
  /// ShapeFeatures::off_centre's second entry, from all of a capture's views) of at least this on each of the three
  /// placements (the capture, the second and the held-out capture), name misalignment whatever the verdict
  /// (DiagnosisResult::hem_tilt): a specimen laid off the axis hangs more cloth, and its hem lower, on one side each
  /// time it is laid, however it was turned; a centred elastic specimen tilts only as far as its folds do, and an
  /// effect that tilts one placement (a curled edge, a camera error) need not tilt the others (rule H, an addendum to
  /// docs/preregistrations/session90.md: on seeds 121-124 the smallest placement's tilt read 10.3-19.0 mm on all 12
  /// misalignments and at most 5.85 mm on the 66 other captures). Reads the captures alone, no fit; after the other
  /// signatures; not with attribute false. The refits stand as they ran. 0: off. Every report records the placements'
  /// tilts (DiagnosisResult::placement_hem_tilt_mm) either way.
  double hem_tilt_misalignment = 0.0;

  /// Small budgets for tests and the --quick benchmark.
  [[nodiscard]] static DiagnosisSettings quick();
  /// quick()'s budgets on a finer fitting mesh (kFineResolution), with the shape floor calibrated for that mesh
  /// (kFineShapeFloor): the --fine preset, which spends more of the 10-minute budget on fidelity
  /// (docs/DIAGNOSIS_RESULTS.md, "Branch diag-s6"). 1.05: the largest validated shape distance of 16 calibration
  /// controls (--seed 2, 60x60 reality, this preset, session 9: the stiffness range scaled with density) was 0.95,
  /// plus 10% (1.17 before, from 1.06; at 24x24 the same controls needed 1.42).
  [[nodiscard]] static DiagnosisSettings fine();
  static constexpr int kFineResolution = 32;
  static constexpr double kFineShapeFloor = 1.05;
  /// The same rule for the mean over the capture and a held-out capture (placement 1): of the same 16 calibration
  /// controls with their placement 1 (--fine --held-out-capture), the largest mean was 0.94, plus 10%.
  static constexpr double kFineHeldOutShapeFloor = 1.03;
  /// The --fine preset's turn_over_yield (rule U, registered in session 78 for fresh seeds 103-104: +1 -0, no control
  /// named; adopted in session 79, docs/DIAGNOSIS_RESULTS.md, "Session 79"): over seeds 80-104 the first turn-over
  /// raised the drape coefficient by 0.02 or more on 41 of 53 yields, 7 of 56 curls and none of 81 controls (at most
  /// +0.0161) nor of 191 other captures.
  static constexpr double kFineTurnOverYield = 0.02;
};

struct DiagnosisResult {
  /// The budgets it ran with (report.json "settings"): a --quick run's figures are not a full run's.
  struct Budgets {
    int resolution = 0;                // vertices per side of the fitting mesh
    int initial_states = 0;            // of the fit
    int max_baseline_evaluations = 0;  // per simplex of the baseline fit
    bool attribution = true;           // false: gap, floors and localisation only
    double turn_over_yield = 0.0;      // DiagnosisSettings::turn_over_yield where it could name yield (0: off)
    double turn_over_alternation = 0.0;    // DiagnosisSettings::turn_over_alternation where it could (0: off)
    double off_centre_misalignment = 0.0;  // DiagnosisSettings::off_centre_misalignment where it could (0: off)
    double off_centre_mm = 0.0;            // DiagnosisSettings::off_centre_mm where it could (0: off)
    bool off_centre_mm_over_yield = false;  // DiagnosisSettings::off_centre_mm_over_yield where it could
    double hem_tilt_misalignment = 0.0;     // DiagnosisSettings::hem_tilt_misalignment where it could (0: off)
  } budgets;
  /// Each capture it read (report.json "placements"): its directory and the face the specimen lay on (a turned
  /// specimen's rest shape, a curl or a yield's creases, bends the other way face down).
  struct Placement {
    std::string role;  // "capture", "second_capture" or "held_out_capture"
    std::string directory;
    bool face_down = false;
  };
  std::vector<Placement> placements;
  BendingParameters initial_guess;  // the drape-coefficient guess, or the given start (clamped to the box)
  /// Where the initial guess came from: "drape coefficient", "given start" (DiagnosisSettings::start) or
  /// "measured bending" (the capture's).
  std::string initial_guess_from;
  double search_within_factor = 0.0;  // the fit's box around the start (start_box or within_factor); 0: the whole box
  BendingParameters fitted;
  ReducedBending fitted_reduced{};
  int baseline_evaluations = 0;  // both simplexes'
  int start_evaluations = 0;     // the starts scored after the first simplex (DiagnosisSettings::start_levels)
  ReducedBending start{};        // where the simplex of the kept fit started: the guess or the best start
  double best_start_score = std::numeric_limits<double>::quiet_NaN();  // the best start's fit score (NaN: none scored)
  bool restarted = false;        // the second simplex ran and is the fit (the best start beat the first's end)
  std::vector<double> baseline_history;
  Evaluation fit;
  /// The fitted parameters from the validation states (AttributionSettings): the gap is measured on its best drape,
  /// which no fit selected on (the fit's own best is the luckiest of its evaluations of a multistable objective).
  Evaluation validated;
  [[nodiscard]] const ScoredDrape& gap_drape() const { return validated.best; }
  /// With a second or a held-out capture (other placements of the specimen): the same validation drapes scored
  /// against it. The gate tests the mean of the capture's terms and the paired capture's (gap_terms): the second
  /// capture's, else the held-out capture's.
  std::optional<Evaluation> validated_second, validated_held_out;
  /// The best of them against the paired capture (null without one).
  [[nodiscard]] const ScoredDrape* paired_gap_drape() const {
    const auto& paired = validated_second ? validated_second : validated_held_out;
    return paired ? &paired->best : nullptr;
  }
  [[nodiscard]] GapTerms gap() const { return gap_terms(validated.best, paired_gap_drape()); }
  /// The validation drapes' distances to the capture and among themselves (the fitted fabric's multistability).
  ValidationSpread validation_spread;
  /// Whether the capture's placements fold alike, against the fitted model's drapes from the validation states
  /// (reported; not in the gate).
  FoldRepeatability fold_repeatability;
  /// The four views' cross-view slope on every placement (the capture's first) and the multipath test on them.
  MultipathTest multipath;
  /// The camera's pose error read off the platform top and bare side before the fit (the sensor candidate's start),
  /// or why it could not be (rigid_pose_error).
  std::optional<RigidPose> rigid_pose;
  std::string rigid_pose_error;
  Floors floors;
  double gap_all = 0.0, gap_fit = 0.0, gap_held_out = 0.0;
  bool within_floors = false;
  Localisation localisation;
  ShapeSet fit_target;  // the capture's shape features
  Attribution attribution;
  /// Where each refit leaves the gap: its validated drape localised against the capture as the baseline's is (the
  /// same floors and camera), the bar's and each candidate's (attribution.candidates' order; unset for a refit
  /// without a validated drape). Reported only: where an effect closes the gap, against where the baseline left it.
  std::optional<Localisation> bar_localisation;
  std::vector<std::optional<Localisation>> candidate_localisations;
  /// The refits' bending scale bounds (AttributionSettings::bending_scale_lower/upper, ln of the factor on the fit's
  /// alpha and beta) where the attribution ran.
  double refit_scale_lower = 0.0, refit_scale_upper = 0.0;
  /// The verdict: the named effect ("none" within the floors, "unexplained" if no candidate shrinks it enough,
  /// "not attributed" above the floors when DiagnosisSettings::attribute is false; "yield" from the turn-over where
  /// turn_over is set, "yield" or "unexplained" from its alternation where alternation is set, "misalignment" from the
  /// hem's centre where off_centre or hem_tilt is set, whatever the refits named).
  std::string verdict;
  /// Second to the named effect (with "unexplained", the best candidate: the withdrawn yield where the alternation
  /// withdrew it); empty where the turn-over, its alternation or the hem's centre named the effect.
  std::string runner_up;
  int simulations = 0;
  double seconds = 0.0;
  double seconds_fit = 0.0, seconds_floors = 0.0, seconds_attribution = 0.0;
  /// CPU time of this process over the diagnosis, all its threads (a fleet's workers not counted). Unlike `seconds`
  /// it leaves out waiting for a core another process holds and time the process was stopped (SIGSTOP), so it is
  /// the figure to compare runtimes measured on a shared machine by.
  double cpu_seconds = 0.0;
  /// The threads it was allowed (AttributionSettings::jobs; with a fleet, the refits in flight); fewer run at once
  /// where there are fewer refits or initial states to share out.
  int jobs = 1;
  /// With DiagnosisSettings::confirm_resolution where the first mesh found the gap: the diagnosis on the other mesh
  /// (the first mesh's where this one is the confirming mesh's, and the reverse), whole. `seconds`, `cpu_seconds` and
  /// `simulations` above are then both diagnoses' together.
  struct MeshConfirmation {
    int resolution = 0;          // the confirming mesh's vertices per side
    bool gap_found = false;      // the confirming mesh found the gap above its floors: its diagnosis is this one
    std::shared_ptr<const DiagnosisResult> other;
  };
  std::optional<MeshConfirmation> mesh_confirmation;
  /// With DiagnosisSettings::confirm_placement_rise where it fired: this diagnosis is the one with the placement
  /// drape test; `other`, whole, the one without it, whose verdict named no effect. `seconds`, `cpu_seconds` and
  /// `simulations` above are both diagnoses' together.
  struct PlacementConfirmation {
    double rise = 0.0;   // the second capture's drape coefficient less the capture's
    double floor = 0.0;  // DiagnosisSettings::confirm_placement_rise
    std::shared_ptr<const DiagnosisResult> other;
  };
  std::optional<PlacementConfirmation> placement_confirmation;
  /// With DiagnosisSettings::turn_over_yield where it fired: the verdict is "yield" from the turn-over, not from the
  /// refits, whose verdict was `refits_verdict` (the attribution above stands as it ran).
  struct TurnOverYield {
    double rise = 0.0;           // the second capture's drape coefficient less the capture's
    double floor = 0.0;          // DiagnosisSettings::turn_over_yield
    std::string refits_verdict;  // "none" or "unexplained"
  };
  std::optional<TurnOverYield> turn_over;
  /// With DiagnosisSettings::turn_over_alternation where it fired: the verdict is "yield" from the turn-over's
  /// alternation where the refits named no effect (`refits_verdict` "none" or "unexplained"), or "unexplained" where
  /// the refits' yield was withdrawn (`refits_verdict` "yield"); the attribution above stands as it ran.
  struct TurnOverAlternation {
    double alternation = 0.0;    // the second capture's drape coefficient less the mean of the other two's
    double floor = 0.0;          // DiagnosisSettings::turn_over_alternation
    std::string refits_verdict;  // the verdict before it
    [[nodiscard]] bool withdrew() const { return refits_verdict == "yield"; }
  };
  std::optional<TurnOverAlternation> alternation;
  /// With DiagnosisSettings::off_centre_misalignment or off_centre_mm where it fired: the verdict is
  /// "misalignment" from the hem's centre, not from the refits, whose verdict was `refits_verdict` (the attribution
  /// above stands as it ran).
  struct OffCentreMisalignment {
    double ratio = 0.0;          // the off-centre feature group's difference over its floor
    double floor = 0.0;          // DiagnosisSettings::off_centre_misalignment (0: off)
    double offset_mm = 0.0;      // the off-centre feature group's difference, mm
    double offset_floor_mm = 0.0;  // DiagnosisSettings::off_centre_mm (0: off)
    bool by_offset = false;      // the offset named it (rules D and D2), else the ratio (rule E)
    std::string refits_verdict;  // the verdict before it: "none" or "unexplained" ("yield": rule D2)
    /// What it read, for the log, the console and report.md: "7.21 mm (at least 6.5 mm)" by the offset, else
    /// "3.49 times its floor (at least 2.5)".
    [[nodiscard]] std::string difference() const;
  };
  std::optional<OffCentreMisalignment> off_centre;
  /// The hem's tilt on each placement read (the capture, the second, the held-out capture, as many as were given),
  /// mm: the first harmonic of the hem's height against the angle about the axis
  /// (DiagnosisSettings::hem_tilt_misalignment); empty where a placement saw too little of the skirt to read it.
  std::vector<double> placement_hem_tilt_mm;
  /// With DiagnosisSettings::hem_tilt_misalignment where it fired: the verdict is "misalignment" from the hem's tilt
  /// on every placement, not from the refits or an earlier signature, whose verdict was `refits_verdict` (the
  /// attribution above stands as it ran).
  struct HemTiltMisalignment {
    double smallest_mm = 0.0;    // the least tilted placement's tilt
    double floor_mm = 0.0;       // DiagnosisSettings::hem_tilt_misalignment
    std::string refits_verdict;  // the verdict before it (any but "misalignment")
  };
  std::optional<HemTiltMisalignment> hem_tilt;
  /// The refits' own verdict: the verdict before the first signature that changed it (turn_over, alternation,
  /// off_centre, hem_tilt, in the order diagnose() lays them), else the verdict.
  [[nodiscard]] const std::string& refits_verdict() const;
  /// The candidate refit of `effect` (attribution.candidates), null where none ran.
  [[nodiscard]] const CandidateResult* refit(Effect effect) const;
  /// Whether a signature (turn_over, alternation, off_centre, hem_tilt) set the verdict rather than the refits.
  [[nodiscard]] bool signature_set() const { return turn_over || alternation || off_centre || hem_tilt; }
  /// The named effect's refit: the first candidate where the attribution named it; where a signature set the verdict,
  /// the refit of the effect it named (the yield refit where the turn-over or its alternation named yield, the
  /// misalignment refit where the hem's centre named misalignment); null where no effect is named (the alternation's
  /// withdrawal included) or its refit did not run.
  [[nodiscard]] const CandidateResult* named_refit() const;
  /// How much adding the named effect shrinks the gap's excess above the floors (report.json "shrinkage"): the first
  /// candidate's (with "unexplained", the best one's); where a signature named an effect, its refit's; 0 where no
  /// such refit ran.
  [[nodiscard]] double named_shrinkage() const;
};

/// Other placements of the capture's specimen on the tester (attribution.hpp, OtherCaptures); either may be null.
struct OtherPlacements {
  const Capture* second = nullptr;    // in the gate and every candidate refit (not the baseline fit)
  const Capture* held_out = nullptr;  // in no fit: the confirmation (and the gate without a second)
};

/// The whole diagnosis (docs/DIAGNOSIS.md; "Held-out capture" and "Second capture" for `others`).
[[nodiscard]] sim::Expected<DiagnosisResult> diagnose(const Capture& capture, const DiagnosisSettings& settings,
                                                      const OtherPlacements& others = {});

/// An error unless `other` can be another capture of `capture`'s specimen: the same specimen facts, and not the
/// capture's own directory. `role` names it in the message ("held-out capture").
[[nodiscard]] sim::Status check_same_specimen(const Capture& capture, const Capture& other,
                                              std::string_view role = "held-out capture");

[[nodiscard]] nlohmann::json to_json(const DiagnosisResult& result, const Capture& capture);

}  // namespace drapegen::diagnosis
