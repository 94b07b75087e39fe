#pragma once
// 8-bit RGB images as PNG files (previews, residual maps, plots), written atomically like every other output.

#include <span>
#include <string>

#include "drapegen/sim/expected.hpp"

namespace drapegen::storage {

/// PNG bytes of a width x height image: `rgb` holds the rows top to bottom, 3 bytes per pixel.
[[nodiscard]] sim::Expected<std::string> encode_png_rgb(int width, int height, std::span<const unsigned char> rgb);
/// encode_png_rgb, then write_file_atomic. Errors name the path.
[[nodiscard]] sim::Status write_png_rgb(const std::string& path, int width, int height,
                                        std::span<const unsigned char> rgb);

}  // namespace drapegen::storage
