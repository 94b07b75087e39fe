#include <gtest/gtest.h>

#include <cmath>

#include "drapegen/diagnosis/fold_repeatability.hpp"

using namespace drapegen::diagnosis;

namespace {
/// An outline sampled directly: base radius, an ellipse and corners (orders 2 and 4, turned by `low_phase`) and
/// folds of the given orders (turned by `phase`).
HemProfile outline(std::vector<int> fold_orders, double phase, double low_phase = 0.0, double centre_x = 0.0) {
  HemProfile p;
  p.radius.resize(kHemBins);
  for (int k = 0; k < kHemBins; ++k) {
    const double t = (k + 0.5) * 2 * M_PI / kHemBins;
    double r = 0.15 + centre_x * std::cos(t) + 0.01 * std::cos(2 * (t - low_phase)) +
               0.005 * std::cos(4 * (t - low_phase));
    for (int n : fold_orders) r += 0.008 * std::cos(n * (t - phase));
    p.radius[k] = r;
  }
  return p;
}
}  // namespace

TEST(FoldRepeatability, FoldContentDropsTheLowOrders) {
  const HemProfile f = fold_content(outline({}, 0.0, 0.3, 0.004));
  for (double r : f.radius) EXPECT_NEAR(r, 0.0, 1e-12);
  const HemProfile g = fold_content(outline({7}, 0.0, 0.3, 0.004));
  for (int k = 0; k < kHemBins; ++k) {
    const double t = (k + 0.5) * 2 * M_PI / kHemBins;
    EXPECT_NEAR(g.radius[k], 0.008 * std::cos(7 * t), 1e-12);
  }
}

TEST(FoldRepeatability, SameFoldsHoweverTurnedCorrelateFully) {
  const HemProfile a = outline({7, 9}, 0.0);
  // Turned by 41.3 degrees (between bins), with another ellipse and centre offset: the folds are the same.
  const HemProfile b = rotate(outline({7, 9}, 0.0, 1.1, 0.006), 41.3 * M_PI / 180.0);
  EXPECT_GT(fold_correlation(a, b), 0.97);
  EXPECT_NEAR(fold_correlation(a, a), 1.0, 1e-12);
  EXPECT_NEAR(fold_correlation(a, b), fold_correlation(b, a), 0.03);
}

TEST(FoldRepeatability, OtherFoldsDoNot) {
  // Seven folds against nine: orthogonal at every turn.
  EXPECT_LT(std::abs(fold_correlation(outline({7}, 0.0), outline({9}, 0.4))), 0.05);
  // Seven and nine against seven alone: the shared half (variance 1 of 2): 1/sqrt(2) at the right turn.
  EXPECT_NEAR(fold_correlation(outline({7, 9}, 0.0), outline({7}, 0.0)), 1.0 / std::sqrt(2.0), 0.02);
  // No folds at all: nothing to correlate.
  EXPECT_EQ(fold_correlation(outline({}, 0.0), outline({7}, 0.0)), 0.0);
}

TEST(FoldRepeatability, PairsInOrder) {
  const std::vector<HemProfile> p{outline({7}, 0.0), outline({7}, 0.5), outline({9}, 0.0)};
  const std::vector<double> c = pairwise_fold_correlations(p);
  ASSERT_EQ(c.size(), 3u);
  EXPECT_GT(c[0], 0.97);          // 0-1: the same folds turned
  EXPECT_LT(std::abs(c[1]), 0.05);  // 0-2
  EXPECT_LT(std::abs(c[2]), 0.05);  // 1-2
  const FoldRepeatability r = fold_repeatability(p, {});
  EXPECT_EQ(r.capture, c);
  EXPECT_TRUE(r.model.empty());
  EXPECT_EQ(r.model_drapes, 0);
  EXPECT_FALSE(r.measured());
}
