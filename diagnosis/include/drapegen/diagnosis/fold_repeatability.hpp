#pragma once
// Whether the specimen drapes the same way twice. Laid on the tester again, an elastic specimen folds where it folded
// before, in its own frame, unless it has several stable drapes; the fitted model says which (its drapes from
// several initial states). A specimen that keeps creases from its last drape (a yield moment, hysteresis) is laid
// again from them and folds elsewhere. The fold content of two outlines (the hem radius against angle without its
// low orders) is compared at the turn that matches them best, since the specimen's orientation on the table is
// unknown. docs/DIAGNOSIS_RESULTS.md, "Session 26".

#include <vector>

#include "drapegen/diagnosis/forward_model.hpp"
#include "drapegen/diagnosis/hem_profile.hpp"
#include "drapegen/sim/initial_state.hpp"
#include "drapegen/sim/mesh.hpp"

namespace drapegen::diagnosis {

/// The outline's folds: the profile minus its orders 0..kOrientationOrders (centre offset, the anisotropy's ellipse,
/// the square's corners), which every drape of a fabric shares.
[[nodiscard]] HemProfile fold_content(const HemProfile& profile);

/// An outline in the specimen's own frame: mirrored (angle -theta) if the specimen lies face down, else as it is. A
/// specimen turned over folds where it folded before in its own frame, which the table sees mirrored.
[[nodiscard]] HemProfile specimen_frame(const HemProfile& outline, bool face_down);

/// The correlation of two outlines' fold content at the turn (whole bins) that matches them best: 1 for the same
/// folds however turned, near 0 for unrelated ones. 0 if either has no fold content (below 1 um RMS).
[[nodiscard]] double fold_correlation(const HemProfile& a, const HemProfile& b);

/// Every pair's fold_correlation (i < j, in order 01, 02, .., 12, ..).
[[nodiscard]] std::vector<double> pairwise_fold_correlations(const std::vector<HemProfile>& outlines);

/// Every pair's fold_correlation of the drapes' outlines (hem_profile_from_mesh, each in its specimen frame:
/// sim::lies_face_down).
[[nodiscard]] std::vector<double> drape_fold_correlations(const std::vector<sim::ClothMesh>& drapes);

/// drape_fold_correlations of the drapes a model chose on each placement (null: that placement not given), paired as
/// the capture's placements are (FoldRepeatability::capture).
[[nodiscard]] std::vector<double> placement_fold_correlations(const ScoredDrape& capture, const ScoredDrape* second,
                                                              const ScoredDrape* held_out);

/// The drapes of `evaluation` from sine states (`states`: its initial states, in order): no placement starts flat.
[[nodiscard]] std::vector<sim::ClothMesh> sine_drapes(const Evaluation& evaluation,
                                                      const std::vector<sim::InitialStateSpec>& states);

struct FoldRepeatability {
  /// Between the capture's placements (the capture, the second, the held-out capture: pairs 01, 02, 12 of those given).
  std::vector<double> capture;
  /// Between the fitted model's drapes from the validation states' sine states (flat excluded: no placement starts
  /// flat), every pair.
  std::vector<double> model;
  int model_drapes = 0;
  /// Between the fitted model's best drapes on each placement (the one each placement's fit views choose among the
  /// validation drapes), paired as `capture` is.
  std::vector<double> model_placements;
  [[nodiscard]] bool measured() const { return !capture.empty() && model.size() >= 2; }
};

/// The capture's placements fold less alike than the fitted model's drapes: every capture pair below the model pairs'
/// 10th percentile (sorted, element floor(0.1 n)) minus kFoldsUnlikeMargin ("repeat_excess", pre-registered in
/// session 26; on seeds 17-20 it held for 9 of 20 curled specimens, 1 of 20 yielding ones and none of the other 85,
/// controls included: docs/DIAGNOSIS_RESULTS.md, "Session 27"). False unless measured().
[[nodiscard]] bool folds_less_alike(const FoldRepeatability& f);
inline constexpr double kFoldsUnlikeMargin = 0.1;

/// `placements`: the captures' outlines (every view) in the specimen frame, the capture first; `drapes`: the model's
/// drapes.
[[nodiscard]] FoldRepeatability fold_repeatability(const std::vector<HemProfile>& placements,
                                                   const std::vector<sim::ClothMesh>& drapes);

}  // namespace drapegen::diagnosis
