#pragma once
// Coulomb friction between the cloth and the platform's top disk: the alternative to the adhesive boundary condition
// (Section 5.2.1 holds the vertices that start on the top fixed, as if static friction were unlimited).

#include <Eigen/Core>
#include <vector>

#include "drapegen/sim/energy.hpp"
#include "drapegen/sim/platform.hpp"

namespace drapegen::sim {

struct FrictionParameters {
  double coefficient = 0.3;  // Coulomb mu
  /// Tangential displacement below which the contact sticks elastically (the friction force grows linearly to mu N),
  /// m. Smooths the stick-slip transition so that the energy is C1.
  double stick_distance = 1e-4;
};

/// E = sum_v mu N_v f(|P (x_v - anchor_v)|) over the vertices that start on the top, with P the projection onto the
/// horizontal top plane, anchor_v the vertex's start position, f(u) = u^2 / (2 eps) below eps = stick_distance and
/// u - eps / 2 beyond: the force is mu N_v u / eps while sticking and mu N_v when sliding. The normal force N_v is
/// lagged (update_lagged reads it from the contact term at the current state: the upward component of its force), as
/// in incremental-potential friction. Every vertex that leaves the top (N_v = 0) carries no friction, also one that
/// slid over the rim onto the wall (pushed sideways only).
class PlatformFriction final : public EnergyTerm {
 public:
  PlatformFriction(const PlatformContact& contact, std::vector<int> vertices, const Eigen::Matrix3Xd& anchors,
                   const FrictionParameters& params);

  [[nodiscard]] std::string_view name() const override { return "friction"; }
  [[nodiscard]] int arity() const override { return 1; }
  [[nodiscard]] int element_count() const override { return static_cast<int>(vertices_.size()); }
  void element_vertices(int element, int* out) const override { *out = vertices_[element]; }

  /// Recomputes the normal forces; returns their largest change relative to the largest normal force.
  double update_lagged(const Eigen::Matrix3Xd& x) override;
  [[nodiscard]] double energy(const Eigen::Matrix3Xd& x) const override;
  double evaluate(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd* gradient, HessianSink* hessian) const override;

  [[nodiscard]] const Eigen::VectorXd& normal_forces() const { return normal_; }

 private:
  const PlatformContact* contact_;
  std::vector<int> vertices_;
  Eigen::Matrix2Xd anchors_;
  Eigen::VectorXd normal_;
  FrictionParameters params_;
};

}  // namespace drapegen::sim
