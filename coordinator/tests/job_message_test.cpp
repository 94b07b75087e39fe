#include <gtest/gtest.h>

#include "drapegen/coordinator/job_message.hpp"
#include "drapegen/coordinator/planner.hpp"
#include "drapegen/coordinator/run_config.hpp"

namespace drapegen::coordinator {
namespace {

// The run's bending model reaches every job message (and passes the codec's field rules); a configuration without
// the key (every run before it existed) sends the paper's model.
TEST(JobMessage, CarriesTheRunsBendingModel) {
  for (const auto& [toml, expected] : {std::pair<std::string, std::string>{"samples = 2", "dihedral"},
                                       {"samples = 2\nbending_model = \"dihedral\"", "dihedral"},
                                       {"samples = 2\nbending_model = \"triangle\"", "triangle"}}) {
    auto config = parse_run_config(toml, "run.toml");
    ASSERT_TRUE(config) << config.error().message;
    auto plan = plan_run(*config);
    ASSERT_TRUE(plan) << plan.error().message;
    const storage::JobRecord& job = plan->jobs.front();
    auto message = make_job_message(*config, plan->samples.front(), job, 1, "");
    ASSERT_TRUE(message) << message.error().message;
    EXPECT_EQ(message->spec().bending_model(), expected) << toml;
    EXPECT_TRUE(message->any_failure_reason());  // this coordinator records worker_error (older ones dropped it)
    proto::v1::Envelope envelope;
    *envelope.mutable_job() = *message;
    const auto decoded = proto::decode(proto::encode(envelope));
    ASSERT_TRUE(decoded) << decoded.error().message;
    EXPECT_EQ(decoded->job().spec().bending_model(), expected);
  }
}


// Every setting the worker computes with reaches the job message, each at a value other than its default.
TEST(JobMessage, CarriesTheRunsSettings) {
  auto config = parse_run_config(R"(
samples = 2
orientations = 3
resolution = 17
noise = "none"
renderer = "software"
[solver]
max_iterations = 77
tolerance = 2e-4
coarse_start_resolution = 11
max_self_intersections = 4
[network]
lease_s = 42
)",
                                 "run.toml");
  ASSERT_TRUE(config) << config.error().message;
  auto plan = plan_run(*config);
  ASSERT_TRUE(plan) << plan.error().message;
  const storage::JobRecord& job = plan->jobs.front();
  const auto message = make_job_message(*config, plan->samples.front(), job, 2, "");
  ASSERT_TRUE(message) << message.error().message;
  const auto& spec = message->spec();
  EXPECT_EQ(message->job_id(), static_cast<std::uint64_t>(job.id));
  EXPECT_EQ(message->attempt(), 2u);
  EXPECT_EQ(message->lease_ms(), 42000u);
  EXPECT_EQ(spec.orientations(), 3);
  EXPECT_EQ(spec.resolution(), 17);
  EXPECT_EQ(spec.noise(), "none");
  EXPECT_EQ(spec.renderer(), "software");
  EXPECT_EQ(spec.max_iterations(), 77);
  EXPECT_DOUBLE_EQ(spec.tolerance(), 2e-4);
  EXPECT_EQ(spec.coarse_start_resolution(), 11);
  EXPECT_EQ(spec.max_self_intersections(), 4);
  EXPECT_EQ(spec.render_seed(), job.render_seed);
  const auto& s = plan->samples.front();
  EXPECT_EQ(spec.parameters().alpha_warp(), s.alpha[0]);
  EXPECT_EQ(spec.parameters().beta_weft(), s.beta[2]);
  EXPECT_EQ(spec.parameters().density_g_per_m2(), s.density_g_per_m2);
}

}  // namespace
}  // namespace drapegen::coordinator
