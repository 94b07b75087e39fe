#include "drapegen/sim/platform.hpp"

#include <Eigen/Dense>

#include <cmath>
#include <stdexcept>

namespace drapegen::sim {

PlatformDistance platform_distance(const PlatformSpec& spec, const Eigen::Vector3d& p) {
  // Distance to the core cylinder (radius R - f, top at -f), minus the fillet radius f: a rounded rim for free.
  const double f = spec.fillet;
  const double r = std::hypot(p.x(), p.y());
  const double dr = r - (spec.radius - f);
  const double dz = p.z() + f;
  const Eigen::Vector3d radial = r > 1e-12 ? Eigen::Vector3d(p.x() / r, p.y() / r, 0.0) : Eigen::Vector3d::UnitX();
  const Eigen::Vector3d azimuthal(-radial.y(), radial.x(), 0.0);
  PlatformDistance out;
  if (dr > 0.0 && dz > 0.0) {  // rim: distance to the core's top circle
    const double rho = std::hypot(dr, dz);
    const double nr = dr / rho, nz = dz / rho;
    out.distance = rho - f;
    out.gradient = nr * radial + nz * Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d meridian = nz * radial - nr * Eigen::Vector3d::UnitZ();
    out.hessian = meridian * meridian.transpose() / rho;
    if (r > 1e-12) out.hessian += (nr / r) * azimuthal * azimuthal.transpose();
  } else if (dr > dz) {  // side wall (or inside, nearer the wall)
    out.distance = dr - f;
    out.gradient = radial;
    if (r > 1e-12) out.hessian = azimuthal * azimuthal.transpose() / r;
  } else {  // top disk (or inside, nearer the top)
    out.distance = dz - f;
    out.gradient = Eigen::Vector3d::UnitZ();
  }
  return out;
}

PlatformContact::PlatformContact(const ClothMesh& mesh, const PlatformSpec& spec) : spec_(spec) {
  if (!(spec.radius > 0.0) || !(spec.fillet >= 0.0) || !(spec.fillet < spec.radius) || !(spec.height > 0.0) ||
      !(spec.contact_offset >= 0.0) || !(spec.contact_stiffness > 0.0)) {
    throw std::invalid_argument("platform: radius, height and stiffness must be positive, 0 <= fillet < radius");
  }
  stiffness_ = rest_vertex_areas(mesh) * spec.contact_stiffness;
  scale_ = std::max(spec.contact_offset, 1e-4);
}

double PlatformContact::energy(const Eigen::Matrix3Xd& x) const { return evaluate(x, nullptr, nullptr); }

double PlatformContact::evaluate(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd* gradient, HessianSink* hessian) const {
  double total = 0.0;
  const bool exact = hessian != nullptr && hessian->mode() == HessianMode::kExact;
  for (int i = 0; i < element_count(); ++i) {
    const Eigen::Vector3d p = x.col(i);
    // Quick reject: above the top with margin, or far outside the wall.
    if (p.z() > spec_.contact_offset + 1e-9 || p.z() < -spec_.height) {
      if (hessian != nullptr) {
        const Eigen::Matrix3d zero = Eigen::Matrix3d::Zero();
        hessian->add(i, zero.data());
      }
      continue;
    }
    const PlatformDistance d = platform_distance(spec_, p);
    const double gap = d.distance - spec_.contact_offset;
    Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
    if (gap < 0.0) {
      // Cubic penalty k p^3 / (3 t) in the penetration p = -gap, t = contact_offset: its Hessian is continuous where
      // contact starts, so Newton does not chatter as vertices slide on and off the wall.
      const double k = stiffness_[i] / scale_;
      const double p = -gap;
      total += k * p * p * p / 3.0;
      if (gradient != nullptr) gradient->col(i) -= k * p * p * d.gradient;
      h = 2.0 * k * p * d.gradient * d.gradient.transpose();
      if (exact) h -= k * p * p * d.hessian;  // negative semi-definite: dropped by the projection
    }
    if (hessian != nullptr) hessian->add(i, h.data());
  }
  return total;
}

double PlatformContact::max_penetration(const Eigen::Matrix3Xd& x) const {
  double deepest = 0.0;
  for (int i = 0; i < element_count(); ++i) {
    const double gap = platform_distance(spec_, x.col(i)).distance - spec_.contact_offset;
    deepest = std::max(deepest, -gap);
  }
  return deepest;
}

std::vector<int> PlatformContact::vertices_on_top(const Eigen::Matrix3Xd& x, double tolerance) const {
  std::vector<int> out;
  for (int i = 0; i < element_count(); ++i) {
    const Eigen::Vector3d p = x.col(i);
    if (std::hypot(p.x(), p.y()) < spec_.radius - spec_.fillet && std::abs(p.z() - spec_.contact_offset) <= tolerance) {
      out.push_back(i);
    }
  }
  return out;
}

}  // namespace drapegen::sim
