#pragma once
// The baseline model's six bending parameters and the reduced coordinates the fit searches in.

#include <array>
#include <utility>

#include "drapegen/sim/anisotropy.hpp"

namespace drapegen::diagnosis {

/// Paper units: alpha in g*mm^2/s^2, beta in g*mm^3/s^2 (warp, bias, weft).
struct BendingParameters {
  sim::DirectionalValues alpha{10000.0, 10000.0, 10000.0};
  sim::DirectionalValues beta{-25000.0, -25000.0, -25000.0};
};

/// `p` with alpha and beta in every direction times `factor`: a stiffer (or softer) fabric whose bending law has the
/// same shape (the same -beta/alpha).
[[nodiscard]] BendingParameters scaled(const BendingParameters& p, double factor);

/// Reduced coordinates (the fit's search space, all of similar scale):
///   x0 = ln(geometric mean of alpha),  x1 = ln(alpha_warp / alpha_weft),
///   x2 = ln(alpha_bias / sqrt(alpha_warp alpha_weft)),  x3 = -beta / alpha in mm (one ratio for all directions).
/// The six parameters have a 4-dimensional image: beta is alpha times one shared (negative) length.
using ReducedBending = std::array<double, 4>;
[[nodiscard]] BendingParameters from_reduced(const ReducedBending& x);
/// The reduced coordinates of `p` (x3 is the alpha-weighted mean ratio).
[[nodiscard]] ReducedBending to_reduced(const BendingParameters& p);

/// The reduced coordinates of every bending whose six parameters each lie within a factor F of those of `x`'s:
/// x0 +- ln F (a mean of the three ln alpha), x1 and x2 +- 2 ln F (differences of them), x3 within x 1/F^2 .. F^2
/// (a ratio of beta to alpha) and at least +- kMinRatioWidth mm (a start with no softening, x3 = 0, keeps some room).
/// Returns {lower, upper}.
[[nodiscard]] std::pair<ReducedBending, ReducedBending> reduced_box(const ReducedBending& x, double factor);
inline constexpr double kMinRatioWidth = 0.1;  // mm

/// The drape depends on alpha / density only (paper Section 5.1.2), so the stiffness range scales with the specimen's
/// density: alpha from 200 to 300000 at the standard 300 g/m^2 (fabrics618: 1778 .. 148108 there), times
/// density / 300. A fixed range of alpha held the lightest fabrics (29 g/m^2, alpha 350) above their stiffness.
[[nodiscard]] double stiffness_scale(double density_g_per_m2);

/// The search box: alpha 200 .. 300000 (times stiffness_scale), ratios e^+-1.5, -beta/alpha 0 .. 6 mm (fabrics618:
/// up to about 5).
[[nodiscard]] ReducedBending reduced_lower(double density_g_per_m2);
[[nodiscard]] ReducedBending reduced_upper(double density_g_per_m2);

}  // namespace drapegen::diagnosis
