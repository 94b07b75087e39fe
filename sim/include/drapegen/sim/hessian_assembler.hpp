#pragma once
// Assembles element Hessians straight into a fixed compressed-column pattern (lower triangle) over free DOFs.

#include <Eigen/Core>
#include <vector>

#include "drapegen/sim/energy.hpp"

namespace drapegen::sim {

/// The sparsity pattern is built once from the terms' stencils; every later assembly only scatters values.
/// DOF order: three per free vertex, free vertices in increasing index order. Fixed vertices are eliminated.
class HessianAssembler {
 public:
  HessianAssembler(int vertex_count, const std::vector<bool>& fixed, const std::vector<const EnergyTerm*>& terms);

  [[nodiscard]] int dof_count() const { return 3 * free_count_; }
  /// -1 for fixed vertices.
  [[nodiscard]] int free_index(int vertex) const { return free_index_[vertex]; }

  /// Compressed sparse column storage of the lower triangle.
  [[nodiscard]] const std::vector<int>& column_pointers() const { return colptr_; }
  [[nodiscard]] const std::vector<int>& row_indices() const { return rowind_; }
  [[nodiscard]] std::vector<double>& values() { return values_; }
  [[nodiscard]] const std::vector<double>& values() const { return values_; }
  /// Index of the diagonal entry of every DOF in `values()`.
  [[nodiscard]] const std::vector<int>& diagonal_positions() const { return diagonal_; }

  /// y = (A + shift * I) x with the symmetric matrix A whose lower triangle is stored.
  void multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y, double shift = 0.0) const;

  /// Clears the values and assembles the Hessians of all terms at x (also returns the total energy and adds the
  /// full 3 x N gradient into `gradient`).
  double assemble(const Eigen::Matrix3Xd& x, HessianMode mode, Eigen::Matrix3Xd& gradient);

 private:
  class Sink;
  struct TermMap {
    const EnergyTerm* term;
    int arity;
    // Per element, per ordered local pair (a, b), per column c of the block: the value index of row 0 of that
    // block column (-1 where the pair is not stored: a fixed or absent vertex, or the block lies above the diagonal).
    std::vector<int> offsets;
  };

  /// free_index, and -1 for an element's unused slot (vertex -1).
  [[nodiscard]] int free_or_absent(int vertex) const { return vertex < 0 ? -1 : free_index_[vertex]; }

  int free_count_ = 0;
  std::vector<int> free_index_;
  std::vector<int> colptr_, rowind_, diagonal_;
  std::vector<double> values_;
  std::vector<TermMap> maps_;
};

}  // namespace drapegen::sim
