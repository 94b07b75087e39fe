#pragma once
// One drape to its data points: the tester scene rendered from every planned view, the noise applied, ready for
// ExrWriter. This is the call a worker makes per drape.

#include <cstdint>
#include <string>
#include <vector>

#include "drapegen/renderer/exr.hpp"
#include "drapegen/renderer/noise.hpp"
#include "drapegen/renderer/renderer.hpp"
#include "drapegen/renderer/rig.hpp"

namespace drapegen::renderer {

struct RenderRequest {
  RigSpec rig;
  AugmentationSpec augmentation;
  NoiseModel noise = NoiseModel::kinect();
  std::uint64_t seed = 0;
  std::string source;  // stored in the EXR header
};

/// Fails if any cloth vertex falls outside the unperturbed camera's image (or behind it) at any planned table
/// angle: the drape does not fit the view (or is not in metres); or if every vertex lies inside the platform's
/// cylinder, where no camera sees the cloth (the views would hold the platform alone).
[[nodiscard]] sim::Status check_in_view(const TriangleMesh& cloth, const RigSpec& rig,
                                        const std::vector<DataPointSetup>& setups);

/// Renders `cloth` (plus the cylinder) for every data point of `request`. If `clean` is given it receives the
/// noise-free images (one vector of views per data point).
[[nodiscard]] sim::Expected<std::vector<DataPointRecord>> render_data_points(
    Renderer& renderer, const TriangleMesh& cloth, const RenderRequest& request,
    std::vector<std::vector<DepthImage>>* clean = nullptr);

}  // namespace drapegen::renderer
