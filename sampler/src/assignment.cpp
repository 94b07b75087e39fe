#include "drapegen/sampler/assignment.hpp"

#include <limits>
#include <stdexcept>

namespace drapegen::sampler {

// Shortest augmenting paths with row/column potentials (Kuhn-Munkres in its O(n^3) form): rows are added one at a
// time; each addition grows a Dijkstra-like tree over reduced costs until it reaches a free column, then flips the
// path. Index 0 is a virtual column that holds the row being added.
std::vector<int> solve_assignment(const Eigen::MatrixXd& cost) {
  const int n = static_cast<int>(cost.rows());
  if (cost.cols() != n) throw std::invalid_argument("solve_assignment: the cost matrix must be square");
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> u(n + 1, 0.0), v(n + 1, 0.0), min_reduced(n + 1);
  std::vector<int> row_of(n + 1, 0), previous(n + 1, 0);
  std::vector<char> in_tree(n + 1);
  for (int row = 1; row <= n; ++row) {
    row_of[0] = row;
    int col = 0;
    std::fill(min_reduced.begin(), min_reduced.end(), inf);
    std::fill(in_tree.begin(), in_tree.end(), 0);
    do {
      in_tree[col] = 1;
      const int i = row_of[col];
      double delta = inf;
      int next = 0;
      for (int j = 1; j <= n; ++j) {
        if (in_tree[j]) continue;
        const double reduced = cost(i - 1, j - 1) - u[i] - v[j];
        if (reduced < min_reduced[j]) {
          min_reduced[j] = reduced;
          previous[j] = col;
        }
        if (min_reduced[j] < delta) {
          delta = min_reduced[j];
          next = j;
        }
      }
      for (int j = 0; j <= n; ++j) {
        if (in_tree[j]) {
          u[row_of[j]] += delta;
          v[j] -= delta;
        } else {
          min_reduced[j] -= delta;
        }
      }
      col = next;
    } while (row_of[col] != 0);
    while (col != 0) {  // flip the augmenting path
      const int back = previous[col];
      row_of[col] = row_of[back];
      col = back;
    }
  }
  std::vector<int> assignment(n, -1);
  for (int j = 1; j <= n; ++j) assignment[row_of[j] - 1] = j - 1;
  return assignment;
}

}  // namespace drapegen::sampler
