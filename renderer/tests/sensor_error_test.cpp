#include <gtest/gtest.h>

#include <cmath>

#include "drapegen/renderer/rig.hpp"
#include "drapegen/renderer/sensor_error.hpp"

using namespace drapegen::renderer;

namespace {
Intrinsics intr() { return Intrinsics::pinhole(100, 60, 252, 252, 49.5, 29.5); }
}  // namespace

TEST(SensorError, ConcavityZeroOnPlanesPositiveInValleys) {
  DepthImage tilted(100, 60), valley(100, 60);
  for (int v = 0; v < 60; ++v)
    for (int u = 0; u < 100; ++u) {
      tilted.at(u, v) = static_cast<float>(0.7 + 0.001 * u);
      valley.at(u, v) = static_cast<float>(0.7 + 0.003 * (20 - std::abs(u - 50)));  // deepest at u = 50
    }
  const auto st = SensorError::concavity(tilted, intr(), 4);
  const auto sv = SensorError::concavity(valley, intr(), 4);
  EXPECT_NEAR(st[30 * 100 + 50], 0.0, 1e-4);
  EXPECT_GT(sv[30 * 100 + 50], 0.05);       // the valley floor
  EXPECT_NEAR(sv[30 * 100 + 40], 0.0, 1e-4);  // its flank is planar
  SensorError e;
  e.multipath_gain = 0.01;
  const DepthImage out = e.apply(valley, intr());
  EXPECT_NEAR(out.at(50, 30) - valley.at(50, 30), 0.01 * sv[30 * 100 + 50], 1e-6);
  EXPECT_NEAR(out.at(40, 30), valley.at(40, 30), 1e-6);
}

TEST(SensorError, BiasKeepsHolesAndPoseMovesTheCamera) {
  DepthImage d(100, 60);
  d.at(10, 10) = 0.8f;
  SensorError e;
  e.bias_offset = 0.004;
  e.bias_slope = 0.01;
  e.bias_reference = 0.7;
  const DepthImage out = e.apply(d, intr());
  EXPECT_NEAR(out.at(10, 10), 0.8 + 0.004 + 0.001, 1e-6);
  EXPECT_EQ(out.at(11, 10), 0.0f);
  EXPECT_TRUE(e.any());
  EXPECT_TRUE(e.changes_depth());

  const Camera recorded = RigSpec{}.camera();
  SensorError none;
  EXPECT_FALSE(none.any());
  EXPECT_FALSE(none.changes_depth());
  EXPECT_TRUE(none.true_camera(recorded).world_to_camera.isApprox(recorded.world_to_camera));
  SensorError pose;
  pose.translation = Eigen::Vector3d(0.01, 0, 0);
  EXPECT_TRUE(pose.any());
  EXPECT_FALSE(pose.changes_depth());  // a pose error moves the camera, not the depths
  const Camera moved = pose.true_camera(recorded);
  // A point seen at the image centre moves by f * 0.01 / z pixels along u.
  const Eigen::Vector3d target(0, 0, -0.08);
  const auto a = recorded.project(target), b = moved.project(target);
  ASSERT_TRUE(a && b);
  EXPECT_NEAR((*b)[0] - (*a)[0], 252.0 * 0.01 / (*a)[2], 1e-6);
}
