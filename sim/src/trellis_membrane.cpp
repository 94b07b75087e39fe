#include "drapegen/sim/trellis_membrane.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <unsupported/Eigen/AutoDiff>

namespace drapegen::sim {
namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

/// Gradient of s(a, b) = a.b / (|a| |b|) (the sine of the shear angle) with respect to (a, b), for any scalar type.
template <typename T>
Eigen::Matrix<T, 6, 1> shear_sine_gradient(const Eigen::Matrix<T, 3, 1>& a, const Eigen::Matrix<T, 3, 1>& b) {
  const T p = a.dot(b), la = a.norm(), lb = b.norm();
  const T inv = T(1.0) / (la * lb);
  Eigen::Matrix<T, 6, 1> g;
  g.template head<3>() = inv * (b - (p / (la * la)) * a);
  g.template tail<3>() = inv * (a - (p / (lb * lb)) * b);
  return g;
}

}  // namespace

TrellisMembrane::TrellisMembrane(const ClothMesh& mesh, const TrellisParameters& params)
    : triangles_(mesh.triangles), params_(params), band_(mesh, params.yarn) {
  if (!(params.shear_stiffness >= 0.0) || !std::isfinite(params.shear_stiffness)) {
    throw std::invalid_argument("trellis membrane: the shear stiffness must be non-negative and finite");
  }
  const Eigen::Vector2d warp(std::cos(mesh.material_angle), std::sin(mesh.material_angle));
  const Eigen::Vector2d weft(-warp.y(), warp.x());
  const int nt = mesh.triangle_count();
  weights_.resize(nt);
  area_.resize(nt);
  for (int t = 0; t < nt; ++t) {
    // F = sum_v x_v grad(N_v)^T, so F d = sum_v x_v (grad(N_v) . d).
    const RestTriangle rest = rest_triangle(mesh, t);
    weights_[t].col(0) = rest.gradients * warp;
    weights_[t].col(1) = rest.gradients * weft;
    area_[t] = rest.area;
  }
}

void TrellisMembrane::element_vertices(int element, int* out) const {
  for (int a = 0; a < 3; ++a) out[a] = triangles_(a, element);
}

double TrellisMembrane::energy(const Eigen::Matrix3Xd& x) const { return evaluate(x, nullptr, nullptr); }

double TrellisMembrane::evaluate(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd* gradient, HessianSink* hessian) const {
  const double sigma = params_.yarn.stiffness, shear = params_.shear_stiffness;
  double total = 0.0;
  Eigen::Matrix<double, 9, 9> element;
  for (int t = 0; t < element_count(); ++t) {
    const Eigen::Matrix<double, 3, 2>& w = weights_[t];
    Eigen::Vector3d a = Eigen::Vector3d::Zero(), b = Eigen::Vector3d::Zero();
    for (int v = 0; v < 3; ++v) {
      a += w(v, 0) * x.col(triangles_(v, t));
      b += w(v, 1) * x.col(triangles_(v, t));
    }
    const double la = a.norm(), lb = b.norm();
    if (!(la > 0.0 && lb > 0.0)) return std::numeric_limits<double>::quiet_NaN();  // a collapsed yarn
    const auto ga = band_.stretch_energy(la), gb = band_.stretch_energy(lb);
    // Shear as the principal stretches 1 +- sin(gamma)/2 it causes, through the same band energy: equal to the
    // isotropic membrane's charge for a pure shear when G = sigma, including its anti-locking dead zone.
    const double sine = a.dot(b) / (la * lb);
    const auto gp = band_.stretch_energy(1.0 + 0.5 * sine), gm = band_.stretch_energy(1.0 - 0.5 * sine);
    const double area = area_[t];
    total += area * (sigma * (ga.value + gb.value) + shear * (gp.value + gm.value));
    if (gradient == nullptr && hessian == nullptr) continue;

    // d psi / d(a, b).
    const Eigen::Vector3d ua = a / la, ub = b / lb;
    Vector6d g;
    g.head<3>() = sigma * ga.first * ua;
    g.tail<3>() = sigma * gb.first * ub;
    const Vector6d ds = shear_sine_gradient<double>(a, b);
    const double dpsi = 0.5 * shear * (gp.first - gm.first), d2psi = 0.25 * shear * (gp.second + gm.second);
    g += dpsi * ds;
    g *= area;
    if (gradient != nullptr) {
      for (int v = 0; v < 3; ++v) gradient->col(triangles_(v, t)) += w(v, 0) * g.head<3>() + w(v, 1) * g.tail<3>();
    }
    if (hessian == nullptr) continue;

    // d^2 psi / d(a, b)^2: the stretch blocks in closed form, the shear part by differentiating its gradient.
    Matrix6d h = Matrix6d::Zero();
    const Eigen::Matrix3d id = Eigen::Matrix3d::Identity();
    h.topLeftCorner<3, 3>() = sigma * (ga.second * ua * ua.transpose() + ga.first / la * (id - ua * ua.transpose()));
    h.bottomRightCorner<3, 3>() =
        sigma * (gb.second * ub * ub.transpose() + gb.first / lb * (id - ub * ub.transpose()));
    if (shear > 0.0) {
      using Dual = Eigen::AutoDiffScalar<Vector6d>;
      Eigen::Matrix<Dual, 3, 1> ad, bd;
      for (int k = 0; k < 3; ++k) {
        ad[k] = Dual(a[k], 6, k);
        bd[k] = Dual(b[k], 6, 3 + k);
      }
      const Eigen::Matrix<Dual, 6, 1> gd = shear_sine_gradient<Dual>(ad, bd);
      h += d2psi * ds * ds.transpose();
      for (int r = 0; r < 6; ++r) h.row(r) += dpsi * gd[r].derivatives().transpose();
    }
    h = (0.5 * area * (h + h.transpose())).eval();  // eval: h appears on both sides
    if (hessian->mode() != HessianMode::kExact) {
      Eigen::SelfAdjointEigenSolver<Matrix6d> eig(h);
      h = eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).asDiagonal() * eig.eigenvectors().transpose();
    }
    for (int u = 0; u < 3; ++u) {
      for (int v = 0; v < 3; ++v) {
        element.block<3, 3>(3 * u, 3 * v) = w(u, 0) * w(v, 0) * h.topLeftCorner<3, 3>() +
                                            w(u, 0) * w(v, 1) * h.topRightCorner<3, 3>() +
                                            w(u, 1) * w(v, 0) * h.bottomLeftCorner<3, 3>() +
                                            w(u, 1) * w(v, 1) * h.bottomRightCorner<3, 3>();
      }
    }
    hessian->add(t, element.data());
  }
  return total;
}

}  // namespace drapegen::sim
