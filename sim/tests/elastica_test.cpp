#include "drapegen/sim/elastica.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

namespace drapegen::sim {
namespace {

constexpr double kGravity = 9.81;

/// The solved curve, failing the test on an error.
CantileverCurve solve(double length, double alpha, double beta, double density, int samples = 2001) {
  const Expected<CantileverCurve> curve = solve_heavy_cantilever(length, alpha, beta, density, kGravity, samples);
  EXPECT_TRUE(curve.has_value()) << (curve ? "" : curve.error().message);
  return curve ? *curve : CantileverCurve{};
}

double master(double gamma) {
  const Expected<double> hw = master_curve_height_over_width(gamma);
  EXPECT_TRUE(hw.has_value()) << (hw ? "" : hw.error().message);
  return hw ? *hw : std::numeric_limits<double>::quiet_NaN();
}

/// Clockwise tangent turning between consecutive chords over the spacing h: a second-order curvature at point i.
double chord_curvature(const std::vector<Eigen::Vector2d>& p, int i, double h) {
  const Eigen::Vector2d a = p[i] - p[i - 1], b = p[i + 1] - p[i];
  return -std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b)) / h;
}

/// Moment of the weight beyond point i about point i (trapezoid rule), per unit width.
std::vector<double> weight_moments(const std::vector<Eigen::Vector2d>& p, double weight_per_area, double h) {
  std::vector<double> moment(p.size(), 0.0);
  for (std::size_t i = 0; i + 1 < p.size(); ++i) {
    double sum = 0.0;
    for (std::size_t j = i; j + 1 < p.size(); ++j) sum += 0.5 * (p[j].x() + p[j + 1].x() - 2.0 * p[i].x()) * h;
    moment[i] = weight_per_area * sum;
  }
  return moment;
}

/// Largest |alpha kappa + beta kappa^2 - M| over interior points, relative to the clamp moment.
double equilibrium_residual(const CantileverCurve& curve, double length, double alpha, double beta, double density) {
  const int n = static_cast<int>(curve.points.size());
  const double h = length / (n - 1);
  const std::vector<double> moment = weight_moments(curve.points, density * kGravity, h);
  double worst = 0.0;
  for (int i = 1; i + 1 < n; ++i) {
    const double kappa = chord_curvature(curve.points, i, h);
    worst = std::max(worst, std::abs(alpha * kappa + beta * kappa * kappa - moment[i]));
  }
  return worst / moment[0];
}

TEST(HeavyCantilever, SmallGammaFollowsLinearBeamTheory) {
  // Linear beam theory: tip drop rho g L^4 / (8 alpha), so H / W -> Gamma / 8.
  for (const double gamma : {1e-3, 1e-2}) {
    EXPECT_NEAR(master(gamma), gamma / 8.0, 0.01 * gamma / 8.0) << "Gamma = " << gamma;
  }
  // The first geometric correction is softening of O(Gamma^2): already visible at Gamma = 1.
  EXPECT_LT(master(1.0), 0.999 / 8.0);
}

TEST(HeavyCantilever, HeightOverWidthIncreasesWithGamma) {
  double previous = 0.0;
  for (const double gamma : {1e-3, 1e-2, 0.1, 1.0, 3.0, 10.0, 30.0, 100.0, 300.0, 1e3, 1e4}) {
    const double hw = master(gamma);
    EXPECT_GT(hw, previous) << "Gamma = " << gamma;
    previous = hw;
  }
}

TEST(HeavyCantilever, HangsNearlyVerticallyAtLargeGamma) {
  // Gamma = 1000: L = 1, alpha = 1, rho g = 1000.
  const Expected<CantileverCurve> curve = solve_heavy_cantilever(1.0, 1.0, 0.0, 1000.0, 1.0);
  ASSERT_TRUE(curve.has_value()) << curve.error().message;
  EXPECT_NEAR(curve->tip_angle, std::numbers::pi / 2.0, 1e-6);
  const Eigen::Vector2d tip = curve->points.back();
  EXPECT_LT(tip.x(), 0.1);   // bends over within a short boundary layer at the clamp ...
  EXPECT_LT(tip.y(), -0.9);  // ... and hangs down for the rest of its length
  EXPECT_GT(curve->height_over_width, 10.0);
  // Gamma = 1e4 is still resolved and hangs steeper still.
  EXPECT_GT(master(1e4), curve->height_over_width);
}

TEST(HeavyCantilever, DependsOnlyOnGamma) {
  // Three strips with Gamma = rho g L^3 / alpha = 5.
  const double gamma = 5.0;
  const CantileverCurve a = solve(0.2, 0.3 * kGravity * 0.008 / gamma, 0.0, 0.3);
  const CantileverCurve b = solve(0.05, 1e-6, 0.0, gamma * 1e-6 / (kGravity * 1.25e-4));
  const CantileverCurve c = solve(1.5, 2.0 * kGravity * 3.375 / gamma, 0.0, 2.0);
  EXPECT_NEAR(a.height_over_width, b.height_over_width, 1e-9 * a.height_over_width);
  EXPECT_NEAR(a.height_over_width, c.height_over_width, 1e-9 * a.height_over_width);
  EXPECT_NEAR(a.height_over_width, master(gamma), 1e-9 * a.height_over_width);
  EXPECT_NEAR(a.tip_angle, c.tip_angle, 1e-9);
  // The shapes are the same up to scale.
  for (std::size_t i = 0; i < a.points.size(); i += 100) {
    EXPECT_LT((a.points[i] / 0.2 - c.points[i] / 1.5).norm(), 1e-9) << "point " << i;
  }
}

TEST(HeavyCantilever, CurveGeometry) {
  const double length = 0.15;
  const CantileverCurve curve = solve(length, 8e-4, 0.0, 0.25, 301);  // Gamma ~ 10
  ASSERT_EQ(curve.points.size(), 301u);
  EXPECT_EQ(curve.points.front(), Eigen::Vector2d::Zero());
  const double h = length / 300.0;
  for (std::size_t i = 1; i < curve.points.size(); ++i) {
    const Eigen::Vector2d chord = curve.points[i] - curve.points[i - 1];
    EXPECT_NEAR(chord.norm(), h, 1e-4 * h) << "segment " << i;  // inextensible, equal arc-length steps
    EXPECT_GT(chord.x(), 0.0);                                   // never past vertical
    EXPECT_LT(chord.y(), 0.0);                                   // always descending
  }
  // Clamped horizontally: the first chord leaves at an angle of about kappa(0) h / 2 only.
  const Eigen::Vector2d first = curve.points[1];
  EXPECT_LT(std::abs(std::atan2(first.y(), first.x())), 0.02);
  const Eigen::Vector2d tip = curve.points.back();
  EXPECT_NEAR(curve.height_over_width, -tip.y() / tip.x(), 1e-12);
  const Eigen::Vector2d last = tip - curve.points[curve.points.size() - 2];
  EXPECT_NEAR(curve.tip_angle, std::atan2(-last.y(), last.x()), 1e-6);  // no curvature at the free tip
}

TEST(HeavyCantilever, OutputResolutionDoesNotChangeTheSolution) {
  const CantileverCurve coarse = solve(0.1, 1e-5, -1e-8, 0.2, 3);
  const CantileverCurve fine = solve(0.1, 1e-5, -1e-8, 0.2, 2001);
  EXPECT_NEAR(coarse.height_over_width, fine.height_over_width, 1e-12 * fine.height_over_width);
  EXPECT_LT((coarse.points.back() - fine.points.back()).norm(), 1e-12);
}

// The check's own quadrature and curvature differences are second order in the spacing, so its residual must fall
// fourfold when the spacing halves: the solver is exact to the resolution of the check.
TEST(HeavyCantilever, SatisfiesMomentBalanceLinear) {
  const double length = 0.12, alpha = 2e-5, density = 0.25;  // Gamma ~ 21
  const double coarse = equilibrium_residual(solve(length, alpha, 0.0, density, 1001), length, alpha, 0.0, density);
  const double fine = equilibrium_residual(solve(length, alpha, 0.0, density, 2001), length, alpha, 0.0, density);
  EXPECT_LT(coarse, 1e-5);
  EXPECT_LT(fine, coarse / 3.0);
}

TEST(HeavyCantilever, SatisfiesMomentBalanceSoftening) {
  // Clamp curvature ~ 0.9 kappa*: deep in the softening range.
  const double length = 0.04, alpha = 1e-5, beta = -2e-8, density = 0.3;
  const CantileverCurve curve = solve(length, alpha, beta, density, 1001);
  const double coarse = equilibrium_residual(curve, length, alpha, beta, density);
  const double fine = equilibrium_residual(solve(length, alpha, beta, density, 2001), length, alpha, beta, density);
  EXPECT_LT(coarse, 1e-4);
  EXPECT_LT(fine, coarse / 3.0);
  // Residual of the same curve against the linear law: the check can tell the laws apart.
  EXPECT_GT(equilibrium_residual(curve, length, alpha, 0.0, density), 0.1);
}

TEST(HeavyCantilever, SofteningDeflectsMoreAndStiffeningLess) {
  const double length = 0.03, alpha = 1e-5, density = 0.3;
  const double linear = solve(length, alpha, 0.0, density).height_over_width;
  EXPECT_GT(solve(length, alpha, -2e-8, density).height_over_width, 1.1 * linear);
  EXPECT_LT(solve(length, alpha, 2e-8, density).height_over_width, 0.95 * linear);
}

TEST(HeavyCantilever, NoEquilibriumBeyondPeakTorque) {
  // alpha^2 / (4 |beta|) = 1.25e-3 N m, while a 10 cm strip of 0.3 kg/m^2 needs several times that at the clamp.
  const Expected<CantileverCurve> curve = solve_heavy_cantilever(0.1, 1e-5, -2e-8, 0.3);
  ASSERT_FALSE(curve.has_value());
  EXPECT_NE(curve.error().message.find("peak torque"), std::string::npos) << curve.error().message;
  // A slightly less negative beta carries the same strip.
  EXPECT_TRUE(solve_heavy_cantilever(0.1, 1e-5, -2e-9, 0.3).has_value());
}

TEST(HeavyCantilever, RejectsBadInput) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(solve_heavy_cantilever(0.0, 1e-5, 0.0, 0.3).has_value());
  EXPECT_FALSE(solve_heavy_cantilever(-0.1, 1e-5, 0.0, 0.3).has_value());
  EXPECT_FALSE(solve_heavy_cantilever(nan, 1e-5, 0.0, 0.3).has_value());
  EXPECT_FALSE(solve_heavy_cantilever(0.1, 0.0, 0.0, 0.3).has_value());
  EXPECT_FALSE(solve_heavy_cantilever(0.1, inf, 0.0, 0.3).has_value());
  EXPECT_FALSE(solve_heavy_cantilever(0.1, 1e-5, nan, 0.3).has_value());
  EXPECT_FALSE(solve_heavy_cantilever(0.1, 1e-5, 0.0, 0.0).has_value());
  EXPECT_FALSE(solve_heavy_cantilever(0.1, 1e-5, 0.0, -0.3).has_value());
  EXPECT_FALSE(solve_heavy_cantilever(0.1, 1e-5, 0.0, 0.3, -9.81).has_value());
  EXPECT_FALSE(solve_heavy_cantilever(0.1, 1e-5, 0.0, 0.3, nan).has_value());
  EXPECT_FALSE(solve_heavy_cantilever(0.1, 1e-5, 0.0, 0.3, 9.81, 2).has_value());
  EXPECT_FALSE(master_curve_height_over_width(-1.0).has_value());
  EXPECT_FALSE(master_curve_height_over_width(nan).has_value());
  // Beyond what double precision can resolve (the tip angle would underflow): an error, not garbage.
  EXPECT_FALSE(master_curve_height_over_width(1e7).has_value());
  // Far beyond it (a strip of almost no stiffness): the same error at once, not a count of integration steps past an
  // int's range.
  EXPECT_FALSE(master_curve_height_over_width(1e20).has_value());
  const Expected<CantileverCurve> limp = solve_heavy_cantilever(0.1, 1e-20, 0.0, 0.3);
  ASSERT_FALSE(limp.has_value());
  EXPECT_NE(limp.error().message.find("too large to resolve"), std::string::npos) << limp.error().message;
}

TEST(HeavyCantilever, WeightlessStripStaysStraight) {
  EXPECT_EQ(master(0.0), 0.0);
  const Expected<CantileverCurve> curve = solve_heavy_cantilever(0.2, 1e-5, 0.0, 0.3, 0.0, 5);
  ASSERT_TRUE(curve.has_value());
  EXPECT_EQ(curve->height_over_width, 0.0);
  EXPECT_EQ(curve->points.back(), Eigen::Vector2d(0.2, 0.0));
}

}  // namespace
}  // namespace drapegen::sim
