#pragma once
// The spread of the validation drapes among themselves: the fitted parameters simulated from the validation states
// form as many stable drapes, and how far these lie from each other (shape distance, all views) measures the fitted
// fabric's multistability for this capture, against which the capture's own distance to its nearest validation drape
// can be compared. docs/DIAGNOSIS_RESULTS.md, "Branch diag-s7".

#include <vector>

#include "drapegen/diagnosis/forward_model.hpp"

namespace drapegen::diagnosis {

struct ValidationSpread {
  /// Per validation state: its shape distance to the capture over all views (ScoredDrape::shape_all) and its group
  /// differences to the capture (group_differences, m; -1 where a group is missing).
  std::vector<double> capture_distance;
  std::vector<std::vector<double>> capture_groups;
  /// Symmetric: the shape distance between validation drapes i and j over all views (feature_distance with the
  /// default scales; 0 on the diagonal).
  std::vector<std::vector<double>> pairwise;
  /// pairwise_groups[i][j]: group_differences of drapes i and j (m), for i < j (empty otherwise).
  std::vector<std::vector<std::vector<double>>> pairwise_groups;
  /// Per state i: the smallest pairwise[i][j] over j != i (leave-one-out nearest neighbour; empty with < 2 states).
  std::vector<double> nearest_other;
};

/// From the validation drapes' shape features (their `shape.all`) and the capture's (`target`).
[[nodiscard]] ValidationSpread validation_spread(const std::vector<ScoredDrape>& states, const ShapeFeatures& target);

}  // namespace drapegen::diagnosis
