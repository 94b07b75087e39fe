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

/// A camera 0.5 m above the platform looking straight down, and what it sees: the plane z = 0 everywhere (within the
/// cylinder's radius the platform top, beyond it the rim and then the skirt's region).
struct DownView {
  renderer::Camera camera = renderer::Camera::look_at(renderer::Intrinsics::pinhole(64, 64, 80, 80, 31.5, 31.5),
                                                      {0, 0, 0.5}, {0, 0, 0}, Eigen::Vector3d::UnitY());
  renderer::DepthImage clean{64, 64};
  DownView() { std::fill(clean.depth.begin(), clean.depth.end(), 0.5f); }
  /// The horizontal radius of the point pixel (u, v) sees.
  [[nodiscard]] double radius(int u, int v) const {
    const Eigen::Vector3d p = camera.world_to_camera.inverse() * (0.5 * camera.ray(u, v));
    return std::hypot(p.x(), p.y());
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
  DownView view;
  ASSERT_NEAR(view.radius(31, 31), 0.0, 0.005);
  renderer::DepthImage on_top = view.clean, everywhere = view.clean;
  int top_pixels = 0;
  for (int v = 0; v < 64; ++v) {
    for (int u = 0; u < 64; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * 64 + u;
      everywhere.depth[i] += 0.004f;
      if (view.radius(u, v) < kR - 0.005) on_top.depth[i] += 0.004f, ++top_pixels;
    }
  }
  ASSERT_GT(top_pixels, 100);
  const HemProfile outline = round_outline(0.3);  // far outside the image: no hem in view
  ErrorFootprint top, uniform;
  top.add_view(view.clean, on_top, view.camera, outline, kR);
  uniform.add_view(view.clean, everywhere, view.camera, outline, kR);
  EXPECT_EQ(top.regions(), std::vector<Region>{Region::kTop});
  EXPECT_EQ(uniform.regions(), std::vector<Region>{Region::kGlobal});
  double pixels = 0.0;
  for (const RegionShare& s : uniform.shares()) {
    pixels += s.pixel_share;
    if (s.pixel_share > 0.0) EXPECT_NEAR(s.enrichment, 1.0, 1e-9) << region_name(s.region);
  }
  EXPECT_NEAR(pixels, 1.0, 1e-12);
  const auto shares = top.shares();
  EXPECT_NEAR(shares[static_cast<int>(Region::kTop)].energy_share, 1.0, 1e-12);
  EXPECT_NEAR(top.pixels[static_cast<int>(Region::kTop)], top_pixels, 0.5);
  EXPECT_EQ(ErrorFootprint{}.regions(), std::vector<Region>{Region::kGlobal});  // no error at all
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
  for (const auto& [name, share] : b["sensor_footprint"].items())
    if (share["pixel_share"].get<double>() > 0.0) EXPECT_NEAR(share["enrichment"].get<double>(), 1.0, 0.05) << name;
  EXPECT_EQ(b["regions"], nlohmann::json::array({"global"}));
  EXPECT_FALSE(p.contains("sensor_footprint"));
  EXPECT_EQ(p["regions"], nlohmann::json::array({"global"}));
}

}  // namespace
