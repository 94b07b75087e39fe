// Acceptance 2: OSMesa's depth agrees with an independent CPU ray cast of the same mesh and camera on a real drape
// from sim/ (>= 99% of foreground pixels within 0.5 mm, noise off). The 100x100 drape is checked by
// drapegen_render_bench --crosscheck (docs/BENCHMARKS.md).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "drapegen/renderer/depth_renderer.hpp"
#include "drapegen/renderer/ray_caster.hpp"
#include "drapegen/renderer/rig.hpp"
#include "drapegen/sim/drape.hpp"

namespace drapegen::renderer {
namespace {

/// A 30x30 drape of the paper's median fabric (about a second to solve).
const TriangleMesh& real_drape() {
  static const TriangleMesh cloth = [] {
    sim::DrapeConfig c;
    c.fabric = sim::fabric_from_paper_units({13923, 11455, 8821}, {-35390, -29660, -22042}, 300.0);
    c.specimen.vertices_x = c.specimen.vertices_y = 30;
    c.specimen.seed = 1;
    c.initial.shape = sim::InitialShape::kSine;
    c.initial.seed = 1;
    auto result = sim::simulate_drape(c);
    if (!result) throw std::runtime_error(result.error().message);
    auto mesh = cloth_triangles(result->mesh);
    if (!mesh) throw std::runtime_error(mesh.error().message);
    return *mesh;
  }();
  return cloth;
}

TEST(RayCaster, MatchesAnalyticPlane) {
  TriangleMesh plane;
  plane.vertices = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  plane.triangles = {{0, 1, 2}, {0, 2, 3}};
  const RayCaster caster(plane);
  const Camera camera = Camera::look_at(RigSpec{}.intrinsics(), {0.0, -0.5, 0.6}, {0, 0, 0}, {0, 0, 1});
  const DepthImage image = caster.render(camera);
  const Eigen::Vector3d n = camera.world_to_camera.linear() * Eigen::Vector3d::UnitZ();
  const double h = (camera.world_to_camera * Eigen::Vector3d::Zero()).dot(n);
  for (int v = 0; v < 180; v += 7) {
    for (int u = 0; u < 240; u += 7) EXPECT_NEAR(image.at(u, v), h / n.dot(camera.ray(u, v)), 1e-7);  // stored as float
  }
}

TEST(RayCaster, AgreesWithOsmesaOnARealDrape) {
  auto renderer = DepthRenderer::create();
  ASSERT_TRUE(renderer) << renderer.error().message;
  const RigSpec rig;
  const TriangleMesh scene = tester_scene(real_drape(), rig);
  ASSERT_TRUE(renderer->set_scene(scene));
  const RayCaster caster(scene);
  // Two data points with perturbed cameras and affine image transforms: 8 views.
  const auto setups = plan_data_points(rig, AugmentationSpec{.orientations = 2}, 11);
  long foreground = 0, agree = 0, background_mismatch = 0;
  double worst_in_agreement = 0.0;
  for (const auto& setup : setups) {
    for (const auto& view : setup.views) {
      auto gl = renderer->render(view.camera, view.model);
      ASSERT_TRUE(gl);
      const DepthImage cpu = caster.render(view.camera, view.model);
      for (std::size_t i = 0; i < cpu.depth.size(); ++i) {
        const float a = gl->depth[i], b = cpu.depth[i];
        if (a == 0.0f && b == 0.0f) continue;
        ++foreground;
        const double diff = std::abs(static_cast<double>(a) - b);
        if (a > 0.0f && b > 0.0f && diff <= 5e-4) {
          ++agree;
          worst_in_agreement = std::max(worst_in_agreement, diff);
        }
        if ((a == 0.0f) != (b == 0.0f)) ++background_mismatch;
      }
    }
  }
  const double fraction = static_cast<double>(agree) / foreground;
  std::printf("cross-check: %ld foreground pixels, %.4f%% within 0.5 mm (worst of those %.2g m), %ld hit in one only\n",
              foreground, 100.0 * fraction, worst_in_agreement, background_mismatch);
  EXPECT_GT(foreground, 8 * 3000);
  EXPECT_GE(fraction, 0.99);
}

// RendererOptions::skip_empty_triangles leaves out triangles that cover no pixel centre: the images must be the same
// bit for bit as drawing every triangle, also when the drape is partly outside the image or reaches the near plane.
TEST(DepthRenderer, SkippingEmptyTrianglesChangesNoPixel) {
  auto all = DepthRenderer::create(RendererOptions{.skip_empty_triangles = false});
  auto skipping = DepthRenderer::create(RendererOptions{.skip_empty_triangles = true});
  ASSERT_TRUE(all && skipping);
  const RigSpec rig;
  const TriangleMesh scene = tester_scene(real_drape(), rig);
  ASSERT_TRUE(all->set_scene(scene));
  ASSERT_TRUE(skipping->set_scene(scene));
  struct View {
    Camera camera;
    Eigen::Isometry3d model;
  };
  std::vector<View> views;
  for (const auto& setup : plan_data_points(rig, AugmentationSpec{.orientations = 2}, 5)) {
    for (const auto& view : setup.views) views.push_back({view.camera, view.model});
  }
  Camera shifted = rig.camera();  // half the drape beyond the right edge of the image
  shifted.intrinsics.K(0, 2) += 120.0;
  views.push_back({shifted, Eigen::Isometry3d::Identity()});
  // The camera 30 mm above the cloth on the platform, looking down: the near plane (50 mm) cuts the cloth.
  views.push_back({Camera::look_at(rig.intrinsics(), {0.0, 0.0, 0.03}, {0.0, 0.0, -0.1}, {0, 1, 0}),
                   Eigen::Isometry3d::Identity()});
  int differing = 0, foreground = 0;
  for (const View& view : views) {
    auto a = all->render(view.camera, view.model);
    auto b = skipping->render(view.camera, view.model);
    ASSERT_TRUE(a && b);
    foreground += a->foreground_count();
    for (std::size_t i = 0; i < a->depth.size(); ++i) {
      differing += a->depth[i] != b->depth[i] || a->incidence[i] != b->incidence[i];
    }
  }
  EXPECT_GT(foreground, 8 * 3000);
  EXPECT_EQ(differing, 0);
}

}  // namespace
}  // namespace drapegen::renderer
