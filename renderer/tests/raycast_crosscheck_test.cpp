// Acceptance 2: each renderer's depth (OSMesa and the software rasteriser) agrees with an independent CPU ray cast of
// the same mesh and camera on a real drape from sim/ (>= 99% of foreground pixels within 0.5 mm, noise off). The
// 100x100 drape is checked by drapegen_render_bench --crosscheck (docs/BENCHMARKS.md).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "drapegen/renderer/depth_renderer.hpp"
#include "drapegen/renderer/ray_caster.hpp"
#include "drapegen/renderer/rig.hpp"
#include "drapegen/renderer/software_renderer.hpp"
#include "drapegen/sim/drape.hpp"
#include "shared_renderer.hpp"

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

/// How two depth images of the same views agree.
struct Agreement {
  long foreground = 0;           // pixels with a return in either
  long agree = 0;                // ... in both, within 0.5 mm
  long one_only = 0;             // ... in one only
  double worst_in_agreement = 0.0;
  void add(const DepthImage& a, const DepthImage& b) {
    for (std::size_t i = 0; i < a.depth.size(); ++i) {
      const float x = a.depth[i], y = b.depth[i];
      if (x == 0.0f && y == 0.0f) continue;
      ++foreground;
      const double diff = std::abs(static_cast<double>(x) - y);
      if (x > 0.0f && y > 0.0f && diff <= 5e-4) {
        ++agree;
        worst_in_agreement = std::max(worst_in_agreement, diff);
      }
      if ((x == 0.0f) != (y == 0.0f)) ++one_only;
    }
  }
  [[nodiscard]] double fraction() const { return static_cast<double>(agree) / static_cast<double>(foreground); }
};

class RealDrape : public ::testing::TestWithParam<const char*> {};

TEST_P(RealDrape, AgreesWithTheRayCast) {
  Renderer& renderer = shared_renderer(GetParam());
  const RigSpec rig;
  const TriangleMesh scene = tester_scene(real_drape(), rig);
  ASSERT_TRUE(renderer.set_scene(scene));
  const RayCaster caster(scene);
  // Two data points with perturbed cameras and affine image transforms: 8 views.
  Agreement agreement;
  for (const auto& setup : plan_data_points(rig, AugmentationSpec{.orientations = 2}, 11)) {
    for (const auto& view : setup.views) {
      auto image = renderer.render(view.camera, view.model);
      ASSERT_TRUE(image);
      agreement.add(*image, caster.render(view.camera, view.model));
    }
  }
  std::printf("%s cross-check: %ld foreground pixels, %.4f%% within 0.5 mm (worst of those %.2g m), %ld hit in one "
              "only\n",
              GetParam(), agreement.foreground, 100.0 * agreement.fraction(), agreement.worst_in_agreement,
              agreement.one_only);
  EXPECT_GT(agreement.foreground, 8 * 3000);
  EXPECT_GE(agreement.fraction(), 0.99);
}

INSTANTIATE_TEST_SUITE_P(Renderers, RealDrape, ::testing::ValuesIn(kRendererKinds));

/// Views of the tester scene that exercise clipping: half the drape beyond the right edge of the image, and the
/// camera 30 mm above the cloth on the platform looking down (the near plane, 50 mm, cuts the cloth).
std::vector<std::pair<Camera, Eigen::Isometry3d>> clipping_views(const RigSpec& rig) {
  Camera shifted = rig.camera();
  shifted.intrinsics.K(0, 2) += 120.0;
  return {{shifted, Eigen::Isometry3d::Identity()},
          {Camera::look_at(rig.intrinsics(), {0.0, 0.0, 0.03}, {0.0, 0.0, -0.1}, {0, 1, 0}),
           Eigen::Isometry3d::Identity()}};
}

// Near-plane clipping and partly visible geometry: the software rasteriser draws what OpenGL draws (the ray cast
// knows no near plane), with the same incidence cosine.
TEST(SoftwareRenderer, AgreesWithOsmesaWhereClipped) {
  const RigSpec rig;
  const TriangleMesh scene = tester_scene(real_drape(), rig);
  DepthRenderer& gl = shared_renderer();
  SoftwareRenderer software;
  ASSERT_TRUE(gl.set_scene(scene));
  ASSERT_TRUE(software.set_scene(scene));
  Agreement agreement;
  double worst_incidence = 0.0;
  for (const auto& [camera, model] : clipping_views(rig)) {
    auto a = gl.render(camera, model);
    auto b = software.render(camera, model);
    ASSERT_TRUE(a && b);
    agreement.add(*a, *b);
    for (std::size_t i = 0; i < a->depth.size(); ++i) {
      if (a->depth[i] > 0.0f && b->depth[i] > 0.0f && std::abs(a->depth[i] - b->depth[i]) <= 5e-4f) {
        worst_incidence = std::max(worst_incidence, static_cast<double>(std::abs(a->incidence[i] - b->incidence[i])));
      }
    }
  }
  std::printf("software vs OSMesa where clipped: %ld foreground pixels, %.4f%% within 0.5 mm, %ld hit in one only; "
              "largest incidence difference %.2g\n",
              agreement.foreground, 100.0 * agreement.fraction(), agreement.one_only, worst_incidence);
  EXPECT_GT(agreement.foreground, 2 * 3000);
  EXPECT_GE(agreement.fraction(), 0.99);
  EXPECT_LT(worst_incidence, 1e-2);
}

// The software rasteriser skips the platform's back faces (TriangleMesh::closed_from): the images are those of the
// whole scene but for pixel centres exactly on the platform's silhouette edges (the back face's under the top-left
// rule).
TEST(SoftwareRenderer, SkippingThePlatformsBackFacesChangesAlmostNothing) {
  const RigSpec rig;
  const TriangleMesh scene = tester_scene(real_drape(), rig);
  ASSERT_EQ(scene.closed_from, real_drape().triangle_count());
  TriangleMesh all_open = scene;
  all_open.closed_from = -1;
  SoftwareRenderer culling, drawing_all;
  ASSERT_TRUE(culling.set_scene(scene));
  ASSERT_TRUE(drawing_all.set_scene(all_open));
  long foreground = 0, differing = 0;
  for (const auto& setup : plan_data_points(rig, AugmentationSpec{.orientations = 3}, 7)) {
    for (const auto& view : setup.views) {
      auto a = culling.render(view.camera, view.model);
      auto b = drawing_all.render(view.camera, view.model);
      ASSERT_TRUE(a && b);
      foreground += b->foreground_count();
      for (std::size_t i = 0; i < a->depth.size(); ++i) {
        differing += a->depth[i] != b->depth[i] || a->incidence[i] != b->incidence[i];
      }
    }
  }
  std::printf("platform back faces skipped: %ld of %ld foreground pixels differ\n", differing, foreground);
  EXPECT_GT(foreground, 12 * 3000);
  EXPECT_LE(differing, 12);  // at most about one silhouette pixel per view
}

// RendererOptions::skip_empty_triangles leaves out triangles that cover no pixel centre: the images must be the same
// bit for bit as drawing every triangle, also when the drape is partly outside the image or reaches the near plane.
TEST(DepthRenderer, SkippingEmptyTrianglesChangesNoPixel) {
  auto all = DepthRenderer::create(RendererOptions{.range = {}, .skip_empty_triangles = false});
  auto skipping = DepthRenderer::create(RendererOptions{.range = {}, .skip_empty_triangles = true});
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
  for (const auto& [camera, model] : clipping_views(rig)) views.push_back({camera, model});
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
