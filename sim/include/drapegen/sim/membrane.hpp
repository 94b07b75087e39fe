#pragma once
// In-plane elasticity: corotational linear FEM on triangles with an adaptive reference state (paper Section 4.1).

#include <Eigen/Core>
#include <vector>

#include "drapegen/sim/energy.hpp"
#include "drapegen/sim/mesh.hpp"

namespace drapegen::sim {

struct MembraneParameters {
  /// In-plane stiffness sigma, kg/s^2 (N/m). The paper's default is 200.
  double stiffness = 200.0;
  /// Principal stretches inside [band_low, band_high] are absorbed by the reference state (anti-locking, Fig. 9).
  /// Set both to 1 for a plain corotational model.
  double band_low = 0.99;
  double band_high = 1.01;
  /// Stiffness left inside the band, relative to `stiffness` (keeps the Newton system non-singular).
  double band_stiffness_ratio = 0.01;
};

/// The in-plane model interface: later variants (orthotropic, low shear) implement the same EnergyTerm.
///
/// The paper lets the reference state follow the deformation within a stretch band [0.99, 1.01]. Adapting the
/// reference of a triangle to its current principal stretches clamped to the band, until nothing changes, reaches
/// the state that minimises the band ("dead zone") energy below; this class solves that energy directly, so Newton
/// sees the true problem instead of a lagged one:
///
///   psi(F) = A * sum_i g(s_i),  g'' = 2 sigma * eps inside [low, high], 2 sigma beyond, with a linear ramp between
///   over half a band width (so that g is C2 and Newton's quadratic model has no jump where a stretch leaves the band),
///
/// with s_i the singular values of the deformation gradient F (3x2) of the rest triangle. Without a band this is the
/// corotational energy sigma * A * |F - R|^2. A small stiffness eps * sigma inside the band keeps in-plane modes from
/// being singular. The Hessian comes from the analytic eigen-system of a singular-value energy (stretch, twist, flip
/// and out-of-plane modes), so its projection to PSD costs nothing.
class CorotationalMembrane final : public EnergyTerm {
 public:
  CorotationalMembrane(const ClothMesh& mesh, const MembraneParameters& params);

  [[nodiscard]] std::string_view name() const override { return "membrane"; }
  [[nodiscard]] int arity() const override { return 3; }
  [[nodiscard]] int element_count() const override { return static_cast<int>(triangles_.cols()); }
  void element_vertices(int element, int* out) const override;

  [[nodiscard]] double energy(const Eigen::Matrix3Xd& x) const override;
  double evaluate(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd* gradient, HessianSink* hessian) const override;

  /// g(s) / (sigma A), its first and second derivative: the energy density of one principal stretch.
  struct StretchEnergy {
    double value, first, second;
  };
  [[nodiscard]] StretchEnergy stretch_energy(double s) const;

 private:
  [[nodiscard]] Eigen::Matrix<double, 3, 2> deformation_gradient(const Eigen::Matrix3Xd& x, int t) const;

  Eigen::Matrix3Xi triangles_;
  std::vector<RestTriangle> rest_;
  MembraneParameters params_;
};

}  // namespace drapegen::sim
