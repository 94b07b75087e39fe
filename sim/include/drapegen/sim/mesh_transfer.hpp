#pragma once
// Transfer of a deformation between two triangulations of the same specimen.

#include <Eigen/Core>

#include "drapegen/sim/mesh.hpp"

namespace drapegen::sim {

/// World positions at the given rest points, interpolated linearly over the triangle of `from` that contains each
/// point in the rest frame (the nearest triangle for points just outside it, e.g. on a jittered border).
[[nodiscard]] Eigen::Matrix3Xd transfer_positions(const ClothMesh& from, const Eigen::Matrix2Xd& rest_points);

}  // namespace drapegen::sim
