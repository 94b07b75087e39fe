#include "drapegen/sim/sparse_cholesky.hpp"

#include <cholmod.h>

#include <algorithm>
#include <cstdint>
#include <mutex>
#include <utility>
#include <vector>

#ifdef DRAPEGEN_HAVE_OPENMP
#include <omp.h>
#endif

#include "drapegen/sim/bfloat16_panel.hpp"
#include "drapegen/sim/logging.hpp"
#include "drapegen/sim/packed_triangle.hpp"

namespace drapegen::sim {
namespace {

/// While alive, OpenMP parallel regions (CHOLMOD's) run on the encountering thread alone: max-active-levels is
/// lowered to 0 and restored afterwards. Only constructed under blas_mutex(), so no two guards overlap.
class SerialOpenMp {
 public:
  explicit SerialOpenMp(bool active) : active_(active) {
#ifdef DRAPEGEN_HAVE_OPENMP
    if (!active_) return;
    saved_levels_ = omp_get_max_active_levels();
    omp_set_max_active_levels(0);
#endif
  }
  ~SerialOpenMp() {
#ifdef DRAPEGEN_HAVE_OPENMP
    if (active_) omp_set_max_active_levels(saved_levels_);
#endif
  }
  SerialOpenMp(const SerialOpenMp&) = delete;
  SerialOpenMp& operator=(const SerialOpenMp&) = delete;

 private:
  bool active_;
  int saved_levels_ = 0;
};

/// CHOLMOD's supernodal factorisation and solve call BLAS, and Debian's serial OpenBLAS is not safe to call from two
/// threads at once: concurrent drapes in one process (diagnose --jobs 2) got results that differed from run to run,
/// and identical ones with the reference BLAS (docs/DIAGNOSIS_RESULTS.md, "Session 7"). So every CHOLMOD call that
/// may reach BLAS holds this lock; uncontended (one drape per process: workers, drapegen simulate) it costs nothing.
std::mutex& blas_mutex() {
  static std::mutex m;
  return m;
}

/// Factors with at least this many values (8 MB in single precision: more than the share of a last-level cache one
/// core of a busy node can count on) keep the rows below their diagonal blocks in bfloat16 for preconditioning: the
/// triangular solves are bound by memory traffic there (docs/BENCHMARKS.md, session 7). Smaller ones stay in cache
/// and gain nothing from it.
constexpr std::size_t kBfloat16MinEntries = std::size_t{1} << 21;

// y += A x and y -= A^T x for a column-major panel below a supernode's diagonal block, by storage type.
void multiply_add(const float* a, int rows, int cols, const float* x, float* y) {
  Eigen::Map<Eigen::VectorXf>(y, rows).noalias() +=
      Eigen::Map<const Eigen::MatrixXf>(a, rows, cols) * Eigen::Map<const Eigen::VectorXf>(x, cols);
}
void transpose_multiply_subtract(const float* a, int rows, int cols, const float* x, float* y) {
  Eigen::Map<Eigen::VectorXf>(y, cols).noalias() -=
      Eigen::Map<const Eigen::MatrixXf>(a, rows, cols).transpose() * Eigen::Map<const Eigen::VectorXf>(x, rows);
}
void multiply_add(const std::uint16_t* a, int rows, int cols, const float* x, float* y) {
  bfloat16_multiply_add(a, rows, cols, x, y);
}
void transpose_multiply_subtract(const std::uint16_t* a, int rows, int cols, const float* x, float* y) {
  bfloat16_transpose_multiply_subtract(a, rows, cols, x, y);
}

}  // namespace

struct SparseCholesky::Impl {
  bool parallel = false;
  cholmod_common common{};
  cholmod_factor* factor = nullptr;
  // The matrix CHOLMOD factorises: the lower triangle of P A P^T, P the fill-reducing order of the first analysis,
  // in compressed columns. Handed over already permuted, it is factorised as it stands (natural ordering, lower
  // triangle); the assembler's own layout would cost CHOLMOD two transposes per factorisation (3% of a drape).
  // order[k]: the DOF at position k; scatter[p]: where the assembler's value p goes.
  std::vector<int> colptr, rowind, order, scatter;
  std::vector<double> values;
  Eigen::VectorXd permuted_rhs;
  bool analysed = false;
  // The preconditioner's compact copy of a supernodal factor, made on first use after each factorisation (empty
  // until then): per supernode, its diagonal block packed in single precision (packed_triangle.hpp) and the rows below
  // it in single precision or, for a factor of at least kBfloat16MinEntries values, in bfloat16.
  std::vector<float> diagonal;
  std::vector<float> below_single;
  std::vector<std::uint16_t> below_bfloat16;
  std::vector<std::size_t> diagonal_offset, below_offset;
  std::vector<float> work;
  std::vector<float> update;  // scratch for one supernode's rows below its diagonal block

  /// P^T L^-T L^-1 P rhs with the compact copy; `below` is below_single or below_bfloat16.
  template <class Panel>
  void solve_compact(const Panel* below, const Eigen::VectorXd& rhs, Eigen::VectorXd& solution) {
    const int* super = static_cast<const int*>(factor->super);
    const int* pi = static_cast<const int*>(factor->pi);
    const int* s = static_cast<const int*>(factor->s);
    const int* perm = order.data();
    const int nsuper = static_cast<int>(factor->nsuper);
    const int n = static_cast<int>(factor->n);
    work.resize(n);
    if (update.size() < static_cast<std::size_t>(n)) update.resize(n);
    Eigen::Map<Eigen::VectorXf> y(work.data(), n);
    for (int k = 0; k < n; ++k) y[k] = static_cast<float>(rhs[perm[k]]);
    // L y = P b, supernode by supernode: the dense diagonal block, then the rows below it.
    for (int k = 0; k < nsuper; ++k) {
      const int k1 = super[k], ncol = super[k + 1] - k1, nbelow = pi[k + 1] - pi[k] - ncol;
      float* own = y.data() + k1;
      packed_lower_solve(diagonal.data() + diagonal_offset[k], ncol, own);
      if (nbelow > 0) {
        std::fill(update.begin(), update.begin() + nbelow, 0.0f);
        multiply_add(below + below_offset[k], nbelow, ncol, own, update.data());
        const int* rows = s + pi[k] + ncol;
        for (int i = 0; i < nbelow; ++i) y[rows[i]] -= update[i];
      }
    }
    // L^T x = y, in reverse.
    for (int k = nsuper - 1; k >= 0; --k) {
      const int k1 = super[k], ncol = super[k + 1] - k1, nbelow = pi[k + 1] - pi[k] - ncol;
      float* own = y.data() + k1;
      if (nbelow > 0) {
        const int* rows = s + pi[k] + ncol;
        for (int i = 0; i < nbelow; ++i) update[i] = y[rows[i]];
        transpose_multiply_subtract(below + below_offset[k], nbelow, ncol, update.data(), own);
      }
      packed_lower_transpose_solve(diagonal.data() + diagonal_offset[k], ncol, own);
    }
    solution.resize(n);
    for (int k = 0; k < n; ++k) solution[perm[k]] = static_cast<double>(y[k]);
  }

  /// Fills the compact copy from the factor (supernodal, LL^T).
  void make_compact_copy() {
    const int* super = static_cast<const int*>(factor->super);
    const int* pi = static_cast<const int*>(factor->pi);
    const int* px = static_cast<const int*>(factor->px);
    const double* x = static_cast<const double*>(factor->x);
    const int nsuper = static_cast<int>(factor->nsuper);
    diagonal_offset.assign(nsuper + 1, 0);
    below_offset.assign(nsuper + 1, 0);
    for (int k = 0; k < nsuper; ++k) {
      const std::size_t ncol = super[k + 1] - super[k], nrow = pi[k + 1] - pi[k];
      diagonal_offset[k + 1] = diagonal_offset[k] + packed_triangle_size(ncol);
      below_offset[k + 1] = below_offset[k] + (nrow - ncol) * ncol;
    }
    const bool bfloat16 = factor->xsize >= kBfloat16MinEntries;
    diagonal.resize(diagonal_offset[nsuper]);
    below_single.resize(bfloat16 ? 0 : below_offset[nsuper]);
    below_bfloat16.resize(bfloat16 ? below_offset[nsuper] : 0);
    for (int k = 0; k < nsuper; ++k) {
      const int ncol = super[k + 1] - super[k], nrow = pi[k + 1] - pi[k];
      pack_lower_triangle(x + px[k], ncol, nrow, diagonal.data() + diagonal_offset[k]);
      for (int j = 0; j < ncol; ++j) {
        const double* column = x + px[k] + static_cast<std::size_t>(j) * nrow;
        const std::size_t b = below_offset[k] + static_cast<std::size_t>(j) * (nrow - ncol);
        if (bfloat16) {
          for (int i = ncol; i < nrow; ++i) below_bfloat16[b + i - ncol] = to_bfloat16(static_cast<float>(column[i]));
        } else {
          for (int i = ncol; i < nrow; ++i) below_single[b + i - ncol] = static_cast<float>(column[i]);
        }
      }
    }
  }

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

  /// Finds the fill-reducing order of the assembler's pattern (nested dissection, postordered), builds the
  /// permuted pattern and the scatter map, and analyses the permuted pattern in its natural order. False on failure.
  bool analyse(const HessianAssembler& matrix) {
    const int n = matrix.dof_count();
    const std::vector<int>& cp = matrix.column_pointers();
    const std::vector<int>& ri = matrix.row_indices();
    cholmod_sparse a = view_of(cp, ri, matrix.values());
    cholmod_factor* ordering = cholmod_analyze(&a, &common);
    if (ordering == nullptr || common.status < CHOLMOD_OK) {
      if (ordering != nullptr) cholmod_free_factor(&ordering, &common);
      return false;
    }
    const int method = common.method[common.selected].ordering;
    order.assign(static_cast<const int*>(ordering->Perm), static_cast<const int*>(ordering->Perm) + n);
    cholmod_free_factor(&ordering, &common);
    std::vector<int> position(n);
    for (int k = 0; k < n; ++k) position[order[k]] = k;
    // Entry (i, j) of the lower triangle goes to (max, min) of its new positions: count per new column, then fill.
    colptr.assign(n + 1, 0);
    for (int j = 0; j < n; ++j) {
      for (int p = cp[j]; p < cp[j + 1]; ++p) ++colptr[std::min(position[ri[p]], position[j]) + 1];
    }
    for (int k = 0; k < n; ++k) colptr[k + 1] += colptr[k];
    std::vector<std::pair<int, int>> entries(cp[n]);  // (new row, assembler index), by new column
    std::vector<int> next(colptr.begin(), colptr.end() - 1);
    for (int j = 0; j < n; ++j) {
      for (int p = cp[j]; p < cp[j + 1]; ++p) {
        const int r = position[ri[p]], c = position[j];
        entries[next[std::min(r, c)]++] = {std::max(r, c), p};
      }
    }
    rowind.resize(cp[n]);
    scatter.resize(cp[n]);
    for (int k = 0; k < n; ++k) {
      std::sort(entries.begin() + colptr[k], entries.begin() + colptr[k + 1]);
      for (int q = colptr[k]; q < colptr[k + 1]; ++q) {
        rowind[q] = entries[q].first;
        scatter[entries[q].second] = q;
      }
    }
    values.assign(cp[n], 0.0);
    // The permuted matrix is already in elimination order (postordered by the first analysis): keep it.
    const int saved_nmethods = common.nmethods, saved_ordering = common.method[0].ordering;
    const int saved_postorder = common.postorder;
    common.nmethods = 1;
    common.method[0].ordering = CHOLMOD_NATURAL;
    common.postorder = 0;
    cholmod_sparse b = view();
    factor = cholmod_analyze(&b, &common);
    common.nmethods = saved_nmethods;
    common.method[0].ordering = saved_ordering;
    common.postorder = saved_postorder;
    if (factor == nullptr || common.status < CHOLMOD_OK || factor->ordering != CHOLMOD_NATURAL) {
      if (factor != nullptr) cholmod_free_factor(&factor, &common);
      return false;
    }
    logger()->debug("cholmod: n {} nnz(A) {} nnz(L) {:.0f} xsize {} nsuper {} flops {:.3g} supernodal {} ordering {}",
                    n, cp[n], common.lnz, factor->xsize, factor->nsuper, common.fl, factor->is_super, method);
    return true;
  }

  static cholmod_sparse view_of(const std::vector<int>& cp, const std::vector<int>& ri, const std::vector<double>& x) {
    cholmod_sparse a{};
    a.nrow = a.ncol = cp.size() - 1;
    a.nzmax = x.size();
    a.p = const_cast<int*>(cp.data());
    a.i = const_cast<int*>(ri.data());
    a.x = const_cast<double*>(x.data());
    a.stype = -1;  // lower triangle stored
    a.itype = CHOLMOD_INT;
    a.xtype = CHOLMOD_REAL;
    a.dtype = CHOLMOD_DOUBLE;
    a.sorted = 1;
    a.packed = 1;
    return a;
  }

  cholmod_sparse view() { return view_of(colptr, rowind, values); }
};

SparseCholesky::SparseCholesky(bool parallel) : impl_(std::make_unique<Impl>()) { impl_->parallel = parallel; }
SparseCholesky::~SparseCholesky() = default;

FactorStatus SparseCholesky::factorize(const HessianAssembler& matrix, double shift) {
  Impl& m = *impl_;
  const std::lock_guard blas(blas_mutex());
  const SerialOpenMp serial(!m.parallel);
  if (!m.analysed) {
    if (!m.analyse(matrix)) return FactorStatus::kFailed;
    m.analysed = true;
  }
  const std::vector<double>& values = matrix.values();
  for (std::size_t p = 0; p < values.size(); ++p) m.values[m.scatter[p]] = values[p];
  if (shift != 0.0) {
    for (int p : matrix.diagonal_positions()) m.values[m.scatter[p]] += shift;
  }
  cholmod_sparse a = m.view();
  m.diagonal.clear();
  const int ok = cholmod_factorize(&a, m.factor, &m.common);
  if (m.common.status == CHOLMOD_NOT_POSDEF) return FactorStatus::kNotPositiveDefinite;
  if (!ok || m.common.status < CHOLMOD_OK) return FactorStatus::kFailed;
  return FactorStatus::kOk;
}

bool SparseCholesky::solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& solution) {
  Impl& m = *impl_;
  if (m.factor == nullptr || rhs.size() != static_cast<Eigen::Index>(m.order.size())) return false;
  if (m.factor->minor < m.factor->n) return false;  // the last factorisation failed part way: no factor to solve with
  // The factor is of P A P^T: solve (P A P^T) y = P rhs, then the solution is P^T y.
  m.permuted_rhs.resize(rhs.size());
  for (Eigen::Index k = 0; k < rhs.size(); ++k) m.permuted_rhs[k] = rhs[m.order[k]];
  cholmod_dense b{};
  b.nrow = static_cast<size_t>(rhs.size());
  b.ncol = 1;
  b.nzmax = b.nrow;
  b.d = b.nrow;
  b.x = m.permuted_rhs.data();
  b.xtype = CHOLMOD_REAL;
  b.dtype = CHOLMOD_DOUBLE;
  cholmod_dense* x = nullptr;
  {
    const std::lock_guard blas(blas_mutex());
    x = cholmod_solve(CHOLMOD_A, m.factor, &b, &m.common);
  }
  if (x == nullptr) return false;
  solution.resize(rhs.size());
  const double* y = static_cast<const double*>(x->x);
  for (Eigen::Index k = 0; k < rhs.size(); ++k) solution[m.order[k]] = y[k];
  cholmod_free_dense(&x, &m.common);
  return solution.allFinite();
}

bool SparseCholesky::solve_approximate(const Eigen::VectorXd& rhs, Eigen::VectorXd& solution) {
  Impl& m = *impl_;
  cholmod_factor* f = m.factor;
  if (f == nullptr || f->minor < f->n) return false;
  if (!f->is_super || !f->is_ll || f->itype != CHOLMOD_INT) return solve(rhs, solution);
  if (m.diagonal.empty()) m.make_compact_copy();
  if (m.below_bfloat16.empty()) {
    m.solve_compact(m.below_single.data(), rhs, solution);
  } else {
    m.solve_compact(m.below_bfloat16.data(), rhs, solution);
  }
  return solution.allFinite();
}

}  // namespace drapegen::sim
