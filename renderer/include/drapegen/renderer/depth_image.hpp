#pragma once
// A depth image: camera-space z in metres per pixel, row-major from the top-left, 0 where there is no return.

#include <vector>

namespace drapegen::renderer {

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
};

}  // namespace drapegen::renderer
