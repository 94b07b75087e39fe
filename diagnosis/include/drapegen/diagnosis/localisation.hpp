#pragma once
// Where the gap sits: residual energy back-projected onto the specimen (platform top, rim, skirt, hem, exposed
// cylinder), per view, and in the hem's angular harmonics, fold count and phase.

#include <string>
#include <vector>

#include "drapegen/diagnosis/candidate_effect.hpp"
#include "drapegen/diagnosis/forward_model.hpp"
#include "drapegen/diagnosis/shape_features.hpp"

namespace drapegen::diagnosis {

struct RegionShare {
  Region region = Region::kSkirt;
  double energy_share = 0.0;  // fraction of the residual energy (sum of squared residuals)
  double pixel_share = 0.0;   // fraction of the pixels
  double enrichment = 0.0;    // energy_share / pixel_share
};

struct Localisation {
  /// Where the gap sits: the region of the shape-feature group (or the stable term) that exceeds its floor the most
  /// (localise_features), kGlobal for the stable term or if nothing exceeds its floor.
  Region dominant = Region::kGlobal;
  /// Per feature group (kFeatureGroups order) and for the stable term: the capture's difference from the fitted
  /// drape over the largest floor sample's (at least half the group's scale).
  std::vector<double> group_ratio;
  double stable_ratio = 0.0;
  /// The residual maps' most enriched region, kGlobal if none stands out (pixel residuals: fold placement shows).
  Region pixel_region = Region::kGlobal;
  std::vector<RegionShare> regions;
  std::vector<double> view_share;     // fraction of the residual energy per view
  std::vector<Harmonic> hem_difference;  // harmonics of (capture - model) hem radius
  int capture_folds = 0, model_folds = 0;
  double capture_fold_phase = 0.0, model_fold_phase = 0.0;  // radians, phase of the fold-count harmonic
  double capture_drape_coefficient = 0.0, model_drape_coefficient = 0.0;
};

/// Region of a specimen-frame point given the fitted drape's outline (the hem: within 25 mm of the outline).
[[nodiscard]] Region classify_point(const Eigen::Vector3d& p, const HemProfile& model_outline, double cylinder_radius);

/// `drape` is the fitted drape scored against the capture (its residual maps).
[[nodiscard]] Localisation localise(const ForwardModel& model, const ScoredDrape& drape);

/// The region a feature group describes: the outline groups the hem, the skirt groups the skirt.
[[nodiscard]] Region feature_region(FeatureGroup group);
/// Sets group_ratio, stable_ratio and dominant from the fitted drape's shape features against the capture's and the
/// floors (floors.hpp) of each group.
void localise_features(Localisation& localisation, const ScoredDrape& drape, const Target& capture,
                       const std::vector<double>& group_floor, double stable_floor);

}  // namespace drapegen::diagnosis
