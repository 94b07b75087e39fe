#pragma once
// The interface every potential energy of the quasistatic problem implements.

#include <Eigen/Core>
#include <string_view>

namespace drapegen::sim {

/// How an element Hessian is formed.
enum class HessianMode {
  kExact,      // the true second derivative (used by derivative checks)
  kProjected,  // projected to positive semi-definite per element (what Newton uses)
  kGaussNewton,  // a cheaper positive semi-definite approximation where a term has one (bending: without the torque
                 // times the angle's second derivative), else as kProjected; for Newton far from equilibrium
};

/// Receives one dense element Hessian at a time, (3 * arity) x (3 * arity), column-major, vertex-major DOF order.
class HessianSink {
 public:
  virtual ~HessianSink() = default;
  [[nodiscard]] virtual HessianMode mode() const = 0;
  virtual void add(int element, const double* hessian) = 0;
};

/// A sum of per-element energies over vertex stencils of fixed arity. Positions are 3 x N in metres, energies in J.
class EnergyTerm {
 public:
  virtual ~EnergyTerm() = default;

  [[nodiscard]] virtual std::string_view name() const = 0;
  /// Vertices per element (1: per-vertex terms, 3: triangles, 4: hinges).
  [[nodiscard]] virtual int arity() const = 0;
  [[nodiscard]] virtual int element_count() const = 0;
  /// Writes the element's `arity()` vertex indices to `out`; -1 marks an unused slot (an element with fewer
  /// vertices than the arity, e.g. a border triangle's missing wing).
  virtual void element_vertices(int element, int* out) const = 0;
  /// Whether the term has a non-zero Hessian at all (gravity does not).
  [[nodiscard]] virtual bool has_hessian() const { return true; }

  /// Updates quantities that depend on the state but are held fixed while the energy is minimised (the bending
  /// directions of the curvature-based anisotropy). Returns the largest relative change of any element's parameters
  /// (0 for terms without such quantities). The energy is a fixed function of x between two calls.
  virtual double update_lagged(const Eigen::Matrix3Xd& /*x*/) { return 0.0; }
  /// Updates history variables that only the loads at equilibrium may change (a yielding bending term's plastic rest
  /// angles): called in the solver's outer loop alone, never on the way there, where the initial state and the
  /// unbalanced steps carry curvatures no load caused. Returns the largest relative change, as update_lagged does.
  virtual double update_history(const Eigen::Matrix3Xd& /*x*/) { return 0.0; }

  [[nodiscard]] virtual double energy(const Eigen::Matrix3Xd& x) const = 0;
  /// The energy at the end `to` of a straight step from `from`, or +infinity when the step leaves the region where
  /// the energy is defined (the line search shortens such steps): a hinge may not fold through the wrap of its
  /// dihedral angle at pi in one step (fold_barrier.hpp). One pass: the line search's cost per trial.
  [[nodiscard]] virtual double step_energy(const Eigen::Matrix3Xd& /*from*/, const Eigen::Matrix3Xd& to) const {
    return energy(to);
  }
  /// Returns the energy, adds the gradient into `gradient` (3 x N) when non-null and hands every element Hessian
  /// to `hessian` when non-null.
  virtual double evaluate(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd* gradient, HessianSink* hessian) const = 0;
};

}  // namespace drapegen::sim
