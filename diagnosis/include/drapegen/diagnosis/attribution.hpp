#pragma once
// Which effect explains the gap: each candidate is added to the model with its own parameters, refitted on the fit
// views (with the bending scale free as well), and judged by how much it shrinks the excess above the floors that
// made the gate fire (excess_above_floors: the stable term and the shape distance over their floors), confirmed on
// the held-out view (which must not get worse). Both the baseline and each refitted candidate are judged on fresh
// initial states that no fit selected on (validation states): the fit's best score is the minimum of a multistable,
// noisy objective over its evaluations, so a refit compared with it must beat the baseline's luckiest draw.
// Confidence: a block bootstrap over the held-out view's residual tiles of the named effect against the runner-up.
// With a held-out capture (a second placement of the specimen, in no fit), every validation drape is also scored
// against it (the yield candidate's are draped again there, from the plastic set its best validation drape left):
// the excess is that of the mean of both captures' gap terms (gap_terms), the confirmation and the bootstrap use the
// held-out capture's views instead of the held-out view.

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "drapegen/diagnosis/candidate_effect.hpp"
#include "drapegen/diagnosis/floors.hpp"
#include "drapegen/diagnosis/forward_model.hpp"
#include "drapegen/diagnosis/nelder_mead.hpp"

namespace drapegen::diagnosis {

struct CandidateResult {
  Effect effect = Effect::kYield;
  std::vector<std::string> names;
  std::vector<double> parameters;   // as in effect_space
  double alpha_scale = 1.0;         // the refitted bending scale relative to the baseline fit
  double fit_score = 0.0, held_out_score = 0.0, all_score = 0.0;
  /// gap_shrinkage of excess_above_floors: the baseline's against this candidate's refitted drape.
  double shrinkage = 0.0;
  double held_out_shrinkage = 0.0;  // 1 - held_out_after / held_out_before (the view not in the refit)
  bool confirmed = false;           // the held-out view does not get worse
  int evaluations = 0;
  /// The strength scan (AttributionSettings::scan_levels), if one ran: (parameter, fit score) per level.
  std::vector<std::pair<double, double>> scan;
  double seconds = 0.0;
  ScoredDrape drape;      // the refit's best drape (fit states)
  ScoredDrape validated;  // the refitted setup's best drape from the validation states: shrinkage, confirmation
  /// The same validation drapes scored against the held-out capture (its best), if there is one; for a yielding
  /// candidate, its drapes from the validation states laid again with the plastic set (ForwardModel::laid_again).
  std::optional<ScoredDrape> validated_held_out;
  /// A yielding candidate's held-out drapes start from a plastic set (attribute): its largest rest angle, rad.
  std::optional<double> held_out_plastic_set;
  [[nodiscard]] const ScoredDrape* held_out_drape() const {
    return validated_held_out ? &*validated_held_out : nullptr;
  }
  ModelSetup setup;                             // the refitted setup
  std::vector<sim::ClothMesh> validation_meshes;  // its drapes from the validation states
};

/// A second capture of the specimen, held out of every fit: its forward model and the fitted baseline's best
/// validation drape scored against it.
struct HeldOutCapture {
  ForwardModel* model = nullptr;
  const ScoredDrape* baseline = nullptr;
};

/// What the confirmation compares of a validated drape: its score over all views of the held-out capture if there
/// is one (`held_out_capture`, the same setup's drape scored against it), else its score over the held-out view.
[[nodiscard]] double confirmation_score(const ScoredDrape& drape, const ScoredDrape* held_out_capture);

struct AttributionSettings {
  NelderMeadOptions optimiser{.max_evaluations = 14};
  int sensor_evaluations = 200;     // render-only refits are cheap
  double significant_shrinkage = 0.25;
  int bootstrap_samples = 1000;
  int tile_px = 16;
  /// Fresh initial states (flat, then sine) from which the gap is measured at the fitted parameters (the gate) and
  /// each refitted candidate is compared with it.
  int validation_states = 10;
  /// Effects with one parameter that need simulation (yield, shear, curl, friction): first evaluate this many
  /// strengths evenly spaced over the parameter's range (bending as fitted), then refine (bending scale and strength)
  /// from the best with the rest of the same budget (optimiser.max_evaluations simulations in all). 0: the simplex
  /// from the effect's fixed start (effect_space) alone; so is a value above the budget - kSimplexAfterScan.
  int scan_levels = 0;
  /// New evaluations the simplex keeps after a strength scan (its two new vertices and one move, at least).
  static constexpr int kSimplexAfterScan = 3;
  std::uint64_t validation_seed = 2000;
  int jobs = 1;                     // candidate refits in parallel (one forward model per thread)
  std::vector<Effect> candidates{std::begin(kAllEffects), std::end(kAllEffects)};
};

struct Attribution {
  /// The bar: the baseline's bending parameters alone refitted (reduced coordinates, same budget), validated the same
  /// way; its shrinkage is against the baseline's. Candidates are measured against the better of the two.
  CandidateResult bar;
  std::vector<CandidateResult> candidates;  // sorted by shrinkage, best first
  bool named = false;                       // the best is confirmed and shrinks the gap significantly
  double confidence = 0.0;                  // bootstrap P(best beats runner-up on the held-out view)
};

/// The validation states: fresh initial states (flat, then sine) that no fit selects on.
[[nodiscard]] std::vector<sim::InitialStateSpec> validation_states(const AttributionSettings& settings);

/// `baseline` is the fitted setup, `fit` its evaluation (fit states) and `validated` its evaluation from the
/// validation states; `floors` from measure_floors. make_model creates a forward model for another thread (jobs > 1).
[[nodiscard]] sim::Expected<Attribution> attribute(
    ForwardModel& model, const ModelSetup& baseline, const Evaluation& fit, const Evaluation& validated,
    const Floors& floors, const AttributionSettings& settings,
    const std::function<sim::Expected<std::unique_ptr<ForwardModel>>()>& make_model = {},
    HeldOutCapture* held_out = nullptr);

/// 1 - excess_after / excess_before (0 when excess_before is 0): 1 when the candidate brings the drape within the
/// floors, 0 when it leaves the excess as it was, negative when it adds to it.
[[nodiscard]] double gap_shrinkage(double excess_before, double excess_after);

/// The probability, by block bootstrap over tiles of the held-out views (every view with `all_views`: a held-out
/// capture), that `a`'s squared residuals are smaller than `b`'s in total.
[[nodiscard]] double bootstrap_confidence(const ForwardModel& model, const ScoredDrape& a, const ScoredDrape& b,
                                          int samples, int tile_px, std::uint64_t seed, bool all_views = false);

}  // namespace drapegen::diagnosis
