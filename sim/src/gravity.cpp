#include "drapegen/sim/gravity.hpp"

#include <cmath>
#include <stdexcept>

namespace drapegen::sim {

Gravity::Gravity(const ClothMesh& mesh, double areal_density, double gravity) {
  if (!(areal_density > 0.0) || !std::isfinite(areal_density)) {
    throw std::invalid_argument("areal density must be positive and finite");
  }
  if (!std::isfinite(gravity)) throw std::invalid_argument("gravity must be finite");
  weight_ = rest_vertex_areas(mesh) * (areal_density * gravity);
}

double Gravity::energy(const Eigen::Matrix3Xd& x) const { return x.row(2).dot(weight_); }

double Gravity::evaluate(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd* gradient, HessianSink* /*hessian*/) const {
  if (gradient != nullptr) gradient->row(2) += weight_.transpose();
  return energy(x);
}

}  // namespace drapegen::sim
