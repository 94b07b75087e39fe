// The simulated cantilever (paper Sections 4.2.1, 4.3.1 and 4.4, Fig. 10 and 13) against the planar heavy
// elastica, the regression of the bending moduli and Eq. 8. Coarse meshes keep the suite fast; the fine-resolution
// numbers are printed by bench/cantilever_sweep.cpp.
//
// What limits the accuracy (see cantilever.hpp): the dihedral model on the equilateral lattice is a plate of
// Poisson ratio -1/3, so a strip that is free to curve across is softer than alpha (8/9 alpha for a long narrow
// strip at small deflection). Strips twice as wide as long are held flat across by the clamp and follow the rod
// (elastica) solution; large Gamma concentrates the bending in a boundary layer of length L Gamma^(-1/3) at the
// clamp, which needs more segments.
#include "drapegen/sim/cantilever.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "drapegen/sim/anisotropy.hpp"
#include "drapegen/sim/cantilever_fit.hpp"
#include "drapegen/sim/elastica.hpp"

namespace drapegen::sim {
namespace {

constexpr double kGravity = 9.81;
constexpr double kDensity = 0.3;  // kg/m^2

CantileverSpec strip(double length, double width, int segments, double alpha, double beta = 0.0) {
  CantileverSpec spec;
  spec.length = length;
  spec.width = width;
  spec.segments = segments;
  spec.fabric.alpha = {alpha, alpha, alpha};
  spec.fabric.beta = {beta, beta, beta};
  spec.fabric.density = kDensity;
  spec.gravity = kGravity;
  return spec;
}

CantileverResult simulate(const CantileverSpec& spec) {
  const Expected<CantileverResult> result = simulate_cantilever(spec);
  EXPECT_TRUE(result.has_value()) << (result ? "" : result.error().message);
  if (!result) return {};
  EXPECT_EQ(result->report.outcome, SolveOutcome::kConverged) << result->report.message;
  return *result;
}

double master(double gamma) {
  const Expected<double> hw = master_curve_height_over_width(gamma);
  EXPECT_TRUE(hw.has_value());
  return hw ? *hw : std::numeric_limits<double>::quiet_NaN();
}

BendingFit fit(const CantileverResult& result, bool fit_beta) {
  const Expected<BendingFit> f = fit_bending_moduli(result.curve, kDensity, kGravity, fit_beta);
  EXPECT_TRUE(f.has_value()) << (f ? "" : f.error().message);
  return f ? *f : BendingFit{};
}

/// alpha giving the gravito-bending parameter Gamma = rho g L^3 / alpha.
double alpha_for(double gamma, double length) { return kDensity * kGravity * std::pow(length, 3) / gamma; }

// Fig. 10: H/W against the master curve of the heavy elastica, L = 0.1 m.
//  - Gamma <= 100: width 2 L, 20 segments. Measured relative errors +0.25 %, +0.29 %, +0.68 %, +0.60 %, -0.63 %
//    at Gamma = 0.01, 0.1, 1, 10, 100; asserted within 1.5 %.
//  - Gamma = 1000: the bending sits in a boundary layer of length L Gamma^(-1/3) = L / 10 at the clamp, two
//    segments of a 20-segment strip (H/W -8.4 %), so this point uses 40 segments; the strip is so strongly bent that
//    curving across needs stretching, and a width of L / 2 is enough to hold it flat. Measured -1.15 %; asserted
//    within 3 %.
TEST(Cantilever, FollowsTheMasterCurve) {
  const double length = 0.1;
  struct Case {
    double gamma, width;
    int segments;
    double tolerance;
  };
  for (const Case& c : {Case{0.01, 0.2, 20, 0.015}, Case{0.1, 0.2, 20, 0.015}, Case{1.0, 0.2, 20, 0.015},
                        Case{10.0, 0.2, 20, 0.015}, Case{100.0, 0.2, 20, 0.015}, Case{1000.0, 0.05, 40, 0.03}}) {
    SCOPED_TRACE(testing::Message() << "Gamma = " << c.gamma);
    const CantileverResult r = simulate(strip(length, c.width, c.segments, alpha_for(c.gamma, length)));
    EXPECT_NEAR(r.gamma, c.gamma, 1e-9 * c.gamma);
    EXPECT_NEAR(r.height_over_width / master(c.gamma), 1.0, c.tolerance) << "Gamma = " << c.gamma;
  }
}

// The clamp face sits halfway between the two clamped lattice rows, where the discrete model puts it. With the
// clamp face on the second clamped row instead, H/W was ~2 h / L too large (+19 % at 10 segments, +10 % at 20).
// Measured -0.89 %, -0.01 %, +0.45 % at 6, 10 and 20 segments (Gamma = 1, width 2 L); asserted within 1.5 %.
TEST(Cantilever, ClampIsResolvedOnCoarseMeshes) {
  const double length = 0.05, gamma = 1.0;
  for (const int segments : {6, 10, 20}) {
    SCOPED_TRACE(testing::Message() << segments << " segments");
    const CantileverResult r = simulate(strip(length, 2.0 * length, segments, alpha_for(gamma, length)));
    EXPECT_NEAR(r.height_over_width / master(gamma), 1.0, 0.015) << segments << " segments";
    // The centre line: one point per lattice row from the last clamped row (x = h/2) to the tip.
    ASSERT_EQ(static_cast<int>(r.curve.size()), segments + 1);
    const double h = length / (segments + 0.5);
    EXPECT_NEAR(r.curve.front().x(), 0.5 * h, 1e-12);
    EXPECT_NEAR(r.curve.front().y(), 0.0, 1e-12);
    EXPECT_NEAR(-r.curve.back().y() / r.curve.back().x(), r.height_over_width, 1e-12);
    for (std::size_t i = 1; i < r.curve.size(); ++i) EXPECT_LT(r.curve[i].y(), r.curve[i - 1].y());
  }
}

// A long narrow strip curls across (the lattice's Poisson ratio is -1/3) and is softer than the elastica: 8/9 alpha
// in the limit, so up to +12.5 % in H/W at small Gamma (less here: the clamp holds the first strip width flat).
// Measured at L = 0.1 m, width 0.02 m, 20 segments, Gamma = 1: H/W +4.6 %, regression alpha -5.2 %; the same strip
// 0.2 m wide: +0.68 %, +0.64 %. This pins the known behaviour of the model: if the bending model changes (e.g.
// becomes a plate of Poisson ratio 0), revisit cantilever.hpp.
TEST(Cantilever, NarrowStripIsSofterThanTheElastica) {
  const double length = 0.1, gamma = 1.0, alpha = alpha_for(gamma, length);
  const CantileverResult narrow = simulate(strip(length, 0.02, 20, alpha));
  const CantileverResult wide = simulate(strip(length, 0.2, 20, alpha));
  const double narrow_error = narrow.height_over_width / master(gamma) - 1.0;
  const double wide_error = wide.height_over_width / master(gamma) - 1.0;
  EXPECT_GT(narrow_error, 0.03);
  EXPECT_LT(narrow_error, 0.13);
  EXPECT_LT(std::abs(wide_error), 0.015);
  EXPECT_LT(fit(narrow, false).alpha, 0.97 * alpha);
  EXPECT_NEAR(fit(wide, false).alpha, alpha, 0.03 * alpha);
}

// The per-triangle curvature model is a plate with Poisson ratio 0: a narrow strip does not curl across, and it
// follows the elastica like a wide one (hinge model: +8 % above). Measured (sweep, 30 segments, width L / 5): +0.2 % to
// +1.1 % for Gamma <= 147.
TEST(Cantilever, TriangleModelNarrowStripFollowsTheElastica) {
  const double length = 0.1, gamma = 1.0, alpha = alpha_for(gamma, length);
  CantileverSpec spec = strip(length, 0.02, 20, alpha);
  spec.bending_model = BendingModel::kNonlinearTriangle;
  const CantileverResult narrow = simulate(spec);
  EXPECT_LT(std::abs(narrow.height_over_width / master(gamma) - 1.0), 0.02);
}

// Section 4.3.1, beta = 0: the regression of the simulated centre line recovers alpha. L = 0.04 m, alpha = 1e-5
// (Gamma = 18.8), width 2 L, 20 segments. Measured +3.0 % (with beta fitted too: alpha +2.3 %, beta 8e-10);
// asserted within 5 %. The regression is a rod model and the strip is a plate, so the width biases it both ways:
// a wide strip does not bend uniformly across at large deflection and its centre line looks stiffer (+2.4 % with 40
// segments, about +3 % for Gamma >= 20 with 80 segments in the sweep); a narrow one curls across and is softer (width
// L / 5: -4.5 % with 40 segments).
TEST(Cantilever, RegressionRecoversAlpha) {
  const double length = 0.04, alpha = 1e-5;
  const CantileverResult r = simulate(strip(length, 2.0 * length, 20, alpha));
  const BendingFit linear = fit(r, false);
  EXPECT_NEAR(linear.alpha, alpha, 0.05 * alpha);
  EXPECT_LT(linear.rms_relative_residual, 0.02);
  // Fitting beta as well finds little of it: at the clamp curvature (140 / m) its torque is 1.1 % of alpha's.
  const BendingFit quadratic = fit(r, true);
  EXPECT_NEAR(quadratic.alpha, alpha, 0.05 * alpha);
  EXPECT_LT(std::abs(quadratic.beta) * 140.0, 0.05 * alpha);
}

// Section 4.3.1 with a softening law: alpha = 1e-5 N*m, beta = -2e-8 N*m^2 (peak torque alpha^2 / (4 |beta|) =
// 1.25e-3 N at kappa* = 250 / m), L = 0.04 m: the clamp curvature reaches ~0.9 kappa*, where the quadratic term
// takes ~45 % off the linear torque, so beta is well identified (the elastica solver confirms an equilibrium
// exists). Width 2 L, 30 segments. Measured: H/W +0.05 % from the elastica, alpha +2.1 %, beta -0.4 %, residual
// 0.0066 against 0.093 for the linear law (24 segments: alpha +1.6 %, beta -4.1 %; a strip 0.01 m wide, free to
// curve across where it bends least: alpha -9 %, beta -33 %). Asserted: H/W within 1.5 %, alpha and beta within 5 %.
TEST(Cantilever, RegressionRecoversSofteningAlphaAndBeta) {
  const double length = 0.04, alpha = 1e-5, beta = -2e-8;
  const Expected<CantileverCurve> reference = solve_heavy_cantilever(length, alpha, beta, kDensity, kGravity);
  ASSERT_TRUE(reference.has_value()) << reference.error().message;
  const CantileverResult r = simulate(strip(length, 2.0 * length, 30, alpha, beta));
  EXPECT_NEAR(r.height_over_width / reference->height_over_width, 1.0, 0.015);
  const BendingFit quadratic = fit(r, true);
  EXPECT_NEAR(quadratic.alpha, alpha, 0.05 * alpha);
  EXPECT_NEAR(quadratic.beta, beta, 0.05 * std::abs(beta));
  // The linear law cannot explain the curve: a much larger residual and a biased alpha.
  const BendingFit linear = fit(r, false);
  EXPECT_GT(linear.rms_relative_residual, 4.0 * quadratic.rms_relative_residual);
  EXPECT_LT(linear.alpha, 0.9 * alpha);
}

// Fig. 13 / Eq. 8: strips cut at phi from the warp, curvature-based anisotropy rule, beta = 0. The bias modulus is
// deliberately not the mean of warp and weft (1.4e-5 vs 2e-5 N*m): then Eq. 8 differs from Eq. 7 (cos^2 warp +
// sin^2 weft) by up to 30 % and from linear interpolation in phi by 5 - 14 %, and the test can tell them apart.
// L = 0.05 m (Gamma 12 - 37), 16 segments. Each cut strip is compared with an isotropic strip of modulus Eq. 8(phi),
// which must bend the same way; that also takes out the regression's bias (+3 % ... +5.5 % here, see above). The
// strips are 2 L wide so that they stay flat across: a narrower one curls across by an amount that depends on the
// modulus across the strip as well, which differs between the cut strip and the isotropic one (width L / 2: up to
// 2 % in H/W at phi = 90, and how much depended on the solver's handling of the lagged bending directions).
// Measured: regression alpha / Eq. 8 in [+2.6 %, +5.5 %]; against the isotropic strip alpha within [-0.39 %, +0.20 %]
// and H/W within [-0.23 %, +0.43 %]. Asserted: 7 %, 1 % and 1 %, and the bias-corrected alpha closer to Eq. 8 than to
// Eq. 7 or to linear interpolation. Convergence is expected too: with the curvature rule the bending directions lag
// the shape, and Newton has been seen to stall on narrower strips (residual 0.1 - 0.3 after 400 iterations at one
// angle or another, depending on the solver version and with either clamp layout), which is a solver problem.
TEST(Cantilever, CutStripsFollowEq8) {
  const DirectionalValues alpha{1e-5, 1.4e-5, 3e-5};
  const double length = 0.05;
  const auto linear_in_phi = [&](double phi) {
    const double t = phi / (std::numbers::pi / 4);
    return t <= 1.0 ? alpha.warp + t * (alpha.bias - alpha.warp) : alpha.bias + (t - 1.0) * (alpha.weft - alpha.bias);
  };
  for (int degrees = 0; degrees <= 90; degrees += 15) {
    SCOPED_TRACE(testing::Message() << "phi = " << degrees << " degrees");
    const double phi = degrees * std::numbers::pi / 180.0;
    const double expected = interpolate_directional(alpha, phi);
    CantileverSpec cut = strip(length, 2.0 * length, 16, expected);
    cut.fabric.alpha = alpha;
    cut.cut_angle = phi;
    cut.anisotropy = AnisotropyRule::kCurvature;
    const CantileverResult r = simulate(cut);
    const CantileverResult isotropic = simulate(strip(length, 2.0 * length, 16, expected));
    EXPECT_NEAR(r.gamma, isotropic.gamma, 1e-9 * r.gamma);
    const double fitted = fit(r, false).alpha;
    const double isotropic_fit = fit(isotropic, false).alpha;
    EXPECT_NEAR(fitted / expected, 1.0, 0.07);
    EXPECT_NEAR(fitted / isotropic_fit, 1.0, 0.01);
    EXPECT_NEAR(r.height_over_width / isotropic.height_over_width, 1.0, 0.01);
    if (degrees % 45 != 0) {  // the three sample directions are exact in every rule
      const double corrected = fitted * expected / isotropic_fit;
      const double c = std::pow(std::cos(phi), 2);
      const double eq7 = c * alpha.warp + (1.0 - c) * alpha.weft;
      EXPECT_LT(std::abs(corrected - expected), std::abs(corrected - eq7));
      EXPECT_LT(std::abs(corrected - expected), std::abs(corrected - linear_in_phi(phi)));
    }
  }
}

// Other triangulations and jitter run through the same clamp and centre-line code.
TEST(Cantilever, RunsOnEveryTriangulation) {
  const double length = 0.05, gamma = 1.0;
  for (const Triangulation t : {Triangulation::kEquilateral, Triangulation::kAlternating, Triangulation::kRandom}) {
    SCOPED_TRACE(testing::Message() << "triangulation " << static_cast<int>(t));
    CantileverSpec spec = strip(length, length, 10, alpha_for(gamma, length));
    spec.triangulation = t;
    spec.jitter = 0.2;
    spec.seed = 7;
    const CantileverResult r = simulate(spec);
    ASSERT_EQ(static_cast<int>(r.curve.size()), 11);
    // Jitter moves the second clamped row, so the first centre-line point may lie in a triangle with a free vertex.
    EXPECT_LT(std::abs(r.curve.front().y()), 0.05 * std::abs(r.curve.back().y()));
    // Measured -3.7 % (equilateral), +5.5 % (alternating), +2.1 % (random) at 10 segments, jitter 0.2, seed 7; the
    // right-triangle grids are softer on narrow strips (the dihedral angle couples with twist on skewed stencils),
    // so only a loose bound here.
    EXPECT_NEAR(r.height_over_width / master(gamma), 1.0, 0.1) << static_cast<int>(t);
  }
}

TEST(Cantilever, RejectsBadInput) {
  const CantileverSpec good = strip(0.05, 0.02, 10, 1e-5);
  ASSERT_TRUE(simulate_cantilever(good).has_value());
  const auto fails = [](const CantileverSpec& spec) { return !simulate_cantilever(spec).has_value(); };
  CantileverSpec s = good;
  s.length = -0.05;
  EXPECT_TRUE(fails(s));
  s = good;
  s.length = 0.0;
  EXPECT_TRUE(fails(s));
  s = good;
  s.length = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(fails(s));
  s = good;
  s.width = 0.0;
  EXPECT_TRUE(fails(s));
  s = good;
  s.gravity = 0.0;  // no weight: nothing to solve (it ended "diverged")
  EXPECT_TRUE(fails(s));
  s = good;
  s.fabric.alpha = {0.0, 0.0, 0.0};
  EXPECT_TRUE(fails(s));
  s = good;
  s.fabric.alpha.bias = 0.0;  // anisotropic with one zero sample
  EXPECT_TRUE(fails(s));
  s = good;
  s.fabric.density = 0.0;
  EXPECT_TRUE(fails(s));
  s = good;
  s.fabric.beta.warp = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(fails(s));
  s = good;
  s.segments = 1;
  EXPECT_TRUE(fails(s));
  s = good;
  s.segments = 0;
  EXPECT_TRUE(fails(s));
  s = good;
  s.gravity = -9.81;
  EXPECT_TRUE(fails(s));
  s = good;
  s.jitter = 0.5;  // beyond what keeps the rest triangles valid
  EXPECT_TRUE(fails(s));
  s = good;
  s.cut_angle = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(fails(s));
}

}  // namespace
}  // namespace drapegen::sim
