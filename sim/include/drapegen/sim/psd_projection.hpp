#pragma once
// Projection of a small symmetric matrix onto the positive semi-definite cone.

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

namespace drapegen::sim {

/// Replaces `m` by its nearest positive semi-definite matrix (negative eigenvalues clamped to zero).
template <int N>
void project_to_psd(Eigen::Matrix<double, N, N>& m) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, N, N>> eig(m);
  if (eig.eigenvalues().minCoeff() >= 0.0) return;
  const Eigen::Matrix<double, N, 1> clamped = eig.eigenvalues().cwiseMax(0.0);
  m = eig.eigenvectors() * clamped.asDiagonal() * eig.eigenvectors().transpose();
}

}  // namespace drapegen::sim
