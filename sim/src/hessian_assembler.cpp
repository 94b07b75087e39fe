#include "drapegen/sim/hessian_assembler.hpp"

#include <algorithm>
#include <stdexcept>

namespace drapegen::sim {

class HessianAssembler::Sink final : public HessianSink {
 public:
  Sink(HessianMode mode, const TermMap& map, std::vector<double>& values)
      : mode_(mode), map_(map), values_(values) {}
  [[nodiscard]] HessianMode mode() const override { return mode_; }
  void add(int element, const double* h) override {
    const int n = map_.arity;
    const int ld = 3 * n;
    const int* base = map_.offsets.data() + static_cast<std::size_t>(element) * n * n * 3;
    for (int a = 0; a < n; ++a) {
      for (int b = 0; b < n; ++b) {
        const int* col = base + (a * n + b) * 3;
        if (col[0] < 0) continue;
        for (int c = 0; c < 3; ++c) {
          const double* src = h + (3 * b + c) * ld + 3 * a;
          for (int r = (a == b ? c : 0); r < 3; ++r) values_[col[c] + r] += src[r];
        }
      }
    }
  }

 private:
  HessianMode mode_;
  const TermMap& map_;
  std::vector<double>& values_;
};

HessianAssembler::HessianAssembler(int vertex_count, const std::vector<bool>& fixed,
                                   const std::vector<const EnergyTerm*>& terms) {
  if (static_cast<int>(fixed.size()) != vertex_count) throw std::invalid_argument("assembler: fixed mask size");
  free_index_.assign(vertex_count, -1);
  for (int v = 0; v < vertex_count; ++v) {
    if (!fixed[v]) free_index_[v] = free_count_++;
  }
  // Lower-triangle block adjacency: for column block j, the row blocks i > j.
  std::vector<std::vector<int>> lower(free_count_);
  std::vector<int> verts;
  for (const EnergyTerm* term : terms) {
    if (!term->has_hessian()) continue;
    const int n = term->arity();
    verts.resize(n);
    for (int e = 0; e < term->element_count(); ++e) {
      term->element_vertices(e, verts.data());
      for (int a = 0; a < n; ++a) {
        for (int b = 0; b < n; ++b) {
          const int i = free_or_absent(verts[a]), j = free_or_absent(verts[b]);
          if (i > j && j >= 0) lower[j].push_back(i);
        }
      }
    }
  }
  for (auto& rows : lower) {
    std::sort(rows.begin(), rows.end());
    rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
  }
  const int n_dof = 3 * free_count_;
  colptr_.assign(n_dof + 1, 0);
  for (int j = 0; j < free_count_; ++j) {
    for (int c = 0; c < 3; ++c) {
      colptr_[3 * j + c + 1] = colptr_[3 * j + c] + (3 - c) + 3 * static_cast<int>(lower[j].size());
    }
  }
  rowind_.resize(colptr_.back());
  diagonal_.resize(n_dof);
  for (int j = 0; j < free_count_; ++j) {
    for (int c = 0; c < 3; ++c) {
      int pos = colptr_[3 * j + c];
      diagonal_[3 * j + c] = pos;
      for (int r = c; r < 3; ++r) rowind_[pos++] = 3 * j + r;
      for (int i : lower[j]) {
        for (int r = 0; r < 3; ++r) rowind_[pos++] = 3 * i + r;
      }
    }
  }
  values_.assign(rowind_.size(), 0.0);

  for (const EnergyTerm* term : terms) {
    TermMap map{term, term->arity(), {}};
    if (!term->has_hessian()) {
      maps_.push_back(std::move(map));
      continue;
    }
    const int n = map.arity;
    verts.resize(n);
    map.offsets.assign(static_cast<std::size_t>(term->element_count()) * n * n * 3, -1);
    for (int e = 0; e < term->element_count(); ++e) {
      term->element_vertices(e, verts.data());
      for (int a = 0; a < n; ++a) {
        for (int b = 0; b < n; ++b) {
          const int i = free_or_absent(verts[a]), j = free_or_absent(verts[b]);
          if (i < 0 || j < 0 || i < j) continue;
          int* out = map.offsets.data() + ((static_cast<std::size_t>(e) * n + a) * n + b) * 3;
          if (i == j) {
            if (a != b) throw std::invalid_argument("assembler: element repeats a vertex");
            for (int c = 0; c < 3; ++c) out[c] = colptr_[3 * j + c] - c;
          } else {
            const auto it = std::lower_bound(lower[j].begin(), lower[j].end(), i);
            const int k = static_cast<int>(it - lower[j].begin());
            for (int c = 0; c < 3; ++c) out[c] = colptr_[3 * j + c] + (3 - c) + 3 * k;
          }
        }
      }
    }
    maps_.push_back(std::move(map));
  }
}

double HessianAssembler::assemble(const Eigen::Matrix3Xd& x, HessianMode mode, Eigen::Matrix3Xd& gradient) {
  std::fill(values_.begin(), values_.end(), 0.0);
  double energy = 0.0;
  for (const TermMap& map : maps_) {
    Sink sink(mode, map, values_);
    energy += map.term->evaluate(x, &gradient, map.term->has_hessian() ? &sink : nullptr);
  }
  return energy;
}

void HessianAssembler::multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y, double shift) const {
  // By 3x3 blocks (the pattern is one of vertex blocks: the three columns of a free vertex share their rows): one row
  // index per block instead of nine, and the block's two products (below and above the diagonal) from one load.
  y = shift * x;
  const double* v = values_.data();
  for (int j = 0; j < free_count_; ++j) {
    const int p0 = colptr_[3 * j], p1 = colptr_[3 * j + 1], p2 = colptr_[3 * j + 2];
    const double xj0 = x[3 * j], xj1 = x[3 * j + 1], xj2 = x[3 * j + 2];
    // The diagonal block's lower triangle: column 0 holds rows 0-2, column 1 rows 1-2, column 2 row 2.
    double yj0 = v[p0] * xj0 + v[p0 + 1] * xj1 + v[p0 + 2] * xj2;
    double yj1 = v[p0 + 1] * xj0 + v[p1] * xj1 + v[p1 + 1] * xj2;
    double yj2 = v[p0 + 2] * xj0 + v[p1 + 1] * xj1 + v[p2] * xj2;
    // Then the blocks below it, column c of block k at column c's start + (3 - c) + 3 k.
    const double* c0 = v + p0 + 3;
    const double* c1 = v + p1 + 2;
    const double* c2 = v + p2 + 1;
    const int* rows = rowind_.data() + p0 + 3;
    const int blocks = (p1 - p0 - 3) / 3;
    for (int k = 0; k < blocks; ++k, c0 += 3, c1 += 3, c2 += 3) {
      const int i = rows[3 * k];
      const double xi0 = x[i], xi1 = x[i + 1], xi2 = x[i + 2];
      y[i] += c0[0] * xj0 + c1[0] * xj1 + c2[0] * xj2;
      y[i + 1] += c0[1] * xj0 + c1[1] * xj1 + c2[1] * xj2;
      y[i + 2] += c0[2] * xj0 + c1[2] * xj1 + c2[2] * xj2;
      yj0 += c0[0] * xi0 + c0[1] * xi1 + c0[2] * xi2;
      yj1 += c1[0] * xi0 + c1[1] * xi1 + c1[2] * xi2;
      yj2 += c2[0] * xi0 + c2[1] * xi1 + c2[2] * xi2;
    }
    y[3 * j] += yj0;
    y[3 * j + 1] += yj1;
    y[3 * j + 2] += yj2;
  }
}

}  // namespace drapegen::sim
