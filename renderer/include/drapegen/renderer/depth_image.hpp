#pragma once
// A depth image: camera-space z in metres per pixel, row-major from the top-left, 0 where there is no return.

#include <algorithm>
#include <limits>
#include <vector>

namespace drapegen::renderer {

/// An inclusive rectangle of pixels (u0..u1, v0..v1); empty when u0 > u1 or v0 > v1 (as made).
struct PixelBox {
  int u0 = std::numeric_limits<int>::max(), v0 = std::numeric_limits<int>::max();
  int u1 = std::numeric_limits<int>::min(), v1 = std::numeric_limits<int>::min();

  [[nodiscard]] bool empty() const { return u0 > u1 || v0 > v1; }
  /// Grows the box to contain the pixels (a0..a1, b0..b1).
  void add(int a0, int b0, int a1, int b1) {
    u0 = std::min(u0, a0);
    v0 = std::min(v0, b0);
    u1 = std::max(u1, a1);
    v1 = std::max(v1, b1);
  }
  void add(const PixelBox& other) { add(other.u0, other.v0, other.u1, other.v1); }
};

struct DepthImage {
  int width = 0;
  int height = 0;
  /// Camera-space z (along the optical axis, not the ray length), metres; 0: nothing hit / no return.
  std::vector<float> depth;
  /// Cosine of the angle between the viewing ray and the surface normal, in [0, 1] where hit, 0 elsewhere. Filled
  /// by the renderers (the noise model needs it); empty after noise or reading a file.
  std::vector<float> incidence;

  DepthImage() = default;
  DepthImage(int w, int h) : width(w), height(h), depth(static_cast<std::size_t>(w) * h, 0.0f) {}

  [[nodiscard]] float at(int u, int v) const { return depth[static_cast<std::size_t>(v) * width + u]; }
  [[nodiscard]] float& at(int u, int v) { return depth[static_cast<std::size_t>(v) * width + u]; }
  [[nodiscard]] int foreground_count() const {
    int n = 0;
    for (float z : depth) n += z > 0.0f;
    return n;
  }
  /// The smallest box holding every pixel with a return (empty if none).
  [[nodiscard]] PixelBox foreground_box() const;
};

}  // namespace drapegen::renderer
