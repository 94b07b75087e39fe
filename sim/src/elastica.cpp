#include "drapegen/sim/elastica.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

namespace drapegen::sim {
namespace {

constexpr double kHalfPi = std::numbers::pi / 2.0;

// The integration always takes at least this many RK4 steps over the strip, however few points are requested ...
constexpr int kMinSteps = 2000;
// ... and resolves the clamp boundary layer of a hanging strip, whose decay length is about L / sqrt(Gamma), with
// steps of at most this fraction of it.
constexpr double kStepsPerDecayLength = 50.0;
// Smallest trial tip angle from the vertical. The clamp angle grows from it by up to exp(2/3 sqrt(Gamma)), so this
// bounds the Gamma that double precision can represent (about 5e5).
constexpr double kSmallestTipAngle = 1e-280;
// The Gamma at which that growth reaches 1 / kSmallestTipAngle (about 9.3e5). Beyond it no tip angle is resolved, and
// the boundary layer's step count (kStepsPerDecayLength sqrt(Gamma)) would only grow, past an int's range from 1.6e15.
const double kLargestGamma = std::pow(1.5 * std::log(1.0 / kSmallestTipAngle), 2);
constexpr int kMaxBisections = 200;
// Accepted mismatch of the clamp angle from horizontal after shooting (radians).
constexpr double kClampAngleTolerance = 1e-8;

/// The bending law in dimensionless form: m = k + b k^2, with moment m = M L / alpha, curvature k = kappa L and
/// b = beta / (alpha L).
class DimensionlessLaw {
 public:
  explicit DimensionlessLaw(double b) : b_(b) {}

  /// The peak moment of a softening law (b < 0); +infinity otherwise.
  [[nodiscard]] double peak_moment() const {
    return b_ < 0.0 ? 1.0 / (-4.0 * b_) : std::numeric_limits<double>::infinity();
  }

  /// The curvature that carries moment m: the root of k + b k^2 = m on the rising branch, written without
  /// cancellation. Moments beyond the peak map to the peak curvature; only rejected trial steps ever see them.
  [[nodiscard]] double curvature(double m) const {
    const double discriminant = 1.0 + 4.0 * b_ * m;
    if (discriminant <= 0.0) return 1.0 / (-2.0 * b_);
    return 2.0 * m / (1.0 + std::sqrt(discriminant));
  }

 private:
  double b_;
};

/// How one trial integration from the tip towards the clamp ended.
enum class Shot {
  kUndershoot,      // reached the clamp with the tangent still pointing below the horizontal: tip angle too small
  kOvershootAngle,  // the tangent turned past the horizontal before reaching the clamp: tip angle too large
  kOvershootPeak,   // the moment exceeded the peak torque before reaching the clamp: tip angle too large
};

struct ShotResult {
  Shot outcome;
  Eigen::Vector4d state;  // where the integration stopped
};

/// Integrates the dimensionless heavy elastica from the free tip towards the clamp.
///
/// The independent variable is u = 1 - s / L (0 at the tip, 1 at the clamp) and the state is
/// q = (phi, m, X, Y): phi the tangent angle from the downward vertical (pi/2 - theta, theta the angle below the
/// horizontal), m the dimensionless moment and (X, Y) the position relative to the tip in units of L. With
/// dM/ds = -rho g (L - s) cos(theta) and dtheta/ds = kappa(M):
///   dphi/du = k(m),  dm/du = Gamma u sin(phi),  dX/du = -sin(phi),  dY/du = cos(phi),
/// starting from q = (phi_tip, 0, 0, 0). The clamp condition is phi = pi/2 at u = 1. Integrating from the tip
/// follows the growing solution, so it is stable even for a strip hanging nearly vertically.
class TipShooter {
 public:
  TipShooter(double gamma, DimensionlessLaw law, int intervals, int substeps)
      : gamma_(gamma), law_(law), intervals_(intervals), substeps_(substeps), peak_(law.peak_moment()) {}

  /// Integrates from the tip angle phi_tip. When `trajectory` is given it receives the state at u = j / intervals
  /// for j = 0 .. intervals (complete only for an undershoot).
  ShotResult shoot(double phi_tip, std::vector<Eigen::Vector4d>* trajectory) const {
    Eigen::Vector4d q(phi_tip, 0.0, 0.0, 0.0);
    if (trajectory != nullptr) {
      trajectory->assign(1, q);
      trajectory->reserve(static_cast<std::size_t>(intervals_) + 1);
    }
    const double h = 1.0 / (static_cast<double>(intervals_) * substeps_);
    for (int j = 0; j < intervals_; ++j) {
      for (int k = 0; k < substeps_; ++k) {
        q = rk4_step(static_cast<double>(j * substeps_ + k) * h, h, q);
        if (q[0] > kHalfPi) return {Shot::kOvershootAngle, q};
        if (q[1] > peak_) return {Shot::kOvershootPeak, q};
      }
      if (trajectory != nullptr) trajectory->push_back(q);
    }
    return {Shot::kUndershoot, q};
  }

 private:
  [[nodiscard]] Eigen::Vector4d rate(double u, const Eigen::Vector4d& q) const {
    const double sin_phi = std::sin(q[0]);
    return {law_.curvature(q[1]), gamma_ * u * sin_phi, -sin_phi, std::cos(q[0])};
  }

  [[nodiscard]] Eigen::Vector4d rk4_step(double u, double h, const Eigen::Vector4d& q) const {
    const Eigen::Vector4d k1 = rate(u, q);
    const Eigen::Vector4d k2 = rate(u + 0.5 * h, q + 0.5 * h * k1);
    const Eigen::Vector4d k3 = rate(u + 0.5 * h, q + 0.5 * h * k2);
    const Eigen::Vector4d k4 = rate(u + h, q + h * k3);
    return q + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
  }

  double gamma_;
  DimensionlessLaw law_;
  int intervals_;
  int substeps_;
  double peak_;
};

/// RK4 substeps per output interval: enough for kMinSteps overall and for the clamp boundary layer.
int substeps_for(double gamma, int intervals) {
  const double steps = std::max(static_cast<double>(kMinSteps), kStepsPerDecayLength * std::sqrt(gamma));
  return std::max(1, static_cast<int>(std::ceil(steps / intervals)));
}

/// The tip angle from the vertical (phi_tip) that brings the tangent horizontal at the clamp, or an error.
///
/// The clamp angle increases monotonically with the tip angle (the system is cooperative: both right-hand sides
/// increase with the other variable), so bisection is safe. It runs on log(phi_tip): for a nearly vertical strip the
/// clamp angle depends on phi_tip through a factor of up to exp(2/3 sqrt(Gamma)), and phi_tip is then tiny, which
/// floating point represents with full relative precision.
Expected<double> shoot_tip_angle(const TipShooter& shooter) {
  if (shooter.shoot(kHalfPi, nullptr).outcome == Shot::kUndershoot) {
    return kHalfPi;  // the load is too small to turn the tangent by one rounding unit: a straight strip
  }
  double lo = std::log(kSmallestTipAngle);
  double hi = std::log(kHalfPi);
  if (shooter.shoot(kSmallestTipAngle, nullptr).outcome != Shot::kUndershoot) {
    return Error{"solve_heavy_cantilever: Gamma = rho*g*L^3/alpha is too large to resolve in double precision"};
  }
  Shot hi_outcome = Shot::kOvershootAngle;
  for (int iteration = 0; iteration < kMaxBisections; ++iteration) {
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi) break;
    const Shot outcome = shooter.shoot(std::exp(mid), nullptr).outcome;
    if (outcome == Shot::kUndershoot) {
      lo = mid;
    } else {
      hi = mid;
      hi_outcome = outcome;
    }
  }
  const ShotResult best = shooter.shoot(std::exp(lo), nullptr);
  if (kHalfPi - best.state[0] <= kClampAngleTolerance) return std::exp(lo);
  if (hi_outcome == Shot::kOvershootPeak) {
    return Error{"solve_heavy_cantilever: no equilibrium - the bending moment would exceed the peak torque "
                 "alpha^2/(4|beta|) of the softening law (beyond kappa* = alpha/(2|beta|) the torque is a plateau)"};
  }
  return Error{"solve_heavy_cantilever: shooting did not converge (clamp angle off by " +
               std::to_string(kHalfPi - best.state[0]) + " rad)"};
}

Status validate(double length, double alpha, double beta, double areal_density, double gravity, int samples) {
  const auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (!positive(length)) return Error{"solve_heavy_cantilever: length must be finite and positive"};
  if (!positive(alpha)) return Error{"solve_heavy_cantilever: alpha must be finite and positive"};
  if (!std::isfinite(beta)) return Error{"solve_heavy_cantilever: beta must be finite"};
  if (!positive(areal_density)) return Error{"solve_heavy_cantilever: areal_density must be finite and positive"};
  if (!std::isfinite(gravity) || gravity < 0.0) {
    return Error{"solve_heavy_cantilever: gravity must be finite and non-negative"};
  }
  if (samples < 3) return Error{"solve_heavy_cantilever: samples must be at least 3"};
  return {};
}

}  // namespace

Expected<CantileverCurve> solve_heavy_cantilever(double length, double alpha, double beta, double areal_density,
                                                 double gravity, int samples) {
  if (const Status status = validate(length, alpha, beta, areal_density, gravity, samples); !status) {
    return status.error();
  }
  const double gamma = areal_density * gravity * length * length * length / alpha;
  if (!std::isfinite(gamma)) return Error{"solve_heavy_cantilever: Gamma = rho*g*L^3/alpha overflows"};
  if (gamma > kLargestGamma) {
    return Error{"solve_heavy_cantilever: Gamma = rho*g*L^3/alpha is too large to resolve in double precision"};
  }

  const int intervals = samples - 1;
  CantileverCurve curve;
  curve.points.resize(static_cast<std::size_t>(samples));
  if (gamma == 0.0) {  // no load: a straight horizontal strip
    for (int i = 0; i < samples; ++i) curve.points[i] = {length * i / intervals, 0.0};
    return curve;
  }

  const TipShooter shooter(gamma, DimensionlessLaw(beta / (alpha * length)), intervals,
                           substeps_for(gamma, intervals));
  const Expected<double> phi_tip = shoot_tip_angle(shooter);
  if (!phi_tip) return phi_tip.error();

  std::vector<Eigen::Vector4d> trajectory;
  shooter.shoot(*phi_tip, &trajectory);  // an undershoot within tolerance: the trajectory is complete
  const Eigen::Vector4d& clamp = trajectory.back();
  for (int i = 0; i <= intervals; ++i) {
    const Eigen::Vector4d& q = trajectory[static_cast<std::size_t>(intervals - i)];
    curve.points[i] = length * Eigen::Vector2d(q[2] - clamp[2], q[3] - clamp[3]);
  }
  curve.height_over_width = clamp[3] / -clamp[2];
  curve.tip_angle = kHalfPi - *phi_tip;
  return curve;
}

Expected<double> master_curve_height_over_width(double gamma) {
  if (!std::isfinite(gamma) || gamma < 0.0) {
    return Error{"master_curve_height_over_width: Gamma must be finite and non-negative"};
  }
  // Unit length, stiffness and weight per length: Gamma is then rho. The integration accuracy does not depend on
  // the number of output points, so three suffice.
  if (gamma == 0.0) return 0.0;
  const Expected<CantileverCurve> curve = solve_heavy_cantilever(1.0, 1.0, 0.0, gamma, 1.0, 3);
  if (!curve) return curve.error();
  return curve->height_over_width;
}

}  // namespace drapegen::sim
