#pragma once
// Bending moduli from the deflection curve of a cantilever strip: the regression of Feng et al. 2022,
// Section 4.3.1. The torque at every sample follows from the weight of the strip beyond it (Eq. 5-6), the curvature
// from the curve's shape, and alpha, beta from a least-squares fit of tau = alpha * kappa + beta * kappa^2.
// Everything is per unit width (the paper's strip width E is dropped).

#include <Eigen/Core>
#include <vector>

#include "drapegen/sim/expected.hpp"

namespace drapegen::sim {

/// Result of the cantilever regression.
struct BendingFit {
  double alpha = 0.0;  // linear bending modulus, N*m (per unit width)
  double beta = 0.0;   // quadratic bending modulus, N*m^2 (per unit width); 0 when not fitted
  /// Norm of the torque residual over the norm of the torques, ||tau - tau_fit|| / ||tau||.
  double rms_relative_residual = 0.0;
  /// Samples that entered the regression (the resampled curve minus the ends, where curvature is one-sided).
  int samples_used = 0;
};

/// Estimates the bending moduli of a strip from its deflection curve under its own weight.
///
/// `curve` is the centre line in metres, ordered clamp -> tip with y up (any spacing, e.g. a simulated strip's
/// centre line or the output of solve_heavy_cantilever); the clamp may point along +x or -x. It is interpolated by
/// a C2 cubic spline through the points (no smoothing: denoise measured curves first, as the paper does with its
/// Bezier fit) and resampled at `samples` points:
///   - uniformly along x, as the paper does (N = 256), when x is strictly monotone along the curve and that
///     sampling leaves no gap longer than four times the mean arc-length spacing;
///   - otherwise uniformly along arc length: a strip that hangs past vertical has a non-monotone x, which the
///     paper's sampling cannot represent, and a nearly vertical strip would leave its hanging part almost
///     unsampled.
/// The torque at each sample is Eq. 6 (trapezoid rule), tau_i = rho g sum_{j >= i} (x_j + x_{j+1} - 2 x_i) / 2
/// |r_{j+1} - r_j|; the curvature kappa_i = -dtheta/ds comes from the slope of a local least-squares cubic
/// through the tangent angles theta of the 6 chords around the sample. Both are signed clockwise-positive:
/// positive for a strip along +x bending down, negative for its mirror image along -x. The regression is
/// tau = alpha kappa + beta kappa |kappa| (the paper's law for unsigned curvature, extended as an odd function),
/// or tau = alpha kappa when !fit_beta.
///
/// Returns an Error on fewer than 4 distinct points, non-finite coordinates, non-positive or non-finite
/// areal_density or gravity, samples < 16, a straight curve (no curvature to regress on) or a curvature range
/// too narrow to separate alpha from beta.
[[nodiscard]] Expected<BendingFit> fit_bending_moduli(const std::vector<Eigen::Vector2d>& curve, double areal_density,
                                                      double gravity = 9.81, bool fit_beta = true,
                                                      int samples = 256);

}  // namespace drapegen::sim
