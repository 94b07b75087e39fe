#include "drapegen/renderer/depth_image.hpp"

namespace drapegen::renderer {

PixelBox DepthImage::foreground_box() const {
  // Row by row from both ends: the rows' empty stretches are skipped with predictable branches.
  PixelBox box;
  for (int v = 0; v < height; ++v) {
    const float* row = depth.data() + static_cast<std::size_t>(v) * width;
    int first = 0;
    while (first < width && !(row[first] > 0.0f)) ++first;
    if (first == width) continue;
    int last = width - 1;
    while (!(row[last] > 0.0f)) --last;
    box.add(first, v, last, v);
  }
  return box;
}

}  // namespace drapegen::renderer
