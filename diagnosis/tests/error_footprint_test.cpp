#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include <nlohmann/json.hpp>

#include "drapegen/diagnosis/error_footprint.hpp"
#include "small_reality.hpp"

using namespace drapegen;
using namespace drapegen::diagnosis;

namespace {

constexpr double kR = 0.05;  // the tester's cylinder radius (m)

/// A camera about 0.5 m above the platform looking down at it a little obliquely (so that its pose is not its own
/// inverse), and what it sees of the plane z = `height`: the depth of every pixel and the point there.
struct PlaneView {
  renderer::Camera camera = renderer::Camera::look_at(renderer::Intrinsics::pinhole(64, 64, 80, 80, 31.5, 31.5),
                                                      {0.04, -0.03, 0.5}, {0, 0, -0.05}, Eigen::Vector3d::UnitY());
  renderer::DepthImage clean{64, 64};
  std::vector<Eigen::Vector3d> points;  // per pixel, in the specimen's frame
  explicit PlaneView(double height) {
    const Eigen::Matrix3d to_world = camera.world_to_camera.linear().transpose();
    for (int v = 0; v < 64; ++v) {
      for (int u = 0; u < 64; ++u) {
        const Eigen::Vector3d ray = camera.ray(u, v), along = to_world * ray;
        const double z = (height - camera.position().z()) / along.z();  // camera depth: ray has z = 1
        clean.depth[static_cast<std::size_t>(v) * 64 + u] = static_cast<float>(z);
        points.push_back(camera.position() + z * along);
      }
    }
  }
};

HemProfile round_outline(double r) {
  HemProfile h;
  h.radius.assign(kHemBins, r);
  return h;
}

// An error on the top's pixels alone (to 5 mm from its edge: classify_point's top) stands out on the top; one of the
// same size everywhere stands out nowhere.
TEST(ErrorFootprint, AnErrorOnTheTopAloneStandsOutThereAndAUniformOneNowhere) {
  const PlaneView view(0.0);
  renderer::DepthImage on_top = view.clean, everywhere = view.clean;
  int top_pixels = 0;
  for (std::size_t i = 0; i < view.points.size(); ++i) {
    everywhere.depth[i] += 0.004f;
    if (std::hypot(view.points[i].x(), view.points[i].y()) < kR - 0.005) on_top.depth[i] += 0.004f, ++top_pixels;
  }
  ASSERT_GT(top_pixels, 100);
  const HemProfile outline = round_outline(0.3);  // (the plane lies at the top's height: no hem there)
  ErrorFootprint top, uniform;
  top.add_view(view.clean, on_top, view.camera, outline, kR);
  uniform.add_view(view.clean, everywhere, view.camera, outline, kR);
  EXPECT_EQ(top.regions(), std::vector<Region>{Region::kTop});
  EXPECT_EQ(uniform.regions(), std::vector<Region>{Region::kGlobal});
  double pixels = 0.0;
  for (const RegionShare& s : uniform.shares()) {
    pixels += s.pixel_share;
    if (s.pixel_share > 0.0) {
      EXPECT_NEAR(s.enrichment, 1.0, 1e-5) << region_name(s.region);  // float depths
    }
  }
  EXPECT_NEAR(pixels, 1.0, 1e-12);
  const auto shares = top.shares();
  EXPECT_NEAR(shares[static_cast<int>(Region::kTop)].energy_share, 1.0, 1e-12);
  EXPECT_NEAR(top.pixels[static_cast<int>(Region::kTop)], top_pixels, 2.0);  // float depths at the edge
  EXPECT_EQ(ErrorFootprint{}.regions(), std::vector<Region>{Region::kGlobal});  // no error at all
}

// Below the top, the outline decides the hem: with an outline of 0.1 m over the angles [0, pi) and 0.4 m over the
// rest, an error on the points beyond 75 mm from the axis at y > 0 is the hem's, and the same error at y < 0 (whose
// hem lies beyond the image) the skirt's. A footprint in another frame than the outline's (the camera not inverted,
// the points turned) puts them elsewhere.
TEST(ErrorFootprint, BelowTheTopTheOutlineDecidesTheHem) {
  const PlaneView view(-0.05);
  HemProfile outline;
  for (int k = 0; k < kHemBins; ++k) outline.radius.push_back(k < kHemBins / 2 ? 0.1 : 0.4);
  renderer::DepthImage north = view.clean, south = view.clean;
  int north_pixels = 0, south_pixels = 0;
  for (std::size_t i = 0; i < view.points.size(); ++i) {
    const Eigen::Vector3d& p = view.points[i];
    if (std::hypot(p.x(), p.y()) <= 0.08) continue;
    if (p.y() > 0.005) north.depth[i] += 0.004f, ++north_pixels;
    if (p.y() < -0.005) south.depth[i] += 0.004f, ++south_pixels;
  }
  ASSERT_GT(north_pixels, 200);
  ASSERT_GT(south_pixels, 200);
  ErrorFootprint n, s;
  n.add_view(view.clean, north, view.camera, outline, kR);
  s.add_view(view.clean, south, view.camera, outline, kR);
  EXPECT_EQ(n.regions(), std::vector<Region>{Region::kHem});
  EXPECT_EQ(s.regions(), std::vector<Region>{Region::kSkirt});
  EXPECT_NEAR(n.shares()[static_cast<int>(Region::kHem)].energy_share, 1.0, 1e-12);
  EXPECT_NEAR(s.shares()[static_cast<int>(Region::kSkirt)].energy_share, 1.0, 1e-12);
}

// The reality generator's truth: a multipath capture's regions are where its rendered error stands out (recorded
// with the footprint, whose enriched regions they are); a depth bias's error is the same everywhere, its footprint
// flat and its region global; a capture without a depth error has no footprint.
TEST(ErrorFootprint, TheRealityGeneratorPlacesMultipathWhereItsErrorLies) {
  const auto read = [](const char* name, const char* effect) {
    const auto r = fixture::generate_small_reality(name, fixture::small_reality_spec({effect}, 5));
    if (!r) return nlohmann::json();
    std::ifstream in(r->truth_path);
    return nlohmann::json::parse(in);
  };
  const auto m = read("footprint_multipath", "multipath=20"), b = read("footprint_bias", "bias=5"),
             p = read("footprint_pose", "pose=1");
  ASSERT_TRUE(m.is_object() && b.is_object() && p.is_object());
  ASSERT_TRUE(m.contains("sensor_footprint"));
  const auto& f = m["sensor_footprint"];
  std::vector<std::string> enriched;
  for (const auto& [name, share] : f.items()) {
    const double pixels = share["pixel_share"], enrichment = share["enrichment"];
    if (pixels >= kMinPixelShare && enrichment >= kMinRegionEnrichment) enriched.push_back(name);
  }
  ASSERT_FALSE(enriched.empty());
  std::vector<std::string> regions = m["regions"];
  std::sort(enriched.begin(), enriched.end());
  std::sort(regions.begin(), regions.end());
  EXPECT_EQ(regions, enriched);
  // The platform top is a plane seen from above: no valley, no multipath there.
  EXPECT_LT(f["top"]["enrichment"].get<double>(), 0.5);
  for (const auto& [name, share] : b["sensor_footprint"].items()) {
    if (share["pixel_share"].get<double>() > 0.0) {
      EXPECT_NEAR(share["enrichment"].get<double>(), 1.0, 0.05) << name;
    }
  }
  EXPECT_EQ(b["regions"], nlohmann::json::array({"global"}));
  EXPECT_FALSE(p.contains("sensor_footprint"));
  EXPECT_EQ(p["regions"], nlohmann::json::array({"global"}));
}

}  // namespace
