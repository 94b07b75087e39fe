#include <gtest/gtest.h>

#include <cmath>

#include "drapegen/diagnosis/fold_repeatability.hpp"
#include "drapegen/sim/initial_state.hpp"

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
  EXPECT_NEAR(fold_correlation(a, b), fold_correlation(b, a), 1e-9);  // the same turn, backwards
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

namespace {
/// A skirt's hem only: a ring of vertices 0.1 m below the top at the outline's radius (its edges sampled between).
drapegen::sim::ClothMesh hem_ring(std::vector<int> fold_orders, double phase) {
  const HemProfile p = outline(std::move(fold_orders), phase);
  constexpr int n = 720;
  drapegen::sim::ClothMesh m;
  m.rest.setZero(2, n);
  m.positions.resize(3, n);
  m.triangles.resize(3, n);
  for (int k = 0; k < n; ++k) {
    const double t = 2 * M_PI * k / n;
    const double r = p.radius[static_cast<int>(k * kHemBins / n)];
    m.positions.col(k) << r * std::cos(t), r * std::sin(t), -0.1;
    m.triangles.col(k) << k, (k + 1) % n, (k + 2) % n;
  }
  return m;
}
}  // namespace

TEST(FoldRepeatability, DrapesCorrelateByTheirOutlines) {
  const std::vector<drapegen::sim::ClothMesh> drapes{hem_ring({7}, 0.0), hem_ring({7}, 0.7), hem_ring({9}, 0.0)};
  const std::vector<double> c = drape_fold_correlations(drapes);
  ASSERT_EQ(c.size(), 3u);
  EXPECT_GT(c[0], 0.95);            // the same seven folds, turned
  EXPECT_LT(std::abs(c[1]), 0.1);   // seven against nine
  EXPECT_LT(std::abs(c[2]), 0.1);
  EXPECT_TRUE(drape_fold_correlations({drapes[0]}).empty());
}

TEST(FoldRepeatability, ATurnedOverSpecimensFoldsMatchInItsOwnFrame) {
  // Six folds leaning one way (a sawtooth of three harmonics): no turn matches the pattern with its mirror image
  // (the best matches 0.63 of it), so only the specimen frame (the face-down outline mirrored back) finds a
  // turned-over specimen's folds where they were.
  auto folds = [](bool mirrored, double turn) {
    HemProfile p;
    p.radius.resize(kHemBins);
    for (int k = 0; k < kHemBins; ++k) {
      const double t = (mirrored ? -1.0 : 1.0) * ((k + 0.5) * 2 * M_PI / kHemBins - turn);
      p.radius[k] = 0.15 + 0.008 * (std::sin(6 * t) + std::sin(12 * t) / 2 + std::sin(18 * t) / 3);
    }
    return p;
  };
  const HemProfile up = folds(false, 0.0), down = folds(true, 1.3);
  EXPECT_LT(fold_correlation(up, down), 0.8);
  EXPECT_GT(fold_correlation(specimen_frame(up, false), specimen_frame(down, true)), 0.97);
  EXPECT_EQ(specimen_frame(down, false).radius, down.radius);
}

TEST(FoldRepeatability, SineDrapesOnly) {
  using drapegen::sim::InitialShape;
  Evaluation e;
  e.states.resize(4);
  for (int k = 0; k < 4; ++k) e.states[k].mesh = hem_ring({7 + k}, 0.0);
  std::vector<drapegen::sim::InitialStateSpec> states(4);
  states[0].shape = InitialShape::kFlat;
  states[1].shape = states[3].shape = InitialShape::kSine;
  states[2].shape = InitialShape::kFold;
  const auto sine = sine_drapes(e, states);
  ASSERT_EQ(sine.size(), 2u);
  EXPECT_EQ(sine[0].positions, e.states[1].mesh.positions);
  EXPECT_EQ(sine[1].positions, e.states[3].mesh.positions);
  states.resize(2);  // states beyond those given are not the evaluation's sine states
  EXPECT_EQ(sine_drapes(e, states).size(), 1u);
}

TEST(FoldRepeatability, FoldsLessAlikeWhenEveryCapturePairIsBelowTheModelsTenthPercentileByTheMargin) {
  FoldRepeatability f;
  f.model = {0.95, 0.2, 0.96, 0.97, 0.94, 0.93, 0.98, 0.99, 0.95, 0.96};  // 10th percentile: sorted[1] = 0.93
  f.capture = {0.5, 0.82, 0.6};
  EXPECT_TRUE(folds_less_alike(f));
  f.capture = {0.5, 0.84, 0.6};  // one pair within the margin
  EXPECT_FALSE(folds_less_alike(f));
  f.capture.clear();  // not measured
  EXPECT_FALSE(folds_less_alike(f));
}
