#include "drapegen/storage/png.hpp"

#include <png.h>

#include <csetjmp>
#include <cstring>
#include <fmt/format.h>
#include <new>

#include "drapegen/storage/atomic_file.hpp"

namespace drapegen::storage {
namespace {

/// Where libpng's callbacks write: the encoded bytes and, on failure, libpng's message.
struct Sink {
  std::string bytes;
  char message[256] = "libpng failed";
};

void append(png_structp png, png_bytep data, png_size_t n) {
  try {
    static_cast<Sink*>(png_get_io_ptr(png))->bytes.append(reinterpret_cast<const char*>(data), n);
  } catch (const std::bad_alloc&) {
    png_error(png, "out of memory");  // no exception may cross libpng's C frames
  }
}

[[noreturn]] void keep_error(png_structp png, png_const_charp message) {
  Sink* sink = static_cast<Sink*>(png_get_error_ptr(png));
  std::strncpy(sink->message, message, sizeof sink->message - 1);
  png_longjmp(png, 1);
}

/// Encodes into `sink`; false (with sink->message) if libpng fails. Nothing here but libpng's own state changes
/// between setjmp and a longjmp back to it.
bool encode(Sink* sink, int width, int height, std::span<const unsigned char> rgb) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, sink, keep_error, nullptr);
  if (png == nullptr) return false;
  png_infop info = png_create_info_struct(png);
  if (info == nullptr) {
    png_destroy_write_struct(&png, nullptr);
    return false;
  }
  if (setjmp(png_jmpbuf(png)) != 0) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  png_set_write_fn(png, sink, append, nullptr);
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8, PNG_COLOR_TYPE_RGB,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < height; ++y) {
    png_write_row(png, const_cast<png_bytep>(&rgb[static_cast<std::size_t>(y) * width * 3]));
  }
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

}  // namespace

sim::Expected<std::string> encode_png_rgb(int width, int height, std::span<const unsigned char> rgb) {
  if (width <= 0 || height <= 0 || rgb.size() != static_cast<std::size_t>(width) * height * 3) {
    return sim::Error{fmt::format("PNG: {} bytes are not a {}x{} RGB image", rgb.size(), width, height)};
  }
  Sink sink;
  if (!encode(&sink, width, height, rgb)) return sim::Error{fmt::format("PNG: {}", sink.message)};
  return std::move(sink.bytes);
}

sim::Status write_png_rgb(const std::string& path, int width, int height, std::span<const unsigned char> rgb) {
  auto bytes = encode_png_rgb(width, height, rgb);
  if (!bytes) return sim::Error{fmt::format("cannot write {}: {}", path, bytes.error().message)};
  return write_file_atomic(path, *bytes);
}

}  // namespace drapegen::storage
