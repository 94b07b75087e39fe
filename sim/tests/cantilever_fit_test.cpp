#include "drapegen/sim/cantilever_fit.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "drapegen/sim/elastica.hpp"

namespace drapegen::sim {
namespace {

constexpr double kGravity = 9.81;
using Curve = std::vector<Eigen::Vector2d>;

Curve elastica(double length, double alpha, double beta, double density, int samples = 2001) {
  const Expected<CantileverCurve> curve = solve_heavy_cantilever(length, alpha, beta, density, kGravity, samples);
  EXPECT_TRUE(curve.has_value()) << (curve ? "" : curve.error().message);
  return curve ? curve->points : Curve{};
}

BendingFit fit(const Curve& curve, double density, bool fit_beta) {
  const Expected<BendingFit> result = fit_bending_moduli(curve, density, kGravity, fit_beta);
  EXPECT_TRUE(result.has_value()) << (result ? "" : result.error().message);
  return result ? *result : BendingFit{};
}

/// An equilibrium strip (linear law) whose clamp end curls up and back past vertical, so x is not monotone along
/// it. Integrates the heavy elastica from the free tip, whose tangent makes angle phi_tip with the downward
/// vertical, with RK4 in the arc length u from the tip: dphi/du = M / alpha, dM/du = rho g u sin(phi).
Curve curled_strip(double length, double alpha, double density, double phi_tip, int steps) {
  const double h = length / steps, weight = density * kGravity;
  const auto rate = [&](double u, const Eigen::Vector4d& q) {
    return Eigen::Vector4d(q[1] / alpha, weight * u * std::sin(q[0]), -std::sin(q[0]), std::cos(q[0]));
  };
  Eigen::Vector4d q(phi_tip, 0.0, 0.0, 0.0);  // (phi, M, x, y) with the tip at the origin
  Curve tip_to_clamp{Eigen::Vector2d::Zero()};
  for (int i = 0; i < steps; ++i) {
    const double u = i * h;
    const Eigen::Vector4d k1 = rate(u, q), k2 = rate(u + h / 2, q + h / 2 * k1), k3 = rate(u + h / 2, q + h / 2 * k2),
                          k4 = rate(u + h, q + h * k3);
    q += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    tip_to_clamp.emplace_back(q[2], q[3]);
  }
  Curve clamp_to_tip(tip_to_clamp.rbegin(), tip_to_clamp.rend());
  for (Eigen::Vector2d& p : clamp_to_tip) p -= tip_to_clamp.back();
  return clamp_to_tip;
}

TEST(CantileverFit, RecoversAlphaFromLinearElastica) {
  const double alpha = 1e-5, density = 0.3;
  for (const double length : {0.02, 0.05, 0.1}) {  // Gamma ~ 2.4, 37, 294
    const Curve curve = elastica(length, alpha, 0.0, density);
    const BendingFit linear = fit(curve, density, false);
    EXPECT_NEAR(linear.alpha, alpha, 0.01 * alpha) << "L = " << length;
    EXPECT_EQ(linear.beta, 0.0);
    EXPECT_LT(linear.rms_relative_residual, 1e-3);
    EXPECT_EQ(linear.samples_used, 250);  // 256 minus 3 samples at each end
    // Fitting beta as well finds (almost) none: its effect at the largest curvature is tiny.
    const BendingFit quadratic = fit(curve, density, true);
    EXPECT_NEAR(quadratic.alpha, alpha, 0.01 * alpha) << "L = " << length;
    EXPECT_LT(std::abs(quadratic.beta) * 300.0, 0.01 * alpha) << "L = " << length;  // kappa stays below 300 / m
  }
}

TEST(CantileverFit, RecoversAlphaAndBetaFromSofteningElastica) {
  // kappa* = alpha / (2 |beta|) = 250 / m. The clamp curvature reaches about 0.3, 0.55 and 0.9 kappa*, so the
  // quadratic term changes the torque by 15 - 45 % there and beta is well identified.
  const double alpha = 1e-5, beta = -2e-8, density = 0.3;
  for (const double length : {0.02, 0.03, 0.04}) {
    const Curve curve = elastica(length, alpha, beta, density);
    const BendingFit result = fit(curve, density, true);
    EXPECT_NEAR(result.alpha, alpha, 0.05 * alpha) << "L = " << length;
    EXPECT_NEAR(result.beta, beta, 0.05 * std::abs(beta)) << "L = " << length;
    EXPECT_LT(result.rms_relative_residual, 1e-3);
    // A linear law cannot explain the same curve: larger residual and a biased alpha.
    const BendingFit linear = fit(curve, density, false);
    EXPECT_GT(linear.rms_relative_residual, 10.0 * result.rms_relative_residual);
    EXPECT_LT(linear.alpha, 0.95 * alpha);
  }
}

TEST(CantileverFit, WorksOnACoarseCentreLine) {
  // A simulated strip's centre line has a few dozen vertices, not thousands.
  const double alpha = 1e-5, beta = -2e-8, density = 0.3;
  const BendingFit linear = fit(elastica(0.05, alpha, 0.0, density, 41), density, false);
  EXPECT_NEAR(linear.alpha, alpha, 0.01 * alpha);
  const BendingFit softening = fit(elastica(0.03, alpha, beta, density, 51), density, true);
  EXPECT_NEAR(softening.alpha, alpha, 0.05 * alpha);
  EXPECT_NEAR(softening.beta, beta, 0.05 * std::abs(beta));
}

TEST(CantileverFit, InvariantUnderMirrorAndScalesWithWeight) {
  const double alpha = 1e-5, beta = -2e-8, density = 0.3;
  const Curve curve = elastica(0.03, alpha, beta, density);
  Curve mirrored = curve;
  for (Eigen::Vector2d& p : mirrored) p.x() = -p.x();  // clamp pointing along -x
  const BendingFit a = fit(curve, density, true), b = fit(mirrored, density, true);
  EXPECT_NEAR(a.alpha, b.alpha, 1e-9 * a.alpha);
  EXPECT_NEAR(a.beta, b.beta, 1e-9 * std::abs(a.beta));
  // The torque is proportional to the weight, so are the moduli.
  const BendingFit heavy = fit(curve, 2.0 * density, true);
  EXPECT_NEAR(heavy.alpha, 2.0 * a.alpha, 1e-12 * a.alpha);
  EXPECT_NEAR(heavy.beta, 2.0 * a.beta, 1e-12 * std::abs(a.beta));
  // A translated curve (clamp not at the origin) gives the same fit.
  Curve shifted = curve;
  for (Eigen::Vector2d& p : shifted) p += Eigen::Vector2d(0.3, 1.2);
  EXPECT_NEAR(fit(shifted, density, true).alpha, a.alpha, 1e-6 * a.alpha);
}

TEST(CantileverFit, HandlesAStripCurlingPastVertical) {
  const double length = 0.1, alpha = 1e-5, density = 0.3;
  const Curve curve = curled_strip(length, alpha, density, 2e-4, 4000);
  // Precondition: x first decreases (clamp pointing up and back), then increases, then the strip hangs.
  bool decreasing = false, increasing = false;
  for (std::size_t i = 1; i < curve.size(); ++i) {
    decreasing = decreasing || curve[i].x() < curve[i - 1].x();
    increasing = increasing || curve[i].x() > curve[i - 1].x();
  }
  ASSERT_TRUE(decreasing && increasing);
  const BendingFit result = fit(curve, density, false);
  EXPECT_NEAR(result.alpha, alpha, 0.01 * alpha);
  EXPECT_LT(result.rms_relative_residual, 1e-3);
}

TEST(CantileverFit, RejectsBadInput) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const Curve good = elastica(0.05, 1e-5, 0.0, 0.3, 101);
  EXPECT_TRUE(fit_bending_moduli(good, 0.3).has_value());
  EXPECT_FALSE(fit_bending_moduli(good, 0.0).has_value());
  EXPECT_FALSE(fit_bending_moduli(good, -0.3).has_value());
  EXPECT_FALSE(fit_bending_moduli(good, nan).has_value());
  EXPECT_FALSE(fit_bending_moduli(good, 0.3, 0.0).has_value());
  EXPECT_FALSE(fit_bending_moduli(good, 0.3, nan).has_value());
  EXPECT_FALSE(fit_bending_moduli(good, 0.3, kGravity, true, 15).has_value());

  EXPECT_FALSE(fit_bending_moduli({}, 0.3).has_value());
  EXPECT_FALSE(fit_bending_moduli(Curve(good.begin(), good.begin() + 3), 0.3).has_value());
  EXPECT_FALSE(fit_bending_moduli(Curve(10, Eigen::Vector2d(0.1, 0.2)), 0.3).has_value());  // one distinct point
  Curve broken = good;
  broken[50].y() = nan;
  EXPECT_FALSE(fit_bending_moduli(broken, 0.3).has_value());
}

TEST(CantileverFit, RejectsAStraightStrip) {
  Curve horizontal, vertical;
  for (int i = 0; i < 20; ++i) {
    horizontal.emplace_back(0.01 * i, 0.0);
    vertical.emplace_back(0.0, -0.01 * i);
  }
  const Expected<BendingFit> h = fit_bending_moduli(horizontal, 0.3);
  ASSERT_FALSE(h.has_value());
  EXPECT_NE(h.error().message.find("straight"), std::string::npos) << h.error().message;
  EXPECT_FALSE(fit_bending_moduli(vertical, 0.3, kGravity, false).has_value());
}

}  // namespace
}  // namespace drapegen::sim
