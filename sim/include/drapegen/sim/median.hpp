#pragma once
// The median of a sample: its middle value, or the mean of its two middle values when the count is even. One
// definition for the library (the diagnosis's typical floors) and every benchmark that prints a median.

#include <algorithm>
#include <cstddef>
#include <limits>
#include <vector>

namespace drapegen::sim {

/// NaN for an empty sample (the caller says what "no data" means).
[[nodiscard]] inline double median(std::vector<double> values) {
  const std::size_t n = values.size();
  if (n == 0) return std::numeric_limits<double>::quiet_NaN();
  const auto upper = values.begin() + static_cast<std::ptrdiff_t>(n / 2);
  std::nth_element(values.begin(), upper, values.end());
  if (n % 2 == 1) return *upper;
  return 0.5 * (*std::max_element(values.begin(), upper) + *upper);  // the lower middle: the largest below `upper`
}

}  // namespace drapegen::sim
