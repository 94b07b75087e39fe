#include "drapegen/coordinator/planner.hpp"

#include <algorithm>

#include "drapegen/sampler/parameter_sampler.hpp"
#include "drapegen/sampler/random.hpp"
#include "drapegen/sampler/vae_model.hpp"

namespace drapegen::coordinator {

sampler::RecipeOptions recipe_options(const RunConfig& config) {
  sampler::RecipeOptions o;
  o.seed = config.seed;
  o.states_per_sample = config.states_per_sample;
  o.weight_sine = config.weight_sine;
  o.weight_fold = config.weight_fold;
  o.weight_drape = config.weight_drape;
  o.max_drift_mm = config.max_drift_mm;
  return o;
}

std::int64_t job_id(const RunConfig& config, std::int64_t sample, int slot) {
  return sample * config.states_per_sample + slot + 1;
}

std::uint64_t render_seed(std::uint64_t seed, std::int64_t sample, int slot) {
  return sampler::derive_seed(seed, {3, static_cast<std::uint64_t>(sample), static_cast<std::uint64_t>(slot)});
}

sampler::InitialStateRecipe fallback_recipe(const RunConfig& config, std::int64_t sample, int slot) {
  return sampler::make_recipes(recipe_options(config), sample, {}).at(static_cast<std::size_t>(slot));
}

sim::Expected<Plan> plan_run(const RunConfig& config) {
  auto model = config.model.empty() ? sampler::builtin_vae_model() : sampler::load_vae_model(config.model);
  if (!model) return model.error();
  sampler::SamplerOptions options;
  options.count = config.samples;
  options.seed = config.seed;
  auto sampled = sampler::sample_parameters(*model, options);
  if (!sampled) return sampled.error();
  const auto recipes = recipe_options(config);
  if (sim::Status s = sampler::validate(recipes); !s) return s.error();

  Plan plan;
  plan.samples.reserve(sampled->vectors.size());
  plan.jobs.reserve(sampled->vectors.size() * static_cast<std::size_t>(config.states_per_sample));
  for (std::size_t i = 0; i < sampled->vectors.size(); ++i) {
    const auto sample = static_cast<std::int64_t>(i);
    const auto v = sampler::at_density(sampled->vectors[i], config.density);
    storage::SampleRecord record;
    record.sample = sample;
    record.alpha = {v.alpha.warp, v.alpha.bias, v.alpha.weft};
    record.beta = {v.beta.warp, v.beta.bias, v.beta.weft};
    record.density_g_per_m2 = config.density;
    plan.samples.push_back(record);
    const bool poison = std::find(config.poison_samples.begin(), config.poison_samples.end(), sample) !=
                        config.poison_samples.end();
    for (const auto& recipe : sampler::make_recipes_in_order(recipes, sample)) {
      storage::JobRecord job;
      job.id = job_id(config, sample, recipe.slot);
      job.sample = sample;
      job.slot = recipe.slot;
      job.recipe_json = sampler::to_json(recipe).dump();
      job.render_seed = render_seed(config.seed, sample, recipe.slot);
      job.mode = config.mode == "noop" ? "noop" : poison ? "poison" : "drape";
      plan.jobs.push_back(std::move(job));
    }
  }
  return plan;
}

}  // namespace drapegen::coordinator
