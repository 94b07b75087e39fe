#pragma once
// Plans a run from its configuration with the sampler: the parameter vectors (VAE subspace, paper Section 5.1.3) and
// every job's initial-state recipe and seeds (Section 5.2.1). The plan is a pure function of the configuration, so a
// run planned twice with the same seed is identical job for job.

#include <cstdint>
#include <string>
#include <vector>

#include "drapegen/coordinator/run_config.hpp"
#include "drapegen/sampler/initial_state_recipe.hpp"
#include "drapegen/sampler/recipe_generator.hpp"
#include "drapegen/sim/expected.hpp"
#include "drapegen/storage/records.hpp"

namespace drapegen::coordinator {

struct Plan {
  std::vector<storage::SampleRecord> samples;
  std::vector<storage::JobRecord> jobs;  // id = sample * states_per_sample + slot + 1
};

/// Samples the vectors (at config.density) and makes every job (sampler::make_recipes_in_order: a drape recipe's
/// source is a drape of an earlier sample). Errors: an unreadable model file, sampler errors.
[[nodiscard]] sim::Expected<Plan> plan_run(const RunConfig& config);

[[nodiscard]] sampler::RecipeOptions recipe_options(const RunConfig& config);

/// The job id of (sample, slot).
[[nodiscard]] std::int64_t job_id(const RunConfig& config, std::int64_t sample, int slot);

/// The seed of a job's rendering (orientations, perturbations, noise): derive_seed(seed, {3, sample, slot}).
[[nodiscard]] std::uint64_t render_seed(std::uint64_t seed, std::int64_t sample, int slot);

/// The recipe a drape job falls back to when its source drape failed: the slot's recipe drawn with no existing
/// drapes (sine or fold from the same stream; deterministic).
[[nodiscard]] sampler::InitialStateRecipe fallback_recipe(const RunConfig& config, std::int64_t sample, int slot);

}  // namespace drapegen::coordinator
