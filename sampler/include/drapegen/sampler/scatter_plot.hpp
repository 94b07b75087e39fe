#pragma once
// A scatter plot of two features, generated (blue) over measured (orange), like the paper's Fig. 15, saved as PNG.

#include <string>
#include <vector>

#include "drapegen/sampler/parameters.hpp"
#include "drapegen/sim/expected.hpp"

namespace drapegen::sampler {

struct ScatterPlotSpec {
  int x_feature = 0;  // index into kFeatureNames
  int y_feature = 3;
  int width = 800, height = 640;
};

/// Draws generated points in blue and measured ones in orange (on top), with a frame, tick marks at whole numbers
/// of the feature (sign(k) ln|k|) and the axis names, and writes an 8-bit RGB PNG.
[[nodiscard]] sim::Status write_scatter_png(const std::string& path, const ScatterPlotSpec& spec,
                                            const std::vector<Features>& generated,
                                            const std::vector<Features>& measured);

}  // namespace drapegen::sampler
