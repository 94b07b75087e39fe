#include "drapegen/sim/fabric.hpp"

#include <cmath>

namespace drapegen::sim {

FabricParameters fabric_from_paper_units(const DirectionalValues& alpha_paper, const DirectionalValues& beta_paper,
                                         double density_g_per_m2) {
  FabricParameters f;
  f.alpha = {alpha_paper.warp * 1e-9, alpha_paper.bias * 1e-9, alpha_paper.weft * 1e-9};
  f.beta = {beta_paper.warp * 1e-12, beta_paper.bias * 1e-12, beta_paper.weft * 1e-12};
  f.density = density_g_per_m2 * 1e-3;
  return f;
}

FabricParameters normalized(const FabricParameters& fabric) {
  const double s = kStandardDensity / fabric.density;
  auto scale = [s](const DirectionalValues& v) { return DirectionalValues{v.warp * s, v.bias * s, v.weft * s}; };
  return FabricParameters{scale(fabric.alpha), scale(fabric.beta), scale(fabric.gamma), kStandardDensity};
}

Status validate(const FabricParameters& fabric, BendingModel model) {
  auto all = [](const DirectionalValues& v, auto pred) { return pred(v.warp) && pred(v.bias) && pred(v.weft); };
  auto positive = [](double x) { return std::isfinite(x) && x > 0.0; };
  auto finite = [](double x) { return std::isfinite(x); };
  if (!positive(fabric.density)) return Error{"density must be positive and finite"};
  if (model == BendingModel::kQuadratic) {
    if (!all(fabric.gamma, positive)) return Error{"gamma (warp, bias, weft) must be positive and finite"};
    return {};
  }
  if (!all(fabric.alpha, positive)) return Error{"alpha (warp, bias, weft) must be positive and finite"};
  if (!all(fabric.beta, finite)) return Error{"beta (warp, bias, weft) must be finite"};
  return {};
}

}  // namespace drapegen::sim
