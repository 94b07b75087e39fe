#include <gtest/gtest.h>

#include <random>

#include "drapegen/renderer/depth_image.hpp"

namespace drapegen::renderer {
namespace {

/// The box by the definition: every pixel visited.
PixelBox box_by_definition(const DepthImage& image) {
  PixelBox box;
  for (int v = 0; v < image.height; ++v)
    for (int u = 0; u < image.width; ++u)
      if (image.at(u, v) > 0.0f) box.add(u, v, u, v);
  return box;
}

void expect_same_box(const PixelBox& a, const PixelBox& b) {
  EXPECT_EQ(a.empty(), b.empty());
  if (a.empty() || b.empty()) return;
  EXPECT_EQ(a.u0, b.u0);
  EXPECT_EQ(a.v0, b.v0);
  EXPECT_EQ(a.u1, b.u1);
  EXPECT_EQ(a.v1, b.v1);
}

TEST(DepthImage, ForegroundBoxOfEmptyImageIsEmpty) { EXPECT_TRUE(DepthImage(240, 180).foreground_box().empty()); }

TEST(DepthImage, ForegroundBoxMatchesTheDefinition) {
  // Widths around the search's 16-pixel blocks; single returns at every column and in the first and last row;
  // negative and NaN depths are not returns.
  std::mt19937 rng(5);
  for (int width : {1, 7, 15, 16, 17, 31, 32, 33, 240}) {
    for (int u = 0; u < width; ++u) {
      DepthImage image(width, 3);
      image.at(u, 1) = 0.7f;
      expect_same_box(image.foreground_box(), box_by_definition(image));
    }
    for (int trial = 0; trial < 50; ++trial) {
      DepthImage image(width, 9);
      const int returns = static_cast<int>(rng() % 4);
      for (int k = 0; k < returns; ++k) image.at(static_cast<int>(rng() % width), static_cast<int>(rng() % 9)) = 0.5f;
      image.at(static_cast<int>(rng() % width), static_cast<int>(rng() % 9)) = -1.0f;
      image.at(static_cast<int>(rng() % width), static_cast<int>(rng() % 9)) = std::numeric_limits<float>::quiet_NaN();
      expect_same_box(image.foreground_box(), box_by_definition(image));
    }
  }
}

}  // namespace
}  // namespace drapegen::renderer
