#include "exr_scanline.hpp"

#include <libdeflate.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <numeric>
#include <stdexcept>

namespace drapegen::renderer::exr_scanline {
namespace {

static_assert(std::endian::native == std::endian::little, "the file format is little-endian; so are the pixels given");

template <class T>
void append(std::string& out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out.append(bytes, sizeof(T));
}

template <class T>
void append(std::vector<char>& out, T value) {
  const char* bytes = reinterpret_cast<const char*>(&value);
  out.insert(out.end(), bytes, bytes + sizeof(T));
}

void append(std::vector<char>& out, const std::string& s) { out.insert(out.end(), s.begin(), s.end()); }

/// libdeflate's compressor for one level, made once per thread and level (zlib's compress2, which OpenEXR 3.1 calls,
/// sets up and frees a stream for every chunk). It writes zlib streams, as the file format asks, in less time than
/// zlib and, on the noisy depth images, in fewer bytes (docs/RENDERER.md, "Storage choice").
class Deflater {
 public:
  Deflater() = default;
  Deflater(const Deflater&) = delete;
  Deflater& operator=(const Deflater&) = delete;
  ~Deflater() {
    if (compressor_ != nullptr) libdeflate_free_compressor(compressor_);
  }

  /// The zlib stream of in[0, n) at `level` into out (resized to fit).
  void deflate(const unsigned char* in, std::size_t n, int level, std::vector<unsigned char>& out) {
    if (compressor_ == nullptr || level != level_) {
      if (compressor_ != nullptr) libdeflate_free_compressor(compressor_);
      compressor_ = libdeflate_alloc_compressor(level);
      if (compressor_ == nullptr) throw std::runtime_error("libdeflate: cannot make a compressor");
      level_ = level;
    }
    out.resize(libdeflate_zlib_compress_bound(compressor_, n));
    const std::size_t size = libdeflate_zlib_compress(compressor_, in, n, out.data(), out.size());
    if (size == 0) throw std::runtime_error("libdeflate: compression failed");
    out.resize(size);
  }

 private:
  libdeflate_compressor* compressor_ = nullptr;
  int level_ = 0;
};

/// ZIP and ZIPS chunk data before deflating: the bytes split into the even-numbered ones followed by the odd-numbered
/// ones, then each byte after the first replaced by its difference from the byte before it, plus 128 (mod 256).
/// Written as loops without a carried value, which the compiler vectorises.
void split_and_predict(const unsigned char* raw, std::size_t n, std::vector<unsigned char>& split,
                       std::vector<unsigned char>& out) {
  split.resize(n);
  out.resize(n);
  const std::size_t half = (n + 1) / 2, pairs = n / 2;
  for (std::size_t i = 0; i < pairs; ++i) {
    split[i] = raw[2 * i];
    split[half + i] = raw[2 * i + 1];
  }
  if (n % 2 != 0) split[half - 1] = raw[n - 1];
  if (n > 0) out[0] = split[0];
  for (std::size_t i = 1; i < n; ++i) out[i] = static_cast<unsigned char>(split[i] - split[i - 1] + 128);
}

}  // namespace

void Attributes::add(const std::string& name, const std::string& type, std::string value) {
  list_.push_back({name, type, std::move(value)});
}

void Attributes::add_int(const std::string& name, std::int32_t value) {
  std::string v;
  append(v, value);
  add(name, "int", std::move(v));
}

void Attributes::add_float(const std::string& name, float value) {
  std::string v;
  append(v, value);
  add(name, "float", std::move(v));
}

void Attributes::add_double(const std::string& name, double value) {
  std::string v;
  append(v, value);
  add(name, "double", std::move(v));
}

void Attributes::add_string(const std::string& name, const std::string& value) { add(name, "string", value); }

void Attributes::add_box2i(const std::string& name, int x0, int y0, int x1, int y1) {
  std::string v;
  for (std::int32_t x : {x0, y0, x1, y1}) append(v, x);
  add(name, "box2i", std::move(v));
}

void Attributes::add_v2f(const std::string& name, float x, float y) {
  std::string v;
  append(v, x);
  append(v, y);
  add(name, "v2f", std::move(v));
}

void Attributes::add_m33f(const std::string& name, const float (&m)[9]) {
  std::string v;
  for (float x : m) append(v, x);
  add(name, "m33f", std::move(v));
}

void Attributes::add_m44f(const std::string& name, const float (&m)[16]) {
  std::string v;
  for (float x : m) append(v, x);
  add(name, "m44f", std::move(v));
}

std::vector<char> write(const Image& image, int display_width, int display_height, Compression compression,
                        int zip_level, const Attributes& attributes) {
  const int width = image.x1 - image.x0 + 1, height = image.y1 - image.y0 + 1;
  const std::size_t channels = image.channel_names.size();
  if (width <= 0 || height <= 0 || channels == 0 || image.pixels.size() != channels) {
    throw std::invalid_argument("EXR image: empty data window or channels without pixels");
  }
  const std::size_t pixel_bytes = image.type == PixelType::kHalf ? 2 : 4;
  const std::size_t line_bytes = pixel_bytes * static_cast<std::size_t>(width);

  // Channels sorted by name, as the file lists them and stores their lines.
  std::vector<std::size_t> order(channels);
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return image.channel_names[a] < image.channel_names[b]; });

  Attributes header = attributes;
  std::string channel_list;
  for (std::size_t c : order) {
    channel_list += image.channel_names[c];
    channel_list += '\0';
    append(channel_list, static_cast<std::int32_t>(image.type));
    append(channel_list, std::uint32_t{0});  // pLinear, then 3 reserved bytes
    append(channel_list, std::int32_t{1});   // x sampling
    append(channel_list, std::int32_t{1});   // y sampling
  }
  channel_list += '\0';
  header.add("channels", "chlist", std::move(channel_list));
  header.add("compression", "compression", std::string(1, static_cast<char>(compression)));
  header.add_box2i("dataWindow", image.x0, image.y0, image.x1, image.y1);
  header.add_box2i("displayWindow", 0, 0, display_width - 1, display_height - 1);
  header.add("lineOrder", "lineOrder", std::string(1, '\0'));  // increasing y
  header.add_float("pixelAspectRatio", 1.0f);
  header.add_v2f("screenWindowCenter", 0.0f, 0.0f);
  header.add_float("screenWindowWidth", 1.0f);
  std::vector<Attributes::Attribute> sorted = header.list();
  std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return a.name < b.name; });

  bool long_names = false;
  for (const auto& a : sorted) long_names = long_names || a.name.size() > 31 || a.type.size() > 31;
  for (const auto& name : image.channel_names) long_names = long_names || name.size() > 31;

  std::vector<char> file;
  for (unsigned char byte : {0x76, 0x2f, 0x31, 0x01}) file.push_back(static_cast<char>(byte));
  append(file, std::int32_t{2 | (long_names ? 0x400 : 0)});  // version 2, single-part scan-line
  for (const auto& a : sorted) {
    append(file, a.name);
    file.push_back('\0');
    append(file, a.type);
    file.push_back('\0');
    append(file, static_cast<std::int32_t>(a.value.size()));
    append(file, a.value);
  }
  file.push_back('\0');

  const int lines_per_chunk = compression == Compression::kZip ? 16 : 1;
  const int chunks = (height + lines_per_chunk - 1) / lines_per_chunk;
  const std::size_t table = file.size();
  file.resize(table + sizeof(std::uint64_t) * chunks);

  thread_local Deflater deflater;
  thread_local std::vector<unsigned char> raw, split, predicted, deflated;
  for (int k = 0; k < chunks; ++k) {
    const int first = k * lines_per_chunk, lines = std::min(lines_per_chunk, height - first);
    raw.resize(line_bytes * channels * lines);
    unsigned char* out = raw.data();
    for (int line = first; line < first + lines; ++line) {
      for (std::size_t c : order) {
        std::memcpy(out, static_cast<const unsigned char*>(image.pixels[c]) + line_bytes * line, line_bytes);
        out += line_bytes;
      }
    }
    const unsigned char* data = raw.data();
    std::size_t size = raw.size();
    if (compression != Compression::kNone) {
      split_and_predict(raw.data(), raw.size(), split, predicted);
      deflater.deflate(predicted.data(), predicted.size(), zip_level, deflated);
      if (deflated.size() < raw.size()) {  // otherwise the chunk is stored as it is
        data = deflated.data();
        size = deflated.size();
      }
    }
    const auto offset = static_cast<std::uint64_t>(file.size());
    std::memcpy(file.data() + table + sizeof(std::uint64_t) * k, &offset, sizeof(offset));
    append(file, static_cast<std::int32_t>(image.y0 + first));
    append(file, static_cast<std::int32_t>(size));
    file.insert(file.end(), reinterpret_cast<const char*>(data), reinterpret_cast<const char*>(data) + size);
  }
  return file;
}

}  // namespace drapegen::renderer::exr_scanline
