#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "drapegen/diagnosis/shape_features.hpp"

using namespace drapegen::diagnosis;

namespace {

constexpr double kR = 0.05;  // cylinder radius

/// A synthetic drape: a skirt from the rim out to a hem r(theta) = r0 + a cos(n (theta - phase)), falling with a
/// slope and folded with depth `fold` (z varies with the fold phase), shifted by drift_x; a hem lifted by `lift` m.
struct Drape {
  double r0 = 0.14, a = 0.02, phase = 0.0, drift_x = 0.0, fold = 0.01, lift = 0.0;
  int n = 6;
};

Eigen::Matrix3Xd drape_points(const Drape& d) {
  const int angles = 720, radial = 60;
  Eigen::Matrix3Xd p(3, angles * radial);
  int k = 0;
  for (int i = 0; i < angles; ++i) {
    const double t = 2 * M_PI * (i + 0.5) / angles;
    const double c = std::cos(d.n * (t - d.phase));
    const double hem = d.r0 + d.a * c;
    for (int j = 0; j < radial; ++j) {
      const double s = (j + 0.5) / radial;  // 0 at the rim, 1 at the hem
      const double r = kR + 0.003 + s * (hem - kR - 0.003);
      const double z = -0.01 - 0.12 * s - d.fold * s * c + (s > 0.9 ? d.lift : 0.0);
      p.col(k++) << r * std::cos(t) + d.drift_x, r * std::sin(t), z;
    }
  }
  return p;
}

}  // namespace

TEST(ShapeFeatures, IgnoreWhereTheFoldsFall) {
  Drape a;
  Drape b = a;
  b.phase = 0.37;  // the same drape turned: folds elsewhere
  const ShapeFeatures fa = shape_features(drape_points(a), kR, true);
  const ShapeFeatures fb = shape_features(drape_points(b), kR, true);
  ASSERT_TRUE(fa.valid && fb.valid);
  EXPECT_EQ(fa.folds, 6);
  ASSERT_EQ(fa.off_centre.size(), 2u);
  EXPECT_NEAR(fa.off_centre[0], 0.0, 1e-3);
  EXPECT_NEAR(fa.off_centre[1], 0.0, 1e-3);
  const auto d = group_differences(fa, fb);
  for (std::size_t k = 0; k < d.size(); ++k) {
    EXPECT_GE(d[k], 0.0) << feature_group_name(kFeatureGroups[k]);  // negative: a group not compared
    EXPECT_LT(d[k], 2e-3) << feature_group_name(kFeatureGroups[k]);
  }
  EXPECT_LT(feature_distance(fa, fb, default_feature_scales()), 0.25);
}

TEST(ShapeFeatures, SeeOffCentreHemLiftAndFoldCount) {
  const ShapeFeatures base = shape_features(drape_points({}), kR, true);
  const auto scales = default_feature_scales();

  Drape shifted;
  shifted.drift_x = 0.02;
  const ShapeFeatures fs = shape_features(drape_points(shifted), kR, true);
  EXPECT_NEAR(fs.off_centre[0], 0.02, 0.004);
  EXPECT_GT(group_differences(base, fs)[static_cast<int>(FeatureGroup::kOffCentre)], 0.01);

  Drape lopsided;  // one side hangs lower: the hem height's first harmonic
  lopsided.fold = 0.0;
  Eigen::Matrix3Xd p = drape_points(lopsided);
  for (int i = 0; i < p.cols(); ++i) p(2, i) += 0.1 * p(2, i) * p(0, i) / 0.14;
  const ShapeFeatures fo = shape_features(p, kR, true);
  EXPECT_GT(fo.off_centre[1], 0.008);

  Drape lifted;
  lifted.lift = 0.02;
  const ShapeFeatures fl = shape_features(drape_points(lifted), kR, true);
  EXPECT_GT(group_differences(base, fl)[static_cast<int>(FeatureGroup::kHemHeight)], 0.01);

  Drape more;
  more.n = 9;
  const ShapeFeatures fm = shape_features(drape_points(more), kR, true);
  EXPECT_EQ(fm.folds, 9);
  EXPECT_GT(feature_distance(base, fm, scales), 1.0);
}

TEST(ShapeFeatures, PartialViewsLeaveTheOutlineGroupsOut) {
  Eigen::Matrix3Xd all = drape_points({});
  // Keep the half with x > 0 only (one camera's side).
  Eigen::Matrix3Xd half(3, all.cols());
  int n = 0;
  for (int i = 0; i < all.cols(); ++i)
    if (all(0, i) > 0.0) half.col(n++) = all.col(i);
  half.conservativeResize(3, n);
  const ShapeFeatures f = shape_features(half, kR, false);
  ASSERT_TRUE(f.valid);
  // Against the whole drape: the outline groups are missing from the half view, the skirt compares (and agrees).
  const ShapeFeatures whole = shape_features(all, kR, true);
  ASSERT_TRUE(whole.valid);
  const auto d = group_differences(f, whole);
  EXPECT_LT(d[static_cast<int>(FeatureGroup::kHarmonics)], 0.0);
  EXPECT_LT(d[static_cast<int>(FeatureGroup::kFolds)], 0.0);
  EXPECT_GE(d[static_cast<int>(FeatureGroup::kSkirtHeight)], 0.0);
  EXPECT_LT(d[static_cast<int>(FeatureGroup::kSkirtHeight)], 0.003);
  // Too few points: not valid, and no group compares.
  const ShapeFeatures none = shape_features(Eigen::Matrix3Xd(3, 0), kR, true);
  EXPECT_FALSE(none.valid);
  for (double x : group_differences(none, f)) EXPECT_LT(x, 0.0);
}

TEST(ShapeFeatures, SkipNonFiniteAndFarPoints) {
  // Points a camera of a broken calibration back-projects (NaN, inf, a "no return" sentinel depth thousands of km
  // away) have no bin and no annulus: skipped, the features the same as without them.
  Eigen::Matrix3Xd p = drape_points(Drape{});
  const ShapeFeatures clean = shape_features(p, kR, true);
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  p.col(0) << nan, nan, nan;
  p.col(1) << 0.1, nan, -0.1;
  p.col(2) << inf, 0.0, -0.1;
  p.col(3) << 3e7, 1e7, -0.1;  // finite, but its annulus index is beyond an int
  const ShapeFeatures skipped = shape_features(p, kR, true);
  ASSERT_TRUE(clean.valid && skipped.valid);
  EXPECT_EQ(skipped.folds, clean.folds);
  const auto d = group_differences(clean, skipped);
  for (std::size_t k = 0; k < d.size(); ++k) {
    EXPECT_GE(d[k], 0.0) << feature_group_name(kFeatureGroups[k]);
    EXPECT_LT(d[k], 2e-3) << feature_group_name(kFeatureGroups[k]);
  }
}
