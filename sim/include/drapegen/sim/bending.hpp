#pragma once
// Bending energies: the paper's nonlinear dihedral-angle model (Eq. 1-3) and the quadratic model (Eq. 4), both
// anisotropic by Eq. 8 with a bending direction per hinge (curvature-based or edge-based rule, Section 4.4).

#include <Eigen/Core>
#include <limits>
#include <vector>

#include "drapegen/sim/anisotropy.hpp"
#include "drapegen/sim/energy.hpp"
#include "drapegen/sim/mesh.hpp"

namespace drapegen::sim {

/// The torque law tau(kappa) = alpha * kappa + beta * kappa^2 per unit hinge length (alpha in N*m, beta in N*m^2).
///
/// Softening (beta < 0) makes the torque peak at kappa_peak = alpha / (2|beta|) and fall beyond it, which would be a
/// negative stiffness (alpha + 2 beta kappa <= 0) and a torque that changes sign. The model holds the torque at its
/// peak beyond kappa_peak instead: a plateau, like a yield moment. The energy stays C1 and convex in theta.
struct TorqueLaw {
  double alpha = 0.0;
  double beta = 0.0;

  /// Curvature where the plateau starts (infinity if beta >= 0).
  [[nodiscard]] double peak_curvature() const;
  [[nodiscard]] double torque(double kappa) const;     // kappa >= 0
  [[nodiscard]] double stiffness(double kappa) const;  // d torque / d kappa, >= 0
  /// Integral of the torque from 0 to kappa (energy per unit hinge length per unit of the curvature scale).
  [[nodiscard]] double work(double kappa) const;
};

/// Rest geometry shared by hinge-based models.
struct HingeRest {
  double edge_length = 0.0;   // e
  double height_sum = 0.0;    // H0 + H1 (rest heights of the two wings over the edge)
};

[[nodiscard]] std::vector<HingeRest> hinge_rest_geometry(const ClothMesh& mesh, const Topology& topology);

/// Per-direction bending moduli of the nonlinear dihedral model (SI units).
struct DihedralModuli {
  DirectionalValues alpha;  // N*m
  DirectionalValues beta;   // N*m^2
  [[nodiscard]] bool isotropic() const;
};

/// E_h = e * integral_0^|theta| tau(c xi) dxi with c = 2 / (H0 + H1), i.e. kappa = 2 theta / (H0 + H1) (Eq. 3).
class DihedralBending final : public EnergyTerm {
 public:
  DihedralBending(const ClothMesh& mesh, const Topology& topology, const DihedralModuli& moduli, AnisotropyRule rule);

  [[nodiscard]] std::string_view name() const override { return "bending"; }
  [[nodiscard]] int arity() const override { return 4; }
  [[nodiscard]] int element_count() const override { return static_cast<int>(hinges_.size()); }
  void element_vertices(int element, int* out) const override;

  /// Recomputes each hinge's bending direction (curvature rule) and its torque law by Eq. 8.
  double update_lagged(const Eigen::Matrix3Xd& x) override;
  /// Plastic flow (set_yield_curvature): the return mapping of every hinge loaded beyond its yield angle.
  double update_history(const Eigen::Matrix3Xd& x) override;
  /// False if a hinge's angle wraps (changes by more than pi) between the two states: folded through pi.
  [[nodiscard]] bool admissible_step(const Eigen::Matrix3Xd& from, const Eigen::Matrix3Xd& to) const;
  /// Includes each hinge's fold barrier (fold_barrier.hpp).
  [[nodiscard]] double energy(const Eigen::Matrix3Xd& x) const override;
  /// energy(to), or +infinity unless admissible_step(from, to); each hinge's angle at `to` is computed once.
  [[nodiscard]] double step_energy(const Eigen::Matrix3Xd& from, const Eigen::Matrix3Xd& to) const override;
  double evaluate(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd* gradient, HessianSink* hessian) const override;

  [[nodiscard]] const std::vector<TorqueLaw>& laws() const { return laws_; }
  [[nodiscard]] const Eigen::VectorXd& bending_angles() const { return phi_; }

  /// Rest dihedral angles (0 by default: flat): E_h = e * integral_0^|theta - theta_rest| tau(c xi) dxi. Edge curl
  /// sets them (edge_curl.hpp); plastic flow moves them.
  void set_rest_angles(const Eigen::VectorXd& angles);
  [[nodiscard]] const Eigen::VectorXd& rest_angles() const { return rest_angle_; }

  /// Elastoplastic hinges (bending hysteresis, internal friction): the torque cannot exceed the torque the hinge's
  /// law gives at `yield_curvature` (1/m). At every update_history() (at equilibrium: the solver's outer loop) a
  /// hinge loaded beyond it flows: its rest angle moves until the torque equals the yield torque (return mapping).
  /// Infinity (the default) is elastic.
  void set_yield_curvature(double yield_curvature);

 private:
  /// Sets every hinge's torque law from its bending angle; returns the largest relative change of alpha or beta.
  double assign_laws();
  /// Hinge i's energy at dihedral angle `angle`, fold barrier included.
  [[nodiscard]] double hinge_energy(std::size_t i, double angle) const;

  const ClothMesh* mesh_;
  const Topology* topology_;
  std::vector<Hinge> hinges_;
  std::vector<HingeRest> rest_;
  std::vector<TorqueLaw> laws_;
  Eigen::VectorXd phi_;
  DihedralModuli moduli_;
  AnisotropyRule rule_;
  Eigen::VectorXd rest_angle_;
  double yield_curvature_ = std::numeric_limits<double>::infinity();
};

/// Bergou et al. 2006 (paper Eq. 4): E_h = 3 gamma / ((H0 + H1) e) * |K x|^2 with the hinge's cotangent weights K.
/// Equal to the linear dihedral model for small angles when gamma = alpha / 3.
class QuadraticBending final : public EnergyTerm {
 public:
  QuadraticBending(const ClothMesh& mesh, const Topology& topology, const DirectionalValues& gamma,
                   AnisotropyRule rule);

  [[nodiscard]] std::string_view name() const override { return "bending"; }
  [[nodiscard]] int arity() const override { return 4; }
  [[nodiscard]] int element_count() const override { return static_cast<int>(hinges_.size()); }
  void element_vertices(int element, int* out) const override;
  double update_lagged(const Eigen::Matrix3Xd& x) override;
  [[nodiscard]] double energy(const Eigen::Matrix3Xd& x) const override;
  double evaluate(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd* gradient, HessianSink* hessian) const override;

 private:
  const ClothMesh* mesh_;
  const Topology* topology_;
  std::vector<Hinge> hinges_;
  std::vector<Eigen::Vector4d> weights_;  // cotangent weights per hinge vertex
  std::vector<double> scale_;             // 3 / ((H0 + H1) e)
  std::vector<double> gamma_;
  Eigen::VectorXd phi_;
  DirectionalValues gamma_dir_;
  AnisotropyRule rule_;
};

}  // namespace drapegen::sim
