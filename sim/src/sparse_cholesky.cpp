#include "drapegen/sim/sparse_cholesky.hpp"

#include <cholmod.h>

#include <algorithm>
#include <cstring>
#include <mutex>
#include <vector>

#ifdef DRAPEGEN_HAVE_OPENMP
#include <omp.h>
#endif

#include "drapegen/sim/logging.hpp"

namespace drapegen::sim {
namespace {

/// While alive, OpenMP parallel regions (CHOLMOD's) run on the encountering thread alone. Concurrent guards share
/// one saved setting: the first saves and lowers max-active-levels, the last restores it.
class SerialOpenMp {
 public:
  explicit SerialOpenMp(bool active) : active_(active) {
#ifdef DRAPEGEN_HAVE_OPENMP
    if (!active_) return;
    Shared& s = shared();
    const std::lock_guard lock(s.mutex);
    if (s.users++ == 0) {
      s.saved_levels = omp_get_max_active_levels();
      omp_set_max_active_levels(0);
    }
#endif
  }
  ~SerialOpenMp() {
#ifdef DRAPEGEN_HAVE_OPENMP
    if (!active_) return;
    Shared& s = shared();
    const std::lock_guard lock(s.mutex);
    if (--s.users == 0) omp_set_max_active_levels(s.saved_levels);
#endif
  }
  SerialOpenMp(const SerialOpenMp&) = delete;
  SerialOpenMp& operator=(const SerialOpenMp&) = delete;

 private:
  struct Shared {
    std::mutex mutex;
    int users = 0;
    int saved_levels = 0;
  };
  static Shared& shared() {
    static Shared s;
    return s;
  }
  bool active_;
};

}  // namespace

struct SparseCholesky::Impl {
  bool parallel = false;
  cholmod_common common{};
  cholmod_factor* factor = nullptr;
  std::vector<int> colptr, rowind;
  std::vector<double> values;
  bool analysed = false;
  std::vector<float> single;  // single-precision copy of a supernodal factor's values, empty until needed
  std::vector<float> work;
  Eigen::VectorXf update;  // scratch for one supernode's rows below its diagonal block

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

SparseCholesky::SparseCholesky(bool parallel) : impl_(std::make_unique<Impl>()) { impl_->parallel = parallel; }
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
  const SerialOpenMp serial(!m.parallel);
  if (!m.analysed) {
    m.factor = cholmod_analyze(&a, &m.common);
    if (m.factor == nullptr || m.common.status < CHOLMOD_OK) return FactorStatus::kFailed;
    m.analysed = true;
    logger()->debug("cholmod: n {} nnz(A) {} nnz(L) {:.0f} xsize {} nsuper {} flops {:.3g} supernodal {} ordering {}", a.nrow, a.nzmax,
                    m.common.lnz, m.factor->xsize, m.factor->nsuper, m.common.fl, m.factor->is_super, m.common.method[m.common.selected].ordering);
  }
  m.single.clear();
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

bool SparseCholesky::solve_approximate(const Eigen::VectorXd& rhs, Eigen::VectorXd& solution) {
  Impl& m = *impl_;
  cholmod_factor* f = m.factor;
  if (f == nullptr || f->minor < f->n) return false;
  if (!f->is_super || !f->is_ll || f->itype != CHOLMOD_INT) return solve(rhs, solution);
  const int* super = static_cast<const int*>(f->super);
  const int* pi = static_cast<const int*>(f->pi);
  const int* px = static_cast<const int*>(f->px);
  const int* s = static_cast<const int*>(f->s);
  const int* perm = static_cast<const int*>(f->Perm);
  const int nsuper = static_cast<int>(f->nsuper);
  const int n = static_cast<int>(f->n);
  if (m.single.empty()) {
    const double* x = static_cast<const double*>(f->x);
    m.single.assign(x, x + f->xsize);
  }
  m.work.resize(n);
  if (m.update.size() < n) m.update.resize(n);
  Eigen::Map<Eigen::VectorXf> y(m.work.data(), n);
  for (int k = 0; k < n; ++k) y[k] = static_cast<float>(rhs[perm[k]]);
  using Block = Eigen::Map<const Eigen::MatrixXf>;
  // L y = P b, supernode by supernode: the dense diagonal block, then the rows below it.
  for (int k = 0; k < nsuper; ++k) {
    const int k1 = super[k], ncol = super[k + 1] - k1, nrow = pi[k + 1] - pi[k];
    const Block block(m.single.data() + px[k], nrow, ncol);
    auto own = y.segment(k1, ncol);
    block.topRows(ncol).triangularView<Eigen::Lower>().solveInPlace(own);
    if (nrow > ncol) {
      auto update = m.update.head(nrow - ncol);
      update.noalias() = block.bottomRows(nrow - ncol) * own;
      const int* rows = s + pi[k] + ncol;
      for (int i = 0; i < nrow - ncol; ++i) y[rows[i]] -= update[i];
    }
  }
  // L^T x = y, in reverse.
  for (int k = nsuper - 1; k >= 0; --k) {
    const int k1 = super[k], ncol = super[k + 1] - k1, nrow = pi[k + 1] - pi[k];
    const Block block(m.single.data() + px[k], nrow, ncol);
    auto own = y.segment(k1, ncol);
    if (nrow > ncol) {
      auto gathered = m.update.head(nrow - ncol);
      const int* rows = s + pi[k] + ncol;
      for (int i = 0; i < nrow - ncol; ++i) gathered[i] = y[rows[i]];
      own.noalias() -= block.bottomRows(nrow - ncol).transpose() * gathered;
    }
    block.topRows(ncol).triangularView<Eigen::Lower>().transpose().solveInPlace(own);
  }
  solution.resize(n);
  for (int k = 0; k < n; ++k) solution[perm[k]] = static_cast<double>(y[k]);
  return solution.allFinite();
}

}  // namespace drapegen::sim
