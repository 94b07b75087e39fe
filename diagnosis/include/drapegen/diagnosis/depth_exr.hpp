#pragma once
// One depth image as a plain single-channel OpenEXR file: channel "Z", 32-bit float, camera-space z in metres,
// 0 = no return. Any tool can write it (e.g. OpenEXR's own, or Python's OpenEXR bindings).

#include <string>

#include "drapegen/renderer/depth_image.hpp"
#include "drapegen/sim/expected.hpp"

namespace drapegen::diagnosis {

/// The file's bytes (for a set of files written together).
[[nodiscard]] sim::Expected<std::string> encode_depth_exr(const renderer::DepthImage& depth);
[[nodiscard]] sim::Status write_depth_exr(const std::string& path, const renderer::DepthImage& depth);
/// Reads channel "Z" (or the file's only channel); the image is the display window, pixels outside the data window
/// are 0. Fails with a message on a missing or damaged file.
[[nodiscard]] sim::Expected<renderer::DepthImage> read_depth_exr(const std::string& path);

}  // namespace drapegen::diagnosis
