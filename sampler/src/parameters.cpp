#include "drapegen/sampler/parameters.hpp"

#include <cmath>

namespace drapegen::sampler {
namespace {

double signed_log(double k) { return k > 0 ? std::log(k) : -std::log(-k); }
double signed_exp(double f) { return f >= 0 ? std::exp(f) : -std::exp(-f); }

ParameterVector scaled(const ParameterVector& p, double factor) {
  return {{p.alpha.warp * factor, p.alpha.bias * factor, p.alpha.weft * factor},
          {p.beta.warp * factor, p.beta.bias * factor, p.beta.weft * factor}};
}

}  // namespace

Features to_features(const ParameterVector& p) {
  return {signed_log(p.alpha.warp), signed_log(p.alpha.bias), signed_log(p.alpha.weft),
          signed_log(p.beta.warp),  signed_log(p.beta.bias),  signed_log(p.beta.weft)};
}

ParameterVector from_features(const Features& f) {
  return {{signed_exp(f[0]), signed_exp(f[1]), signed_exp(f[2])},
          {signed_exp(f[3]), signed_exp(f[4]), signed_exp(f[5])}};
}

ParameterVector at_density(const ParameterVector& normalised, double density_g_per_m2) {
  return scaled(normalised, density_g_per_m2 / kStandardDensityGPerM2);
}

ParameterVector normalise_density(const ParameterVector& measured, double density_g_per_m2) {
  return scaled(measured, kStandardDensityGPerM2 / density_g_per_m2);
}

}  // namespace drapegen::sampler
