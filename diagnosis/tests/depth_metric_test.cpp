#include <gtest/gtest.h>

#include <cmath>

#include "drapegen/diagnosis/depth_metric.hpp"

using namespace drapegen;
using namespace drapegen::diagnosis;

namespace {
renderer::Intrinsics intr() { return renderer::Intrinsics::pinhole(120, 90, 126, 126, 59.5, 44.5); }
/// A corrugated surface (folds along u) at 0.7 m.
renderer::DepthImage folds(double offset, int x0 = 20, int x1 = 100) {
  renderer::DepthImage d(120, 90);
  for (int v = 10; v < 80; ++v)
    for (int u = x0; u < x1; ++u) d.at(u, v) = static_cast<float>(0.7 + offset + 0.01 * std::sin(u * 0.4));
  return d;
}
}  // namespace

TEST(DepthMetric, IdenticalIsZero) {
  const auto f = view_features(folds(0.0), intr());
  const auto c = compare_view(f, folds(0.0));
  EXPECT_NEAR(c.score, 0.0, 1e-5);  // float normals: acos near 1 leaves ~0.01 deg
  EXPECT_GT(c.overlap, 5000);
}

TEST(DepthMetric, OffsetSilhouetteAndFolds) {
  const auto f = view_features(folds(0.0), intr());
  int mask = 0;
  for (auto m : f.fold_mask) mask += m;
  EXPECT_GT(mask, 100);  // the corrugation is detected as folds
  const auto shifted = compare_view(f, folds(0.005));
  EXPECT_NEAR(shifted.depth_rms, 0.005, 1e-4);
  EXPECT_NEAR(shifted.silhouette, 0.0, 1e-12);
  EXPECT_LT(shifted.fold_rms_deg, 1.0);  // a pure offset keeps the normals
  const auto narrower = compare_view(f, folds(0.0, 20, 80));
  EXPECT_NEAR(narrower.silhouette, 20.0 / 80.0, 1e-9);
  // Far off: truncated.
  const auto far = compare_view(f, folds(0.5));
  EXPECT_NEAR(far.depth_rms, MetricWeights{}.truncation, 1e-6);
  // Folds out of phase cost in the fold term.
  renderer::DepthImage flat(120, 90);
  for (int v = 10; v < 80; ++v)
    for (int u = 20; u < 100; ++u) flat.at(u, v) = 0.7f;
  EXPECT_GT(compare_view(f, flat).fold_rms_deg, 10.0);
}

// With the pose, the stable term is over the pixels where both see the platform top or the bare cylinder. A model
// that sees none of them where the capture does (its camera stated wrong, or the drape elsewhere) disagrees as much
// as a pixel can: the stable term is the truncation, not 0 (it was 0, and such a view lowered the gap). A capture
// that sees none has no stable term in that view.
TEST(DepthMetric, AViewWhereNoRigidSurfaceIsSeenByBothCostsTheTruncation) {
  const auto camera = renderer::Camera::look_at(intr(), {0.0, 0.0, 0.7}, {0.0, 0.0, 0.0}, Eigen::Vector3d::UnitY());
  // Looking straight down from 0.7 m: the platform top (z = 0) at camera depth 0.7, a skirt 10 cm below it, 7 cm or
  // more from the axis.
  auto scene = [&](bool top_seen) {
    renderer::DepthImage d(120, 90);
    for (int v = 0; v < 90; ++v) {
      for (int u = 0; u < 120; ++u) {
        const Eigen::Vector3d top = 0.7 * camera.ray(u, v), skirt = 0.8 * camera.ray(u, v);
        if (std::hypot(top.x(), top.y()) < 0.04 && top_seen) d.at(u, v) = 0.7f;
        if (std::hypot(skirt.x(), skirt.y()) > 0.07) d.at(u, v) = 0.8f;  // clear of the cylinder's side
      }
    }
    return d;
  };
  const MetricWeights weights;
  const auto captured = view_features(scene(true), camera, weights);
  const auto same = compare_view(captured, scene(true), weights);
  EXPECT_GT(same.stable_pixels, 100);
  EXPECT_NEAR(same.stable_rms, 0.0, 1e-9);
  const auto missed = compare_view(captured, scene(false), weights);
  EXPECT_EQ(missed.stable_pixels, 0);
  EXPECT_DOUBLE_EQ(missed.stable_rms, weights.truncation);
  EXPECT_GT(missed.score, same.score + weights.stable * weights.truncation);
  EXPECT_GT(missed.captured_stable_pixels, 100);
  // A capture that sees no rigid surface in this view has no stable term there (ForwardModel leaves it out of the
  // mean): not the truncation, which would add the same constant to every score and floor.
  const auto bare = view_features(scene(false), camera, weights);
  const auto none = compare_view(bare, scene(true), weights);
  EXPECT_EQ(none.captured_stable_pixels, 0);
  EXPECT_DOUBLE_EQ(none.stable_rms, 0.0);
}
