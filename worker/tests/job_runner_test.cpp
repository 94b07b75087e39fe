#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <unistd.h>

#include "drapegen/proto/codec.hpp"
#include "drapegen/proto/recipe.hpp"
#include "drapegen/proto/simulation.hpp"
#include "drapegen/proto/text.hpp"
#include "drapegen/renderer/exr.hpp"
#include "drapegen/sampler/recipe_generator.hpp"
#include "drapegen/worker/job_runner.hpp"

namespace drapegen::worker {
namespace {
namespace v1 = proto::v1;

v1::Job tiny_job(v1::JobMode mode) {
  v1::Job job;
  job.set_job_id(5);
  job.set_attempt(1);
  auto* s = job.mutable_spec();
  s->set_mode(mode);
  s->set_resolution(15);
  s->set_orientations(2);
  s->set_noise("kinect");
  s->set_render_seed(11);
  s->set_max_iterations(400);
  s->set_tolerance(1e-3);
  s->set_max_self_intersections(1000000);
  s->set_coarse_start_resolution(0);
  auto* p = s->mutable_parameters();
  p->set_alpha_warp(13923);
  p->set_alpha_bias(11455);
  p->set_alpha_weft(8821);
  p->set_beta_warp(-35390);
  p->set_beta_bias(-29660);
  p->set_beta_weft(-22042);
  p->set_density_g_per_m2(300);
  sampler::RecipeOptions options;
  options.seed = 1;
  *s->mutable_recipe() = proto::to_proto(sampler::make_recipes(options, 0, {})[0]);
  return job;
}

std::string scratch();

// The scratch directory goes at exit.
const struct RemoveScratch {
  ~RemoveScratch() {
    std::error_code ec;
    std::filesystem::remove_all(scratch(), ec);
  }
} remove_scratch;

std::string scratch() {
  return (std::filesystem::temp_directory_path() / ("drapegen_job_runner_test_" + std::to_string(::getpid())))
      .string();
}

TEST(JobRunner, ComputesADrapeWithItsFilesInMemory) {
  JobRunner runner(scratch());
  const auto answer = runner.run(tiny_job(v1::JOB_MODE_DRAPE));
  ASSERT_EQ(answer.body_case(), v1::Envelope::kResult) << answer.failure().message();
  const auto& r = answer.result();
  EXPECT_EQ(r.job_id(), 5u);
  EXPECT_EQ(r.metrics().outcome(), "converged");
  EXPECT_GT(r.metrics().drape_coefficient(), 0.1);
  EXPECT_LT(r.metrics().drape_coefficient(), 1.0);
  EXPECT_EQ(r.mesh_ply().rfind("ply", 0), 0u);
  ASSERT_EQ(r.exr_size(), 2);
  const auto point = renderer::read_exr(std::vector<char>(r.exr(1).begin(), r.exr(1).end()));
  ASSERT_TRUE(point) << point.error().message;
  EXPECT_EQ(point->index, 1);
  EXPECT_EQ(point->views.size(), 4u);
  // Replay: the same job gives the same bytes.
  const auto again = runner.run(tiny_job(v1::JOB_MODE_DRAPE));
  ASSERT_EQ(again.body_case(), v1::Envelope::kResult);
  EXPECT_EQ(again.result().mesh_ply(), r.mesh_ply());
  EXPECT_EQ(again.result().exr(0), r.exr(0));
}

// The job names its renderer: both draw the same drape (the mesh bytes are equal) into nearly the same depth, not
// the same bytes, each deterministically; a renderer this build lacks fails the job as a render error.
TEST(JobRunner, RendersWithTheJobsRenderer) {
  JobRunner runner(scratch());
  std::vector<v1::Envelope> answers;
  for (const char* name : {"osmesa", "software", "software", "osmesa"}) {
    v1::Job job = tiny_job(v1::JOB_MODE_DRAPE);
    job.mutable_spec()->set_renderer(name);
    job.mutable_spec()->set_noise("none");
    answers.push_back(runner.run(job));
    ASSERT_EQ(answers.back().body_case(), v1::Envelope::kResult) << name << ": " << answers.back().failure().message();
  }
  EXPECT_EQ(answers[0].result().mesh_ply(), answers[1].result().mesh_ply());
  EXPECT_EQ(answers[1].result().exr(0), answers[2].result().exr(0));
  EXPECT_EQ(answers[0].result().exr(0), answers[3].result().exr(0));
  EXPECT_NE(answers[0].result().exr(0), answers[1].result().exr(0));  // the field was read: another rasteriser
  v1::Job unknown = tiny_job(v1::JOB_MODE_DRAPE);
  unknown.mutable_spec()->set_renderer("vulkan");
  const auto refused = runner.run(unknown);
  ASSERT_EQ(refused.body_case(), v1::Envelope::kFailure);
  EXPECT_EQ(refused.failure().reason(), v1::FAILURE_REASON_RENDER_ERROR);
  EXPECT_NE(refused.failure().message().find("vulkan"), std::string::npos) << refused.failure().message();
  const auto decode = [](const v1::Envelope& e) {
    return renderer::read_exr(std::vector<char>(e.result().exr(0).begin(), e.result().exr(0).end()));
  };
  const auto a = decode(answers[0]), b = decode(answers[1]);
  ASSERT_TRUE(a && b);
  int compared = 0, agree = 0;
  for (std::size_t v = 0; v < a->views.size(); ++v) {
    const auto& da = a->views[v].depth;
    const auto& db = b->views[v].depth;
    for (int y = 0; y < da.height; ++y) {
      for (int x = 0; x < da.width; ++x) {
        if (da.at(x, y) == 0.0f && db.at(x, y) == 0.0f) continue;
        ++compared;
        agree += std::abs(da.at(x, y) - db.at(x, y)) < 5e-4f ? 1 : 0;
      }
    }
  }
  ASSERT_GT(compared, 1000);
  EXPECT_GT(agree, 0.99 * compared) << agree << " of " << compared;
}

// The job names its bending model: "triangle" drapes with per-triangle curvature tensors (another converged drape
// of the same job), "dihedral" and an empty name are the paper's model, and any other name is an invalid job.
TEST(JobRunner, DrapesWithTheJobsBendingModel) {
  const auto config_for = [](const char* model) {
    v1::Job job = tiny_job(v1::JOB_MODE_DRAPE);
    job.mutable_spec()->set_bending_model(model);
    return drape_config(job.spec(), "");
  };
  ASSERT_TRUE(config_for("") && config_for("dihedral") && config_for("triangle"));
  EXPECT_EQ(config_for("")->bending_model, sim::BendingModel::kNonlinearDihedral);
  EXPECT_EQ(config_for("dihedral")->bending_model, sim::BendingModel::kNonlinearDihedral);
  EXPECT_EQ(config_for("triangle")->bending_model, sim::BendingModel::kNonlinearTriangle);
  ASSERT_FALSE(config_for("quadratic"));
  EXPECT_EQ(config_for("quadratic").error().message, "unknown bending model 'quadratic' (dihedral or triangle)");

  JobRunner runner(scratch());
  v1::Job job = tiny_job(v1::JOB_MODE_DRAPE);
  job.mutable_spec()->set_bending_model("quadratic");
  const auto refused = runner.run(job);
  ASSERT_EQ(refused.body_case(), v1::Envelope::kFailure);
  EXPECT_EQ(refused.failure().reason(), v1::FAILURE_REASON_INVALID_JOB);

  job.mutable_spec()->set_bending_model("triangle");
  const auto triangle = runner.run(job);
  ASSERT_EQ(triangle.body_case(), v1::Envelope::kResult) << triangle.failure().message();
  EXPECT_EQ(triangle.result().metrics().outcome(), "converged");
  const auto dihedral = runner.run(tiny_job(v1::JOB_MODE_DRAPE));
  ASSERT_EQ(dihedral.body_case(), v1::Envelope::kResult);
  EXPECT_NE(triangle.result().mesh_ply(), dihedral.result().mesh_ply());
  EXPECT_GT(triangle.result().metrics().drape_coefficient(), 0.1);
  EXPECT_LT(triangle.result().metrics().drape_coefficient(), 1.0);
}

TEST(JobRunner, PoisonDiverges) {
  JobRunner runner(scratch());
  const auto answer = runner.run(tiny_job(v1::JOB_MODE_POISON));
  ASSERT_EQ(answer.body_case(), v1::Envelope::kFailure);
  EXPECT_EQ(answer.failure().reason(), v1::FAILURE_REASON_DIVERGED) << answer.failure().message();
  EXPECT_EQ(answer.failure().attempt(), 1u);
}

TEST(JobRunner, RefusesADrapeRecipeWithoutItsMesh) {
  JobRunner runner(scratch());
  auto job = tiny_job(v1::JOB_MODE_DRAPE);
  job.mutable_spec()->mutable_recipe()->set_kind(v1::Recipe::KIND_DRAPE);
  job.mutable_spec()->mutable_recipe()->set_source_sample(1);
  job.mutable_spec()->mutable_recipe()->set_source_slot(0);
  const auto answer = runner.run(job);
  ASSERT_EQ(answer.body_case(), v1::Envelope::kFailure);
  EXPECT_EQ(answer.failure().reason(), v1::FAILURE_REASON_INVALID_JOB);
  EXPECT_EQ(answer.failure().message(), "drape recipe without mesh");
}

// A failure message naming a path in another encoding still reaches the coordinator: the receiver drops a frame
// whose string field is not UTF-8, and the job would wait out its lease.
TEST(JobRunner, FailureMessagesAreOneLineOfValidUtf8) {
  JobRunner runner("/proc/1/latin1-\xE9t\xE9\nscratch");  // cannot be made: the error names it
  v1::Job job = tiny_job(v1::JOB_MODE_DRAPE);
  job.set_any_failure_reason(true);
  const auto answer = runner.run(job);
  ASSERT_EQ(answer.body_case(), v1::Envelope::kFailure);
  const std::string& message = answer.failure().message();
  EXPECT_NE(message.find("latin1-?t?"), std::string::npos) << message;
  EXPECT_EQ(answer.failure().reason(), v1::FAILURE_REASON_WORKER_ERROR);  // the worker's scratch, not the job
  EXPECT_TRUE(proto::is_utf8(message));
  EXPECT_EQ(message.find('\n'), std::string::npos);
  v1::Envelope back;
  EXPECT_TRUE(back.ParseFromString(proto::encode(answer)));
}

// A scratch file the worker cannot write is the worker's failure: the job itself is fine, and statistics that called
// it an invalid job sent the user looking for bad parameters.
TEST(JobRunner, AScratchFileItCannotWriteIsAWorkerError) {
  const std::string dir = scratch() + "/blocked";
  std::error_code ec;
  std::filesystem::create_directories(dir + "/drape_5.ply/inside", ec);  // a directory where the mesh goes
  ASSERT_FALSE(ec) << ec.message();
  JobRunner runner(dir);
  v1::Job job = tiny_job(v1::JOB_MODE_DRAPE);
  job.set_any_failure_reason(true);
  const auto answer = runner.run(job);
  ASSERT_EQ(answer.body_case(), v1::Envelope::kFailure);
  EXPECT_EQ(answer.failure().reason(), v1::FAILURE_REASON_WORKER_ERROR) << answer.failure().message();
  EXPECT_NE(answer.failure().message().find("drape_5.ply"), std::string::npos) << answer.failure().message();
  EXPECT_STREQ(proto::reason_name(answer.failure().reason()), "worker_error");
  // From a coordinator older than the reason, whose check would drop it (the job then waits out its lease): the
  // reason it knows.
  job.set_any_failure_reason(false);
  EXPECT_EQ(runner.run(job).failure().reason(), v1::FAILURE_REASON_INVALID_JOB);
}

TEST(JobRunner, NoopAnswersAtOnce) {
  JobRunner runner(scratch());
  const auto answer = runner.run(tiny_job(v1::JOB_MODE_NOOP));
  ASSERT_EQ(answer.body_case(), v1::Envelope::kResult);
  EXPECT_EQ(answer.result().metrics().outcome(), "noop");
  EXPECT_TRUE(answer.result().mesh_ply().empty());
}

TEST(JobRunner, SimulatesTheDrapeItIsSentAsTheSenderWould) {
  sim::DrapeConfig config;
  config.specimen.vertices_x = config.specimen.vertices_y = 10;
  config.specimen.seed = 3;
  config.initial.shape = sim::InitialShape::kSine;
  config.initial.seed = 2;
  config.solver.max_iterations = 300;
  config.effects.bending_yield_curvature = 40.0;
  v1::Job job = tiny_job(v1::JOB_MODE_SIMULATE);
  auto wire = proto::to_proto(config);
  ASSERT_TRUE(wire) << wire.error().message;
  *job.mutable_spec()->mutable_simulation() = *wire;
  JobRunner runner(scratch());
  const auto answer = runner.run(job);
  ASSERT_EQ(answer.body_case(), v1::Envelope::kResult) << answer.failure().message();
  EXPECT_TRUE(answer.result().mesh_ply().empty());
  EXPECT_EQ(answer.result().exr_size(), 0);
  auto drape = proto::from_proto(answer.result().drape());
  ASSERT_TRUE(drape) << drape.error().message;
  auto local = sim::simulate_drape(config);
  ASSERT_TRUE(local);
  EXPECT_EQ(drape->mesh.positions, local->mesh.positions);  // bit for bit
  EXPECT_EQ(drape->rest_angles, local->rest_angles);
  EXPECT_EQ(drape->report.outcome, local->report.outcome);
  EXPECT_EQ(answer.result().metrics().outcome(), std::string(sim::to_string(local->report.outcome)));

  // A drape that stops at the iteration limit comes back too (the sender judges it); one that cannot be built fails.
  config.solver.max_iterations = 1;
  *job.mutable_spec()->mutable_simulation() = *proto::to_proto(config);
  const auto stopped = runner.run(job);
  ASSERT_EQ(stopped.body_case(), v1::Envelope::kResult);
  EXPECT_EQ(stopped.result().drape().outcome(), static_cast<int>(sim::SolveOutcome::kIterationLimit));
  config.fabric.alpha.warp = -1.0;
  *job.mutable_spec()->mutable_simulation() = *proto::to_proto(config);
  const auto invalid = runner.run(job);
  ASSERT_EQ(invalid.body_case(), v1::Envelope::kFailure);
  EXPECT_EQ(invalid.failure().reason(), v1::FAILURE_REASON_INVALID_JOB);
}

}  // namespace
}  // namespace drapegen::worker
