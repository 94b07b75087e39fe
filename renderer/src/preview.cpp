#include "drapegen/renderer/preview.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fmt/format.h>

#include "drapegen/storage/png.hpp"

namespace drapegen::renderer {
namespace {

/// A perceptual-ish ramp from blue (far) through green and yellow to red (near); t in [0, 1].
std::array<double, 3> ramp(double t) {
  static constexpr std::array<std::array<double, 3>, 5> stops = {{{0.19, 0.25, 0.72},
                                                                  {0.13, 0.62, 0.85},
                                                                  {0.35, 0.78, 0.38},
                                                                  {0.96, 0.80, 0.25},
                                                                  {0.87, 0.27, 0.18}}};
  t = std::clamp(t, 0.0, 1.0) * (stops.size() - 1);
  const int i = std::min(static_cast<int>(t), static_cast<int>(stops.size()) - 2);
  const double f = t - i;
  return {stops[i][0] + f * (stops[i + 1][0] - stops[i][0]), stops[i][1] + f * (stops[i + 1][1] - stops[i][1]),
          stops[i][2] + f * (stops[i + 1][2] - stops[i][2])};
}

void paint(const DepthImage& img, std::vector<unsigned char>& rgb, int stride, int x0, int y0) {
  float lo = 1e30f, hi = 0.0f;
  for (float z : img.depth) {
    if (z > 0.0f) {
      lo = std::min(lo, z);
      hi = std::max(hi, z);
    }
  }
  const double range = hi > lo ? hi - lo : 1.0;
  const int W = img.width, H = img.height;
  auto depth = [&](int u, int v, float fallback) {
    if (u < 0 || u >= W || v < 0 || v >= H) return fallback;
    const float z = img.at(u, v);
    return z > 0.0f ? z : fallback;
  };
  const double light[3] = {-0.45, -0.55, 0.70};  // from the upper left, towards the camera
  for (int v = 0; v < H; ++v) {
    for (int u = 0; u < W; ++u) {
      const float z = img.at(u, v);
      unsigned char* p = &rgb[(static_cast<std::size_t>(y0 + v) * stride + x0 + u) * 3];
      if (!(z > 0.0f)) continue;
      // Normal from central differences, in units of pixels (x, y) and of the pixel footprint (z).
      const double footprint = z / 250.0;
      const double dzdu = (depth(u + 1, v, z) - depth(u - 1, v, z)) / (2.0 * footprint);
      const double dzdv = (depth(u, v + 1, z) - depth(u, v - 1, z)) / (2.0 * footprint);
      const double n[3] = {dzdu, dzdv, -1.0};
      const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + 1.0);
      const double lambert = std::max(0.0, -(n[0] * light[0] + n[1] * light[1] + n[2] * light[2]) / len);
      const double shade = 0.35 + 0.65 * lambert;
      const auto c = ramp(1.0 - (z - lo) / range);
      for (int k = 0; k < 3; ++k) p[k] = static_cast<unsigned char>(std::clamp(255.0 * c[k] * shade, 0.0, 255.0));
    }
  }
}

}  // namespace

sim::Status write_preview_png(const std::string& path, const std::vector<std::vector<DepthImage>>& rows) {
  if (rows.empty() || rows[0].empty()) return sim::Error{"preview: no images"};
  // Every cell is the largest image's size; a smaller image sits in its cell's top left corner (views may differ).
  int W = 0, H = 0;
  std::size_t columns = 0;
  for (const auto& row : rows) {
    columns = std::max(columns, row.size());
    for (const auto& img : row) {
      if (img.width <= 0 || img.height <= 0 || img.depth.size() != static_cast<std::size_t>(img.width) * img.height)
        return sim::Error{"preview: an image is empty or its pixels do not match its size"};
      W = std::max(W, img.width);
      H = std::max(H, img.height);
    }
  }
  const int gap = 2;
  const int width = static_cast<int>(columns) * (W + gap) - gap;
  const int height = static_cast<int>(rows.size()) * (H + gap) - gap;
  // Dark grey where no image is (the gaps between cells, the rest of a smaller image's cell); black where one is.
  std::vector<unsigned char> rgb(static_cast<std::size_t>(width) * height * 3, 64);
  for (std::size_t r = 0; r < rows.size(); ++r) {
    for (std::size_t c = 0; c < rows[r].size(); ++c) {
      const DepthImage& img = rows[r][c];
      const int x0 = static_cast<int>(c) * (W + gap), y0 = static_cast<int>(r) * (H + gap);
      for (int v = 0; v < img.height; ++v)
        std::memset(&rgb[(static_cast<std::size_t>(y0 + v) * width + x0) * 3], 0,
                    static_cast<std::size_t>(img.width) * 3);
      paint(img, rgb, width, x0, y0);
    }
  }

  return storage::write_png_rgb(path, width, height, rgb);
}

}  // namespace drapegen::renderer
