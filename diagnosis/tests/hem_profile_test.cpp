#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "drapegen/diagnosis/hem_profile.hpp"

using namespace drapegen::diagnosis;

namespace {
/// A six-fold outline r = 0.14 + 0.02 cos(6 (theta - phase)) sampled as points below the top.
Eigen::Matrix3Xd lobed_points(double phase, double drift_x = 0.0) {
  const int n = 20000;
  Eigen::Matrix3Xd p(3, n);
  for (int i = 0; i < n; ++i) {
    const double t = 2 * M_PI * i / n;
    const double r = 0.14 + 0.02 * std::cos(6 * (t - phase));
    p.col(i) << r * std::cos(t) + drift_x, r * std::sin(t), -0.1;
  }
  return p;
}
}  // namespace

TEST(HemProfile, CircleAreaAndDrapeCoefficient) {
  Eigen::Matrix3Xd p(3, 7200);
  for (int i = 0; i < 7200; ++i) {
    const double t = 2 * M_PI * i / 7200;
    p.col(i) << 0.12 * std::cos(t), 0.12 * std::sin(t), -0.05;
  }
  const HemProfile h = hem_profile_from_points(p);
  for (double r : h.radius) EXPECT_NEAR(r, 0.12, 1e-6);
  EXPECT_NEAR(enclosed_area(h), M_PI * 0.0144, 1e-6);
  SpecimenFacts s;
  EXPECT_NEAR(drape_coefficient(h, s), (M_PI * 0.0144 - M_PI * 0.0025) / (0.09 - M_PI * 0.0025), 1e-5);
  EXPECT_EQ(fold_count(h), 0);
}

TEST(HemProfile, FoldsHarmonicsAndAlignment) {
  const HemProfile a = hem_profile_from_points(lobed_points(0.0));
  const HemProfile b = hem_profile_from_points(lobed_points(0.2));
  EXPECT_EQ(fold_count(a), 6);
  const auto h = harmonics(a, 8);
  EXPECT_NEAR(h[0].amplitude, 0.14, 3e-3);  // the 98th percentile of a 2.5 deg bin sits above its mean
  EXPECT_NEAR(h[6].amplitude, 0.02, 1e-3);
  EXPECT_LT(h[3].amplitude, 1e-3);
  // b is a turned by 0.2 rad; the six-fold symmetry makes 0.2 - k pi/3 equivalent.
  const Alignment al = align(a, b);
  const double period = M_PI / 3;
  const double wrapped = std::remainder(al.angle - 0.2, period);
  EXPECT_NEAR(wrapped, 0.0, 0.01);
  EXPECT_LT(al.rms, 3e-3);
  const HemProfile turned = rotate(a, 0.2);
  for (int k = 0; k < b.bins(); ++k) EXPECT_NEAR(turned.radius[k], b.radius[k], 2e-3);
}

TEST(HemProfile, OffCentreShowsAsFirstHarmonic) {
  const HemProfile centred = hem_profile_from_points(lobed_points(0.0));
  const HemProfile shifted = hem_profile_from_points(lobed_points(0.0, 0.015));
  HemProfile diff;
  for (int k = 0; k < centred.bins(); ++k) diff.radius.push_back(shifted.radius[k] - centred.radius[k]);
  const auto h = harmonics(diff, 6);
  EXPECT_NEAR(h[1].amplitude, 0.015, 0.003);
  EXPECT_NEAR(std::remainder(h[1].phase, 2 * M_PI), 0.0, 0.1);  // towards +x
}

TEST(HemProfile, OrientationFollowsTheOffCentreNotTheFolds) {
  // The same off-centre drape (10 mm towards 0.7 rad) with its 8 folds elsewhere (another stable drape): the turn
  // must bring the offset's direction onto the target's, whatever the folds do; matching the folds would not.
  auto outline = [](double offset_angle, double fold_phase) {
    HemProfile p;
    p.radius.resize(kHemBins);
    for (int k = 0; k < kHemBins; ++k) {
      const double t = (k + 0.5) * 2.0 * M_PI / kHemBins;
      p.radius[k] = 0.12 + 0.010 * std::cos(t - offset_angle) + 0.02 * std::cos(8.0 * t + fold_phase);
    }
    return p;
  };
  const HemProfile target = outline(0.7, 0.0), model = outline(0.0, 2.0);
  EXPECT_NEAR(align_orientation(model, target).angle, 0.7, 2.0 * M_PI / kHemBins);
  EXPECT_GT(std::abs(align(model, target).angle - 0.7), 0.1);
  // Low-passing keeps the offset and drops the folds.
  const auto h = harmonics(low_pass(target, kOrientationOrders), 8);
  EXPECT_NEAR(h[1].amplitude, 0.010, 1e-4);
  EXPECT_LT(h[8].amplitude, 1e-4);
}

TEST(HemProfile, SkipsNonFinitePoints) {
  // A NaN point has no angle and so no bin: skipped, the outline the same as without it.
  Eigen::Matrix3Xd p = lobed_points(0.0);
  const HemProfile clean = hem_profile_from_points(p);
  p.col(7).setConstant(std::numeric_limits<double>::quiet_NaN());
  p.col(8) << std::numeric_limits<double>::infinity(), 0.0, -0.1;
  const HemProfile skipped = hem_profile_from_points(p);
  ASSERT_EQ(skipped.bins(), clean.bins());
  for (int k = 0; k < clean.bins(); ++k) {
    ASSERT_TRUE(std::isfinite(skipped.radius[k])) << "bin " << k;
    EXPECT_NEAR(skipped.radius[k], clean.radius[k], 1e-4) << "bin " << k;
  }
}
