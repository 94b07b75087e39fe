#include "drapegen/sim/newton_solver.hpp"

#include <chrono>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "drapegen/sim/hessian_assembler.hpp"
#include "drapegen/sim/logging.hpp"
#include "drapegen/sim/sparse_cholesky.hpp"

namespace drapegen::sim {

std::string_view to_string(SolveOutcome outcome) {
  switch (outcome) {
    case SolveOutcome::kConverged: return "converged";
    case SolveOutcome::kIterationLimit: return "iteration_limit";
    case SolveOutcome::kStalled: return "stalled";
    case SolveOutcome::kDiverged: return "diverged";
    case SolveOutcome::kFactorizationFailed: return "factorization_failed";
  }
  return "unknown";
}

void SolveReport::add_work(const SolveReport& other) {
  iterations += other.iterations;
  seconds += other.seconds;
  assembly_seconds += other.assembly_seconds;
  factorization_seconds += other.factorization_seconds;
  pcg_seconds += other.pcg_seconds;
  regularized_iterations += other.regularized_iterations;
  exact_hessian_iterations += other.exact_hessian_iterations;
  lagged_updates += other.lagged_updates;
  reused_factorizations += other.reused_factorizations;
  pcg_iterations += other.pcg_iterations;
  pcg_failures += other.pcg_failures;
  line_search_failures += other.line_search_failures;
}

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

/// The energy at the end of a straight step from `from` to `to`; infinite if a term rules the step out
/// (EnergyTerm::step_energy), so that the line search shortens it like any step that fails.
double trial_energy(const std::vector<EnergyTerm*>& terms, const Eigen::Matrix3Xd& from, const Eigen::Matrix3Xd& to) {
  double e = 0.0;
  for (const EnergyTerm* t : terms) {
    e += t->step_energy(from, to);
    if (!std::isfinite(e)) break;  // ruled out (or not a number): the line search shortens the step
  }
  return e;
}

/// Preconditioned conjugate gradients on (A + shift I) step = -g, preconditioned by a factorisation of an earlier
/// matrix. Succeeds when the residual drops below `tolerance` * |g| within `max_iterations`; fails on negative
/// curvature or a failed solve. `iterations` counts the matrix products.
bool preconditioned_cg(const HessianAssembler& a, double shift, SparseCholesky& preconditioner,
                       const Eigen::VectorXd& g, double tolerance, int max_iterations, Eigen::VectorXd& step,
                       int& iterations) {
  const int n = static_cast<int>(g.size());
  Eigen::VectorXd r = -g, z(n), p(n), ap(n);
  step.setZero(n);
  iterations = 0;
  if (!preconditioner.solve_approximate(r, z)) return false;
  p = z;
  double rz = r.dot(z);
  const double goal = tolerance * g.norm();
  while (iterations < max_iterations) {
    a.multiply(p, ap, shift);
    ++iterations;
    const double pap = p.dot(ap);
    if (!(pap > 0.0)) return false;
    const double step_size = rz / pap;
    step += step_size * p;
    r -= step_size * ap;
    if (r.norm() <= goal) return step.allFinite();
    if (!preconditioner.solve_approximate(r, z)) return false;
    const double rz_next = r.dot(z);
    p = z + (rz_next / rz) * p;
    rz = rz_next;
  }
  return false;
}

}  // namespace

Status validate(const SolverOptions& o) {
  const auto positive = [](double v) { return v > 0.0 && std::isfinite(v); };
  if (o.max_iterations < 1) return Error{"solver: max_iterations must be at least 1"};
  if (!positive(o.tolerance)) return Error{"solver: tolerance must be positive and finite"};
  if (!positive(o.max_step)) return Error{"solver: max_step must be positive and finite"};
  if (!(o.armijo > 0.0 && o.armijo < 1.0)) return Error{"solver: armijo must be in (0, 1)"};
  if (o.max_line_search < 1) return Error{"solver: max_line_search must be at least 1"};
  if (!positive(o.max_regularization)) return Error{"solver: max_regularization must be positive and finite"};
  if (!positive(o.lagged_tolerance)) return Error{"solver: lagged_tolerance must be positive and finite"};
  if (o.max_lagged_outer_updates < 1) return Error{"solver: max_lagged_outer_updates must be at least 1"};
  if (!(o.pcg_tolerance > 0.0 && o.pcg_tolerance < 1.0)) return Error{"solver: pcg_tolerance must be in (0, 1)"};
  if (o.max_pcg_iterations < 0) return Error{"solver: max_pcg_iterations must not be negative"};
  for (const double threshold : {o.exact_hessian_below, o.gauss_newton_above, o.lagged_every_above,
                                 o.lagged_outer_below, o.extrapolate_above, o.max_extrapolation,
                                 o.pcg_refactor_fraction}) {
    if (std::isnan(threshold) || threshold < 0.0) return Error{"solver: thresholds must not be negative or NaN"};
  }
  return {};
}

SolveReport NewtonSolver::solve(const std::vector<EnergyTerm*>& terms, const std::vector<bool>& fixed,
                                double reference_force, Eigen::Matrix3Xd& x) const {
  const auto start = Clock::now();
  SolveReport report;
  const int nv = static_cast<int>(x.cols());
  std::vector<const EnergyTerm*> const_terms(terms.begin(), terms.end());
  HessianAssembler assembler(nv, fixed, const_terms);
  SparseCholesky cholesky;
  const int n = assembler.dof_count();
  Eigen::Matrix3Xd gradient(3, nv);
  Eigen::VectorXd g(n), step(n);
  Eigen::Matrix3Xd trial(3, nv);
  double lambda = 0.0;  // diagonal shift relative to the mean diagonal
  // After a full step accepted into x (= x0 + step), `largest` its largest vertex displacement: returns the step
  // length kept, 1 or longer (then x moved on).
  auto extrapolate = [&](double e0, double slope, double e1, double largest) {
    const double ratio = (e1 - e0) / slope;  // 1/2 where the model's curvature along the step is right, near 1 flatter
    if (!(ratio > options_.extrapolate_above)) return 1.0;
    const double t = std::min({options_.max_extrapolation, 0.5 / (1.0 - std::min(ratio, 0.99)),
                               options_.max_step / std::max(largest, 1e-300)});
    if (t <= 1.0) return 1.0;
    trial = x;
    for (int v = 0; v < nv; ++v) {
      const int f = assembler.free_index(v);
      if (f >= 0) trial.col(v) += (t - 1.0) * step.segment<3>(3 * f);
    }
    const double e_trial = trial_energy(terms, x, trial);
    if (!(std::isfinite(e_trial) && e_trial < e1)) return 1.0;
    x.swap(trial);
    return t;
  };

  auto gather = [&](const Eigen::Matrix3Xd& full, Eigen::VectorXd& reduced) {
    for (int v = 0; v < nv; ++v) {
      const int f = assembler.free_index(v);
      if (f >= 0) reduced.segment<3>(3 * f) = full.col(v);
    }
  };
  auto residual_of = [&](const Eigen::VectorXd& reduced) {
    double worst = 0.0;
    for (int f = 0; f < n / 3; ++f) worst = std::max(worst, reduced.segment<3>(3 * f).norm());
    return worst / reference_force;
  };

  if (!(reference_force > 0.0) || !std::isfinite(reference_force)) {
    report.outcome = SolveOutcome::kDiverged;
    report.message = "the reference force of the residual test must be positive and finite";
    return report;
  }
  if (n == 0) {
    report.outcome = SolveOutcome::kConverged;
    report.message = "no free vertices";
    return report;
  }

  report.residual = std::numeric_limits<double>::infinity();  // until the first assembly
  int exact_cooldown = 0;  // iterations to wait before trying the exact Hessian again
  bool frozen = false;     // state-dependent parameters no longer updated
  int outer_updates = 0;
  bool have_factor = false;
  int last_cg_iterations = 0;  // CG iterations of the last PCG attempt since the last factorisation
  int creeping = 0;  // consecutive iterations whose step moved no vertex measurably
  for (int it = 0; it < options_.max_iterations; ++it) {
    report.iterations = it;
    // The outer loop starts once Newton has stepped: the residual at iteration 1 is the initial state's, which
    // need not be an equilibrium (a flat start has a small one, yet has not fallen yet).
    const bool outer = it > 1 && report.residual < options_.lagged_outer_below;
    const bool early = it < options_.lagged_every_iterations && report.residual > options_.lagged_every_above;
    if (!frozen && (it == 0 || outer || early)) {
      double change = 0.0;
      for (EnergyTerm* t : terms) change = std::max(change, t->update_lagged(x));
      // History (plastic flow) only from an equilibrium: the start and the way down carry curvatures no load caused.
      if (outer) {
        for (EnergyTerm* t : terms) change = std::max(change, t->update_history(x));
      }
      ++report.lagged_updates;
      outer_updates += outer ? 1 : 0;
      report.lagged_change = change;
      // Only the outer loop may freeze the parameters (as documented): an update that changes nothing before the
      // drape has formed (a flat start, where no hinge has bent yet) says nothing about convergence, yet it froze
      // them for good, so that plasticity never acted on drapes from a flat initial state.
      frozen = outer && (change < options_.lagged_tolerance || outer_updates >= options_.max_lagged_outer_updates);
      report.lagged_capped = frozen && change >= options_.lagged_tolerance;
    }
    bool exact = it > 0 && report.residual < options_.exact_hessian_below && exact_cooldown == 0;
    exact_cooldown = std::max(0, exact_cooldown - 1);
    auto t0 = Clock::now();
    gradient.setZero();
    // The residual of the previous iteration (infinite before the first) picks the positive semi-definite model.
    const HessianMode psd =
        report.residual > options_.gauss_newton_above ? HessianMode::kGaussNewton : HessianMode::kProjected;
    double energy = assembler.assemble(x, exact ? HessianMode::kExact : psd, gradient);
    report.assembly_seconds += since(t0);
    gather(gradient, g);
    report.energy = energy;
    report.residual = residual_of(g);
    if (!std::isfinite(energy) || !g.allFinite()) {
      report.outcome = SolveOutcome::kDiverged;
      report.message = fmt::format("non-finite energy or gradient at iteration {}", it);
      break;
    }
    if (report.residual <= options_.tolerance && frozen) {
      report.outcome = SolveOutcome::kConverged;
      if (report.lagged_capped) {
        report.message = fmt::format("state-dependent parameters fixed after {} outer updates, still changing by "
                                     "{:.3g}", outer_updates, report.lagged_change);
      }
      break;
    }

    // Find a descent step, shifting the diagonal until the factorisation succeeds and the line search passes.
    // The shift's scale: the mean diagonal of the Hessian assembled last (measured again after a fallback from the
    // exact Hessian, whose diagonal may be small or negative where the projected one's is not).
    const auto diagonal_mean = [&] {
      double sum = 0.0;
      for (int p : assembler.diagonal_positions()) sum += assembler.values()[p];
      return std::max(sum / n, 1e-300);
    };
    double mean_diagonal = diagonal_mean();
    // A start that is an equilibrium already (a zero gradient) has no descent step to find, and the outer loop that
    // may freeze the lagged state starts at iteration 2: no step until then (the search would raise the shift to
    // its limit and report it stalled).
    bool accepted = !frozen && it <= 1 && report.residual <= options_.tolerance;
    double step_length = 0.0;
    // Inexact Newton: while an earlier factorisation still preconditions the current Hessian well, conjugate
    // gradients replace the factorisation (a product and two triangular solves per iteration instead of a
    // factorisation).
    // A preconditioner that needed most of the allowed CG iterations last time will likely fail now: factorise
    // straight away instead of spending the iterations first.
    bool reuse = have_factor && lambda == 0.0 && options_.max_pcg_iterations > 0 &&
                 last_cg_iterations <= options_.pcg_refactor_fraction * options_.max_pcg_iterations;
    bool solved = false;
    bool non_finite_step = false;  // the last solve gave a non-finite step
    while (!accepted) {
      FactorStatus status = FactorStatus::kOk;
      solved = false;
      if (reuse) {
        int cg_iterations = 0;
        t0 = Clock::now();
        // The forcing term shrinks with the residual, for superlinear convergence near the solution.
        const double forcing = std::min(options_.pcg_tolerance, report.residual);
        solved = preconditioned_cg(assembler, 0.0, cholesky, g, forcing, options_.max_pcg_iterations, step,
                                   cg_iterations);
        report.pcg_seconds += since(t0);
        report.pcg_iterations += cg_iterations;
        last_cg_iterations = cg_iterations;
        if (!solved) {
          ++report.pcg_failures;
          reuse = false;
          continue;
        }
        ++report.reused_factorizations;
      } else {
        t0 = Clock::now();
        status = cholesky.factorize(assembler, lambda * mean_diagonal);
        report.factorization_seconds += since(t0);
        have_factor = status == FactorStatus::kOk;
        last_cg_iterations = 0;
      }
      if (exact && status != FactorStatus::kOk) {  // indefinite: fall back to the projected Hessian
        exact = false;
        exact_cooldown = 5;
        t0 = Clock::now();
        gradient.setZero();
        energy = assembler.assemble(x, psd, gradient);
        report.assembly_seconds += since(t0);
        mean_diagonal = diagonal_mean();
        continue;
      }
      if (status == FactorStatus::kFailed) {
        report.outcome = SolveOutcome::kFactorizationFailed;
        report.message = fmt::format("CHOLMOD failed at iteration {} (shift {:.3g})", it, lambda);
        report.seconds = since(start);
        return report;
      }
      // A non-finite step (a singular factor, or a Hessian with NaN in it) is retried with a stronger shift like a
      // step without descent; if it is still non-finite at the strongest, the solve diverged.
      if (status == FactorStatus::kOk && !solved) solved = cholesky.solve(-g, step);
      non_finite_step = status == FactorStatus::kOk && !solved;
      if (status == FactorStatus::kOk && solved) {
        // Limit the largest vertex displacement.
        double largest = 0.0;
        for (int f = 0; f < n / 3; ++f) largest = std::max(largest, step.segment<3>(3 * f).norm());
        double t = largest > options_.max_step ? options_.max_step / largest : 1.0;
        const double slope = g.dot(step);
        // A direction almost orthogonal to the gradient comes from an ill-conditioned matrix: treat it as failed.
        if (slope < -1e-8 * g.norm() * step.norm()) {
          for (int ls = 0; ls < options_.max_line_search; ++ls, t *= 0.5) {
            trial = x;
            for (int v = 0; v < nv; ++v) {
              const int f = assembler.free_index(v);
              if (f >= 0) trial.col(v) += t * step.segment<3>(3 * f);
            }
            const double e_trial = trial_energy(terms, x, trial);
            // Near convergence the energy change drops below round-off: accept a step whose predicted decrease
            // is at the level of machine precision.
            const bool round_off = report.residual < 10.0 * options_.tolerance &&
                                   -slope * t < 1e-13 * std::abs(energy);
            if (std::isfinite(e_trial) && (e_trial <= energy + options_.armijo * t * slope || round_off)) {
              accepted = true;
              step_length = t;
              x.swap(trial);
              if (ls == 0 && t == 1.0 && options_.extrapolate_above > 0.0 && !round_off) {
                step_length = extrapolate(energy, slope, e_trial, largest);
              }
              break;
            }
          }
        }
        if (!accepted) ++report.line_search_failures;
      }
      if (!accepted && reuse) {  // the old factorisation is too stale: factorise afresh
        reuse = false;
        continue;
      }
      if (!accepted && exact) {  // the exact Hessian gave no usable step: back to the projected one
        exact = false;
        exact_cooldown = 5;
        gradient.setZero();
        energy = assembler.assemble(x, psd, gradient);
        mean_diagonal = diagonal_mean();
        continue;
      }
      if (!accepted) {
        lambda = lambda == 0.0 ? 1e-6 : lambda * 10.0;
        if (lambda > options_.max_regularization) {
          report.outcome = non_finite_step ? SolveOutcome::kDiverged : SolveOutcome::kStalled;
          report.message = fmt::format("{} at iteration {} (residual {:.3g})",
                                       non_finite_step ? "non-finite Newton step" : "no descent step", it,
                                       report.residual);
          report.seconds = since(start);
          return report;
        }
      }
    }
    // Steps that no longer move anything mean the line search is creeping at round-off: stop and say so.
    double moved = 0.0;
    for (int f = 0; f < n / 3; ++f) moved = std::max(moved, step_length * step.segment<3>(3 * f).norm());
    creeping = moved < 1e-12 ? creeping + 1 : 0;
    if (creeping >= 5) {
      report.outcome = SolveOutcome::kStalled;
      report.message = fmt::format("steps below 1e-12 m for 5 iterations at residual {:.3g}", report.residual);
      report.iterations = it + 1;
      report.seconds = since(start);
      return report;
    }
    if (lambda > 0.0) ++report.regularized_iterations;
    if (exact) ++report.exact_hessian_iterations;
    if (progress_) progress_(IterationInfo{it, energy, report.residual, step_length, lambda});
    lambda = lambda < 1e-5 ? 0.0 : lambda * 0.1;
    report.iterations = it + 1;
  }
  if (report.outcome != SolveOutcome::kConverged && report.outcome != SolveOutcome::kDiverged &&
      report.iterations >= options_.max_iterations) {
    // Report the state that is returned, not the one before the last step.
    gradient.setZero();
    report.energy = assembler.assemble(x, HessianMode::kProjected, gradient);
    gather(gradient, g);
    report.residual = residual_of(g);
    if (report.residual <= options_.tolerance && frozen) report.outcome = SolveOutcome::kConverged;
  }
  if (report.outcome != SolveOutcome::kConverged && report.outcome != SolveOutcome::kDiverged &&
      report.iterations >= options_.max_iterations) {
    report.outcome = SolveOutcome::kIterationLimit;
    report.message = fmt::format("residual {:.3g} after {} iterations", report.residual, report.iterations);
  }
  report.seconds = since(start);
  logger()->debug("newton: {} after {} iterations, residual {:.3g}", to_string(report.outcome), report.iterations,
                  report.residual);
  return report;
}

}  // namespace drapegen::sim
