#pragma once
// Where the gap sits: residual energy back-projected onto the specimen (platform top, rim, skirt, hem, exposed
// cylinder), per view, and in the hem's angular harmonics, fold count and phase.

#include <array>
#include <functional>
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
  double rms = 0.0;           // m: RMS of the region's pixel residuals
  /// m: the mean of the region's pixel residuals (capture minus model depth: > 0 where the capture lies further from
  /// the camera), over all views and per view (0 in a view without pixels there). A depth bias shifts it by the
  /// bias in every view; cloth lifted off the platform top shifts the top's below 0.
  double mean = 0.0;
  std::vector<double> view_mean;
  /// The region's RMS over the largest floor sample's in the same region (localise_against_floors; 0 if the floors
  /// have no pixels there): how far this part of the specimen is from what noise and other stable drapes leave.
  double floor_ratio = 0.0;
};

/// A drape's residual maps back-projected onto the specimen: squared residuals and pixels per region (indexed by
/// Region, kGlobal unused), the squared residuals per view and the residuals and pixels per view and region.
struct RegionEnergy {
  static constexpr int kCount = static_cast<int>(Region::kGlobal);
  std::array<double, kCount> energy{}, pixels{};
  std::vector<double> view_energy;
  std::vector<std::array<double, kCount>> view_sum, view_pixels;
  /// m^2: the region's mean squared residual (0 without pixels).
  [[nodiscard]] double mean_square(Region region) const;
  /// m: the region's mean residual, over all views or in one view (0 without pixels).
  [[nodiscard]] double mean(Region region) const;
  [[nodiscard]] double view_mean(std::size_t view, Region region) const;
};

/// The region's energy_share, pixel_share and enrichment (the other fields 0) from squared residuals and pixels per
/// region (indexed by Region).
[[nodiscard]] RegionShare share_of_region(Region region, const std::array<double, RegionEnergy::kCount>& energy,
                                          const std::array<double, RegionEnergy::kCount>& pixels);

struct Localisation {
  /// Where the gap sits (place_gap): from the shape-feature group or the stable term that exceeds its floor the most
  /// (dominant_feature), kGlobal if nothing exceeds its floor.
  Region dominant = Region::kGlobal;
  /// That feature: a feature group's name, "stable" for the stable term, "camera" for the rigid surfaces' camera
  /// (camera_moved), empty if nothing exceeds its floor.
  std::string dominant_feature;
  /// place_gap moved the gap from the skirt to the hem: the folds deepen at the hem (folds_deepen_at_hem).
  bool moved_to_hem = false;
  /// place_gap moved the gap from the skirt to the hem by the hem's centre (rule O, kHemOffCentreMm).
  bool moved_by_offset = false;
  /// place_sensor_gap placed the gap where the pixels stand furthest above their floor (the views disagree).
  bool placed_by_views = false;
  /// m: how far the camera error read off the rigid surfaces moves the platform's centre (rigid_pose.hpp,
  /// platform_displacement; diagnose sets it before localise_features), 0 if not estimated.
  double camera_moved = 0.0;
  /// Per feature group (kFeatureGroups order) and for the stable term: the capture's difference from the fitted
  /// drape over the largest floor sample's (at least half the group's scale).
  std::vector<double> group_ratio;
  /// m: per feature group, the capture's difference from the fitted drape itself (group_differences; -1 where a
  /// drape lacks the group), whose ratio to the floor group_ratio is.
  std::vector<double> group_difference;
  double stable_ratio = 0.0;
  /// The residual maps' most enriched region, kGlobal if none reaches kMinRegionEnrichment (pixel residuals: fold
  /// placement shows).
  Region pixel_region = Region::kGlobal;
  /// The region whose pixel residuals exceed their own floor the most (RegionShare::floor_ratio, among regions with
  /// enough pixels), kGlobal if none exceeds it (localise_against_floors).
  Region floor_region = Region::kGlobal;
  std::vector<RegionShare> regions;
  std::vector<double> view_share;     // fraction of the residual energy per view
  std::vector<Harmonic> hem_difference;  // harmonics of (capture - model) hem radius
  int capture_folds = 0, model_folds = 0;
  double capture_fold_phase = 0.0, model_fold_phase = 0.0;  // radians, phase of the fold-count harmonic
  double capture_drape_coefficient = 0.0, model_drape_coefficient = 0.0;
};

/// The localisation's share of `region` (nullptr if it has none: not localised yet, or kGlobal).
[[nodiscard]] const RegionShare* region_share(const Localisation& localisation, Region region);

/// Region of a specimen-frame point given the fitted drape's outline (the hem: within 25 mm of the outline).
[[nodiscard]] Region classify_point(const Eigen::Vector3d& p, const HemProfile& model_outline, double cylinder_radius);

/// Calls visit(view, point, residual) for every pixel of `drape`'s residual maps that has one (a finite residual and a
/// depth to place it): the point in the specimen frame where the residual sits (placed at the captured depth where the
/// capture returned, else the model's; ViewComparison::depth), views and pixels in order.
void for_each_residual_point(
    const ForwardModel& model, const ScoredDrape& drape,
    const std::function<void(std::size_t view, const Eigen::Vector3d& point, double residual)>& visit);

/// `drape` scored against the capture (or a floor sample, with the capture's cameras): its residuals per region.
[[nodiscard]] RegionEnergy region_energy(const ForwardModel& model, const ScoredDrape& drape);

/// `drape` is the fitted drape scored against the capture (its residual maps).
[[nodiscard]] Localisation localise(const ForwardModel& model, const ScoredDrape& drape);

/// Sets each region's floor_ratio and floor_region: the region's residual RMS over the largest floor sample's there
/// (`floor_mean_square`, m^2 per region, Floors::region_floor).
void localise_against_floors(Localisation& localisation,
                             const std::array<double, RegionEnergy::kCount>& floor_mean_square);

/// The region a feature group describes: the outline groups the hem, the skirt groups the skirt.
[[nodiscard]] Region feature_region(FeatureGroup group);
/// An outline group that carries a change of the skirt above it (harmonics, sorted radii, hem height: every outline
/// group but the centre offset); place_gap counts it for the skirt where the skirt's residual is the denser.
[[nodiscard]] bool follows_skirt(FeatureGroup group);
/// The stable term's ratio to its floor from which stable_region calls a lifted platform top a sensor error
/// (everywhere) rather than the specimen's contact with the platform (calibrated on seeds 4-13,
/// docs/DIAGNOSIS_RESULTS.md, "Session 25": a specimen lifted by friction reached 1.64, a camera pose error that lifts
/// the top 3.15).
inline constexpr double kLiftedTopSensorRatio = 2.25;
/// m: how far above the fitted cloth a lifted platform top must lie for place_gap to let it lead a larger feature
/// group (rule T, registered in session 72, adopted in 73: on seeds 80-92 every friction capture's top lay 2.5-4.7 mm
/// above, every other physical capture's 0.0-0.4 mm, the fit's own offset; docs/DIAGNOSIS_RESULTS.md, "Session 73").
inline constexpr double kLiftedTopContact = 0.001;
/// m: the camera_moved from which place_gap calls the gap a camera error's (everywhere) whatever leads (session 28,
/// seeds 17-20: pose and bias errors 4.6-24 mm; friction, whose cloth sits higher on the top, at most 2.2 mm;
/// anything else at most 1.2 mm).
inline constexpr double kCameraMovedAtPlatform = 0.003;
/// A region stands out in the residual maps (Localisation::pixel_region) from this enrichment: its share of the
/// residual energy over its share of the pixels.
inline constexpr double kMinRegionEnrichment = 1.3;
/// A region counts in the residual maps (pixel_region, floor_region, ErrorFootprint::regions) from this share of the
/// pixels.
inline constexpr double kMinPixelShare = 0.02;
/// Where the stable term's excess (platform top, bare cylinder) sits, from the rigid regions' residuals (their
/// floor_ratio set): the bare cylinder (kCylinder) if the platform top is within its own floor; everywhere (kGlobal)
/// if the top is seen further from the camera than the fitted cloth (mean residual > 0: cloth cannot lie below the
/// platform, a camera error can put it there); a lifted top (mean <= 0): the specimen's contact (kTop) below
/// kLiftedTopSensorRatio times the stable floor, a camera error (kGlobal) from it.
[[nodiscard]] Region stable_region(const Localisation& localisation);
/// What localise_features divides feature group k's difference by: its floor (`group_floor`, Floors::group_floor), at
/// least half the group's scale (default_feature_scales).
[[nodiscard]] double group_ratio_floor(std::size_t k, const std::vector<double>& group_floor);
/// Sets group_difference, group_ratio, stable_ratio (and, by place_gap, dominant) from the fitted drape's shape
/// features against the capture's and the floors (floors.hpp) of each group. Call after localise_against_floors
/// (stable_region reads the regions' floor ratios).
void localise_features(Localisation& localisation, const ScoredDrape& drape, const Target& capture,
                       const std::vector<double>& group_floor, double stable_floor);

/// Sets dominant and dominant_feature from camera_moved, group_ratio, stable_ratio and the regions' enrichment, mean
/// and floor ratio. A camera the rigid surfaces put kCameraMovedAtPlatform or farther from its calibration places
/// it everywhere (kGlobal, "camera"). Else the largest ratio above 1 leads, but the stable term leads whatever else
/// exceeds its floor when it is above its floor with stable_region kTop and the top lifted by kLiftedTopContact or
/// more (a specimen that slid over the platform), when the top is above
/// its own floor and seen farther than the fitted cloth, or when it is at least kLiftedTopSensorRatio times its floor
/// (a camera's error; session 27). The stable term: stable_region. A skirt group: kSkirt. The hem's centre offset:
/// kHem. The other hem groups (harmonics, sorted radii, hem height): kSkirt if the skirt's pixel residual is denser
/// than the hem's (the outline carries a change of the skirt above it), else kHem. Nothing above 1: kGlobal. Last, a
/// gap so placed on the skirt moves to the hem where folds_deepen_at_hem. Rule S: where the skirt's pixel residual is
/// at least kSkirtDenseAtHem times as dense as the hem's (enrichment), neither the centre offset nor the folds' depth
/// puts the gap at the hem; it stays on the skirt. Rule O, after it: a gap a feature group placed on the skirt is the
/// hem's where the hem's centre lies kHemOffCentreMm or more off the fitted drape's (group_difference of the
/// off-centre group; moved_by_offset).
void place_gap(Localisation& localisation);

/// Rule O's offset, mm (rule D's floor, docs/preregistrations/session85.md, not fitted on regions): a specimen laid
/// off centre makes the skirt's residual denser too (rule S's reading sends its gap to the skirt), but only a shifted
/// placement moves the hem's centre. Registered in session 85 as an addendum to session 87's test (+10 -0 in sample on
/// seeds 101-118; +3 -0 on fresh seeds 119-120, three misalignments: adopted in session 85),
/// docs/DIAGNOSIS_RESULTS.md, "Session 87".
inline constexpr double kHemOffCentreMm = 6.5;

/// Rule S's factor: a skirt whose pixel residual is this much denser than the hem's changed as a whole (its shear,
/// its yielding folds), and the outline's centre and the folds' depth at the hem follow it. Registered in session 74
/// on seeds 80-92 (the curl and misalignment gaps placed at the hem: skirt over hem enrichment 0.76-1.25; five shear
/// and a yield capture's: 1.36-1.83; +6 -0 there); on fresh seeds 93-96 +1 -0 (seed 96's yield_01, a skirt change
/// the folds' depth had put at the hem): adopted in session 75, docs/DIAGNOSIS_RESULTS.md, "Session 75".
inline constexpr double kSkirtDenseAtHem = 1.3;

/// The folds' depth (group skirt_spread: the spread of z per annulus of the skirt) stands more than kFoldDepthAtHem
/// times further above its floor than the skirt's mean height (skirt_height): the skirt's mean profile follows the
/// bending while an edge band (a curled hem) sets how deep the folds fall, so place_gap puts such a skirt gap at the
/// hem. Pre-registered in session 65 on seeds 58-65 (curl 4 -> 12 of 14 at the hem, 54 -> 59 of 76 effect captures in
/// the effect's region), tested in session 66 on fresh seeds 66-67 (+2, -0 of 21): docs/DIAGNOSIS_RESULTS.md,
/// "Session 66". The reading (an edge band sets the folds' depth) is a hypothesis, not shown.
[[nodiscard]] bool folds_deepen_at_hem(const Localisation& localisation);
inline constexpr double kFoldDepthAtHem = 1.5;

/// Where the four views disagree (view_consistency.hpp: the multipath test fired) the gap is a sensor error's, and a
/// sensor error moves pixels, not the cloth: the shape features answer to it only through the fit, while the pixels'
/// own excess shows where the readings are off. So the gap goes to floor_region (the region whose pixel residuals
/// stand furthest above their own floor) and placed_by_views is set; where no region stands above its floor
/// (kGlobal), and where the rigid surfaces put the camera off (place_gap's "camera": an error of the whole view,
/// kGlobal), place_gap's region stays. Rule M, pre-registered in session 69 on the 28 multipath captures of seeds
/// 59-73 (13 -> 19 in the effect's region) and tested on fresh seeds 75-77: docs/DIAGNOSIS_RESULTS.md,
/// "Session 69". Call after place_gap (localise_features).
void place_sensor_gap(Localisation& localisation);

}  // namespace drapegen::diagnosis
