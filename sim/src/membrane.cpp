#include "drapegen/sim/membrane.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace drapegen::sim {
namespace {

/// Thin SVD of a 3x2 matrix via the eigen-decomposition of F^T F: F = U diag(s) V^T, with u3 = u1 x u2.
struct Svd32 {
  Eigen::Vector2d s;
  Eigen::Matrix2d v;
  Eigen::Matrix3d u;  // columns u1, u2, u3
};

Svd32 svd32(const Eigen::Matrix<double, 3, 2>& f) {
  const Eigen::Matrix2d c = f.transpose() * f;
  const double mean = 0.5 * (c(0, 0) + c(1, 1));
  const double half_diff = 0.5 * (c(0, 0) - c(1, 1));
  const double radius = std::hypot(half_diff, c(0, 1));
  Svd32 out;
  const double l1 = mean + radius, l2 = std::max(mean - radius, 0.0);
  out.s = Eigen::Vector2d(std::sqrt(l1), std::sqrt(l2));
  // Eigenvector of the larger eigenvalue, robust when c is (nearly) a multiple of the identity.
  Eigen::Vector2d v1 = (half_diff >= 0.0) ? Eigen::Vector2d(half_diff + radius, c(0, 1))
                                          : Eigen::Vector2d(c(0, 1), radius - half_diff);
  const double norm = v1.norm();
  v1 = norm > 0.0 ? Eigen::Vector2d(v1 / norm) : Eigen::Vector2d(1.0, 0.0);
  out.v.col(0) = v1;
  out.v.col(1) = Eigen::Vector2d(-v1.y(), v1.x());
  Eigen::Vector3d u1 = f * out.v.col(0);
  u1 = u1.norm() > 0.0 ? Eigen::Vector3d(u1.normalized()) : Eigen::Vector3d::UnitX();
  Eigen::Vector3d u2 = f * out.v.col(1);
  u2 -= u2.dot(u1) * u1;
  if (u2.norm() < 1e-14 * std::max(1.0, out.s[0])) {
    u2 = u1.unitOrthogonal();
  } else {
    u2.normalize();
  }
  out.u.col(0) = u1;
  out.u.col(1) = u2;
  out.u.col(2) = u1.cross(u2);
  return out;
}

/// Shape-function weights: F.col(c) = sum_k w(k, c) * x_k for the triangle's three vertices.

}  // namespace

CorotationalMembrane::CorotationalMembrane(const ClothMesh& mesh, const MembraneParameters& params)
    : triangles_(mesh.triangles), params_(params) {
  if (!(params.stiffness > 0.0) || !std::isfinite(params.stiffness)) {
    throw std::invalid_argument("membrane stiffness must be positive and finite");
  }
  if (!(params.band_low > 0.0 && params.band_low <= 1.0 && params.band_high >= 1.0)) {
    throw std::invalid_argument("membrane band must satisfy 0 < low <= 1 <= high");
  }
  if (!(params.band_stiffness_ratio > 0.0 && params.band_stiffness_ratio <= 1.0)) {
    throw std::invalid_argument("membrane band stiffness ratio must be in (0, 1]");
  }
  const int nt = mesh.triangle_count();
  rest_.reserve(nt);
  for (int t = 0; t < nt; ++t) rest_.push_back(rest_triangle(mesh, t));
}

void CorotationalMembrane::element_vertices(int element, int* out) const {
  for (int k = 0; k < 3; ++k) out[k] = triangles_(k, element);
}

Eigen::Matrix<double, 3, 2> CorotationalMembrane::deformation_gradient(const Eigen::Matrix3Xd& x, int t) const {
  Eigen::Matrix<double, 3, 2> ds;
  ds.col(0) = x.col(triangles_(1, t)) - x.col(triangles_(0, t));
  ds.col(1) = x.col(triangles_(2, t)) - x.col(triangles_(0, t));
  return ds * rest_[t].inverse;
}

namespace {

/// One side of the band energy, for a stretch excess u >= 0 over a band half-width b: stiffness ratio eps inside the
/// band, rising linearly to 1 over a width w beyond it (so the second derivative is continuous), 1 after that.
CorotationalMembrane::StretchEnergy band_side(double u, double b, double eps) {
  if (b <= 0.0) return {u * u, 2.0 * u, 2.0};
  const double w = 0.5 * b;
  if (u <= b) return {eps * u * u, 2.0 * eps * u, 2.0 * eps};
  if (u <= b + w) {
    const double t = u - b;
    return {eps * b * b + 2.0 * eps * b * t + eps * t * t + (1.0 - eps) * t * t * t / (3.0 * w),
            2.0 * eps * (b + t) + (1.0 - eps) * t * t / w, 2.0 * eps + 2.0 * (1.0 - eps) * t / w};
  }
  const double t = u - b - w;
  const double g1 = 2.0 * eps * (b + w) + (1.0 - eps) * w;
  const double g0 = eps * (b + w) * (b + w) + (1.0 - eps) * w * w / 3.0;
  return {g0 + g1 * t + t * t, g1 + 2.0 * t, 2.0};
}

}  // namespace

CorotationalMembrane::StretchEnergy CorotationalMembrane::stretch_energy(double s) const {
  const double eps = params_.band_stiffness_ratio;
  if (s >= 1.0) return band_side(s - 1.0, params_.band_high - 1.0, eps);
  const StretchEnergy g = band_side(1.0 - s, 1.0 - params_.band_low, eps);
  return {g.value, -g.first, g.second};
}

double CorotationalMembrane::energy(const Eigen::Matrix3Xd& x) const {
  double total = 0.0;
  for (int t = 0; t < element_count(); ++t) {
    const Eigen::Matrix<double, 3, 2> f = deformation_gradient(x, t);
    const Eigen::Matrix2d c = f.transpose() * f;
    const double mean = 0.5 * (c(0, 0) + c(1, 1));
    const double radius = std::hypot(0.5 * (c(0, 0) - c(1, 1)), c(0, 1));
    const double s1 = std::sqrt(mean + radius), s2 = std::sqrt(std::max(mean - radius, 0.0));
    total += params_.stiffness * rest_[t].area * (stretch_energy(s1).value + stretch_energy(s2).value);
  }
  return total;
}

double CorotationalMembrane::evaluate(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd* gradient,
                                      HessianSink* hessian) const {
  double total = 0.0;
  const bool project = hessian != nullptr && hessian->mode() != HessianMode::kExact;
  for (int t = 0; t < element_count(); ++t) {
    const Svd32 svd = svd32(deformation_gradient(x, t));
    const double scale = params_.stiffness * rest_[t].area;
    const StretchEnergy g1 = stretch_energy(svd.s[0]), g2 = stretch_energy(svd.s[1]);
    const Eigen::Vector2d dpsi(scale * g1.first, scale * g2.first);
    total += scale * (g1.value + g2.value);
    const Eigen::Matrix<double, 3, 2>& w = rest_[t].gradients;

    if (gradient != nullptr) {
      const Eigen::Matrix<double, 3, 2> p = svd.u.leftCols<2>() * dpsi.asDiagonal() * svd.v.transpose();
      for (int a = 0; a < 3; ++a) gradient->col(triangles_(a, t)) += p * w.row(a).transpose();
    }
    if (hessian == nullptr) continue;

    // Eigen-system of d^2 psi / dF^2 in vec(F) (column-major 6-vector) space.
    const double s_sum = svd.s[0] + svd.s[1];
    const double k1 = scale * g1.second, k2 = scale * g2.second;
    double twist = s_sum > 1e-12 ? (dpsi[0] + dpsi[1]) / s_sum : k1;
    // Divided difference of g'; its limit g'' where the stretches coincide.
    const double s_diff = svd.s[0] - svd.s[1];
    double flip = s_diff > 1e-9 ? (dpsi[0] - dpsi[1]) / s_diff : 0.5 * (k1 + k2);
    double out0 = svd.s[0] > 1e-12 ? dpsi[0] / svd.s[0] : 0.0;
    double out1 = svd.s[1] > 1e-12 ? dpsi[1] / svd.s[1] : 0.0;
    if (project) {
      twist = std::max(twist, 0.0);
      flip = std::max(flip, 0.0);
      out0 = std::max(out0, 0.0);
      out1 = std::max(out1, 0.0);
    }
    auto mode = [&](const Eigen::Vector3d& a, const Eigen::Vector2d& b) {
      Eigen::Matrix<double, 6, 1> q;
      q.head<3>() = a * b[0];
      q.tail<3>() = a * b[1];
      return q;
    };
    const Eigen::Vector3d u1 = svd.u.col(0), u2 = svd.u.col(1), u3 = svd.u.col(2);
    const Eigen::Vector2d v1 = svd.v.col(0), v2 = svd.v.col(1);
    constexpr double kInvSqrt2 = 0.70710678118654752440;
    Eigen::Matrix<double, 6, 1> q;
    Eigen::Matrix<double, 6, 6> hf = Eigen::Matrix<double, 6, 6>::Zero();
    q = mode(u1, v1);
    hf.noalias() += k1 * q * q.transpose();
    q = mode(u2, v2);
    hf.noalias() += k2 * q * q.transpose();
    q = kInvSqrt2 * (mode(u1, v2) - mode(u2, v1));
    hf.noalias() += twist * q * q.transpose();
    q = kInvSqrt2 * (mode(u1, v2) + mode(u2, v1));
    hf.noalias() += flip * q * q.transpose();
    q = mode(u3, v1);
    hf.noalias() += out0 * q * q.transpose();
    q = mode(u3, v2);
    hf.noalias() += out1 * q * q.transpose();

    // H_x(a, b) = sum_{c, d} w(a, c) w(b, d) hf(c-block, d-block).
    Eigen::Matrix<double, 9, 9> hx;
    for (int a = 0; a < 3; ++a) {
      for (int b = 0; b < 3; ++b) {
        Eigen::Matrix3d block = Eigen::Matrix3d::Zero();
        for (int c = 0; c < 2; ++c) {
          for (int d = 0; d < 2; ++d) block += w(a, c) * w(b, d) * hf.block<3, 3>(3 * c, 3 * d);
        }
        hx.block<3, 3>(3 * a, 3 * b) = block;
      }
    }
    hessian->add(t, hx.data());
  }
  return total;
}

}  // namespace drapegen::sim
