#include <gtest/gtest.h>

#include "drapegen/diagnosis/validation_spread.hpp"

using namespace drapegen::diagnosis;

namespace {

/// Features that have only the hem-height group (no outline: its groups are left out), all three entries at z, so
/// that the shape distance of two of them is |z_a - z_b| / 5 mm (the group's default scale).
ShapeFeatures hem_at(double z) {
  ShapeFeatures f;
  f.hem_height = {z, z, z};
  f.valid = true;
  return f;
}

ScoredDrape drape_at(double z) {
  ScoredDrape d;
  d.shape.all = hem_at(z);
  return d;
}

}  // namespace

TEST(ValidationSpread, PairwiseAndLeaveOneOutNearest) {
  // Three validation drapes with hem heights 0, 5 and 15 mm: shape distances 1 (0-1), 3 (0-2), 2 (1-2).
  const std::vector<ScoredDrape> states{drape_at(0.0), drape_at(0.005), drape_at(0.015)};
  const ValidationSpread s = validation_spread(states, hem_at(0.030));
  ASSERT_EQ(s.pairwise.size(), 3u);
  EXPECT_NEAR(s.pairwise[0][1], 1.0, 1e-9);
  EXPECT_NEAR(s.pairwise[1][0], 1.0, 1e-9);
  EXPECT_NEAR(s.pairwise[0][2], 3.0, 1e-9);
  EXPECT_NEAR(s.pairwise[1][2], 2.0, 1e-9);
  EXPECT_DOUBLE_EQ(s.pairwise[2][2], 0.0);
  ASSERT_EQ(s.nearest_other.size(), 3u);
  EXPECT_NEAR(s.nearest_other[0], 1.0, 1e-9);
  EXPECT_NEAR(s.nearest_other[1], 1.0, 1e-9);
  EXPECT_NEAR(s.nearest_other[2], 2.0, 1e-9);
  // The capture at 30 mm: 6, 5 and 3 from the drapes; its hem-height difference to the last is 15 mm.
  ASSERT_EQ(s.capture_distance.size(), 3u);
  EXPECT_NEAR(s.capture_distance[0], 6.0, 1e-9);
  EXPECT_NEAR(s.capture_distance[1], 5.0, 1e-9);
  EXPECT_NEAR(s.capture_distance[2], 3.0, 1e-9);
  EXPECT_NEAR(s.capture_groups[2][static_cast<int>(FeatureGroup::kHemHeight)], 0.015, 1e-12);
  EXPECT_DOUBLE_EQ(s.capture_groups[2][static_cast<int>(FeatureGroup::kHarmonics)], -1.0);
  EXPECT_NEAR(s.pairwise_groups[0][2][static_cast<int>(FeatureGroup::kHemHeight)], 0.015, 1e-12);
}

TEST(ValidationSpread, OneStateHasNoNearestOther) {
  const ValidationSpread s = validation_spread({drape_at(0.0)}, hem_at(0.01));
  EXPECT_TRUE(s.nearest_other.empty());
  ASSERT_EQ(s.capture_distance.size(), 1u);
  EXPECT_NEAR(s.capture_distance[0], 2.0, 1e-9);
}
