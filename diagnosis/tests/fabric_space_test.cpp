#include <gtest/gtest.h>

#include <cmath>
#include <utility>

#include "drapegen/diagnosis/fabric_space.hpp"

using namespace drapegen::diagnosis;

TEST(FabricSpace, RoundTrip) {
  BendingParameters p;
  p.alpha = {13923, 11455, 8821};
  p.beta = {-2.5 * 13923, -2.5 * 11455, -2.5 * 8821};
  const auto x = to_reduced(p);
  const auto q = from_reduced(x);
  EXPECT_NEAR(q.alpha.warp, p.alpha.warp, 1e-6);
  EXPECT_NEAR(q.alpha.bias, p.alpha.bias, 1e-6);
  EXPECT_NEAR(q.alpha.weft, p.alpha.weft, 1e-6);
  EXPECT_NEAR(q.beta.bias, p.beta.bias, 1e-6);
  EXPECT_NEAR(x[3], 2.5, 1e-12);
  EXPECT_NEAR(std::exp(x[0]), std::cbrt(13923.0 * 11455 * 8821), 1e-6);
}

TEST(FabricSpace, TheStiffnessRangeScalesWithDensity) {
  // The drape depends on alpha / density: every fabric of fabrics618 lies inside the box at its own density, the
  // lightest and softest (29 g/m^2, alpha 350) as well as the heaviest and stiffest (870 g/m^2, alpha 115000).
  for (const auto& [density, alpha] : {std::pair{28.9, 347.0}, std::pair{870.3, 115487.0}, std::pair{300.0, 1778.0}}) {
    EXPECT_LT(reduced_lower(density)[0], std::log(alpha)) << density;
    EXPECT_GT(reduced_upper(density)[0], std::log(alpha)) << density;
  }
  EXPECT_NEAR(reduced_lower(30.0)[0], reduced_lower(300.0)[0] + std::log(0.1), 1e-12);
  EXPECT_NEAR(reduced_upper(600.0)[0], reduced_upper(300.0)[0] + std::log(2.0), 1e-12);
  for (int k = 1; k < 4; ++k) {  // the shape coordinates do not depend on density
    EXPECT_EQ(reduced_lower(30.0)[k], reduced_lower(300.0)[k]);
    EXPECT_EQ(reduced_upper(30.0)[k], reduced_upper(300.0)[k]);
  }
}

TEST(FabricSpace, TheBoxOfAKnownBendingHoldsEveryBendingWithinItsFactor) {
  // Every corner of the six-parameter box (each parameter times F or 1/F) and its centre map inside reduced_box; the
  // box is tight: the corners reach each bound.
  const BendingParameters m{.alpha = {13923, 11455, 8821}, .beta = {-35390, -29660, -22042}};
  const double f = 1.3;
  const auto [lo, hi] = reduced_box(to_reduced(m), f);
  ReducedBending reached_lo = to_reduced(m), reached_hi = to_reduced(m);
  for (int corner = 0; corner < 64; ++corner) {
    auto scale = [&](int bit) { return (corner >> bit) & 1 ? f : 1.0 / f; };
    const BendingParameters p{
        .alpha = {m.alpha.warp * scale(0), m.alpha.bias * scale(1), m.alpha.weft * scale(2)},
        .beta = {m.beta.warp * scale(3), m.beta.bias * scale(4), m.beta.weft * scale(5)}};
    const ReducedBending x = to_reduced(p);
    for (int k = 0; k < 4; ++k) {
      EXPECT_GE(x[k], lo[k] - 1e-12) << "corner " << corner << ", coordinate " << k;
      EXPECT_LE(x[k], hi[k] + 1e-12) << "corner " << corner << ", coordinate " << k;
      reached_lo[k] = std::min(reached_lo[k], x[k]), reached_hi[k] = std::max(reached_hi[k], x[k]);
    }
  }
  for (int k = 0; k < 4; ++k) {
    EXPECT_NEAR(reached_lo[k], lo[k], 1e-9) << k;
    EXPECT_NEAR(reached_hi[k], hi[k], 1e-9) << k;
  }
  // No softening (x3 = 0): the ratio keeps some room instead of a box of width 0.
  const auto [lo0, hi0] = reduced_box({9.0, 0.0, 0.0, 0.0}, f);
  EXPECT_NEAR(lo0[3], -kMinRatioWidth, 1e-15);
  EXPECT_NEAR(hi0[3], kMinRatioWidth, 1e-15);
}

TEST(FabricSpace, AScaledBendingIsStifferInEveryDirectionWithTheSameShape) {
  const BendingParameters p{{13923.0, 11455.0, 8821.0}, {-35390.0, -29660.0, -22042.0}};
  const BendingParameters q = scaled(p, 2.5);
  EXPECT_DOUBLE_EQ(q.alpha.warp, 2.5 * 13923.0);
  EXPECT_DOUBLE_EQ(q.alpha.bias, 2.5 * 11455.0);
  EXPECT_DOUBLE_EQ(q.alpha.weft, 2.5 * 8821.0);
  EXPECT_DOUBLE_EQ(q.beta.warp, 2.5 * -35390.0);
  EXPECT_DOUBLE_EQ(q.beta.bias, 2.5 * -29660.0);
  EXPECT_DOUBLE_EQ(q.beta.weft, 2.5 * -22042.0);
  // In the fit's reduced coordinates only the mean stiffness moves, by ln 2.5.
  const ReducedBending a = to_reduced(p), b = to_reduced(q);
  EXPECT_NEAR(b[0] - a[0], std::log(2.5), 1e-12);
  for (int k = 1; k < 4; ++k) EXPECT_NEAR(b[k], a[k], 1e-12);
}
