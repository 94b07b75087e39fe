#include "drapegen/coordinator/job_message.hpp"

#include <fmt/format.h>

#include "drapegen/proto/recipe.hpp"
#include "drapegen/sampler/initial_state_recipe.hpp"

namespace drapegen::coordinator {
namespace v1 = proto::v1;

sim::Expected<v1::Job> make_job_message(const RunConfig& config, const storage::SampleRecord& s,
                                        const storage::JobRecord& rec, int attempt, std::string source_mesh) {
  v1::Job job;
  job.set_job_id(static_cast<std::uint64_t>(rec.id));
  job.set_attempt(static_cast<std::uint32_t>(attempt));
  job.set_lease_ms(static_cast<std::uint64_t>(config.lease_s * 1000.0));
  job.set_any_failure_reason(true);
  auto* spec = job.mutable_spec();
  spec->set_mode(rec.mode == "noop" ? v1::JOB_MODE_NOOP : rec.mode == "poison" ? v1::JOB_MODE_POISON
                                                                                : v1::JOB_MODE_DRAPE);
  auto* p = spec->mutable_parameters();
  p->set_alpha_warp(s.alpha[0]);
  p->set_alpha_bias(s.alpha[1]);
  p->set_alpha_weft(s.alpha[2]);
  p->set_beta_warp(s.beta[0]);
  p->set_beta_bias(s.beta[1]);
  p->set_beta_weft(s.beta[2]);
  p->set_density_g_per_m2(s.density_g_per_m2);
  auto recipe = sampler::recipe_from_json(nlohmann::json::parse(rec.recipe_json, nullptr, false));
  if (!recipe) return sim::Error{fmt::format("job {}: {}", rec.id, recipe.error().message)};
  *spec->mutable_recipe() = proto::to_proto(*recipe);
  spec->set_resolution(config.resolution);
  spec->set_orientations(config.orientations);
  spec->set_noise(config.noise);
  spec->set_renderer(config.renderer);
  spec->set_bending_model(config.bending_model);
  spec->set_render_seed(rec.render_seed);
  spec->set_max_iterations(config.max_iterations);
  spec->set_tolerance(config.tolerance);
  spec->set_max_self_intersections(config.max_self_intersections);
  spec->set_coarse_start_resolution(config.coarse_start_resolution);
  job.set_source_mesh(std::move(source_mesh));
  return job;
}

std::string result_stem(std::int64_t sample, int slot) { return fmt::format("s{:06d}_k{:02d}", sample, slot); }

}  // namespace drapegen::coordinator
