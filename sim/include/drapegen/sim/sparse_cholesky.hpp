#pragma once
// Sparse Cholesky factorisation through SuiteSparse CHOLMOD, with the symbolic analysis reused across calls.

#include <Eigen/Core>
#include <memory>

#include "drapegen/sim/hessian_assembler.hpp"

namespace drapegen::sim {

enum class FactorStatus {
  kOk,
  kNotPositiveDefinite,
  kFailed,  // out of memory or an internal CHOLMOD error
};

class SparseCholesky {
 public:
  /// `parallel`: let CHOLMOD's OpenMP regions (supernodal numeric factorisation) start their thread team. Off by
  /// default: drapegen runs one solve per core (workers, diagnosis refits), and there the team's hand-offs cost
  /// more than they save (measured: 390k context switches and 40% more CPU time on a 100x100 drape on a busy
  /// 2-core machine). Off, factorize() runs CHOLMOD with OpenMP's max-active-levels at 0 for the duration of the
  /// call, restored afterwards. Distinct instances may be used from different threads: the CHOLMOD calls that reach
  /// BLAS (factorize, solve) are serialised process-wide, since Debian's serial OpenBLAS is not thread-safe.
  explicit SparseCholesky(bool parallel = false);
  ~SparseCholesky();
  SparseCholesky(const SparseCholesky&) = delete;
  SparseCholesky& operator=(const SparseCholesky&) = delete;

  /// Factorises the assembler's matrix plus `shift` on the diagonal. The first call analyses the pattern (fill-
  /// reducing ordering, supernodes); later calls reuse that analysis, since the pattern never changes.
  FactorStatus factorize(const HessianAssembler& matrix, double shift = 0.0);
  /// Solves with the last factorisation; false if it failed (a failed one leaves no usable factor) or none ran.
  [[nodiscard]] bool solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& solution);
  /// Solves approximately with a compact copy of the last successful factorisation (made on first use after each
  /// factorisation): the supernodes' diagonal blocks in single precision, the rows below them in single precision,
  /// or in bfloat16 (bfloat16_panel.hpp) for a factor of at least 2M values: half, or a quarter, of the memory
  /// traffic of solve(). For preconditioning only: the bfloat16 copy's relative error is about 2^-8 times the
  /// condition number's effect, well inside what a stale factorisation already costs.
  /// Falls back to solve() for a simplicial factor (CHOLMOD chooses one for small, sparse problems).
  [[nodiscard]] bool solve_approximate(const Eigen::VectorXd& rhs, Eigen::VectorXd& solution);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace drapegen::sim
