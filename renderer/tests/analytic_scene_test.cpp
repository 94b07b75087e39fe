// Acceptance 1: analytic scenes render to the exact depth (noise off); background pixels are exactly 0. Every test
// runs with each renderer (OSMesa and the software rasteriser).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>

#include "drapegen/renderer/ray_caster.hpp"
#include "shared_renderer.hpp"

namespace drapegen::renderer {
namespace {

class AnalyticScene : public ::testing::TestWithParam<const char*> {
 protected:
  Renderer& renderer = shared_renderer(GetParam());
};

Intrinsics test_intrinsics() { return Intrinsics::pinhole(240, 180, 252.0, 252.0, 119.5, 89.5); }

/// A square of half-size `h` in the plane z = 0 of its own frame, as two triangles.
TriangleMesh square(double h) {
  TriangleMesh m;
  const float s = static_cast<float>(h);
  m.vertices = {{-s, -s, 0}, {s, -s, 0}, {s, s, 0}, {-s, s, 0}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

/// An icosphere of radius r at c, subdivided `levels` times, vertices on the sphere.
TriangleMesh icosphere(const Eigen::Vector3d& c, double r, int levels) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                                    {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (auto& p : v) p.normalize();
  std::vector<std::array<int, 3>> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                       {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      if (auto it = mid.find(key); it != mid.end()) return it->second;
      v.push_back((v[a] + v[b]).normalized());
      return mid[key] = static_cast<int>(v.size()) - 1;
    };
    std::vector<std::array<int, 3>> g;
    for (const auto& tri : f) {
      const int a = midpoint(tri[0], tri[1]), b = midpoint(tri[1], tri[2]), cc = midpoint(tri[2], tri[0]);
      g.push_back({tri[0], a, cc});
      g.push_back({tri[1], b, a});
      g.push_back({tri[2], cc, b});
      g.push_back({a, b, cc});
    }
    f = std::move(g);
  }
  TriangleMesh m;
  for (const auto& p : v) m.vertices.push_back((c + r * p).cast<float>());
  m.triangles = f;
  return m;
}

TEST_P(AnalyticScene, FrontoParallelPlaneHasExactDepthAndZeroBackground) {
  ASSERT_TRUE(renderer.set_scene(square(0.2)));
  for (double d : {0.5, 0.8, 1.3, 2.7}) {
    Camera camera = Camera::look_at(test_intrinsics(), {0, 0, d}, {0, 0, 0}, {0, 1, 0});
    auto image = renderer.render(camera);
    ASSERT_TRUE(image) << image.error().message;
    int plane = 0, background = 0;
    double worst = 0.0;
    for (int v = 0; v < 180; ++v) {
      for (int u = 0; u < 240; ++u) {
        // Where the pixel ray meets z = 0, in the camera's x/y: (u - cx) d / f, with a margin of a pixel.
        const double x = (u - 119.5) * d / 252.0, y = (v - 89.5) * d / 252.0;
        const double margin = 1.5 * d / 252.0;
        const float z = image->at(u, v);
        if (std::abs(x) < 0.2 - margin && std::abs(y) < 0.2 - margin) {
          EXPECT_NEAR(z, d, 1e-4) << "pixel " << u << "," << v << " at distance " << d;
          worst = std::max(worst, std::abs(z - d));
          ++plane;
        } else if (std::abs(x) > 0.2 + margin || std::abs(y) > 0.2 + margin) {
          EXPECT_EQ(z, 0.0f) << "background pixel " << u << "," << v;
          ++background;
        }
      }
    }
    std::printf("%s: plane at %.1f m: %d pixels, worst depth error %.3g m; %d background pixels\n", GetParam(), d,
                plane, worst, background);
    EXPECT_GT(plane, 1000);
    if (d > 0.6) {
      EXPECT_GT(background, 1000);
    }
  }
}

TEST_P(AnalyticScene, TiltedPlaneDepthFollowsThePlaneEquation) {
  ASSERT_TRUE(renderer.set_scene(square(2.0)));
  // Plane z = 0 in the world, seen from 1 m at 50 degrees from its normal: depth along each pixel ray is
  // h / (n . ray) in camera coordinates.
  const double angle = 50.0 * M_PI / 180.0;
  const Eigen::Vector3d eye(0.0, -std::sin(angle), std::cos(angle));
  Camera camera = Camera::look_at(test_intrinsics(), eye, {0, 0, 0}, {0, 0, 1});
  auto image = renderer.render(camera);
  ASSERT_TRUE(image);
  const Eigen::Vector3d n_cam = camera.world_to_camera.linear() * Eigen::Vector3d::UnitZ();
  const double h = (camera.world_to_camera * Eigen::Vector3d::Zero()).dot(n_cam);  // plane: n . X = h
  double worst = 0.0;
  for (int v = 0; v < 180; ++v) {
    for (int u = 0; u < 240; ++u) {
      const double expected = h / n_cam.dot(camera.ray(u, v));
      worst = std::max(worst, std::abs(image->at(u, v) - expected));
      // Incidence: cos of the angle between the ray and the normal.
      const Eigen::Vector3d r = camera.ray(u, v).normalized();
      EXPECT_NEAR(image->incidence[v * 240 + u], std::abs(r.dot(n_cam)), 1e-3);
    }
  }
  std::printf("%s: tilted plane: worst depth error %.3g m\n", GetParam(), worst);
  EXPECT_LT(worst, 1e-4);
}

// A plane 200 km wide seen from 1 m: its corners project millions of pixels outside the image (beyond the software
// rasteriser's guard band, so its triangles are clipped first) and the plane must still fill the image exactly.
TEST_P(AnalyticScene, HugePlaneFillsTheImage) {
  ASSERT_TRUE(renderer.set_scene(square(1e5)));
  const Camera camera = Camera::look_at(test_intrinsics(), {0.1, 0.2, 1.0}, {0.1, 0.2, 0}, {0, 1, 0});
  auto image = renderer.render(camera);
  ASSERT_TRUE(image);
  double worst = 0.0;
  for (float z : image->depth) worst = std::max(worst, std::abs(z - 1.0));
  EXPECT_EQ(image->foreground_count(), 240 * 180);
  EXPECT_LT(worst, 1e-4);
}

TEST_P(AnalyticScene, SphereHasExactDepthAndZeroBackground) {
  const Eigen::Vector3d centre(0.02, -0.01, 0.0);
  const double radius = 0.12;
  // Level 6: 81920 facets, at most ~6 um inside the sphere (the depth error of a facet grows as 1 / cos(incidence)).
  ASSERT_TRUE(renderer.set_scene(icosphere(centre, radius, 6)));
  Camera camera = Camera::look_at(test_intrinsics(), {0.3, -0.6, 0.4}, {0, 0, 0}, {0, 0, 1});
  auto image = renderer.render(camera);
  ASSERT_TRUE(image);
  const Eigen::Vector3d c = camera.world_to_camera * centre;
  int inside = 0, outside = 0;
  double worst = 0.0;
  for (int v = 0; v < 180; ++v) {
    for (int u = 0; u < 240; ++u) {
      const Eigen::Vector3d d = camera.ray(u, v);  // z = 1: the ray parameter is the depth
      // |t d - c|^2 = r^2
      const double a = d.squaredNorm(), b = -2.0 * d.dot(c), cc = c.squaredNorm() - radius * radius;
      const double disc = b * b - 4 * a * cc;
      const double miss = (c - d * (d.dot(c) / a)).norm() - radius;  // ray's distance from the sphere
      const float z = image->at(u, v);
      if (disc > 0.0) {
        const double t = (-b - std::sqrt(disc)) / (2 * a);
        const Eigen::Vector3d hit = t * d;
        const double cos_incidence = std::abs((hit - c).normalized().dot(d.normalized()));
        if (cos_incidence > 0.3) {  // away from the silhouette, where the facets can move the hit a lot
          worst = std::max(worst, std::abs(z - t));
          ++inside;
        }
      }
      if (miss > 0.002) {
        EXPECT_EQ(z, 0.0f) << "background pixel " << u << "," << v;
        ++outside;
      }
    }
  }
  std::printf("%s: sphere: %d pixels compared, worst depth error %.3g m; %d background pixels\n", GetParam(), inside,
              worst, outside);
  EXPECT_GT(inside, 2000);
  EXPECT_GT(outside, 10000);
  EXPECT_LT(worst, 1e-4) << "worst depth error on the sphere";
}

TEST_P(AnalyticScene, ModelPoseTurnsTheScene) {
  // A square standing at x = 0.3 facing -x; turned by 90 degrees about z it stands at y = 0.3.
  TriangleMesh wall;
  wall.vertices = {{0.3f, -0.1f, -0.1f}, {0.3f, 0.1f, -0.1f}, {0.3f, 0.1f, 0.1f}, {0.3f, -0.1f, 0.1f}};
  wall.triangles = {{0, 1, 2}, {0, 2, 3}};
  ASSERT_TRUE(renderer.set_scene(wall));
  Camera camera = Camera::look_at(test_intrinsics(), {0, 0, 0}, {0, 1, 0}, {0, 0, 1});
  Eigen::Isometry3d turn = Eigen::Isometry3d::Identity();
  turn.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  auto seen = renderer.render(camera, turn);
  ASSERT_TRUE(seen);
  EXPECT_NEAR(seen->at(120, 90), 0.3, 1e-4);
  auto unseen = renderer.render(camera);
  ASSERT_TRUE(unseen);
  EXPECT_EQ(unseen->foreground_count(), 0);
}

TEST_P(AnalyticScene, RejectsBadInput) {
  TriangleMesh bad = square(0.1);
  bad.vertices[2].x() = std::nanf("");
  EXPECT_FALSE(renderer.set_scene(bad));
  bad = square(0.1);
  bad.triangles.push_back({0, 1, 9});
  EXPECT_FALSE(renderer.set_scene(bad));
  EXPECT_FALSE(renderer.set_scene(TriangleMesh{}));
  ASSERT_TRUE(renderer.set_scene(square(0.1)));
  Camera camera = Camera::look_at(test_intrinsics(), {0, 0, 1}, {0, 0, 0}, {0, 1, 0});
  camera.intrinsics.width = 0;
  EXPECT_FALSE(renderer.render(camera));
}

INSTANTIATE_TEST_SUITE_P(Renderers, AnalyticScene, ::testing::ValuesIn(kRendererKinds));

TEST(Camera, ProjectionRoundTripsWithRays) {
  const Camera camera = Camera::look_at(test_intrinsics(), {0.3, -0.6, 0.4}, {0, 0, 0}, {0, 0, 1});
  const Eigen::Vector3d p(0.05, 0.02, -0.03);
  const auto uvz = camera.project(p);
  ASSERT_TRUE(uvz);
  const Eigen::Vector3d back = camera.world_to_camera.inverse() * ((*uvz)[2] * camera.ray((*uvz)[0], (*uvz)[1]));
  EXPECT_LT((back - p).norm(), 1e-12);
  // The target projects to the principal point.
  const auto centre = camera.project(Eigen::Vector3d::Zero());
  EXPECT_NEAR((*centre)[0], 119.5, 1e-9);
  EXPECT_NEAR((*centre)[1], 89.5, 1e-9);
}

}  // namespace
}  // namespace drapegen::renderer
