#include "drapegen/renderer/renderer.hpp"

#include <fmt/format.h>

namespace drapegen::renderer {

sim::Status check_view(const Camera& camera, const Eigen::Isometry3d& model) {
  const int W = camera.intrinsics.width, H = camera.intrinsics.height;
  if (W <= 0 || H <= 0 || W > 8192 || H > 8192) return sim::Error{fmt::format("bad image size {}x{}", W, H)};
  if (!camera.intrinsics.K.allFinite() || !camera.world_to_camera.matrix().allFinite() || !model.matrix().allFinite()) {
    return sim::Error{"camera or model pose is not finite"};
  }
  return {};
}

}  // namespace drapegen::renderer
