#include "drapegen/renderer/exr.hpp"

#include <ImfChannelList.h>
#include <ImfDoubleAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputFile.h>
#include <ImfIntAttribute.h>
#include <ImfMatrixAttribute.h>
#include <ImfOutputFile.h>
#include <ImfStdIO.h>
#include <ImfStringAttribute.h>
#include <Imath/half.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fmt/format.h>
#include <algorithm>
#include <map>
#include <string_view>

#include "drapegen/renderer/exr_memory_stream.hpp"
#include "drapegen/storage/atomic_file.hpp"
#include "exr_scanline.hpp"

namespace drapegen::renderer {
namespace {

const std::map<std::string, Imf::Compression>& compressions() {
  static const std::map<std::string, Imf::Compression> m = {
      {"none", Imf::NO_COMPRESSION}, {"rle", Imf::RLE_COMPRESSION},     {"zips", Imf::ZIPS_COMPRESSION},
      {"zip", Imf::ZIP_COMPRESSION}, {"piz", Imf::PIZ_COMPRESSION},     {"pxr24", Imf::PXR24_COMPRESSION},
      {"b44", Imf::B44_COMPRESSION}, {"b44a", Imf::B44A_COMPRESSION},   {"dwaa", Imf::DWAA_COMPRESSION},
      {"dwab", Imf::DWAB_COMPRESSION}};
  return m;
}

/// The compressions encode() writes itself (exr_scanline.hpp); the others go through OpenEXR.
const std::map<std::string, exr_scanline::Compression>& own_compressions() {
  static const std::map<std::string, exr_scanline::Compression> m = {{"none", exr_scanline::Compression::kNone},
                                                                     {"zips", exr_scanline::Compression::kZips},
                                                                     {"zip", exr_scanline::Compression::kZip}};
  return m;
}

/// Short on purpose (every byte of the header is a quarter byte per view); docs/RENDERER.md spells it out.
constexpr const char* kUnits = "Z: camera z, m, 0 = none; K: px, OpenCV; meshToCamera: m, x' = M x; angles: rad";

std::string channel_name(int view) { return fmt::format("view{}.Z", view); }

Imath::M44f to_m44(const Eigen::Isometry3d& T) {
  Imath::M44f m;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) m[i][j] = static_cast<float>(T.matrix()(i, j));
  return m;
}

Imath::M33f to_m33(const Eigen::Matrix3d& K) {
  Imath::M33f m;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m[i][j] = static_cast<float>(K(i, j));
  return m;
}

template <class A>
const A* find(const Imf::Header& h, const std::string& name) {
  return h.findTypedAttribute<A>(name);
}

sim::Expected<DataPointRecord> decode(Imf::IStream& stream) {
  Imf::InputFile file(stream, 0);
  const Imf::Header& h = file.header();
  const auto* views_attr = find<Imf::IntAttribute>(h, "drapegen.views");
  if (views_attr == nullptr) return sim::Error{"not a drapegen depth file (no drapegen.views attribute)"};
  const int views = views_attr->value();
  if (views < 1 || views > 64) return sim::Error{fmt::format("bad view count {}", views)};
  const Imath::Box2i display = h.displayWindow(), data = h.dataWindow();
  const int W = display.max.x - display.min.x + 1, H = display.max.y - display.min.y + 1;
  const int dw = data.max.x - data.min.x + 1, dh = data.max.y - data.min.y + 1;

  DataPointRecord point;
  if (const auto* a = find<Imf::IntAttribute>(h, "drapegen.index")) point.index = a->value();
  if (const auto* a = find<Imf::DoubleAttribute>(h, "drapegen.orientation")) point.orientation = a->value();
  if (const auto* a = find<Imf::StringAttribute>(h, "drapegen.seed")) point.seed = std::stoull(a->value());
  if (const auto* a = find<Imf::StringAttribute>(h, "drapegen.noise")) point.noise = a->value();
  if (const auto* a = find<Imf::StringAttribute>(h, "drapegen.source")) point.source = a->value();

  std::vector<std::vector<float>> buffers(views, std::vector<float>(static_cast<std::size_t>(dw) * dh));
  Imf::FrameBuffer fb;
  for (int v = 0; v < views; ++v) {
    if (h.channels().findChannel(channel_name(v)) == nullptr) {
      return sim::Error{fmt::format("missing channel {}", channel_name(v))};
    }
    char* base =
        reinterpret_cast<char*>(buffers[v].data()) -
        (static_cast<std::ptrdiff_t>(data.min.y) * dw + data.min.x) * static_cast<std::ptrdiff_t>(sizeof(float));
    fb.insert(channel_name(v), Imf::Slice(Imf::FLOAT, base, sizeof(float), sizeof(float) * dw));
  }
  file.setFrameBuffer(fb);
  file.readPixels(data.min.y, data.max.y);

  for (int v = 0; v < views; ++v) {
    ViewRecord r;
    r.depth = DepthImage(W, H);
    for (int y = data.min.y; y <= data.max.y; ++y) {
      for (int x = data.min.x; x <= data.max.x; ++x) {
        if (x < display.min.x || x > display.max.x || y < display.min.y || y > display.max.y) continue;
        r.depth.at(x - display.min.x, y - display.min.y) =
            buffers[v][static_cast<std::size_t>(y - data.min.y) * dw + (x - data.min.x)];
      }
    }
    const std::string prefix = fmt::format("view{}.", v);
    const auto* K = find<Imf::M33fAttribute>(h, prefix + "K");
    const auto* T = find<Imf::M44fAttribute>(h, prefix + "meshToCamera");
    if (K == nullptr || T == nullptr) return sim::Error{fmt::format("missing camera of view {}", v)};
    r.camera.intrinsics.width = W;
    r.camera.intrinsics.height = H;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) r.camera.intrinsics.K(i, j) = K->value()[i][j];
    Eigen::Matrix4d M;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) M(i, j) = T->value()[i][j];
    r.camera.world_to_camera.matrix() = M;
    if (const auto* a = find<Imf::DoubleAttribute>(h, prefix + "tableAngle")) r.table_angle = a->value();
    if (const auto* a = find<Imf::StringAttribute>(h, prefix + "noiseSeed")) r.noise_seed = std::stoull(a->value());
    point.views.push_back(std::move(r));
  }
  return point;
}

}  // namespace

double ExrStorage::max_error(double z_max) const {
  const int e = static_cast<int>(std::floor(std::log2(z_max)));
  const double ulp = std::ldexp(1.0, e - (pixel == Pixel::kHalf ? 10 : 23));
  return 0.5 * quantum + 0.5 * ulp;
}

ExrWriter::ExrWriter(ExrStorage storage) : storage_(std::move(storage)) {}

sim::Status ExrWriter::validate() const {
  if (!compressions().contains(storage_.compression)) {
    return sim::Error{fmt::format("unknown EXR compression '{}'", storage_.compression)};
  }
  // A quantum below a nanometre is no quantisation, and a denormal one overflows z / q to infinity.
  if (!(storage_.quantum == 0.0 || (storage_.quantum >= 1e-9 && storage_.quantum <= 0.01))) {
    return sim::Error{"EXR quantum must be 0 (none) or in [1e-9, 0.01] m"};
  }
  if (storage_.zip_level < 1 || storage_.zip_level > 9) return sim::Error{"zip level must be 1..9"};
  return {};
}

sim::Expected<std::vector<char>> ExrWriter::encode(const DataPointRecord& point) const { return encode(point, false); }

sim::Expected<std::vector<char>> ExrWriter::encode_with_openexr(const DataPointRecord& point) const {
  return encode(point, true);
}

sim::Expected<std::vector<char>> ExrWriter::encode(const DataPointRecord& point, bool with_openexr) const {
  if (sim::Status s = validate(); !s) return s.error();
  if (point.views.empty()) return sim::Error{"data point has no views"};
  const int W = point.views[0].depth.width, H = point.views[0].depth.height;
  for (const auto& v : point.views) {
    if (v.depth.width != W || v.depth.height != H || v.depth.depth.size() != static_cast<std::size_t>(W) * H) {
      return sim::Error{"views differ in size"};
    }
  }
  // The data window is the bounding box of the pixels with a return in any view (OpenEXR readers fill the rest of
  // the display window with 0, which is what no return means here).
  PixelBox returns;
  for (const auto& v : point.views) returns.add(v.depth.foreground_box());
  if (returns.empty()) returns = PixelBox{0, 0, 0, 0};  // nothing anywhere: one pixel of 0
  const int x0 = returns.u0, y0 = returns.v0, x1 = returns.u1, y1 = returns.v1;
  const int dw = x1 - x0 + 1, dh = y1 - y0 + 1;
  const bool half = storage_.pixel == ExrStorage::Pixel::kHalf;
  const int views = static_cast<int>(point.views.size());
  const std::string storage_text =
      fmt::format("{} {} quantum={} m", half ? "half" : "float", storage_.compression, storage_.quantum);
  try {
    // The pixels of the data window, view after view, as stored.
    const std::size_t n = static_cast<std::size_t>(dw) * dh;
    thread_local std::vector<Imath::half> halves;
    thread_local std::vector<float> floats;
    halves.resize(half ? n * views : 0);
    floats.resize(half ? 0 : n * views);
    const double q = storage_.quantum;
    for (int v = 0; v < views; ++v) {
      const DepthImage& depth = point.views[v].depth;
      for (int y = 0; y < dh; ++y) {
        for (int x = 0; x < dw; ++x) {
          float z = depth.at(x0 + x, y0 + y);
          if (!(z > 0.0f) || !std::isfinite(z)) z = 0.0f;
          if (q > 0.0 && z > 0.0f) z = static_cast<float>(q * std::round(z / q));
          const std::size_t i = v * n + static_cast<std::size_t>(y) * dw + x;
          if (half) {
            halves[i] = Imath::half(z);
          } else {
            floats[i] = z;
          }
        }
      }
    }
    auto view_pixels = [&](int v) -> const void* { return half ? static_cast<const void*>(halves.data() + v * n)
                                                               : static_cast<const void*>(floats.data() + v * n); };

    if (!with_openexr && own_compressions().contains(storage_.compression)) {
      exr_scanline::Attributes attributes;
      attributes.add_string("drapegen.units", kUnits);
      attributes.add_int("drapegen.views", views);
      attributes.add_int("drapegen.index", point.index);
      attributes.add_double("drapegen.orientation", point.orientation);
      attributes.add_string("drapegen.seed", std::to_string(point.seed));
      attributes.add_string("drapegen.noise", point.noise);
      attributes.add_string("drapegen.source", point.source);
      attributes.add_string("drapegen.storage", storage_text);
      exr_scanline::Image image;
      image.type = half ? exr_scanline::PixelType::kHalf : exr_scanline::PixelType::kFloat;
      image.x0 = x0;
      image.y0 = y0;
      image.x1 = x1;
      image.y1 = y1;
      for (int v = 0; v < views; ++v) {
        const ViewRecord& r = point.views[v];
        const std::string prefix = fmt::format("view{}.", v);
        float K[9], M[16];
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) K[3 * i + j] = static_cast<float>(r.camera.intrinsics.K(i, j));
        for (int i = 0; i < 4; ++i)
          for (int j = 0; j < 4; ++j) M[4 * i + j] = static_cast<float>(r.camera.world_to_camera.matrix()(i, j));
        attributes.add_m33f(prefix + "K", K);
        attributes.add_m44f(prefix + "meshToCamera", M);
        attributes.add_double(prefix + "tableAngle", r.table_angle);
        attributes.add_string(prefix + "noiseSeed", std::to_string(r.noise_seed));
        image.channel_names.push_back(channel_name(v));
        image.pixels.push_back(view_pixels(v));
      }
      return exr_scanline::write(image, W, H, own_compressions().at(storage_.compression), storage_.zip_level,
                                 attributes);
    }

    Imf::Header header(Imath::Box2i({0, 0}, {W - 1, H - 1}), Imath::Box2i({x0, y0}, {x1, y1}));
    header.compression() = compressions().at(storage_.compression);
    header.zipCompressionLevel() = storage_.zip_level;
    for (int v = 0; v < views; ++v)
      header.channels().insert(channel_name(v), Imf::Channel(half ? Imf::HALF : Imf::FLOAT));
    header.insert("drapegen.units", Imf::StringAttribute(kUnits));
    header.insert("drapegen.views", Imf::IntAttribute(views));
    header.insert("drapegen.index", Imf::IntAttribute(point.index));
    header.insert("drapegen.orientation", Imf::DoubleAttribute(point.orientation));
    header.insert("drapegen.seed", Imf::StringAttribute(std::to_string(point.seed)));
    header.insert("drapegen.noise", Imf::StringAttribute(point.noise));
    header.insert("drapegen.source", Imf::StringAttribute(point.source));
    header.insert("drapegen.storage", Imf::StringAttribute(storage_text));
    for (int v = 0; v < views; ++v) {
      const ViewRecord& r = point.views[v];
      const std::string prefix = fmt::format("view{}.", v);
      header.insert(prefix + "K", Imf::M33fAttribute(to_m33(r.camera.intrinsics.K)));
      header.insert(prefix + "meshToCamera", Imf::M44fAttribute(to_m44(r.camera.world_to_camera)));
      header.insert(prefix + "tableAngle", Imf::DoubleAttribute(r.table_angle));
      header.insert(prefix + "noiseSeed", Imf::StringAttribute(std::to_string(r.noise_seed)));
    }
    Imf::FrameBuffer fb;
    // Slices address pixel (x, y) of the data window at base + x * xStride + y * yStride.
    const std::ptrdiff_t origin = static_cast<std::ptrdiff_t>(y0) * dw + x0;
    for (int v = 0; v < views; ++v) {
      if (half) {
        fb.insert(channel_name(v), Imf::Slice(Imf::HALF, reinterpret_cast<char*>(halves.data() + v * n - origin),
                                              sizeof(Imath::half), sizeof(Imath::half) * dw));
      } else {
        fb.insert(channel_name(v), Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(floats.data() + v * n - origin),
                                              sizeof(float), sizeof(float) * dw));
      }
    }
    MemoryOStream stream;
    {
      Imf::OutputFile file(stream, header, 0);
      file.setFrameBuffer(fb);
      file.writePixels(dh);
    }
    return std::move(stream.data);
  } catch (const std::exception& e) {
    return sim::Error{fmt::format("EXR encoding failed: {}", e.what())};
  }
}

sim::Status ExrWriter::write_file(const std::string& path, const DataPointRecord& point) const {
  auto bytes = encode(point);
  if (!bytes) return bytes.error();
  // Through a synced temporary file: a reader (or a crash) never sees half an image.
  return storage::write_file_atomic(path, std::string_view(bytes->data(), bytes->size()));
}

sim::Expected<DataPointRecord> read_exr(const std::vector<char>& bytes) {
  try {
    MemoryIStream stream(bytes);
    return decode(stream);
  } catch (const std::exception& e) {
    return sim::Error{fmt::format("cannot read EXR data: {}", e.what())};
  }
}

sim::Expected<DataPointRecord> read_exr(const std::string& path) {
  try {
    Imf::StdIFStream stream(path.c_str());
    auto result = decode(stream);
    if (!result) return sim::Error{fmt::format("{}: {}", path, result.error().message)};
    return result;
  } catch (const std::exception& e) {
    return sim::Error{fmt::format("cannot read {}: {}", path, e.what())};
  }
}

}  // namespace drapegen::renderer
