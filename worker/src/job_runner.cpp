#include "drapegen/worker/job_runner.hpp"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fmt/format.h>
#include <limits>

#include "drapegen/proto/codec.hpp"
#include "drapegen/proto/recipe.hpp"
#include "drapegen/proto/simulation.hpp"
#include "drapegen/proto/text.hpp"
#include "drapegen/renderer/data_point.hpp"
#include "drapegen/renderer/make_renderer.hpp"
#include "drapegen/renderer/scene.hpp"
#include "drapegen/sampler/initial_state_recipe.hpp"
#include "drapegen/sim/ply.hpp"
#include "drapegen/storage/atomic_file.hpp"
#include "drapegen/storage/read_file.hpp"

namespace drapegen::worker {
namespace v1 = proto::v1;

namespace {

constexpr std::size_t kMaxFailureMessage = 4096;  // bytes

v1::Envelope failure(const v1::Job& job, v1::FailureReason reason, std::string message,
                     const v1::Metrics* metrics = nullptr) {
  v1::Envelope e;
  auto* f = e.mutable_failure();
  f->set_job_id(job.job_id());
  f->set_attempt(job.attempt());
  // A sender older than the reason would drop the whole failure (and wait out the lease): the reason it knows.
  const bool known = reason != v1::FAILURE_REASON_WORKER_ERROR || job.any_failure_reason();
  f->set_reason(known ? reason : v1::FAILURE_REASON_INVALID_JOB);
  // One line of valid UTF-8: the receiver drops a frame whose string is not (a path in another encoding).
  f->set_message(proto::one_line_utf8(message, kMaxFailureMessage));
  if (metrics) *f->mutable_metrics() = *metrics;
  return e;
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// What every drape reports about its solve, whichever mode ran it.
v1::Metrics solve_metrics(const sim::DrapeResult& drape, std::chrono::steady_clock::time_point start) {
  v1::Metrics metrics;
  metrics.set_outcome(std::string(sim::to_string(drape.report.outcome)));
  metrics.set_iterations(drape.report.iterations);
  metrics.set_coarse_iterations(drape.coarse_report.iterations);
  metrics.set_residual(drape.report.residual);
  metrics.set_energy(drape.report.energy);
  metrics.set_sim_seconds(seconds_since(start));
  return metrics;
}

}  // namespace

sim::Expected<sim::DrapeConfig> drape_config(const v1::JobSpec& spec, const std::string& source_mesh_path) {
  auto recipe = proto::from_proto(spec.recipe());
  if (!recipe) return recipe.error();
  const auto& p = spec.parameters();
  sim::DrapeConfig config;
  if (const auto model = proto::bending_model_name(spec.bending_model()); model == "triangle") {
    config.bending_model = sim::BendingModel::kNonlinearTriangle;
  } else if (model != "dihedral") {
    return sim::Error{fmt::format("unknown bending model '{}' (dihedral or triangle)", spec.bending_model())};
  }
  config.fabric = sim::fabric_from_paper_units({p.alpha_warp(), p.alpha_bias(), p.alpha_weft()},
                                               {p.beta_warp(), p.beta_bias(), p.beta_weft()}, p.density_g_per_m2());
  if (sim::Status s = sim::validate(config.fabric, config.bending_model); !s) return s.error();
  config.specimen.vertices_x = config.specimen.vertices_y = spec.resolution();
  sampler::apply_triangulation(*recipe, config.specimen);
  auto initial = sampler::to_initial_state(*recipe, [&](const sampler::DrapeRef&) { return source_mesh_path; });
  if (!initial) return initial.error();
  config.initial = *initial;
  config.solver.max_iterations = spec.max_iterations();
  config.solver.tolerance = spec.tolerance();
  config.coarse_start_resolution = spec.coarse_start_resolution();
  // Poison (test only): the largest finite gravity overflows the energy and the forces, so the real solver ends
  // with a non-finite residual (classified as diverged below).
  if (spec.mode() == v1::JOB_MODE_POISON) config.gravity = std::numeric_limits<double>::max();
  return config;
}

v1::Envelope JobRunner::simulate(const v1::Job& job) {
  auto config = proto::from_proto(job.spec().simulation());
  if (!config) return failure(job, v1::FAILURE_REASON_INVALID_JOB, config.error().message);
  const auto start = std::chrono::steady_clock::now();
  auto drape = sim::simulate_drape(*config);
  if (!drape) return failure(job, v1::FAILURE_REASON_INVALID_JOB, drape.error().message);
  // Whatever the solve's outcome: the sender judges the drape as it would its own.
  v1::Envelope e;
  auto* result = e.mutable_result();
  result->set_job_id(job.job_id());
  result->set_attempt(job.attempt());
  *result->mutable_metrics() = solve_metrics(*drape, start);
  *result->mutable_drape() = proto::to_proto(*drape);
  return e;
}

JobRunner::JobRunner(std::string scratch_dir) : scratch_(std::move(scratch_dir)) {}
JobRunner::JobRunner(JobRunner&&) noexcept = default;
JobRunner& JobRunner::operator=(JobRunner&&) noexcept = default;
JobRunner::~JobRunner() = default;

v1::Envelope JobRunner::run(const v1::Job& job) {
  try {
    return compute(job);
  } catch (const std::bad_alloc&) {
    return failure(job, v1::FAILURE_REASON_WORKER_ERROR, "out of memory");
  } catch (const std::exception& e) {  // the scratch directory's creation, or a defect: the worker's, not the job's
    return failure(job, v1::FAILURE_REASON_WORKER_ERROR, std::string("unexpected error: ") + e.what());
  }
}

v1::Envelope JobRunner::compute(const v1::Job& job) {
  const auto& spec = job.spec();
  if (spec.mode() == v1::JOB_MODE_NOOP) {
    v1::Envelope e;
    e.mutable_result()->set_job_id(job.job_id());
    e.mutable_result()->set_attempt(job.attempt());
    e.mutable_result()->mutable_metrics()->set_outcome("noop");
    return e;
  }
  if (spec.mode() == v1::JOB_MODE_SIMULATE) return simulate(job);
  std::filesystem::create_directories(scratch_);
  const std::string source_path = fmt::format("{}/source_{}.ply", scratch_, job.job_id());
  const std::string mesh_path = fmt::format("{}/drape_{}.ply", scratch_, job.job_id());
  struct Cleanup {
    std::string a, b;
    ~Cleanup() {
      std::error_code ec;
      std::filesystem::remove(a, ec);
      std::filesystem::remove(b, ec);
    }
  } cleanup{source_path, mesh_path};
  if (spec.recipe().kind() == v1::Recipe::KIND_DRAPE) {
    if (job.source_mesh().empty()) return failure(job, v1::FAILURE_REASON_INVALID_JOB, "drape recipe without mesh");
    if (sim::Status s = storage::write_file_atomic(source_path, job.source_mesh()); !s) {
      return failure(job, v1::FAILURE_REASON_WORKER_ERROR, s.error().message);
    }
  }
  auto config = drape_config(spec, source_path);
  if (!config) return failure(job, v1::FAILURE_REASON_INVALID_JOB, config.error().message);

  const auto sim_start = std::chrono::steady_clock::now();
  auto drape = sim::simulate_drape(*config);
  if (!drape) return failure(job, v1::FAILURE_REASON_INVALID_JOB, drape.error().message);
  v1::Metrics metrics = solve_metrics(*drape, sim_start);
  metrics.set_drape_coefficient(drape->measures.drape_coefficient);
  metrics.set_folds(drape->measures.folds);
  metrics.set_self_intersections(drape->measures.self_intersections);
  metrics.set_bending_model(config->bending_model == sim::BendingModel::kNonlinearTriangle ? "triangle" : "dihedral");
  // A solve that ends with a non-finite residual or energy diverged, whatever the solver called its stop.
  const bool non_finite = !std::isfinite(drape->report.residual) || !std::isfinite(drape->report.energy);
  if (non_finite && drape->report.outcome != sim::SolveOutcome::kConverged) {
    return failure(job, v1::FAILURE_REASON_DIVERGED,
                   fmt::format("{} with a non-finite {}: {}", sim::to_string(drape->report.outcome),
                               std::isfinite(drape->report.residual) ? "energy" : "residual", drape->report.message),
                   &metrics);
  }
  switch (drape->report.outcome) {
    case sim::SolveOutcome::kConverged: break;
    case sim::SolveOutcome::kIterationLimit:
    case sim::SolveOutcome::kStalled:
      return failure(job, v1::FAILURE_REASON_NOT_CONVERGED,
                     fmt::format("{}: {}", sim::to_string(drape->report.outcome), drape->report.message), &metrics);
    case sim::SolveOutcome::kDiverged:
    case sim::SolveOutcome::kFactorizationFailed:
      return failure(job, v1::FAILURE_REASON_DIVERGED,
                     fmt::format("{}: {}", sim::to_string(drape->report.outcome), drape->report.message), &metrics);
  }
  if (drape->measures.self_intersections > spec.max_self_intersections()) {
    return failure(job, v1::FAILURE_REASON_SELF_INTERSECTION,
                   fmt::format("{} self-intersecting triangle pairs (allowed {})", drape->measures.self_intersections,
                               spec.max_self_intersections()),
                   &metrics);
  }
  // The scratch round trip is the worker's own: a full or unwritable scratch directory is no fault of the job.
  if (sim::Status s = sim::write_ply(mesh_path, drape->mesh); !s) {
    return failure(job, v1::FAILURE_REASON_WORKER_ERROR, s.error().message, &metrics);
  }
  auto mesh_bytes = storage::read_file(mesh_path);
  if (!mesh_bytes) return failure(job, v1::FAILURE_REASON_WORKER_ERROR, mesh_bytes.error().message, &metrics);

  const auto render_start = std::chrono::steady_clock::now();
  const auto cloth = renderer::cloth_triangles(drape->mesh);
  if (!cloth) return failure(job, v1::FAILURE_REASON_RENDER_ERROR, cloth.error().message, &metrics);
  renderer::RenderRequest request;
  request.augmentation.orientations = spec.orientations();
  request.noise = spec.noise() == "none" ? renderer::NoiseModel::none() : renderer::NoiseModel::kinect();
  request.seed = spec.render_seed();
  request.source = fmt::format("sample {} slot {}", spec.recipe().sample(), spec.recipe().slot());
  const std::string renderer_name(proto::renderer_name(spec.renderer()));
  metrics.set_renderer(renderer_name);
  std::unique_ptr<renderer::Renderer>& renderer = renderers_[renderer_name];
  if (!renderer) {
    auto created = renderer::make_renderer(renderer_name);
    if (!created) return failure(job, v1::FAILURE_REASON_RENDER_ERROR, created.error().message, &metrics);
    renderer = std::move(created).value();
  }
  auto points = renderer::render_data_points(*renderer, *cloth, request);
  if (!points) return failure(job, v1::FAILURE_REASON_RENDER_ERROR, points.error().message, &metrics);
  const renderer::ExrWriter writer;
  v1::Envelope e;
  auto* result = e.mutable_result();
  for (const auto& point : *points) {
    for (std::size_t v = 0; v < point.views.size(); ++v) {
      if (point.views[v].depth.foreground_count() == 0) {
        return failure(job, v1::FAILURE_REASON_RENDER_ERROR,
                       fmt::format("data point {} view {} is blank", point.index, v), &metrics);
      }
    }
    auto bytes = writer.encode(point);
    if (!bytes) return failure(job, v1::FAILURE_REASON_RENDER_ERROR, bytes.error().message, &metrics);
    result->add_exr(std::string(bytes->begin(), bytes->end()));
  }
  metrics.set_render_seconds(seconds_since(render_start));
  result->set_job_id(job.job_id());
  result->set_attempt(job.attempt());
  *result->mutable_metrics() = metrics;
  result->set_mesh_ply(std::move(mesh_bytes).value());
  return e;
}

}  // namespace drapegen::worker
