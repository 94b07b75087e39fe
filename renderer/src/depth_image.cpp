#include "drapegen/renderer/depth_image.hpp"

namespace drapegen::renderer {
namespace {

/// Whether any of the n depths is a return. No early exit, so that the compiler vectorises it: the empty stretches
/// of a row (most of the image) are skipped several pixels per instruction.
bool any_return(const float* z, int n) {
  int count = 0;
  for (int i = 0; i < n; ++i) count += z[i] > 0.0f;
  return count > 0;
}

}  // namespace

PixelBox DepthImage::foreground_box() const {
  // Row by row: empty rows are skipped whole, the others searched from both ends a block at a time, then pixel by
  // pixel within the block that holds the first (last) return.
  constexpr int kBlock = 16;
  PixelBox box;
  for (int v = 0; v < height; ++v) {
    const float* row = depth.data() + static_cast<std::size_t>(v) * width;
    if (!any_return(row, width)) continue;
    int first = 0;
    while (first + kBlock <= width && !any_return(row + first, kBlock)) first += kBlock;
    while (!(row[first] > 0.0f)) ++first;
    int end = width;  // one past the last return
    while (end - kBlock > first && !any_return(row + end - kBlock, kBlock)) end -= kBlock;
    int last = end - 1;
    while (!(row[last] > 0.0f)) --last;
    box.add(first, v, last, v);
  }
  return box;
}

}  // namespace drapegen::renderer
