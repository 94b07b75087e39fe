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
  SparseCholesky();
  ~SparseCholesky();
  SparseCholesky(const SparseCholesky&) = delete;
  SparseCholesky& operator=(const SparseCholesky&) = delete;

  /// Factorises the assembler's matrix plus `shift` on the diagonal. The first call analyses the pattern (fill-
  /// reducing ordering, supernodes); later calls reuse that analysis, since the pattern never changes.
  FactorStatus factorize(const HessianAssembler& matrix, double shift = 0.0);
  /// Solves with the last successful factorisation.
  [[nodiscard]] bool solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& solution);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace drapegen::sim
