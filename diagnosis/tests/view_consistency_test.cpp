#include "drapegen/diagnosis/view_consistency.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "drapegen/renderer/noise.hpp"
#include "drapegen/renderer/random.hpp"
#include "drapegen/renderer/rig.hpp"
#include "drapegen/renderer/sensor_error.hpp"
#include "drapegen/renderer/software_renderer.hpp"

namespace drapegen::diagnosis {
namespace {

/// A drape-like surface without simulation: a flat top on the cylinder and a skirt hanging at 60 degrees whose
/// radius swings with six folds (valleys and ridges, as the cameras see a draped specimen's).
renderer::TriangleMesh folded_skirt() {
  renderer::TriangleMesh mesh;
  constexpr int kRings = 40, kSectors = 180;
  constexpr double kTop = 0.05, kLength = 0.1;
  for (int i = 0; i <= kRings; ++i) {
    const double s = kLength * i / kRings;  // material distance from the rim
    for (int j = 0; j < kSectors; ++j) {
      const double theta = 2.0 * std::numbers::pi * j / kSectors;
      const double rho = kTop + s * (0.45 + 0.2 * std::cos(6.0 * theta));
      const double z = -s * 0.85;
      mesh.vertices.emplace_back(float(rho * std::cos(theta)), float(rho * std::sin(theta)), float(z));
    }
  }
  mesh.vertices.emplace_back(0.0f, 0.0f, 0.0f);  // the top's centre
  const int centre = mesh.vertex_count() - 1;
  for (int j = 0; j < kSectors; ++j) {
    const int k = (j + 1) % kSectors;
    mesh.triangles.push_back({centre, j, k});
    for (int i = 0; i < kRings; ++i) {
      const int p = i * kSectors + j, q = i * kSectors + k, r = (i + 1) * kSectors + j, t = (i + 1) * kSectors + k;
      mesh.triangles.push_back({p, r, q});
      mesh.triangles.push_back({q, r, t});
    }
  }
  return mesh;
}

/// The rig's four views of the surface, as a capture records them (the table's turn folded into each camera), with
/// `sensor` applied to the clean depth and the Kinect noise model (seed) where `noisy`.
struct Views {
  std::vector<renderer::DepthImage> depth;
  std::vector<renderer::Camera> cameras;
};

Views render_views(const renderer::SensorError& sensor, bool noisy, std::uint64_t seed = 1) {
  const renderer::RigSpec rig;
  renderer::TriangleMesh scene = folded_skirt();
  scene.append(renderer::make_cylinder(rig.cylinder));
  renderer::SoftwareRenderer renderer;
  EXPECT_TRUE(renderer.set_scene(scene));
  Views out;
  const renderer::NoiseModel noise = renderer::NoiseModel::kinect();
  for (int v = 0; v < rig.views; ++v) {
    renderer::Camera camera = rig.camera();
    camera.world_to_camera = camera.world_to_camera * rig.table_pose(0.0, v);
    auto clean = renderer.render(camera);
    EXPECT_TRUE(clean);
    renderer::DepthImage d = sensor.apply(*clean, camera.intrinsics);
    if (noisy) d = noise.apply(d, renderer::mix_seed(seed, static_cast<std::uint64_t>(v)));
    out.depth.push_back(std::move(d));
    out.cameras.push_back(camera);
  }
  return out;
}

double gain_mm(double multipath_mm, bool noisy, std::uint64_t seed = 1) {
  renderer::SensorError sensor;
  sensor.multipath_gain = multipath_mm * 1e-3;
  const Views v = render_views(sensor, noisy, seed);
  const ViewConsistency c = view_consistency(v.depth, v.cameras);
  EXPECT_GT(c.pixels, 1000) << "the views should overlap on the top and the skirt";
  return c.gain * 1e3;
}

TEST(ViewConsistency, ConsistentCleanViewsImplyNoMultipath) {
  EXPECT_NEAR(gain_mm(0.0, false), 0.0, 1.0);
}

TEST(ViewConsistency, TheSlopeFollowsSmallGainsAndSaturatesAtTheGate) {
  // Clean views: proportional to the gain while the residuals stay within the gate (5 mm -> 3.4, 10 mm -> 7.0), then
  // growing ever less as the gate drops the largest (20 mm -> 12.0, 40 mm -> 13.0).
  const double g5 = gain_mm(5.0, false), g10 = gain_mm(10.0, false), g20 = gain_mm(20.0, false),
               g40 = gain_mm(40.0, false);
  EXPECT_GT(g5, 0.4 * 5.0);
  EXPECT_LT(g5, 5.0);
  EXPECT_NEAR(g10 / g5, 2.0, 0.3);
  EXPECT_GT(g20, 1.3 * g10);
  EXPECT_GT(g40, g20);
  EXPECT_LT(g40, 1.3 * g20);
}

TEST(ViewConsistency, NoisyViewsSeparateMultipathFromNone) {
  // With the Kinect noise model: below the multipath test's threshold without multipath, above it with 20 mm.
  const double threshold = 1e3 * ViewConsistencySettings{}.multipath_gain;
  for (std::uint64_t seed : {1u, 2u}) {
    EXPECT_LT(gain_mm(0.0, true, seed), threshold) << "seed " << seed;
    EXPECT_GT(gain_mm(20.0, true, seed), threshold) << "seed " << seed;
  }
}

TEST(MultipathTest, FiresOnlyWhereEveryPlacementReachesTheThreshold) {
  MultipathTest t;
  t.threshold = 0.006;
  EXPECT_FALSE(t.detected());
  EXPECT_EQ(t.smallest_gain(), 0.0);
  t.placements = {{.gain = 0.009}, {.gain = 0.007}, {.gain = 0.0065}};
  EXPECT_TRUE(t.detected());
  EXPECT_DOUBLE_EQ(t.smallest_gain(), 0.0065);
  t.placements[1].gain = 0.005;
  EXPECT_FALSE(t.detected());
  EXPECT_DOUBLE_EQ(t.smallest_gain(), 0.005);
}

}  // namespace
}  // namespace drapegen::diagnosis
