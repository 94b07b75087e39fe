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

}  // namespace
}  // namespace drapegen::coordinator
