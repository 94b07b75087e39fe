#include "drapegen/sim/edge_curl.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "drapegen/sim/bending.hpp"

namespace drapegen::sim {

Eigen::VectorXd edge_curl_rest_angles(const ClothMesh& mesh, const Topology& topology, const EdgeCurl& curl) {
  if (!std::isfinite(curl.curvature)) throw std::invalid_argument("edge curl: the curvature must be finite");
  if (!(curl.width > 0.0) || !std::isfinite(curl.width)) {
    throw std::invalid_argument("edge curl: the width must be positive and finite");
  }
  const std::vector<HingeRest> rest = hinge_rest_geometry(mesh, topology);
  Eigen::VectorXd angles = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(topology.hinges.size()));
  for (std::size_t i = 0; i < topology.hinges.size(); ++i) {
    const Hinge& h = topology.hinges[i];
    const Eigen::Vector2d a = mesh.rest.col(h.v0), b = mesh.rest.col(h.v1);
    const Eigen::Vector2d mid = 0.5 * (a + b);
    // Nearest boundary edge: its distance and in-plane normal.
    double nearest = std::numeric_limits<double>::infinity();
    Eigen::Vector2d normal = Eigen::Vector2d::Zero();
    for (const Eigen::Vector2i& e : topology.boundary_edges) {
      const Eigen::Vector2d p = mesh.rest.col(e[0]), q = mesh.rest.col(e[1]);
      const Eigen::Vector2d t = q - p;
      const double s = std::clamp((mid - p).dot(t) / t.squaredNorm(), 0.0, 1.0);
      const double d = (mid - (p + s * t)).norm();
      if (d < nearest) {
        nearest = d;
        normal = Eigen::Vector2d(t.y(), -t.x()).normalized();
      }
    }
    const double k = curl.curvature * std::max(0.0, 1.0 - nearest / curl.width);
    if (k == 0.0) continue;
    const Eigen::Vector2d edge = (b - a).normalized();
    const Eigen::Vector2d m(edge.y(), -edge.x());
    const double c = m.dot(normal);
    // The dihedral angle is negative where the wings lift along their (+z) normals: curling up is a negative angle.
    angles[static_cast<Eigen::Index>(i)] = -k * c * c * 0.5 * rest[i].height_sum;
  }
  return angles;
}

}  // namespace drapegen::sim
