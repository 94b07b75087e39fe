#pragma once
// Where the gap sits: residual energy back-projected onto the specimen (platform top, rim, skirt, hem, exposed
// cylinder), per view, and in the hem's angular harmonics, fold count and phase.

#include <string>
#include <vector>

#include "drapegen/diagnosis/candidate_effect.hpp"
#include "drapegen/diagnosis/forward_model.hpp"

namespace drapegen::diagnosis {

struct RegionShare {
  Region region = Region::kSkirt;
  double energy_share = 0.0;  // fraction of the residual energy (sum of squared residuals)
  double pixel_share = 0.0;   // fraction of the pixels
  double enrichment = 0.0;    // energy_share / pixel_share
};

struct Localisation {
  std::vector<RegionShare> regions;
  Region dominant = Region::kGlobal;  // the most enriched region, kGlobal if none stands out
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

}  // namespace drapegen::diagnosis
