#include "drapegen/sim/sparse_cholesky.hpp"

#include <cholmod.h>

#include <algorithm>
#include <cstring>
#include <vector>

#include "drapegen/sim/logging.hpp"

namespace drapegen::sim {

struct SparseCholesky::Impl {
  cholmod_common common{};
  cholmod_factor* factor = nullptr;
  std::vector<int> colptr, rowind;
  std::vector<double> values;
  bool analysed = false;

  Impl() {
    cholmod_start(&common);
    common.print = 0;
    common.error_handler = nullptr;
    common.quick_return_if_not_posdef = 1;
    // Cloth meshes are planar graphs: nested dissection (METIS) beats minimum degree on fill and flops.
    common.nmethods = 1;
    common.method[0].ordering = CHOLMOD_METIS;
    common.postorder = 1;
  }
  ~Impl() {
    if (factor != nullptr) cholmod_free_factor(&factor, &common);
    cholmod_finish(&common);
  }

  cholmod_sparse view() {
    cholmod_sparse a{};
    a.nrow = a.ncol = colptr.size() - 1;
    a.nzmax = values.size();
    a.p = colptr.data();
    a.i = rowind.data();
    a.x = values.data();
    a.stype = -1;  // lower triangle stored
    a.itype = CHOLMOD_INT;
    a.xtype = CHOLMOD_REAL;
    a.dtype = CHOLMOD_DOUBLE;
    a.sorted = 1;
    a.packed = 1;
    return a;
  }
};

SparseCholesky::SparseCholesky() : impl_(std::make_unique<Impl>()) {}
SparseCholesky::~SparseCholesky() = default;

FactorStatus SparseCholesky::factorize(const HessianAssembler& matrix, double shift) {
  Impl& m = *impl_;
  if (!m.analysed) {
    m.colptr = matrix.column_pointers();
    m.rowind = matrix.row_indices();
  }
  m.values = matrix.values();
  if (shift != 0.0) {
    for (int p : matrix.diagonal_positions()) m.values[p] += shift;
  }
  cholmod_sparse a = m.view();
  if (!m.analysed) {
    m.factor = cholmod_analyze(&a, &m.common);
    if (m.factor == nullptr || m.common.status < CHOLMOD_OK) return FactorStatus::kFailed;
    m.analysed = true;
    logger()->debug("cholmod: n {} nnz(A) {} nnz(L) {:.0f} flops {:.3g} supernodal {} ordering {}", a.nrow, a.nzmax,
                    m.common.lnz, m.common.fl, m.factor->is_super, m.common.method[m.common.selected].ordering);
  }
  const int ok = cholmod_factorize(&a, m.factor, &m.common);
  if (m.common.status == CHOLMOD_NOT_POSDEF) return FactorStatus::kNotPositiveDefinite;
  if (!ok || m.common.status < CHOLMOD_OK) return FactorStatus::kFailed;
  return FactorStatus::kOk;
}

bool SparseCholesky::solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& solution) {
  Impl& m = *impl_;
  if (m.factor == nullptr) return false;
  cholmod_dense b{};
  b.nrow = static_cast<size_t>(rhs.size());
  b.ncol = 1;
  b.nzmax = b.nrow;
  b.d = b.nrow;
  b.x = const_cast<double*>(rhs.data());
  b.xtype = CHOLMOD_REAL;
  b.dtype = CHOLMOD_DOUBLE;
  cholmod_dense* x = cholmod_solve(CHOLMOD_A, m.factor, &b, &m.common);
  if (x == nullptr) return false;
  solution.resize(rhs.size());
  std::memcpy(solution.data(), x->x, sizeof(double) * static_cast<size_t>(rhs.size()));
  cholmod_free_dense(&x, &m.common);
  return solution.allFinite();
}

}  // namespace drapegen::sim
