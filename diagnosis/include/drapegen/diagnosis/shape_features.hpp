#pragma once
// Shape features of a drape that do not depend on where its folds fall: the hem outline's harmonic amplitudes
// (no phases) and sorted radii, the hem's height, the skirt's mean height and spread against the radius, and the
// fold count. Two stable drapes of the same fabric differ in fold phase, much less in these; the unmodelled effects
// change them (misalignment: the first harmonic; curl: the hem's height; yield, shear, friction: fold count, fold
// depth and the skirt's slope). docs/DIAGNOSIS.md, "Method", "Objective".

#include <Eigen/Core>
#include <string>
#include <vector>

#include "drapegen/diagnosis/capture.hpp"
#include "drapegen/diagnosis/hem_profile.hpp"

namespace drapegen::diagnosis {

/// The feature groups, each compared as an RMS difference in metres (fold count: in folds x kFoldScale).
enum class FeatureGroup { kHarmonics, kOffCentre, kSortedRadii, kHemHeight, kSkirtHeight, kSkirtSpread, kFolds };
inline constexpr FeatureGroup kFeatureGroups[] = {FeatureGroup::kHarmonics,   FeatureGroup::kOffCentre,
                                                  FeatureGroup::kSortedRadii, FeatureGroup::kHemHeight,
                                                  FeatureGroup::kSkirtHeight, FeatureGroup::kSkirtSpread,
                                                  FeatureGroup::kFolds};
inline constexpr int kFeatureGroupCount = 7;
[[nodiscard]] std::string_view feature_group_name(FeatureGroup group);

struct ShapeFeatures {
  std::vector<double> harmonics;       // m: hem-radius amplitudes of orders 0 and 2..12
  /// m: first harmonics (amplitude) of the hem radius (the outline's centre off the axis) and of the hem's height
  /// against angle (one side hanging lower: more cloth on that side).
  std::vector<double> off_centre;
  std::vector<double> sorted_radii;    // m: hem radius quantiles 5%, 15%, ..., 95% (over angle)
  std::vector<double> hem_height;      // m: mean, 10% and 90% quantile of the hem's z over angle
  std::vector<double> skirt_height;    // m: mean z per 10 mm annulus of the skirt (NaN without enough points)
  std::vector<double> skirt_spread;    // m: standard deviation of z per annulus (fold depth)
  double folds = 0.0;
  bool valid = false;                  // enough of the skirt was seen
};

/// From points in the specimen frame (back-projected depth of one or more views). `full_outline`: the points see
/// the whole circumference (else the outline's harmonics, off-centre and folds are left out: a single view sees part).
[[nodiscard]] ShapeFeatures shape_features(const Eigen::Matrix3Xd& points, double cylinder_radius, bool full_outline);
[[nodiscard]] ShapeFeatures shape_features(const Capture& capture, const std::vector<int>& views);

/// Per group: the RMS difference of the entries both have (m; folds in units of kFoldScale); -1 where a group is
/// missing in either.
constexpr double kFoldScale = 0.004;  // m per fold
[[nodiscard]] std::vector<double> group_differences(const ShapeFeatures& a, const ShapeFeatures& b);

/// The distance of two feature sets: the RMS over the groups both have of difference / scale, each group's scale
/// (m) given (e.g. the multistability spread of that group); dimensionless.
[[nodiscard]] double feature_distance(const ShapeFeatures& a, const ShapeFeatures& b, const std::vector<double>& scale);

/// Default group scales (m): what a different stable drape of the same fabric typically changes (measured on the
/// reality generator's controls, docs/DIAGNOSIS.md).
[[nodiscard]] std::vector<double> default_feature_scales();

}  // namespace drapegen::diagnosis
