#include "drapegen/diagnosis/depth_exr.hpp"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>

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
    const int W = display.max.x - display.min.x + 1, H = display.max.y - display.min.y + 1;
    const int dw = data.max.x - data.min.x + 1, dh = data.max.y - data.min.y + 1;
    if (W <= 0 || H <= 0 || W > 16384 || H > 16384) return sim::Error{fmt::format("{}: bad image size", path)};
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
