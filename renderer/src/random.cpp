#include "drapegen/renderer/random.hpp"

#include <cmath>
#include <vector>

namespace drapegen::renderer {
namespace {

/// Inverse of the standard normal CDF by bisection on std::erfc (only used to build the table once).
double inverse_normal_cdf(double p) {
  double lo = -10.0, hi = 10.0;
  for (int i = 0; i < 80; ++i) {
    const double mid = 0.5 * (lo + hi);
    (0.5 * std::erfc(-mid / std::sqrt(2.0)) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

const std::vector<float>& gaussian_table() {
  static const std::vector<float> table = [] {
    constexpr int n = 65536;
    std::vector<double> values(n);
    double sum_sq = 0.0;
    for (int i = 0; i < n / 2; ++i) {  // symmetric: compute one half
      const double x = inverse_normal_cdf((i + 0.5) / n);
      values[i] = x;
      values[n - 1 - i] = -x;
      sum_sq += 2.0 * x * x;
    }
    const double scale = 1.0 / std::sqrt(sum_sq / n);
    std::vector<float> t(n);
    for (int i = 0; i < n; ++i) t[i] = static_cast<float>(values[i] * scale);
    return t;
  }();
  return table;
}

}  // namespace

std::uint64_t mix_seed(std::uint64_t seed, std::uint64_t stream) {
  return sim::splitmix64_mix(seed ^ sim::splitmix64_mix(stream));
}

std::uint64_t Rng::below_threshold(double p) {
  // uniform() = k 2^-53 for an integer k, so uniform() < p exactly when k < p 2^53, i.e. k < ceil(p 2^53).
  constexpr double kScale = 0x1p53;
  if (!(p > 0.0)) return 0;
  if (p >= 1.0) return static_cast<std::uint64_t>(kScale);
  return static_cast<std::uint64_t>(std::ceil(p * kScale));
}

Rng::Rng(std::uint64_t seed) : generator_(seed), gaussian_table_(gaussian_table().data()) {}

}  // namespace drapegen::renderer
