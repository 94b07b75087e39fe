#include "drapegen/storage/png.hpp"

#include <png.h>

#include <fmt/format.h>

#include "drapegen/storage/atomic_file.hpp"

namespace drapegen::storage {
namespace {

void append(png_structp png, png_bytep data, png_size_t n) {
  static_cast<std::string*>(png_get_io_ptr(png))->append(reinterpret_cast<const char*>(data), n);
}

}  // namespace

sim::Expected<std::string> encode_png_rgb(int width, int height, std::span<const unsigned char> rgb) {
  if (width <= 0 || height <= 0 || rgb.size() != static_cast<std::size_t>(width) * height * 3) {
    return sim::Error{fmt::format("PNG: {} bytes are not a {}x{} RGB image", rgb.size(), width, height)};
  }
  std::string bytes;  // its address is libpng's, so it lives in memory across the setjmp
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png != nullptr ? png_create_info_struct(png) : nullptr;
  if (png == nullptr || info == nullptr || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return sim::Error{"PNG: libpng failed"};
  }
  png_set_write_fn(png, &bytes, append, nullptr);
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8, PNG_COLOR_TYPE_RGB,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < height; ++y) {
    png_write_row(png, const_cast<png_bytep>(&rgb[static_cast<std::size_t>(y) * width * 3]));
  }
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return bytes;
}

sim::Status write_png_rgb(const std::string& path, int width, int height, std::span<const unsigned char> rgb) {
  auto bytes = encode_png_rgb(width, height, rgb);
  if (!bytes) return sim::Error{fmt::format("cannot write {}: {}", path, bytes.error().message)};
  return write_file_atomic(path, *bytes);
}

}  // namespace drapegen::storage
