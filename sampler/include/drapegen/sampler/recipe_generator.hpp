#pragma once
// Draws the initial-state recipes of every sample (paper Section 5.2.1: eight per parameter vector, of three types,
// each with a small drift and its own triangulation seed).

#include <cstdint>
#include <span>
#include <vector>

#include "drapegen/sampler/initial_state_recipe.hpp"
#include "drapegen/sim/expected.hpp"

namespace drapegen::sampler {

/// validate()'s limits, for front ends that name their own options.
inline constexpr int kMaxStatesPerSample = 1000;
inline constexpr double kMaxDriftMm = 50.0;

struct RecipeOptions {
  std::uint64_t seed = 0;
  int states_per_sample = 8;
  /// Relative weights of the three kinds; a kDrape draw with no drape to copy falls back to sine or fold (by their
  /// weights, from the same stream).
  double weight_sine = 1.0, weight_fold = 1.0, weight_drape = 1.0;
  /// Drift: uniform in a disk of this radius, millimetres.
  double max_drift_mm = 3.0;
};

[[nodiscard]] sim::Status validate(const RecipeOptions& options);

/// The recipes of `sample` (states_per_sample of them, slots 0, 1, ...). Slot k is drawn from the stream
/// derive_seed(seed, {2, sample, k}), so it does not depend on any other slot or sample. A kDrape source is drawn
/// uniformly from `existing` (drapes already in the data set; the sample's own drapes are never chosen); with none,
/// the slot falls back to sine or fold.
[[nodiscard]] std::vector<InitialStateRecipe> make_recipes(const RecipeOptions& options, std::int64_t sample,
                                                           std::span<const DrapeRef> existing);

/// The same, with the drapes of every earlier sample (0 .. sample - 1, every slot) as the existing ones: the plan of
/// a run that simulates samples in order. Sample 0 never has a kDrape recipe.
[[nodiscard]] std::vector<InitialStateRecipe> make_recipes_in_order(const RecipeOptions& options,
                                                                    std::int64_t sample);

}  // namespace drapegen::sampler
