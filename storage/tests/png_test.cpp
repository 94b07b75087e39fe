#include <gtest/gtest.h>
#include <png.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <unistd.h>
#include <vector>

#include "drapegen/storage/png.hpp"

namespace drapegen::storage {
namespace {

/// Decodes PNG bytes with libpng's simplified API into 8-bit RGB.
std::vector<unsigned char> decode_rgb(const std::string& bytes, int& width, int& height) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_memory(&image, bytes.data(), bytes.size())) return {};
  image.format = PNG_FORMAT_RGB;
  std::vector<unsigned char> rgb(PNG_IMAGE_SIZE(image));
  if (!png_image_finish_read(&image, nullptr, rgb.data(), 0, nullptr)) return {};
  width = static_cast<int>(image.width);
  height = static_cast<int>(image.height);
  return rgb;
}

TEST(Png, EncodesRowsTopToBottomLosslessly) {
  std::vector<unsigned char> rgb(5 * 3 * 3);
  for (std::size_t i = 0; i < rgb.size(); ++i) rgb[i] = static_cast<unsigned char>(17 * i + 3);
  auto bytes = encode_png_rgb(5, 3, rgb);
  ASSERT_TRUE(bytes) << bytes.error().message;
  int width = 0, height = 0;
  EXPECT_EQ(decode_rgb(*bytes, width, height), rgb);
  EXPECT_EQ(width, 5);
  EXPECT_EQ(height, 3);
}

TEST(Png, RefusesSizesThatDoNotMatchAndNamesThePath) {
  const std::vector<unsigned char> rgb(10);
  const auto wrong = encode_png_rgb(2, 2, rgb);
  ASSERT_FALSE(wrong);
  EXPECT_NE(wrong.error().message.find("not a 2x2 RGB image"), std::string::npos) << wrong.error().message;
  EXPECT_FALSE(encode_png_rgb(0, 1, {}));
  // libpng's own refusal (wider than its 1000000-pixel limit) comes back with libpng's reason.
  const std::vector<unsigned char> wide(3 * 1000001, 0);
  const auto too_wide = encode_png_rgb(1000001, 1, wide);
  ASSERT_FALSE(too_wide);
  EXPECT_NE(too_wide.error().message.find("PNG: "), std::string::npos);
  EXPECT_EQ(too_wide.error().message.find("libpng failed"), std::string::npos) << too_wide.error().message;
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("drapegen_png_test_" + std::to_string(::getpid()) + ".png")).string();
  const auto failed = write_png_rgb(path, 2, 2, rgb);
  ASSERT_FALSE(failed);
  EXPECT_NE(failed.error().message.find(path), std::string::npos) << failed.error().message;
  EXPECT_FALSE(std::filesystem::exists(path));
  const std::vector<unsigned char> red{255, 0, 0};
  ASSERT_TRUE(write_png_rgb(path, 1, 1, red));
  std::ifstream in(path, std::ios::binary);
  const std::string written((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  int width = 0, height = 0;
  EXPECT_EQ(decode_rgb(written, width, height), red);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace drapegen::storage
