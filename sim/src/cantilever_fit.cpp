#include "drapegen/sim/cantilever_fit.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <numeric>
#include <utility>

namespace drapegen::sim {
namespace {

constexpr int kMinDistinctPoints = 4;
constexpr int kMinSamples = 16;
// The curvature at sample i is fitted over the chords between samples i - kHalfWindow and i + kHalfWindow.
constexpr int kHalfWindow = 3;
// Uniform-in-x sampling is rejected when a gap exceeds this multiple of the mean arc-length spacing.
constexpr double kMaxGapRatio = 4.0;
// Consecutive input points closer than this fraction of the curve's extent are merged.
constexpr double kDuplicateTolerance = 1e-12;
// A curve whose largest |kappa| * length is below this is straight.
constexpr double kStraightCurvature = 1e-8;
// Smallest accepted ratio of the extreme eigenvalues of the column-scaled normal equations (a condition number of
// the regression of 1e6).
constexpr double kMinGramEigenvalueRatio = 1e-12;
constexpr int kRootBisections = 64;

using Points = std::vector<Eigen::Vector2d>;

/// Cumulative chord length along a polyline, starting at 0.
std::vector<double> cumulative_length(const Points& points) {
  std::vector<double> s(points.size(), 0.0);
  for (std::size_t i = 1; i < points.size(); ++i) s[i] = s[i - 1] + (points[i] - points[i - 1]).norm();
  return s;
}

/// Derivative at nodes[0] of the cubic through four (node, value) pairs (Lagrange form): a third-order accurate
/// one-sided slope.
Eigen::Vector2d end_slope(const double (&nodes)[4], const Eigen::Vector2d* const (&values)[4]) {
  Eigen::Vector2d slope = Eigen::Vector2d::Zero();
  for (int j = 0; j < 4; ++j) {
    double weight = 0.0;
    if (j == 0) {
      for (int k = 1; k < 4; ++k) weight += 1.0 / (nodes[0] - nodes[k]);
    } else {
      double numerator = 1.0, denominator = 1.0;
      for (int k = 0; k < 4; ++k) {
        if (k == j) continue;
        if (k != 0) numerator *= nodes[0] - nodes[k];
        denominator *= nodes[j] - nodes[k];
      }
      weight = numerator / denominator;
    }
    slope += weight * *values[j];
  }
  return slope;
}

/// An interpolating C2 cubic spline through a polyline, parameterized by cumulative chord length, with end slopes
/// from the cubic through the four end points (positions are fourth-order accurate, curvature continuous).
class SplineCurve {
 public:
  explicit SplineCurve(Points knots) : knots_(std::move(knots)), t_(cumulative_length(knots_)) {
    const int n = static_cast<int>(knots_.size());
    tangents_.assign(knots_.size(), Eigen::Vector2d::Zero());
    tangents_.front() = end_slope({t_[0], t_[1], t_[2], t_[3]}, {&knots_[0], &knots_[1], &knots_[2], &knots_[3]});
    tangents_.back() = end_slope({t_[n - 1], t_[n - 2], t_[n - 3], t_[n - 4]},
                                 {&knots_[n - 1], &knots_[n - 2], &knots_[n - 3], &knots_[n - 4]});
    // Continuity of the second derivative at the interior knots k = 1 .. n-2:
    //   h_k m_{k-1} + 2 (h_{k-1} + h_k) m_k + h_{k-1} m_{k+1} = 3 (h_k D_{k-1} + h_{k-1} D_k),
    // h_k the segment lengths and D_k the chord slopes; a diagonally dominant tridiagonal system (Thomas algorithm).
    std::vector<double> upper(knots_.size(), 0.0), diagonal(knots_.size(), 1.0);
    for (int k = 1; k + 1 < n; ++k) {
      const double h0 = t_[k] - t_[k - 1], h1 = t_[k + 1] - t_[k];
      const Eigen::Vector2d rhs = 3.0 * (h1 * (knots_[k] - knots_[k - 1]) / h0 + h0 * (knots_[k + 1] - knots_[k]) / h1);
      const double lower = h1;
      diagonal[k] = 2.0 * (h0 + h1) - lower * upper[k - 1];
      tangents_[k] = rhs - lower * tangents_[k - 1];
      upper[k] = h0 / diagonal[k];
      tangents_[k] /= diagonal[k];
    }
    for (int k = n - 2; k >= 1; --k) tangents_[k] -= upper[k] * tangents_[k + 1];
  }

  [[nodiscard]] const Points& knots() const { return knots_; }
  [[nodiscard]] int segment_count() const { return static_cast<int>(knots_.size()) - 1; }
  [[nodiscard]] double parameter_length() const { return t_.back(); }

  /// The point at local parameter u in [0, 1] of segment k.
  [[nodiscard]] Eigen::Vector2d at(int k, double u) const {
    const double dt = t_[k + 1] - t_[k];
    const double u2 = u * u, u3 = u2 * u;
    return (2.0 * u3 - 3.0 * u2 + 1.0) * knots_[k] + (u3 - 2.0 * u2 + u) * dt * tangents_[k] +
           (-2.0 * u3 + 3.0 * u2) * knots_[k + 1] + (u3 - u2) * dt * tangents_[k + 1];
  }

  /// The point at chord-length parameter t in [0, parameter_length()], found from segment `hint` onwards.
  [[nodiscard]] Eigen::Vector2d at_parameter(double t, int& hint) const {
    while (hint + 1 < segment_count() && t > t_[hint + 1]) ++hint;
    const double u = std::clamp((t - t_[hint]) / (t_[hint + 1] - t_[hint]), 0.0, 1.0);
    return at(hint, u);
  }

  /// The point with abscissa x, for knots with strictly monotone x, found from segment `hint` onwards. The root
  /// within the segment is found by bisection, which the knots bracket.
  [[nodiscard]] Eigen::Vector2d at_abscissa(double x, int& hint) const {
    const double direction = knots_.back().x() > knots_.front().x() ? 1.0 : -1.0;
    while (hint + 1 < segment_count() && direction * (x - knots_[hint + 1].x()) > 0.0) ++hint;
    double lo = 0.0, hi = 1.0;
    for (int i = 0; i < kRootBisections; ++i) {
      const double mid = 0.5 * (lo + hi);
      if (direction * (at(hint, mid).x() - x) < 0.0) {
        lo = mid;
      } else {
        hi = mid;
      }
    }
    return at(hint, 0.5 * (lo + hi));
  }

 private:
  Points knots_;
  std::vector<double> t_;
  Points tangents_;
};

/// The input without consecutive duplicates, or an error on non-finite or too few distinct points.
Expected<Points> distinct_points(const Points& curve) {
  for (const Eigen::Vector2d& p : curve) {
    if (!p.allFinite()) return Error{"fit_bending_moduli: the curve has non-finite coordinates"};
  }
  if (curve.empty()) return Error{"fit_bending_moduli: the curve is empty"};
  Eigen::Vector2d lo = curve.front(), hi = curve.front();
  for (const Eigen::Vector2d& p : curve) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double tolerance = kDuplicateTolerance * (hi - lo).norm();
  Points distinct{curve.front()};
  for (const Eigen::Vector2d& p : curve) {
    if ((p - distinct.back()).norm() > tolerance) distinct.push_back(p);
  }
  if (static_cast<int>(distinct.size()) < kMinDistinctPoints) {
    return Error{"fit_bending_moduli: the curve needs at least 4 distinct points"};
  }
  return distinct;
}

/// True when x strictly increases or strictly decreases along the polyline.
bool strictly_monotone_in_x(const Points& points) {
  bool increasing = true, decreasing = true;
  for (std::size_t i = 1; i < points.size(); ++i) {
    increasing = increasing && points[i].x() > points[i - 1].x();
    decreasing = decreasing && points[i].x() < points[i - 1].x();
  }
  return increasing || decreasing;
}

Points resample_uniform_in_x(const SplineCurve& curve, int samples) {
  const double x0 = curve.knots().front().x(), x1 = curve.knots().back().x();
  Points out(static_cast<std::size_t>(samples));
  int hint = 0;
  for (int i = 0; i < samples; ++i) out[i] = curve.at_abscissa(x0 + (x1 - x0) * i / (samples - 1), hint);
  out.front() = curve.knots().front();
  out.back() = curve.knots().back();
  return out;
}

/// Uniform in the chord-length parameter of the input, which is uniform in arc length up to O(h^2 kappa^2).
Points resample_uniform_in_arc_length(const SplineCurve& curve, int samples) {
  const double length = curve.parameter_length();
  Points out(static_cast<std::size_t>(samples));
  int hint = 0;
  for (int i = 0; i < samples; ++i) out[i] = curve.at_parameter(length * i / (samples - 1), hint);
  return out;
}

/// The paper's sampling (uniform in x) where it is adequate, arc-length sampling otherwise (see the header).
Points resample(const SplineCurve& curve, int samples) {
  if (strictly_monotone_in_x(curve.knots())) {
    Points by_x = resample_uniform_in_x(curve, samples);
    const std::vector<double> s = cumulative_length(by_x);
    double max_gap = 0.0;
    for (std::size_t i = 1; i < s.size(); ++i) max_gap = std::max(max_gap, s[i] - s[i - 1]);
    if (max_gap <= kMaxGapRatio * s.back() / (samples - 1)) return by_x;
  }
  return resample_uniform_in_arc_length(curve, samples);
}

/// Eq. 6 per unit width: the moment about r_i of the weight of the strip beyond r_i, by the trapezoid rule.
/// Positive when the weight bends the strip clockwise (downward for a strip pointing along +x). Uses suffix sums
/// of the segment moments, with x measured from the clamp.
std::vector<double> weight_torques(const Points& r, double weight_per_area) {
  const std::size_t n = r.size();
  std::vector<double> torque(n, 0.0);
  double first_moment = 0.0;  // sum_{j >= i} (x_j + x_{j+1}) / 2 * l_j
  double length = 0.0;        // sum_{j >= i} l_j
  const double x_clamp = r.front().x();
  for (std::size_t i = n - 1; i-- > 0;) {
    const double l = (r[i + 1] - r[i]).norm();
    first_moment += 0.5 * (r[i].x() + r[i + 1].x() - 2.0 * x_clamp) * l;
    length += l;
    torque[i] = weight_per_area * (first_moment - (r[i].x() - x_clamp) * length);
  }
  return torque;
}

/// Unwrapped tangent angles (counter-clockwise from +x) of the chords r_j r_{j+1}, and the arc lengths of the chord
/// midpoints, where each chord angle equals the tangent angle up to O(h^2 kappa').
void chord_angles(const Points& r, const std::vector<double>& s, std::vector<double>& angle,
                  std::vector<double>& midpoint) {
  const std::size_t n = r.size() - 1;
  angle.resize(n);
  midpoint.resize(n);
  for (std::size_t j = 0; j < n; ++j) {
    const Eigen::Vector2d chord = r[j + 1] - r[j];
    angle[j] = std::atan2(chord.y(), chord.x());
    if (j > 0) angle[j] += 2.0 * std::numbers::pi * std::round((angle[j - 1] - angle[j]) / (2.0 * std::numbers::pi));
    midpoint[j] = 0.5 * (s[j] + s[j + 1]);
  }
}

/// Clockwise curvature -dtheta/ds at arc length s_i from a least-squares cubic through the chord angles of the
/// kHalfWindow chords on either side. The cubic makes the estimate accurate to O(h^4) on smooth curves (a line fit over
/// the same window would be biased by O(h^2 kappa'') in the clamp boundary layer of a hanging strip) while the
/// window still averages out noise.
double window_curvature(const std::vector<double>& angle, const std::vector<double>& midpoint, double s_i, int i) {
  const int first = i - kHalfWindow, count = 2 * kHalfWindow;
  const double scale = (midpoint[first + count - 1] - midpoint[first]) / (count - 1);
  Eigen::Matrix4d normal = Eigen::Matrix4d::Zero();
  Eigen::Vector4d rhs = Eigen::Vector4d::Zero();
  for (int j = first; j < first + count; ++j) {
    const double d = (midpoint[j] - s_i) / scale;
    const Eigen::Vector4d basis(1.0, d, d * d, d * d * d);
    normal += basis * basis.transpose();
    rhs += basis * (angle[j] - angle[i]);
  }
  const Eigen::Vector4d coefficients = normal.ldlt().solve(rhs);
  return -coefficients(1) / scale;
}

double dot(const std::vector<double>& a, const std::vector<double>& b) {
  return std::inner_product(a.begin(), a.end(), b.begin(), 0.0);
}

/// Least squares for tau = alpha kappa + beta kappa |kappa| (beta = 0 when !fit_beta) by the normal equations of
/// the columns scaled to unit norm. The scaled Gram matrix [[1, c], [c, 1]] has eigenvalues 1 -/+ |c|; their ratio
/// tells whether the data separate alpha from beta, independently of units.
Expected<BendingFit> regress(const std::vector<double>& kappa, const std::vector<double>& tau, bool fit_beta) {
  std::vector<double> quadratic(kappa.size());
  for (std::size_t i = 0; i < kappa.size(); ++i) quadratic[i] = kappa[i] * std::abs(kappa[i]);
  const double linear_norm = std::sqrt(dot(kappa, kappa)), quadratic_norm = std::sqrt(dot(quadratic, quadratic));
  BendingFit fit;
  if (fit_beta) {
    const double c = dot(kappa, quadratic) / (linear_norm * quadratic_norm);
    if (1.0 - std::abs(c) < kMinGramEigenvalueRatio * (1.0 + std::abs(c))) {
      return Error{"fit_bending_moduli: the curvature range is too narrow to separate alpha from beta"};
    }
    const double b1 = dot(kappa, tau) / linear_norm, b2 = dot(quadratic, tau) / quadratic_norm;
    const double determinant = 1.0 - c * c;
    fit.alpha = (b1 - c * b2) / determinant / linear_norm;
    fit.beta = (b2 - c * b1) / determinant / quadratic_norm;
  } else {
    fit.alpha = dot(kappa, tau) / (linear_norm * linear_norm);
  }
  double residual_squared = 0.0;
  for (std::size_t i = 0; i < kappa.size(); ++i) {
    const double residual = fit.alpha * kappa[i] + fit.beta * quadratic[i] - tau[i];
    residual_squared += residual * residual;
  }
  const double tau_norm = std::sqrt(dot(tau, tau));
  fit.rms_relative_residual = tau_norm > 0.0 ? std::sqrt(residual_squared) / tau_norm : 0.0;
  fit.samples_used = static_cast<int>(kappa.size());
  return fit;
}

}  // namespace

Expected<BendingFit> fit_bending_moduli(const std::vector<Eigen::Vector2d>& curve, double areal_density,
                                        double gravity, bool fit_beta, int samples) {
  if (!std::isfinite(areal_density) || areal_density <= 0.0) {
    return Error{"fit_bending_moduli: areal_density must be finite and positive"};
  }
  if (!std::isfinite(gravity) || gravity <= 0.0) {
    return Error{"fit_bending_moduli: gravity must be finite and positive"};
  }
  if (samples < kMinSamples) return Error{"fit_bending_moduli: samples must be at least 16"};
  Expected<Points> knots = distinct_points(curve);
  if (!knots) return knots.error();

  const Points r = resample(SplineCurve(std::move(*knots)), samples);
  const std::vector<double> s = cumulative_length(r);
  const std::vector<double> torque = weight_torques(r, areal_density * gravity);
  std::vector<double> angle, midpoint;
  chord_angles(r, s, angle, midpoint);

  // Interior samples only: at the ends the curvature window would be one-sided.
  const int first = kHalfWindow, last = samples - 1 - kHalfWindow;
  std::vector<double> kappa, tau;
  double max_curvature = 0.0;
  for (int i = first; i <= last; ++i) {
    kappa.push_back(window_curvature(angle, midpoint, s[i], i));
    tau.push_back(torque[i]);
    if (!std::isfinite(kappa.back()) || !std::isfinite(tau.back())) {
      return Error{"fit_bending_moduli: degenerate curve geometry"};
    }
    max_curvature = std::max(max_curvature, std::abs(kappa.back()));
  }
  if (max_curvature * s.back() < kStraightCurvature) {
    return Error{"fit_bending_moduli: the curve is straight; there is no curvature to regress the torque on"};
  }
  return regress(kappa, tau, fit_beta);
}

}  // namespace drapegen::sim
