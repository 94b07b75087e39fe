#pragma once
// Edge curl: a rest curvature near the free edges of the specimen (knitted and many woven fabrics curl at cut edges;
// Miguel et al. 2012 find the bending residual "often dominated by a difference in curl near the edge").

#include <Eigen/Core>

#include "drapegen/sim/mesh.hpp"

namespace drapegen::sim {

struct EdgeCurl {
  /// Rest curvature at the free edge, 1/m, about an axis along the edge; positive curls the edge towards +z of the
  /// specimen's rest frame (its face as it lies on the tester).
  double curvature = 0.0;
  /// Distance from the edge over which the rest curvature falls linearly to zero, m.
  double width = 0.01;
};

/// Rest dihedral angles of every hinge for DihedralBending::set_rest_angles: the rest curvature tensor near an edge
/// is k(d) n n^T, with n the in-plane normal of the nearest boundary edge and k(d) = curvature * max(0, 1 - d/width)
/// at rest distance d of the hinge's midpoint from the boundary; a hinge with in-plane edge normal m measures the
/// normal curvature k(d) (m.n)^2, i.e. a rest angle of that times (H0 + H1) / 2 (Eq. 3). Throws std::invalid_argument
/// on a non-finite curvature or a non-positive width.
[[nodiscard]] Eigen::VectorXd edge_curl_rest_angles(const ClothMesh& mesh, const Topology& topology,
                                                    const EdgeCurl& curl);

}  // namespace drapegen::sim
