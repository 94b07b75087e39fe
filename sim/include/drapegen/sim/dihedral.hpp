#pragma once
// The signed dihedral angle of a hinge and its first and second derivatives.

#include <Eigen/Core>

namespace drapegen::sim {

using Vector12d = Eigen::Matrix<double, 12, 1>;
using Matrix12d = Eigen::Matrix<double, 12, 12>;

/// Hinge (x0, x1) with wings x2 (triangle x0 x1 x2) and x3 (triangle x1 x0 x3). Returns the signed angle between
/// the two triangle normals about the edge, in (-pi, pi]; 0 when flat; negative when both wings are lifted along
/// their normals.
[[nodiscard]] double dihedral_angle(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1, const Eigen::Vector3d& x2,
                                    const Eigen::Vector3d& x3);

/// Angle and gradient (12-vector, vertex-major).
double dihedral_angle_gradient(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1, const Eigen::Vector3d& x2,
                               const Eigen::Vector3d& x3, Vector12d& gradient);

/// Angle, gradient and Hessian.
double dihedral_angle_hessian(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1, const Eigen::Vector3d& x2,
                              const Eigen::Vector3d& x3, Vector12d& gradient, Matrix12d& hessian);

}  // namespace drapegen::sim
