#pragma once
// A PNG for people: depth images side by side (one row per data point), coloured by depth and shaded by the
// surface slope, background black.

#include <string>
#include <vector>

#include "drapegen/renderer/depth_image.hpp"
#include "drapegen/sim/expected.hpp"

namespace drapegen::renderer {

/// Writes rows[r][c] at grid cell (r, c) (each cell the largest image's size, a smaller image in its top left
/// corner) to an 8-bit RGB PNG via libpng. Depth maps to
/// colour over the foreground's range in each image (near = warm), times a Lambertian shade of the normal
/// estimated from depth differences, so the folds stand out.
[[nodiscard]] sim::Status write_preview_png(const std::string& path,
                                            const std::vector<std::vector<DepthImage>>& rows);

}  // namespace drapegen::renderer
