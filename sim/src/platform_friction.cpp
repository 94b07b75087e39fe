#include "drapegen/sim/platform_friction.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace drapegen::sim {

PlatformFriction::PlatformFriction(const PlatformContact& contact, std::vector<int> vertices,
                                   const Eigen::Matrix3Xd& anchors, const FrictionParameters& params)
    : contact_(&contact), vertices_(std::move(vertices)), params_(params) {
  if (!(params.coefficient >= 0.0) || !std::isfinite(params.coefficient)) {
    throw std::invalid_argument("friction: the coefficient must be non-negative and finite");
  }
  if (!(params.stick_distance > 0.0) || !std::isfinite(params.stick_distance)) {
    throw std::invalid_argument("friction: the stick distance must be positive and finite");
  }
  anchors_.resize(2, static_cast<Eigen::Index>(vertices_.size()));
  for (std::size_t i = 0; i < vertices_.size(); ++i) {
    const int v = vertices_[i];
    if (v < 0 || v >= anchors.cols()) throw std::invalid_argument("friction: vertex index out of range");
    anchors_.col(static_cast<Eigen::Index>(i)) = anchors.col(v).head<2>();
  }
  normal_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(vertices_.size()));
}

double PlatformFriction::update_lagged(const Eigen::Matrix3Xd& x) {
  Eigen::Matrix3Xd force = Eigen::Matrix3Xd::Zero(3, x.cols());
  contact_->evaluate(x, &force, nullptr);
  Eigen::VectorXd updated(normal_.size());
  // The top's share of the contact force (its upward component; `force` holds the energy's gradient): a vertex that
  // slid over the rim onto the wall is pushed sideways, and friction in the top's plane would pull it into the wall.
  for (std::size_t i = 0; i < vertices_.size(); ++i)
    updated[static_cast<Eigen::Index>(i)] = std::max(0.0, -force(2, vertices_[i]));
  const double scale = std::max(updated.maxCoeff(), normal_.size() > 0 ? normal_.maxCoeff() : 0.0);
  const double change = scale > 0.0 ? (updated - normal_).cwiseAbs().maxCoeff() / scale : 0.0;
  normal_ = updated;
  return change;
}

double PlatformFriction::energy(const Eigen::Matrix3Xd& x) const { return evaluate(x, nullptr, nullptr); }

double PlatformFriction::evaluate(const Eigen::Matrix3Xd& x, Eigen::Matrix3Xd* gradient, HessianSink* hessian) const {
  const double eps = params_.stick_distance;
  double total = 0.0;
  Eigen::Matrix3d element;
  for (std::size_t i = 0; i < vertices_.size(); ++i) {
    const Eigen::Index k = static_cast<Eigen::Index>(i);
    const double scale = params_.coefficient * normal_[k];
    const Eigen::Vector2d u = x.col(vertices_[i]).head<2>() - anchors_.col(k);
    const double length = u.norm();
    const bool stick = length < eps;
    total += scale * (stick ? 0.5 * length * length / eps : length - 0.5 * eps);
    if (gradient != nullptr) {
      const Eigen::Vector2d g = stick ? Eigen::Vector2d(scale / eps * u) : Eigen::Vector2d(scale / length * u);
      gradient->col(vertices_[i]).head<2>() += g;
    }
    if (hessian != nullptr) {
      element.setZero();
      if (stick) {
        element.topLeftCorner<2, 2>() = scale / eps * Eigen::Matrix2d::Identity();
      } else {
        const Eigen::Vector2d t = u / length;
        element.topLeftCorner<2, 2>() = scale / length * (Eigen::Matrix2d::Identity() - t * t.transpose());
      }
      hessian->add(static_cast<int>(i), element.data());
    }
  }
  return total;
}

}  // namespace drapegen::sim
