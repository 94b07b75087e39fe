#pragma once
// A woven fabric's in-plane behaviour: stiff yarns, soft shear (the trellis mechanism). The alternative in-plane model
// for fabrics whose shear compliance matters (Cusick: drape depends on bending and shear; Clyde et al. 2017).

#include <Eigen/Core>
#include <vector>

#include "drapegen/sim/energy.hpp"
#include "drapegen/sim/membrane.hpp"
#include "drapegen/sim/mesh.hpp"

namespace drapegen::sim {

struct TrellisParameters {
  /// Yarn stretch along warp and weft: the same band energy as the isotropic membrane (stiffness sigma, kg/s^2,
  /// and the anti-locking band).
  MembraneParameters yarn;
  /// Shear stiffness G, kg/s^2 (N/m), for the change gamma of the angle between the yarns. Small G is a fabric that
  /// shears easily; G = sigma charges a pure shear what the isotropic membrane charges.
  double shear_stiffness = 20.0;
};

/// psi = A * [ sigma (g(|a|) + g(|b|)) + G (g(1 + s/2) + g(1 - s/2)) ],  s = sin(gamma) = a.b / (|a| |b|),
/// with a = F d_warp and b = F d_weft the deformed yarn vectors (F the 3x2 deformation gradient of a rest triangle,
/// d_warp and d_weft the yarn directions in rest coordinates from the mesh's material angle) and g the band energy of
/// CorotationalMembrane: a shear gamma stretches the cloth by 1 +- sin(gamma)/2 along the diagonals, charged with the
/// same anti-locking dead zone as the isotropic model (without it, the trellis locks). The Hessian is formed in the 6-D
/// space of the two deformed yarn vectors (exact, by forward-mode differentiation of the closed-form gradient) and
/// mapped to the triangle's 9 coordinates; the projected mode clamps the 6x6 eigenvalues at zero.
class TrellisMembrane final : public EnergyTerm {
 public:
  TrellisMembrane(const ClothMesh& mesh, const TrellisParameters& params);

  [[nodiscard]] std::string_view name() const override { return "trellis membrane"; }
  [[nodiscard]] int arity() const override { return 3; }
  [[nodiscard]] int element_count() const override { return static_cast<int>(triangles_.cols()); }
  void element_vertices(int element, int* out) const override;

  [[nodiscard]] double energy(const Eigen::Matrix3Xd& x) const override;
  double evaluate(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd* gradient, HessianSink* hessian) const override;

 private:
  Eigen::Matrix3Xi triangles_;
  /// Per triangle and vertex: the coefficients of the vertex in the deformed warp and weft yarn vectors.
  std::vector<Eigen::Matrix<double, 3, 2>> weights_;
  Eigen::VectorXd area_;
  TrellisParameters params_;
  CorotationalMembrane band_;  // for its stretch energy g
};

}  // namespace drapegen::sim
