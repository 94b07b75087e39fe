#include "drapegen/sim/fold_barrier.hpp"

#include <cmath>
#include <limits>
#include <numbers>

namespace drapegen::sim {

double FoldBarrier::energy(double theta, double k, double* first, double* second) {
  if (first != nullptr) *first = 0.0;
  if (second != nullptr) *second = 0.0;
  const double g = std::numbers::pi - std::abs(theta);
  if (g >= kWidth) return 0.0;
  if (!(g > 0.0)) return std::numeric_limits<double>::infinity();
  const double d = g - kWidth;  // < 0
  const double log_ratio = std::log(g / kWidth);
  // b(g) and its derivatives in g; d g / d theta = -sign(theta).
  const double b = -k * d * d * log_ratio;
  const double db = -k * (2.0 * d * log_ratio + d * d / g);
  const double d2b = -k * (2.0 * log_ratio + 4.0 * d / g - d * d / (g * g));
  if (first != nullptr) *first = theta >= 0.0 ? -db : db;
  if (second != nullptr) *second = d2b;
  return b;
}

}  // namespace drapegen::sim
