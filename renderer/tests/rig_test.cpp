// The rig and the seeded augmentation: stratified orientations, reproducible perturbations, the drape in view.
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "drapegen/renderer/data_point.hpp"
#include "drapegen/renderer/rig.hpp"
#include "drapegen/sim/specimen.hpp"

namespace drapegen::renderer {
namespace {

TEST(Rig, OrientationsAreStratifiedAndSeeded) {
  const RigSpec rig;
  const auto a = plan_data_points(rig, AugmentationSpec{}, 5);
  const auto b = plan_data_points(rig, AugmentationSpec{}, 5);
  const auto c = plan_data_points(rig, AugmentationSpec{}, 6);
  ASSERT_EQ(a.size(), 12u);
  for (int k = 0; k < 12; ++k) {
    EXPECT_GE(a[k].orientation, k * M_PI / 6);
    EXPECT_LT(a[k].orientation, (k + 1) * M_PI / 6);
    EXPECT_EQ(a[k].orientation, b[k].orientation);
    EXPECT_NE(a[k].orientation, c[k].orientation);
    ASSERT_EQ(a[k].views.size(), 4u);
    for (int v = 0; v < 4; ++v) {
      EXPECT_TRUE(a[k].views[v].camera.intrinsics.K.isApprox(b[k].views[v].camera.intrinsics.K, 0.0));
      EXPECT_NEAR(a[k].views[v].table_angle, a[k].orientation + v * M_PI / 2, 1e-12);
      EXPECT_NE(a[k].noise_seed(v), c[k].noise_seed(v));
    }
  }
}

TEST(Rig, PerturbationsHaveTheStatedSpread) {
  const RigSpec rig;
  const AugmentationSpec aug;
  const auto points = plan_data_points(rig, aug, 1);
  std::vector<DataPointSetup> many;
  for (int s = 0; s < 200; ++s) {
    auto p = plan_data_points(rig, aug, s);
    many.insert(many.end(), p.begin(), p.end());
  }
  const Eigen::Vector3d nominal = rig.camera().position();
  double sum_sq = 0.0, focal_sq = 0.0;
  for (const auto& p : many) {
    sum_sq += (p.views[0].camera.position() - nominal).squaredNorm() / 3.0;
    // View 0's focal length carries the data point's focal perturbation times the affine scale.
    const double f = p.views[0].camera.intrinsics.K.topLeftCorner<2, 2>().determinant();
    focal_sq += std::pow(std::sqrt(f) / rig.focal_px - 1.0, 2);
  }
  EXPECT_NEAR(std::sqrt(sum_sq / many.size()), aug.position_sigma, 0.1 * aug.position_sigma);
  const double expected_focal = std::hypot(aug.focal_sigma, aug.scale_sigma);
  EXPECT_NEAR(std::sqrt(focal_sq / many.size()), expected_focal, 0.1 * expected_focal);
  // The four views of a data point share the camera pose (the table turns, the camera stays).
  for (const auto& p : points) {
    for (int v = 1; v < 4; ++v) {
      EXPECT_TRUE(p.views[v].camera.world_to_camera.isApprox(p.views[0].camera.world_to_camera));
    }
  }
}

TEST(Rig, NoPerturbationGivesTheNominalCamera) {
  const RigSpec rig;
  const auto points = plan_data_points(rig, AugmentationSpec::orientations_only(3), 2);
  for (const auto& p : points) {
    for (const auto& v : p.views) {
      EXPECT_TRUE(v.camera.intrinsics.K.isApprox(rig.intrinsics().K, 1e-12));
      EXPECT_TRUE(v.camera.world_to_camera.isApprox(rig.camera().world_to_camera, 1e-12));
    }
  }
}

TEST(Rig, FlatSpecimenFitsTheViewAndMillimetresDoNot) {
  // The largest footprint a drape can have: the flat 300 mm specimen (corners at 212 mm), at any orientation.
  sim::ClothMesh flat = sim::make_specimen(sim::SpecimenSpec{.size_x = 0.3, .size_y = 0.3, .vertices_x = 11,
                                                             .vertices_y = 11});
  auto cloth = cloth_triangles(flat);
  ASSERT_TRUE(cloth);
  const RigSpec rig;
  EXPECT_TRUE(check_in_view(*cloth, rig, plan_data_points(rig, AugmentationSpec{.orientations = 36}, 0)));
  // Hanging straight down to 200 mm below the top, at the widest.
  TriangleMesh skirt = *cloth;
  for (auto& p : skirt.vertices) p = Eigen::Vector3f(0.8f * p.x(), 0.8f * p.y(), -0.2f * (p.norm() / 0.2121f));
  EXPECT_TRUE(check_in_view(skirt, rig, plan_data_points(rig, AugmentationSpec{.orientations = 36}, 0)));
  // The same in millimetres is far out of view.
  TriangleMesh mm = *cloth;
  for (auto& p : mm.vertices) p *= 1000.0f;
  const sim::Status s = check_in_view(mm, rig, plan_data_points(rig, AugmentationSpec{}, 0));
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message.find("out of the camera's view"), std::string::npos);
  // Shrunk into the platform (before: in view, so rendered, the views holding the platform alone).
  TriangleMesh inside = *cloth;
  for (auto& p : inside.vertices) p = Eigen::Vector3f(0.1f * p.x(), 0.1f * p.y(), -0.05f);
  const sim::Status hidden = check_in_view(inside, rig, plan_data_points(rig, AugmentationSpec{}, 0));
  ASSERT_FALSE(hidden);
  EXPECT_NE(hidden.error().message.find("mesh lies inside the platform"), std::string::npos);
  // One vertex out of it, on the top: seen.
  inside.vertices.front() = Eigen::Vector3f(0.0f, 0.0f, 0.001f);
  EXPECT_TRUE(check_in_view(inside, rig, plan_data_points(rig, AugmentationSpec{}, 0)));
}

TEST(Rig, CylinderIsClosedAndOnThePlatform) {
  const TriangleMesh c = make_cylinder(CylinderSpec{});
  ASSERT_TRUE(validate(c));
  float top = -1.0f, bottom = 1.0f, r = 0.0f;
  for (const auto& p : c.vertices) {
    top = std::max(top, p.z());
    bottom = std::min(bottom, p.z());
    r = std::max(r, std::hypot(p.x(), p.y()));
  }
  EXPECT_FLOAT_EQ(top, 0.0f);
  EXPECT_FLOAT_EQ(bottom, -0.25f);
  EXPECT_NEAR(r, 0.05f, 1e-7);
  // Closed and wound counter-clockwise seen from outside (TriangleMesh::closed_from): every directed edge appears
  // once and its reverse once, and every normal points away from the axis or along it out of the caps.
  EXPECT_EQ(c.closed_from, 0);
  std::map<std::pair<int, int>, int> edges;
  for (const auto& t : c.triangles) {
    for (int k = 0; k < 3; ++k) ++edges[{t[k], t[(k + 1) % 3]}];
    const Eigen::Vector3f a = c.vertices[t[0]], b = c.vertices[t[1]], d = c.vertices[t[2]];
    const Eigen::Vector3f centroid = (a + b + d) / 3.0f;
    const Eigen::Vector3f outward(centroid.x(), centroid.y(), centroid.z() + 0.125f);  // from the cylinder's middle
    EXPECT_GT((b - a).cross(d - a).dot(outward), 0.0f);
  }
  for (const auto& [edge, count] : edges) {
    EXPECT_EQ(count, 1);
    EXPECT_EQ(edges.count({edge.second, edge.first}), 1u);
  }
  // In the tester's scene the platform's triangles stay marked closed after the cloth's.
  TriangleMesh cloth;
  cloth.vertices = {{0, 0, 0.01f}, {0.1f, 0, 0.01f}, {0, 0.1f, 0.01f}};
  cloth.triangles = {{0, 1, 2}};
  EXPECT_EQ(tester_scene(cloth, RigSpec{}).closed_from, 1);
}

}  // namespace
}  // namespace drapegen::renderer
