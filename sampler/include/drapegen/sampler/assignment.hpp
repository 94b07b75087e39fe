#pragma once
// Exact linear assignment (the Hungarian method with potentials, O(n^3)), used for exact optimal transport between
// two equal-size point sets.

#include <Eigen/Core>
#include <vector>

namespace drapegen::sampler {

/// For a square cost matrix, the column assigned to each row in an assignment of minimal total cost.
[[nodiscard]] std::vector<int> solve_assignment(const Eigen::MatrixXd& cost);

}  // namespace drapegen::sampler
