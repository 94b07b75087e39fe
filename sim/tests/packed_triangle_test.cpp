// The packed diagonal blocks of the preconditioner: packing and both triangular solves, against double-precision
// solves with the same (single-precision) triangle.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>
#include <vector>

#include "drapegen/sim/packed_triangle.hpp"

namespace drapegen::sim {
namespace {

/// A well-conditioned lower triangle of order n stored in an ld x n column-major array (rows n..ld-1 belong to the
/// panel below it and must be ignored by the packing).
Eigen::MatrixXd random_triangle(int n, int ld, std::mt19937& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::MatrixXd l = Eigen::MatrixXd::Zero(ld, n);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < ld; ++i) l(i, j) = i < j ? 1e30 : 0.3 * normal(rng) / std::sqrt(n + 1.0);  // junk above
    l(j, j) = (j % 2 == 0 ? 1.0 : -1.0) * (1.0 + std::abs(normal(rng))) * (j % 3 == 0 ? 1e3 : 1.0);
  }
  return l;
}

TEST(PackedTriangle, PackingKeepsTheTriangleWithReciprocalDiagonal) {
  std::mt19937 rng(5);
  const int n = 5, ld = 9;
  const Eigen::MatrixXd l = random_triangle(n, ld, rng);
  std::vector<float> packed(packed_triangle_size(n));
  EXPECT_EQ(packed.size(), 15u);
  pack_lower_triangle(l.data(), n, ld, packed.data());
  std::size_t p = 0;
  for (int j = 0; j < n; ++j) {
    EXPECT_FLOAT_EQ(packed[p++], static_cast<float>(1.0 / l(j, j)));
    for (int i = j + 1; i < n; ++i) EXPECT_EQ(packed[p++], static_cast<float>(l(i, j)));
  }
  EXPECT_EQ(p, packed.size());
}

TEST(PackedTriangle, SolvesMatchDoublePrecision) {
  std::mt19937 rng(11);
  std::normal_distribution<float> normal(0.0f, 1.0f);
  // Orders around the 8-wide vector loop of the transposed solve, small supernodes (3: one vertex) and a large one.
  for (int n : {0, 1, 2, 3, 6, 7, 8, 9, 17, 64, 301}) {
    const int ld = n + 4;
    const Eigen::MatrixXd l = random_triangle(n, ld, rng);
    std::vector<float> packed(packed_triangle_size(n));
    pack_lower_triangle(l.data(), n, ld, packed.data());
    // The triangle the kernels see: single-precision entries, double-precision arithmetic.
    Eigen::MatrixXd rounded = Eigen::MatrixXd::Zero(n, n);
    std::size_t p = 0;
    for (int j = 0; j < n; ++j) {
      rounded(j, j) = 1.0 / static_cast<double>(packed[p++]);
      for (int i = j + 1; i < n; ++i) rounded(i, j) = packed[p++];
    }
    std::vector<float> y(n);
    for (auto& v : y) v = normal(rng);
    const Eigen::VectorXd b = Eigen::Map<const Eigen::VectorXf>(y.data(), n).cast<double>();
    const Eigen::VectorXd forward = rounded.triangularView<Eigen::Lower>().solve(b);
    const Eigen::VectorXd backward = rounded.triangularView<Eigen::Lower>().transpose().solve(b);

    std::vector<float> yf = y, yb = y;
    packed_lower_solve(packed.data(), n, yf.data());
    packed_lower_transpose_solve(packed.data(), n, yb.data());
    const double tol_f = 1e-5 * (1.0 + (n > 0 ? forward.cwiseAbs().maxCoeff() : 0.0));
    const double tol_b = 1e-5 * (1.0 + (n > 0 ? backward.cwiseAbs().maxCoeff() : 0.0));
    for (int i = 0; i < n; ++i) {
      EXPECT_NEAR(yf[i], forward[i], tol_f) << "n " << n << " row " << i;
      EXPECT_NEAR(yb[i], backward[i], tol_b) << "n " << n << " row " << i;
    }
  }
}

}  // namespace
}  // namespace drapegen::sim
