#include "drapegen/diagnosis/depth_exr.hpp"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>

#include <cstdint>
#include <filesystem>
#include <fmt/format.h>
#include <string_view>

#include "drapegen/renderer/exr_memory_stream.hpp"
#include "drapegen/storage/atomic_file.hpp"

namespace drapegen::diagnosis {

sim::Expected<std::string> encode_depth_exr(const renderer::DepthImage& depth) {
  if (depth.width <= 0 || depth.height <= 0 ||
      depth.depth.size() != static_cast<std::size_t>(depth.width) * depth.height) {
    return sim::Error{fmt::format("bad depth image size {}x{}", depth.width, depth.height)};
  }
  try {
    Imf::Header header(depth.width, depth.height);
    header.channels().insert("Z", Imf::Channel(Imf::FLOAT));
    header.compression() = Imf::ZIP_COMPRESSION;
    header.insert("units", Imf::StringAttribute("metres, camera-space z, 0 = no return"));
    renderer::MemoryOStream stream;
    {
      Imf::OutputFile file(stream, header);
      Imf::FrameBuffer fb;
      fb.insert("Z", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(const_cast<float*>(depth.depth.data())),
                                sizeof(float), sizeof(float) * depth.width));
      file.setFrameBuffer(fb);
      file.writePixels(depth.height);
    }
    return std::string(stream.data.data(), stream.data.size());
  } catch (const std::exception& e) {
    return sim::Error{fmt::format("cannot encode: {}", e.what())};
  }
}

sim::Status write_depth_exr(const std::string& path, const renderer::DepthImage& depth) {
  const auto bytes = encode_depth_exr(depth);
  if (!bytes) return sim::Error{fmt::format("{}: {}", path, bytes.error().message)};
  return storage::write_file_atomic(path, *bytes);
}

sim::Expected<renderer::DepthImage> read_depth_exr(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return sim::Error{fmt::format("{}: no such file", path)};
  try {
    Imf::InputFile file(path.c_str());
    const Imf::Header& h = file.header();
    std::string channel = "Z";
    if (h.channels().findChannel("Z") == nullptr) {
      int count = 0;
      for (auto it = h.channels().begin(); it != h.channels().end(); ++it) {
        channel = it.name();
        ++count;
      }
      if (count != 1) return sim::Error{fmt::format("{}: no channel 'Z' (and not a single-channel file)", path)};
    }
    const Imath::Box2i display = h.displayWindow(), data = h.dataWindow();
    // In 64 bits: a hostile header's windows can span more than an int.
    const auto extent = [](int lo, int hi) { return static_cast<std::int64_t>(hi) - lo + 1; };
    const std::int64_t W64 = extent(display.min.x, display.max.x), H64 = extent(display.min.y, display.max.y);
    const std::int64_t dw64 = extent(data.min.x, data.max.x), dh64 = extent(data.min.y, data.max.y);
    if (W64 <= 0 || H64 <= 0 || W64 > 16384 || H64 > 16384) return sim::Error{fmt::format("{}: bad image size", path)};
    // The data window is read whole: one far larger than any image (30000^2 floats: 3.6 GB) is refused, not allocated.
    if (dw64 <= 0 || dh64 <= 0 || dw64 > 16384 || dh64 > 16384) {
      return sim::Error{fmt::format("{}: bad data window ({} x {} pixels)", path, dw64, dh64)};
    }
    const int W = static_cast<int>(W64), H = static_cast<int>(H64), dw = static_cast<int>(dw64),
              dh = static_cast<int>(dh64);
    std::vector<float> buffer(static_cast<std::size_t>(dw) * dh, 0.0f);
    Imf::FrameBuffer fb;
    char* base = reinterpret_cast<char*>(buffer.data()) - (static_cast<std::ptrdiff_t>(data.min.y) * dw + data.min.x) *
                                                              static_cast<std::ptrdiff_t>(sizeof(float));
    fb.insert(channel, Imf::Slice(Imf::FLOAT, base, sizeof(float), sizeof(float) * dw));
    file.setFrameBuffer(fb);
    file.readPixels(data.min.y, data.max.y);
    renderer::DepthImage image(W, H);
    for (int y = data.min.y; y <= data.max.y; ++y) {
      for (int x = data.min.x; x <= data.max.x; ++x) {
        if (x < display.min.x || x > display.max.x || y < display.min.y || y > display.max.y) continue;
        image.at(x - display.min.x, y - display.min.y) =
            buffer[static_cast<std::size_t>(y - data.min.y) * dw + (x - data.min.x)];
      }
    }
    return image;
  } catch (const std::exception& e) {
    return sim::Error{fmt::format("{}: not a readable OpenEXR depth file: {}", path, e.what())};
  }
}

}  // namespace drapegen::diagnosis
