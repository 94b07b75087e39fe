#include "drapegen/sim/dihedral.hpp"

#include <Eigen/Dense>

#include <cmath>
#include <unsupported/Eigen/AutoDiff>

namespace drapegen::sim {
namespace {

// The gradient in closed form (lever rule): the wing tips move along their normals with 1 / height, the edge
// vertices take the balancing share by the position of each wing tip's foot along the edge. Templated on the
// scalar so that forward-mode automatic differentiation of it yields the exact Hessian.
template <class T>
void gradient_of_angle(const Eigen::Matrix<T, 3, 1>& x0, const Eigen::Matrix<T, 3, 1>& x1,
                       const Eigen::Matrix<T, 3, 1>& x2, const Eigen::Matrix<T, 3, 1>& x3,
                       Eigen::Matrix<T, 12, 1>& g) {
  const Eigen::Matrix<T, 3, 1> e = x1 - x0;
  const T e2 = e.squaredNorm();
  const Eigen::Matrix<T, 3, 1> na = e.cross(x2 - x0);   // |na| = |e| * h_a
  const Eigen::Matrix<T, 3, 1> nb = (x0 - x1).cross(x3 - x1);
  const T len = sqrt(e2);
  const Eigen::Matrix<T, 3, 1> g2 = -(len / na.squaredNorm()) * na;
  const Eigen::Matrix<T, 3, 1> g3 = -(len / nb.squaredNorm()) * nb;
  const T a2 = (x2 - x0).dot(e) / e2;  // foot of x2 along the edge, 0 at x0, 1 at x1
  const T a3 = (x3 - x0).dot(e) / e2;
  g.template segment<3>(0) = -((T(1) - a2) * g2 + (T(1) - a3) * g3);
  g.template segment<3>(3) = -(a2 * g2 + a3 * g3);
  g.template segment<3>(6) = g2;
  g.template segment<3>(9) = g3;
}

}  // namespace

double dihedral_angle(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1, const Eigen::Vector3d& x2,
                      const Eigen::Vector3d& x3) {
  const Eigen::Vector3d e = x1 - x0;
  const Eigen::Vector3d na = e.cross(x2 - x0);
  const Eigen::Vector3d nb = (x0 - x1).cross(x3 - x1);
  const double sine = na.cross(nb).dot(e) / e.norm();
  return std::atan2(sine, na.dot(nb));
}

double dihedral_angle_gradient(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1, const Eigen::Vector3d& x2,
                               const Eigen::Vector3d& x3, Vector12d& gradient) {
  gradient_of_angle<double>(x0, x1, x2, x3, gradient);
  return dihedral_angle(x0, x1, x2, x3);
}

double dihedral_angle_hessian(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1, const Eigen::Vector3d& x2,
                              const Eigen::Vector3d& x3, Vector12d& gradient, Matrix12d& hessian) {
  using Dual = Eigen::AutoDiffScalar<Vector12d>;
  using Vec3 = Eigen::Matrix<Dual, 3, 1>;
  Vec3 p[4];
  const Eigen::Vector3d* in[4] = {&x0, &x1, &x2, &x3};
  for (int v = 0; v < 4; ++v) {
    for (int c = 0; c < 3; ++c) p[v][c] = Dual((*in[v])[c], 12, 3 * v + c);
  }
  Eigen::Matrix<Dual, 12, 1> g;
  gradient_of_angle<Dual>(p[0], p[1], p[2], p[3], g);
  for (int i = 0; i < 12; ++i) {
    gradient[i] = g[i].value();
    hessian.row(i) = g[i].derivatives().transpose();
  }
  hessian = 0.5 * (hessian + hessian.transpose()).eval();
  return dihedral_angle(x0, x1, x2, x3);
}

}  // namespace drapegen::sim
