#pragma once
// A single-part scan-line OpenEXR file written directly (private to the renderer library): the header attributes,
// the line offset table and the chunks, uncompressed (NONE) or deflated (ZIPS: 1 line per chunk, ZIP: 16), as the
// OpenEXR file format specifies them, without OpenEXR's per-file and per-chunk set-up (the header map, the frame
// buffer slices, a zlib stream made and freed for every chunk). The layout is the one OpenEXR 3.1's Imf::OutputFile
// writes (NONE files are the same bytes); ZIP and ZIPS chunks are deflated by libdeflate instead of zlib, faster and
// smaller, into zlib streams any reader inflates (tested in exr_test.cpp).

#include <cstdint>
#include <string>
#include <vector>

namespace drapegen::renderer::exr_scanline {

/// Compression codes of the file format (the ones this writer supports).
enum class Compression : std::uint8_t { kNone = 0, kZips = 2, kZip = 3 };
/// Pixel types of the file format.
enum class PixelType : std::int32_t { kHalf = 1, kFloat = 2 };

/// Header attributes as stored: name, type name and the value's bytes (little-endian). The file lists them sorted by
/// name, as OpenEXR does.
class Attributes {
 public:
  void add_int(const std::string& name, std::int32_t value);
  void add_float(const std::string& name, float value);
  void add_double(const std::string& name, double value);
  void add_string(const std::string& name, const std::string& value);
  void add_box2i(const std::string& name, int x0, int y0, int x1, int y1);
  void add_v2f(const std::string& name, float x, float y);
  /// Row-major 3x3 (m33f) and 4x4 (m44f) float matrices.
  void add_m33f(const std::string& name, const float (&m)[9]);
  void add_m44f(const std::string& name, const float (&m)[16]);
  void add(const std::string& name, const std::string& type, std::string value);

  struct Attribute {
    std::string name, type, value;
  };
  [[nodiscard]] const std::vector<Attribute>& list() const { return list_; }

 private:
  std::vector<Attribute> list_;
};

/// The image: channels of one pixel type over the data window (x0, y0)-(x1, y1), channel c's pixel (x, y) at
/// pixels[c][(y - y0) * width + (x - x0)] as stored (2 bytes for half, 4 for float, host order = little-endian).
struct Image {
  std::vector<std::string> channel_names;  // in the order of `pixels`; the file sorts them by name
  PixelType type = PixelType::kHalf;
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  std::vector<const void*> pixels;
};

/// The whole file. `attributes` must not hold the ones the writer makes from `image` and the arguments (channels,
/// compression, dataWindow, displayWindow, lineOrder, pixelAspectRatio, screenWindowCenter, screenWindowWidth).
[[nodiscard]] std::vector<char> write(const Image& image, int display_width, int display_height,
                                      Compression compression, int zip_level, const Attributes& attributes);

}  // namespace drapegen::renderer::exr_scanline
