#pragma once
// The paper's nonlinear anisotropic bending law (Eq. 1-3, 8) on per-triangle curvature tensors, a discretisation
// that is exact for quadratic surfaces on any triangulation without interior vertices of valence 3.
//
// To first order the three dihedral angles around a triangle are linear in a constant curvature tensor K:
// theta_i = b_i . (K_xx, K_xy, K_yy), with b_i from the rest geometry of hinge i. Solving that 3 x 3 system gives
// the triangle's K_T, and the triangle stores the energy density
//   W = psi_phi(kappa_d) + psi_phi+90(kappa_p) + alpha_t kappa_t^2,
// kappa_d = d.K d along its bending direction d (curvature rule: the greater principal directions of its three
// vertices, Meyer et al. 2003, as the hinge model), kappa_p across it, kappa_t = d.K p the twist, psi the work of
// the torque law alpha kappa + beta kappa^2 in that direction (Eq. 8 interpolation) and alpha_t the mean of the two
// directions' alpha. For isotropic linear bending W = (alpha/2)|K|^2. The hinge model (DihedralBending) measures
// curvature per hinge instead, and on right-triangle grids picks up twist that depends on the diagonals
// (docs/PHYSICS.md). A triangle at the border has only one or two hinges: the components of K they do not measure
// take the values of least linear bending energy (zero moment across the free edge, its natural boundary
// condition), so the whole specimen is one model and no hinge energy remains. Around an interior vertex of valence
// 3 two hinges of each triangle share their wing, so their angles are of the same four vertices and measure one
// bending mode: the second is left out as a free edge is, and those triangles are no longer exact (the grids and
// lattices the specimen generator makes have no such vertex; a PLY mesh may).

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "drapegen/sim/anisotropy.hpp"
#include "drapegen/sim/bending.hpp"
#include "drapegen/sim/energy.hpp"
#include "drapegen/sim/mesh.hpp"

namespace drapegen::sim {

class TriangleCurvatureBending final : public EnergyTerm {
 public:
  /// Throws std::invalid_argument on invalid moduli, the edge rule (a hinge concept) with anisotropic moduli, or a
  /// degenerate curvature system.
  TriangleCurvatureBending(const ClothMesh& mesh, const Topology& topology, const DihedralModuli& moduli,
                           AnisotropyRule rule);

  [[nodiscard]] std::string_view name() const override { return "triangle bending"; }
  [[nodiscard]] int arity() const override { return 6; }
  [[nodiscard]] int element_count() const override { return static_cast<int>(elements_.size()); }
  /// The triangle, then its wings; -1 for a border triangle's missing wings (and a wing left out around a vertex of
  /// valence 3). No vertex appears twice.
  void element_vertices(int element, int* out) const override;
  /// Recomputes each triangle's bending direction (curvature rule) and its torque laws.
  double update_lagged(const Eigen::Matrix3Xd& x) override;
  [[nodiscard]] double energy(const Eigen::Matrix3Xd& x) const override { return evaluate(x, nullptr, nullptr); }
  double evaluate(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd* gradient, HessianSink* hessian) const override;


 private:
  struct Element {
    int vertices[6];             // triangle (0-2), then the wing across each hinge (3-5; -1 where none)
    int hinge_count = 0;         // 3 inside, 1 or 2 at the border
    Hinge hinge[3];              // each hinge in the topology's vertex order
    int slot[3][4];              // hinge vertex -> element slot
    Eigen::Matrix3d constraint;  // row i: d theta_i / d (K_xx, K_xy, K_yy) (rows past hinge_count: zero)
    Eigen::Matrix3d to_tensor;   // (K_xx, K_xy, K_yy) = to_tensor * theta
    double area = 0.0;
    Eigen::Matrix3d measure;     // rows: d kappa_d, d kappa_p, d kappa_t / d theta
    TorqueLaw along, across;     // laws in the bending direction and across it
    double twist = 0.0;          // alpha_t
  };
  /// Sets the laws and curvature measures of element e (and a border triangle's tensor map) for bending direction
  /// d (rest frame, unit); returns the relative change of its moduli.
  double assign(Element& e, const Eigen::Vector2d& d) const;

  const ClothMesh* mesh_;
  const Topology* topology_;
  DihedralModuli moduli_;
  AnisotropyRule rule_;
  std::vector<Element> elements_;
  AnisotropyWorkspace workspace_;
};

}  // namespace drapegen::sim
