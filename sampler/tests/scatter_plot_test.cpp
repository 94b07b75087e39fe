#include "drapegen/sampler/scatter_plot.hpp"

#include <gtest/gtest.h>
#include <png.h>

#include <cstdio>
#include <filesystem>

namespace drapegen::sampler {
namespace {

namespace fs = std::filesystem;

struct Image {
  int width = 0, height = 0;
  std::vector<unsigned char> rgb;
};

Image read_png(const std::string& path) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  Image out;
  if (!png_image_begin_read_from_file(&image, path.c_str())) return out;
  image.format = PNG_FORMAT_RGB;
  out.rgb.resize(PNG_IMAGE_SIZE(image));
  if (!png_image_finish_read(&image, nullptr, out.rgb.data(), 0, nullptr)) return {};
  out.width = static_cast<int>(image.width);
  out.height = static_cast<int>(image.height);
  return out;
}

int count_colour(const Image& img, unsigned char r, unsigned char g, unsigned char b) {
  int n = 0;
  for (std::size_t i = 0; i + 2 < img.rgb.size(); i += 3)
    n += img.rgb[i] == r && img.rgb[i + 1] == g && img.rgb[i + 2] == b;
  return n;
}

TEST(ScatterPlot, DrawsBothSetsIntoAPng) {
  const std::string path =
      (fs::temp_directory_path() / ("drapegen_plot_" + std::to_string(::getpid()) + ".png")).string();
  std::vector<Features> generated, measured;
  for (int i = 0; i < 50; ++i) generated.push_back({8.0 + 0.05 * i, 9, 9, -10.0 - 0.02 * i, -10, -10});
  measured.push_back({9.0, 9, 9, -11.5, -10, -10});  // inside the frame
  ScatterPlotSpec spec;
  ASSERT_TRUE(write_scatter_png(path, spec, generated, measured));
  const Image img = read_png(path);
  EXPECT_EQ(img.width, spec.width);
  EXPECT_EQ(img.height, spec.height);
  // Measured points are 5x5 orange squares (one here, plus the legend's 7x7 swatch), generated 3x3 blue ones.
  EXPECT_EQ(count_colour(img, 255, 127, 14), 25 + 49);
  EXPECT_GT(count_colour(img, 31, 119, 180), 50 * 5);
  fs::remove(path);
  EXPECT_FALSE(write_scatter_png("/nonexistent-dir/plot.png", spec, generated, measured));
  spec.x_feature = 6;
  EXPECT_FALSE(write_scatter_png(path, spec, generated, measured));
  spec.x_feature = 0;
  EXPECT_FALSE(write_scatter_png(path, spec, {}, {}));
}

}  // namespace
}  // namespace drapegen::sampler
