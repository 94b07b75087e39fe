#include "drapegen/diagnosis/validation_spread.hpp"

#include <algorithm>
#include <limits>

namespace drapegen::diagnosis {

ValidationSpread validation_spread(const std::vector<ScoredDrape>& states, const ShapeFeatures& target) {
  const std::vector<double> scales = default_feature_scales();
  const std::size_t n = states.size();
  ValidationSpread s;
  s.pairwise.assign(n, std::vector<double>(n, 0.0));
  s.pairwise_groups.assign(n, std::vector<std::vector<double>>(n));
  for (std::size_t i = 0; i < n; ++i) {
    s.capture_distance.push_back(feature_distance(target, states[i].shape.all, scales));
    s.capture_groups.push_back(group_differences(target, states[i].shape.all));
    for (std::size_t j = i + 1; j < n; ++j) {
      s.pairwise[i][j] = s.pairwise[j][i] = feature_distance(states[i].shape.all, states[j].shape.all, scales);
      s.pairwise_groups[i][j] = group_differences(states[i].shape.all, states[j].shape.all);
    }
  }
  if (n < 2) return s;
  for (std::size_t i = 0; i < n; ++i) {
    double nearest = std::numeric_limits<double>::infinity();
    for (std::size_t j = 0; j < n; ++j) {
      if (j != i) nearest = std::min(nearest, s.pairwise[i][j]);
    }
    s.nearest_other.push_back(nearest);
  }
  return s;
}

}  // namespace drapegen::diagnosis
