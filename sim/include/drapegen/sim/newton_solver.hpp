#pragma once
// Newton-Raphson on the total potential energy: projected Hessians, CHOLMOD, line search and a regularised fallback.

#include <Eigen/Core>
#include <functional>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "drapegen/sim/energy.hpp"
#include "drapegen/sim/expected.hpp"

namespace drapegen::sim {

enum class SolveOutcome {
  kConverged,            // residual below tolerance
  kIterationLimit,       // max_iterations reached first
  kStalled,              // no step lowered the energy (even with the strongest regularisation), or steps stopped moving
  kDiverged,             // non-finite energy, gradient or step
  kFactorizationFailed,  // CHOLMOD failed for a reason other than indefiniteness
};
[[nodiscard]] std::string_view to_string(SolveOutcome outcome);

struct SolverOptions {
  int max_iterations = 600;  // the softest fabrics slide for up to ~460 iterations (docs/BENCHMARKS.md)
  /// Converged when the largest unbalanced force on a free vertex is below tolerance * the largest vertex weight.
  double tolerance = 1e-3;
  double armijo = 1e-4;
  int max_line_search = 30;
  /// Largest vertex displacement of one step, m (keeps penalty contact from being stepped through).
  double max_step = 0.01;
  /// Diagonal shift, relative to the mean diagonal, at which the solver gives up (kStalled).
  double max_regularization = 1e6;
  /// Below this residual, try the exact (unprojected) Hessian first: near a stable equilibrium it is positive
  /// definite and restores quadratic convergence; where CHOLMOD finds it indefinite, the projected one is used.
  double exact_hessian_below = 1.0;
  /// Above this residual, Gauss-Newton element Hessians where a term has them (HessianMode::kGaussNewton); between
  /// the two thresholds, element Hessians projected to PSD.
  double gauss_newton_above = std::numeric_limits<double>::infinity();
  /// State-dependent parameters (anisotropy directions, EnergyTerm::update_lagged) are updated at every iteration
  /// while the residual is above `lagged_every_above`; below it, only once the residual has dropped under
  /// `lagged_outer_below` for the current parameters (an outer fixed-point loop), until the parameters change by
  /// less than `lagged_tolerance` (relative); then they stay fixed and Newton converges on one energy.
  double lagged_every_above = 10.0;
  /// ... but only in the first `lagged_every_iterations` iterations: a parameter field that keeps changing (strong
  /// anisotropy where principal directions are ill-defined) would otherwise make Newton chase a moving energy.
  int lagged_every_iterations = 30;
  double lagged_outer_below = 3.0;
  double lagged_tolerance = 1e-3;
  /// Inexact Newton with a stale preconditioner: the step solves the current Hessian by conjugate gradients,
  /// preconditioned by the last factorisation, to min(`pcg_tolerance`, residual) relative to |g|; when that takes
  /// more than `max_pcg_iterations` (or meets negative curvature) the Hessian is factorised afresh. 0 factorises at
  /// every iteration.
  int max_pcg_iterations = 20;
  double pcg_tolerance = 0.1;
  /// After a PCG solve that needed more than this fraction of max_pcg_iterations, the next iteration factorises
  /// without trying PCG first (1: always try).
  double pcg_refactor_fraction = 0.5;
  /// After a full step (t = 1) that lowered the energy by more than `extrapolate_above` of its first-order prediction
  /// (the energy is flatter along the step than the Hessian says: a fold sliding along a soft valley), try the step
  /// length where the parabola through E(0), E'(0) and E(1) has its minimum, up to `max_extrapolation` (and the
  /// max_step limit), and keep it if the energy is lower there. 0 turns it off.
  double extrapolate_above = 0.75;
  double max_extrapolation = 8.0;
  /// Outer updates after which the parameters are fixed anyway (directions in nearly flat regions can cycle).
  int max_lagged_outer_updates = 6;

  [[nodiscard]] bool operator==(const SolverOptions&) const = default;
};

/// Options a solve can run with: positive finite tolerance, step and thresholds, at least one iteration. A zero or
/// negative max_step passes the line search's test with a zero or uphill step; a NaN tolerance never converges.
[[nodiscard]] Status validate(const SolverOptions& options);

struct SolveReport {
  SolveOutcome outcome = SolveOutcome::kIterationLimit;
  int iterations = 0;
  double seconds = 0.0;
  double assembly_seconds = 0.0;
  double factorization_seconds = 0.0;
  double residual = 0.0;          // relative, as in SolverOptions::tolerance
  double energy = 0.0;            // J
  int regularized_iterations = 0;  // iterations that needed a diagonal shift
  int exact_hessian_iterations = 0;  // iterations that stepped with the unprojected Hessian
  int lagged_updates = 0;            // updates of state-dependent parameters
  int reused_factorizations = 0;     // iterations that stepped with an earlier factorisation (by PCG)
  int pcg_iterations = 0;            // conjugate-gradient iterations (also of PCG attempts that failed)
  int pcg_failures = 0;              // PCG attempts that failed (too many iterations, negative curvature)
  double pcg_seconds = 0.0;
  double lagged_change = 0.0;        // relative change at the last update
  /// The state-dependent parameters were fixed by `max_lagged_outer_updates` while the last update still changed
  /// them by `lagged_tolerance` or more: a converged solve is an equilibrium of the energy with those parameters, not
  /// a fixed point of their update (plastic flow still under way, directions cycling). Never set for a solve whose
  /// parameters settled.
  bool lagged_capped = false;
  int line_search_failures = 0;
  std::string message;

  /// Adds the work counters (iterations, times, counts) of another solve, for reports that span several solves.
  void add_work(const SolveReport& other);
};

struct IterationInfo {
  int iteration;
  double energy;
  double residual;
  double step_length;
  double regularization;
};

/// Minimises sum of `terms` over the vertices not in `fixed`, starting from and writing to `x`.
/// `reference_force` is the force scale of the residual test (the largest vertex weight, N).
class NewtonSolver {
 public:
  explicit NewtonSolver(SolverOptions options = {}) : options_(options) {}
  void set_progress(std::function<void(const IterationInfo&)> callback) { progress_ = std::move(callback); }

  SolveReport solve(const std::vector<EnergyTerm*>& terms, const std::vector<bool>& fixed, double reference_force,
                    Eigen::Matrix3Xd& x) const;

 private:
  SolverOptions options_;
  std::function<void(const IterationInfo&)> progress_;
};

}  // namespace drapegen::sim
