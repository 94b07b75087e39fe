#include "drapegen/diagnosis/fabric_space.hpp"

#include <algorithm>
#include <cmath>

namespace drapegen::diagnosis {

BendingParameters scaled(const BendingParameters& p, double factor) {
  const auto times = [factor](const sim::DirectionalValues& v) {
    return sim::DirectionalValues{v.warp * factor, v.bias * factor, v.weft * factor};
  };
  return {times(p.alpha), times(p.beta)};
}

BendingParameters from_reduced(const ReducedBending& x) {
  const double mean = std::exp(x[0]);
  // geometric mean of (warp, bias, weft) = mean; warp/weft = e^x1; bias / sqrt(warp weft) = e^x2.
  // With g = sqrt(warp weft): warp = g e^(x1/2), weft = g e^(-x1/2), bias = g e^x2, mean^3 = g^3 e^x2.
  const double g = mean * std::exp(-x[2] / 3.0);
  BendingParameters p;
  p.alpha = {g * std::exp(0.5 * x[1]), g * std::exp(x[2]), g * std::exp(-0.5 * x[1])};
  const double ratio = -x[3];  // beta = -ratio_mm * alpha (paper units: g mm^3 / (g mm^2) = mm)
  p.beta = {ratio * p.alpha.warp, ratio * p.alpha.bias, ratio * p.alpha.weft};
  return p;
}

ReducedBending to_reduced(const BendingParameters& p) {
  const auto& a = p.alpha;
  const double g = std::sqrt(a.warp * a.weft);
  ReducedBending x;
  x[0] = std::log(a.warp * a.bias * a.weft) / 3.0;
  x[1] = std::log(a.warp / a.weft);
  x[2] = std::log(a.bias / g);
  x[3] = -(p.beta.warp + p.beta.bias + p.beta.weft) / (a.warp + a.bias + a.weft);
  return x;
}

std::pair<ReducedBending, ReducedBending> reduced_box(const ReducedBending& x, double factor) {
  const double l = std::log(factor);
  ReducedBending lo{x[0] - l, x[1] - 2.0 * l, x[2] - 2.0 * l, 0.0}, hi{x[0] + l, x[1] + 2.0 * l, x[2] + 2.0 * l, 0.0};
  const double f2 = factor * factor;
  lo[3] = std::min({x[3] / f2, x[3] * f2, x[3] - kMinRatioWidth});
  hi[3] = std::max({x[3] / f2, x[3] * f2, x[3] + kMinRatioWidth});
  return {lo, hi};
}

double stiffness_scale(double density_g_per_m2) { return density_g_per_m2 / 300.0; }

ReducedBending reduced_lower(double density_g_per_m2) {
  return {std::log(200.0 * stiffness_scale(density_g_per_m2)), -1.5, -1.5, 0.0};
}

ReducedBending reduced_upper(double density_g_per_m2) {
  return {std::log(300000.0 * stiffness_scale(density_g_per_m2)), 1.5, 1.5, 6.0};
}

}  // namespace drapegen::diagnosis
