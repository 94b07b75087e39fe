#pragma once
// Gravity on lumped vertex masses from the areal density.

#include <Eigen/Core>

#include "drapegen/sim/energy.hpp"
#include "drapegen/sim/mesh.hpp"

namespace drapegen::sim {

constexpr double kStandardGravity = 9.81;  // m/s^2

/// E = sum_i m_i g z_i with m_i = rho * (lumped rest area of vertex i).
class Gravity final : public EnergyTerm {
 public:
  Gravity(const ClothMesh& mesh, double areal_density, double gravity = kStandardGravity);

  [[nodiscard]] std::string_view name() const override { return "gravity"; }
  [[nodiscard]] int arity() const override { return 1; }
  [[nodiscard]] int element_count() const override { return static_cast<int>(weight_.size()); }
  void element_vertices(int element, int* out) const override { *out = element; }
  [[nodiscard]] bool has_hessian() const override { return false; }
  [[nodiscard]] double energy(const Eigen::Matrix3Xd& x) const override;
  double evaluate(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd* gradient, HessianSink* hessian) const override;

  /// Weight of every vertex, N.
  [[nodiscard]] const Eigen::VectorXd& vertex_weights() const { return weight_; }

 private:
  Eigen::VectorXd weight_;
};

}  // namespace drapegen::sim
