#pragma once
// A bending parameter vector in the paper's units and the sampler's feature space (paper Section 5.1.2).

#include <array>
#include "drapegen/sim/anisotropy.hpp"

namespace drapegen::sampler {

/// Number of features: alpha (warp, bias, weft), beta (warp, bias, weft).
inline constexpr int kFeatureCount = 6;
/// Feature names in order (also the column names of parameter files).
inline constexpr std::array<const char*, kFeatureCount> kFeatureNames = {
    "alpha_warp", "alpha_bias", "alpha_weft", "beta_warp", "beta_bias", "beta_weft"};
/// The standard density every sampled vector refers to, g/m^2 (paper: rho_bar = 300 g/m^2).
inline constexpr double kStandardDensityGPerM2 = 300.0;

using Features = std::array<double, kFeatureCount>;

/// Bending moduli at the standard density: alpha in g*mm^2/s^2, beta in g*mm^3/s^2 (the paper's units, as
/// `drapegen simulate --alpha/--beta --density 300` takes them).
struct ParameterVector {
  sim::DirectionalValues alpha;
  sim::DirectionalValues beta;
};

/// sign(k) * ln|k| of the six moduli (the space the subspace model is trained in).
[[nodiscard]] Features to_features(const ParameterVector& p);
/// The inverse: k = sign(f) * exp(|f|).
[[nodiscard]] ParameterVector from_features(const Features& f);

/// The moduli of a fabric of real density `density_g_per_m2` with the same drape: k * rho / rho_bar (paper
/// Section 5.1.2; the drape depends on k / rho only).
[[nodiscard]] ParameterVector at_density(const ParameterVector& normalised, double density_g_per_m2);
/// The inverse: moduli measured at `density_g_per_m2`, normalised to 300 g/m^2.
[[nodiscard]] ParameterVector normalise_density(const ParameterVector& measured, double density_g_per_m2);

}  // namespace drapegen::sampler
