#pragma once
// The drape tester's platform: a cylinder with a rounded rim, and penalty contact of cloth vertices against it.

#include <Eigen/Core>

#include "drapegen/sim/energy.hpp"
#include "drapegen/sim/mesh.hpp"

namespace drapegen::sim {

/// A vertical cylinder whose top disk lies in z = 0, axis through the origin.
struct PlatformSpec {
  double radius = 0.05;       // m (the tester's 100 mm diameter)
  double height = 0.25;       // m (longer than a 300 mm specimen's corner overhang of ~162 mm)
  double fillet = 0.002;      // m, radius of the rounded rim
  double contact_offset = 0.001;  // m, the cloth rests this far from the surface (its half thickness)
  /// Penalty coefficient per unit vertex area, N/m^3: k_i = stiffness * A_i in the cubic penalty of
  /// PlatformContact (its stiffness at a penetration p is 2 k_i p / t).
  double contact_stiffness = 2e7;
};

/// Signed distance from p to the platform's surface (negative inside), with its gradient and Hessian.
struct PlatformDistance {
  double distance = 0.0;
  Eigen::Vector3d gradient = Eigen::Vector3d::Zero();
  Eigen::Matrix3d hessian = Eigen::Matrix3d::Zero();
};
[[nodiscard]] PlatformDistance platform_distance(const PlatformSpec& spec, const Eigen::Vector3d& p);

/// E = sum_i k_i / (3 t) * max(0, offset - d(x_i))^3 over the vertices, t = max(contact offset, 0.1 mm) (C2: no
/// Hessian jump where a vertex touches).
class PlatformContact final : public EnergyTerm {
 public:
  PlatformContact(const ClothMesh& mesh, const PlatformSpec& spec);

  [[nodiscard]] std::string_view name() const override { return "contact"; }
  [[nodiscard]] int arity() const override { return 1; }
  [[nodiscard]] int element_count() const override { return static_cast<int>(stiffness_.size()); }
  void element_vertices(int element, int* out) const override { *out = element; }
  [[nodiscard]] double energy(const Eigen::Matrix3Xd& x) const override;
  double evaluate(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd* gradient, HessianSink* hessian) const override;

  /// Deepest penetration below the contact offset over all vertices, m (0 if none).
  [[nodiscard]] double max_penetration(const Eigen::Matrix3Xd& x) const;
  /// Vertices within `tolerance` of resting on the top disk.
  [[nodiscard]] std::vector<int> vertices_on_top(const Eigen::Matrix3Xd& x, double tolerance) const;

 private:
  PlatformSpec spec_;
  Eigen::VectorXd stiffness_;
  double scale_ = 1e-3;  // penetration at which the stiffness is k_i
};

}  // namespace drapegen::sim
