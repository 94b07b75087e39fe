#include "drapegen/sim/edge_curl.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "drapegen/sim/dihedral.hpp"
#include "drapegen/sim/fold_barrier.hpp"

namespace drapegen::sim {
namespace {

/// The largest rest angle a hinge holds: where the fold barrier begins.
constexpr double kHeldAngle = std::numbers::pi - FoldBarrier::kWidth;

/// The rolled band's cross-section, by arc length s from where the band begins (s = width - d): the tangent turns
/// by phi(s) = curvature s^2 / (2 width) (the integral of k), so a point at s lies at (inward, up) = (integral of
/// cos phi, integral of sin phi). Tabulated once by the midpoint rule.
class RollProfile {
 public:
  explicit RollProfile(const EdgeCurl& curl) : curl_(curl) {
    double along = 0.0, up = 0.0;
    table_[0] = {0.0, 0.0};
    const double ds = curl.width / kSteps;
    for (int i = 0; i < kSteps; ++i) {
      const double s = (i + 0.5) * ds;
      const double phi = curl.curvature * s * s / (2.0 * curl.width);
      along += std::cos(phi) * ds;
      up += std::sin(phi) * ds;
      table_[i + 1] = {along, up};
    }
  }

  /// (inward offset, height) of a rest point at distance d inside the edge: flat beyond the band.
  [[nodiscard]] Eigen::Vector2d at(double d) const {
    if (d >= curl_.width) return {d, 0.0};
    const double s = curl_.width - std::max(d, 0.0);
    const double x = s / curl_.width * kSteps;
    const int i = std::min(kSteps - 1, static_cast<int>(x));
    const double t = x - i;
    const Eigen::Vector2d p = (1.0 - t) * table_[i] + t * table_[i + 1];  // from the band's start towards the edge
    return {curl_.width - p.x(), p.y()};
  }

 private:
  static constexpr int kSteps = 256;
  EdgeCurl curl_;
  std::array<Eigen::Vector2d, kSteps + 1> table_;
};

}  // namespace

Eigen::VectorXd edge_curl_rest_angles(const ClothMesh& mesh, const Topology& topology, const EdgeCurl& curl) {
  if (!std::isfinite(curl.curvature)) throw std::invalid_argument("edge curl: the curvature must be finite");
  if (!(curl.width > 0.0) || !std::isfinite(curl.width)) {
    throw std::invalid_argument("edge curl: the width must be positive and finite");
  }
  const RollProfile roll(curl);
  Eigen::VectorXd angles = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(topology.hinges.size()));
  for (std::size_t i = 0; i < topology.hinges.size(); ++i) {
    const Hinge& h = topology.hinges[i];
    const std::array<int, 4> v{h.v0, h.v1, h.v2, h.v3};
    const Eigen::Vector2d mid = 0.5 * (mesh.rest.col(h.v0) + mesh.rest.col(h.v1));
    // Nearest boundary edge of the hinge's midpoint: a point on it and its in-plane inward normal.
    double nearest = std::numeric_limits<double>::infinity();
    Eigen::Vector2d foot = Eigen::Vector2d::Zero(), inward = Eigen::Vector2d::Zero();
    for (const Eigen::Vector2i& e : topology.boundary_edges) {
      const Eigen::Vector2d p = mesh.rest.col(e[0]), q = mesh.rest.col(e[1]);
      const Eigen::Vector2d t = q - p;
      const double s = std::clamp((mid - p).dot(t) / t.squaredNorm(), 0.0, 1.0);
      const double d = (mid - (p + s * t)).norm();
      if (d < nearest) {
        nearest = d;
        foot = p;
        inward = Eigen::Vector2d(-t.y(), t.x()).normalized();  // boundary edges run counter-clockwise
      }
    }
    if (nearest >= curl.width) continue;
    // The hinge's four vertices on the rolled band of that edge (a developable surface: the rest state is one the
    // mesh can take without stretching), and the dihedral angle they make: consistent with how the hinge measures
    // the angle, whatever its direction on the grid. Curling up (+z) gives a negative angle.
    std::array<Eigen::Vector3d, 4> x;
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector2d r = mesh.rest.col(v[k]);
      const double d = (r - foot).dot(inward);
      const Eigen::Vector2d along = r - d * inward;  // its foot on the edge's line
      const Eigen::Vector2d rolled = roll.at(d);
      x[k] = Eigen::Vector3d(along.x() + rolled.x() * inward.x(), along.y() + rolled.x() * inward.y(), rolled.y());
    }
    // A roll tighter than the mesh resolves turns a hinge by pi or more, which the angle's range (-pi, pi] wraps to
    // the other sign: unwrap it by the roll's sense, then hold it where the fold barrier begins (the barrier would
    // push against a rest angle inside it, and set_rest_angles refuses one beyond pi).
    double theta = dihedral_angle(x[0], x[1], x[2], x[3]);
    const double sense = -std::copysign(1.0, curl.curvature);
    if (theta * sense < -0.5 * std::numbers::pi) theta += sense * 2.0 * std::numbers::pi;
    angles[static_cast<Eigen::Index>(i)] = std::clamp(theta, -kHeldAngle, kHeldAngle);
  }
  return angles;
}

}  // namespace drapegen::sim
