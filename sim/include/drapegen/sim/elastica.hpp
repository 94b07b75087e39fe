#pragma once
// The planar heavy elastica: a strip clamped horizontally at one end and bending under its own weight. This is the
// physics reference of the cantilever test (Feng et al. 2022, Section 4.3) and of the master curve used to
// validate bending models (Romero et al. 2021; Feng et al. 2022, Section 4.2.1 and Fig. 10).
//
// Everything is per unit width of the strip. The bending law is the nonlinear dihedral angle model of Feng et al.
// (Section 4.2.1): torque tau(kappa) = alpha * kappa + beta * kappa^2 for the unsigned curvature kappa. For
// beta < 0 the torque peaks at kappa* = alpha / (2 |beta|) with value alpha^2 / (4 |beta|); beyond kappa* the
// simulator holds the torque at that peak (a plateau), so a bending moment above the peak has no equilibrium.

#include <Eigen/Core>
#include <vector>

#include "drapegen/sim/expected.hpp"

namespace drapegen::sim {

/// The equilibrium shape of a heavy cantilever.
struct CantileverCurve {
  /// Centre line (x, y) in metres: the clamp is at (0, 0) pointing along +x, y is up (so y <= 0 below the clamp).
  /// Ordered clamp -> tip and equally spaced in arc length.
  std::vector<Eigen::Vector2d> points;
  /// Tip drop over horizontal reach, -y_tip / x_tip (0 for an unloaded strip). Tends to Gamma / 8 for small Gamma.
  double height_over_width = 0.0;
  /// Angle of the tangent at the tip below the horizontal, radians, in [0, pi/2).
  double tip_angle = 0.0;
};

/// Solves the planar inextensible heavy elastica clamped horizontally at s = 0 with a free tip at s = length.
///
/// Equilibrium (per unit width): the bending moment M(s) = rho * g * integral_s^L (x(t) - x(s)) dt equals the
/// torque alpha * kappa + beta * kappa^2 of the curvature kappa(s) >= 0. The problem is solved by shooting from the
/// tip (where M = 0) on the tip angle, with RK4 on a grid fine enough for the gravito-bending parameter
/// Gamma = rho * g * L^3 / alpha. The linear case (beta = 0) is tested for Gamma from 1e-3 to 1e4 and resolves up
/// to about 5e5, where the tip is vertical to within ~1e-280 rad.
///
/// Units: length in m, alpha in N*m, beta in N*m^2, areal_density in kg/m^2, gravity in m/s^2. `samples` is the
/// number of output points (>= 3); it does not affect the integration accuracy.
///
/// Returns an Error on non-finite input, non-positive length, alpha or areal_density, negative gravity,
/// samples < 3, when the required moment exceeds the peak torque of a softening law (beta < 0), or when Gamma is too
/// large to resolve in double precision (well above 1e4).
[[nodiscard]] Expected<CantileverCurve> solve_heavy_cantilever(double length, double alpha, double beta,
                                                               double areal_density, double gravity = 9.81,
                                                               int samples = 2001);

/// The dimensionless master curve of the linear heavy cantilever (beta = 0): height_over_width as a function of
/// Gamma = rho * g * L^3 / alpha alone. Gamma must be finite and >= 0 (Gamma = 0 gives 0).
[[nodiscard]] Expected<double> master_curve_height_over_width(double gamma);

}  // namespace drapegen::sim
