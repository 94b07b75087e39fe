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

/// Rest dihedral angles of every hinge for DihedralBending::set_rest_angles. The rest shape near an edge is a roll
/// about the edge: the curvature across it is k(d) = curvature * max(0, 1 - d/width) at rest distance d from the
/// edge, bending the band isometrically (a developable surface the mesh can take without stretching). A hinge
/// within the band of its midpoint's nearest boundary edge gets the dihedral angle its four vertices make on that
/// roll, so the rest angles are those of a realisable shape on any triangulation (a per-hinge normal curvature times
/// (H0 + H1) / 2 is not: on right-triangle grids the diagonals of a cylindrically bent strip stay flat, and such
/// rest angles fight each other). A roll tighter than the mesh resolves (a hinge turned by more than
/// pi - FoldBarrier::kWidth, e.g. 450 /m over 30 mm at 12.5 mm spacing) is held at that angle, with the roll's sign.
/// Throws std::invalid_argument on a non-finite curvature or a non-positive width.
[[nodiscard]] Eigen::VectorXd edge_curl_rest_angles(const ClothMesh& mesh, const Topology& topology,
                                                    const EdgeCurl& curl);

}  // namespace drapegen::sim
