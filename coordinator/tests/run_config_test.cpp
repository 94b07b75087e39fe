#include <gtest/gtest.h>

#include "drapegen/coordinator/planner.hpp"
#include "drapegen/coordinator/run_config.hpp"

namespace drapegen::coordinator {
namespace {

/// The error of `text` as a new run's configuration ("" if none).
std::string new_run_error_of(const std::string& text) {
  auto config = parse_run_config(text, "run.toml");
  if (!config) return config.error().message;
  const sim::Status s = check_new_run(*config, "run.toml");
  return s ? std::string() : s.error().message;
}

std::string error_of(const std::string& text) {
  auto c = parse_run_config(text, "run.toml");
  return c ? std::string() : c.error().message;
}

// Every key, each with a value other than its default: a key the parser drops fails here.
TEST(RunConfig, ParsesEveryKey) {
  const RunConfig d;  // the defaults
  auto c = parse_run_config(R"(
seed = 7
samples = 3
states_per_sample = 2
orientations = 2
resolution = 15
noise = "none"
renderer = "software"
density = 250
bending_model = "triangle"
output = "x"
model = "m.dgvae"
[recipes]
weight_sine = 2
weight_fold = 0.5
weight_drape = 0
max_drift_mm = 2
[solver]
max_iterations = 50
tolerance = 1e-4
coarse_start_resolution = 0
max_self_intersections = 3
[network]
bind = "tcp://127.0.0.1:*"
heartbeat_ms = 100
liveness = 3
lease_s = 60
[security]
curve = true
server_secret_key = "server.key"
authorized_keys = "workers.pub"
[retry]
max_attempts = 4
[progress]
interval_s = 1
[testing]
mode = "noop"
poison_samples = [1, 2]
fail_worker_start = 1
)",
                            "run.toml");
  ASSERT_TRUE(c) << c.error().message;
  EXPECT_EQ(c->seed, 7u);
  EXPECT_EQ(c->samples, 3);
  EXPECT_EQ(c->states_per_sample, 2);
  EXPECT_EQ(c->orientations, 2);
  EXPECT_EQ(c->resolution, 15);
  EXPECT_EQ(c->noise, "none");
  EXPECT_EQ(c->renderer, "software");
  EXPECT_EQ(c->density, 250.0);
  EXPECT_EQ(c->bending_model, "triangle");
  EXPECT_EQ(c->output, "x");
  EXPECT_EQ(c->model, "m.dgvae");
  EXPECT_EQ(c->weight_sine, 2.0);
  EXPECT_EQ(c->weight_fold, 0.5);
  EXPECT_EQ(c->weight_drape, 0.0);
  EXPECT_EQ(c->max_drift_mm, 2.0);
  EXPECT_EQ(c->max_iterations, 50);
  EXPECT_EQ(c->tolerance, 1e-4);
  EXPECT_EQ(c->coarse_start_resolution, 0);
  EXPECT_EQ(c->max_self_intersections, 3);
  EXPECT_EQ(c->bind, "tcp://127.0.0.1:*");
  EXPECT_EQ(c->heartbeat_ms, 100);
  EXPECT_EQ(c->liveness, 3);
  EXPECT_EQ(c->lease_s, 60.0);
  EXPECT_TRUE(c->curve);
  EXPECT_EQ(c->server_secret_key, "server.key");
  EXPECT_EQ(c->authorized_keys, "workers.pub");
  EXPECT_EQ(c->max_attempts, 4);
  EXPECT_EQ(c->progress_interval_s, 1.0);
  EXPECT_EQ(c->mode, "noop");
  EXPECT_EQ(c->poison_samples, (std::vector<std::int64_t>{1, 2}));
  EXPECT_EQ(c->fail_worker_start, 1);
  // Each value above differs from its default (else a dropped key would pass unseen).
  EXPECT_NE(d.seed, 7u);
  EXPECT_NE(d.samples, 3);
  EXPECT_NE(d.states_per_sample, 2);
  EXPECT_NE(d.orientations, 2);
  EXPECT_NE(d.resolution, 15);
  EXPECT_NE(d.noise, "none");
  EXPECT_NE(d.renderer, "software");
  EXPECT_NE(d.density, 250.0);
  EXPECT_NE(d.bending_model, "triangle");
  EXPECT_NE(d.output, "x");
  EXPECT_NE(d.model, "m.dgvae");
  EXPECT_NE(d.weight_sine, 2.0);
  EXPECT_NE(d.weight_fold, 0.5);
  EXPECT_NE(d.weight_drape, 0.0);
  EXPECT_NE(d.max_drift_mm, 2.0);
  EXPECT_NE(d.max_iterations, 50);
  EXPECT_NE(d.tolerance, 1e-4);
  EXPECT_NE(d.coarse_start_resolution, 0);
  EXPECT_NE(d.max_self_intersections, 3);
  EXPECT_NE(d.bind, "tcp://127.0.0.1:*");
  EXPECT_NE(d.heartbeat_ms, 100);
  EXPECT_NE(d.liveness, 3);
  EXPECT_NE(d.lease_s, 60.0);
  EXPECT_FALSE(d.curve);
  EXPECT_NE(d.fail_worker_start, 1);
  EXPECT_NE(d.max_attempts, 4);
  EXPECT_NE(d.progress_interval_s, 1.0);
  EXPECT_NE(d.mode, "noop");
  EXPECT_TRUE(parse_run_config(default_config_toml(), "default"));
}

TEST(RunConfig, NamesTheKeyOfEveryError) {
  EXPECT_EQ(error_of("samples = 0"), "run.toml: samples: must be between 1 and 10000000");
  EXPECT_EQ(error_of("sampels = 3"), "run.toml: sampels: unknown key");

  EXPECT_EQ(error_of("noise = \"loud\""), "run.toml: noise: 'loud' is not one of kinect, none");
  EXPECT_EQ(error_of("renderer = \"gpu\""), "run.toml: renderer: 'gpu' is not one of osmesa, software");
  EXPECT_EQ(error_of("bending_model = \"quadratic\""),
            "run.toml: bending_model: 'quadratic' is not one of dihedral, triangle");
  EXPECT_EQ(error_of("[solver]\ntolerance = \"small\""), "run.toml: solver.tolerance: must be a number");
  EXPECT_EQ(error_of("[network]\nbind = \"http://x\""),
            "run.toml: network.bind: must be a tcp:// or ipc:// endpoint, e.g. tcp://127.0.0.1:5555");
  EXPECT_EQ(error_of("[network]\nport = 1"), "run.toml: network.port: unknown key");
  EXPECT_EQ(error_of("[extra]\nx = 1"), "run.toml: extra: unknown section");
  EXPECT_EQ(error_of("seed = -1"), "run.toml: seed: must be a non-negative integer");
  EXPECT_EQ(error_of("[testing]\npoison_samples = [\"a\"]"),
            "run.toml: testing.poison_samples: must hold non-negative integers");
  EXPECT_NE(error_of("seed = = 1").find("run.toml:1:"), std::string::npos);
}

// What a new run must also pass, and a stored configuration (an earlier build's run, resumed) need not: it was
// planned already, so the job cap means nothing to it, and refusing it would leave the run impossible to resume.
TEST(RunConfig, ANewRunIsCheckedFurtherThanAStoredOne) {
  const std::string big = "samples = 10000000\nstates_per_sample = 64";
  EXPECT_EQ(new_run_error_of(big),
            "run.toml: samples: samples x states_per_sample is 640000000 jobs; at most 2000000 in one run (the plan "
            "is built in memory: split the run, e.g. by seed)");
  EXPECT_EQ(error_of(big), "");
  EXPECT_EQ(new_run_error_of("samples = 250000\nstates_per_sample = 8"), "");
  // ZeroMQ bound port 70000 as 4464 (modulo 65536) and a missing port failed only at bind, "Invalid argument".
  for (const char* bad : {"tcp://127.0.0.1:70000", "tcp://127.0.0.1:0", "tcp://127.0.0.1:-1", "tcp://127.0.0.1:",
                          "tcp://127.0.0.1:5x", "tcp://127.0.0.1:000005555"}) {
    const std::string toml = std::string("[network]\nbind = \"") + bad + "\"";
    EXPECT_NE(new_run_error_of(toml).find("network.bind: '"), std::string::npos) << bad;
    EXPECT_NE(new_run_error_of(toml).find("the port must be 1 .. 65535 or *"), std::string::npos) << bad;
    EXPECT_EQ(error_of(toml), "") << bad;
  }
  EXPECT_NE(new_run_error_of("[network]\nbind = \"tcp://127.0.0.1\"").find("needs a host and a port"),
            std::string::npos);
  EXPECT_NE(new_run_error_of("[network]\nbind = \"ipc://\"").find("names no path"), std::string::npos);
  for (const char* good : {"tcp://127.0.0.1:5555", "tcp://*:*", "tcp://[::1]:65535", "ipc:///tmp/x.sock"}) {
    EXPECT_EQ(new_run_error_of(std::string("[network]\nbind = \"") + good + "\""), "") << good;
  }
  // 1 and 2 switched the coarse start off, silently (drapegen simulate --coarse-start refuses them).
  for (int n : {1, 2}) {
    const std::string toml = "[solver]\ncoarse_start_resolution = " + std::to_string(n);
    EXPECT_EQ(new_run_error_of(toml), "run.toml: solver.coarse_start_resolution: must be 0 (off) or at least 3");
    EXPECT_EQ(error_of(toml), "");
  }
}

TEST(RunConfig, TakesAnyOutputDirectoryAsAnOverride) {
  // Quotes, backslashes and tabs are data, not TOML; a file's own output (however spaced) is replaced.
  const std::string odd = "C:\\temp\t\"run\" #1";
  for (const std::string& text :
       {default_config_toml(), std::string("output=\"y\"\nsamples = 3\n[retry]\nmax_attempts = 5\n")}) {
    auto overridden = with_output(text, "run.toml", odd);
    ASSERT_TRUE(overridden) << overridden.error().message;
    auto before = parse_run_config(text, "run.toml");
    auto after = parse_run_config(*overridden, "run.toml");
    ASSERT_TRUE(before && after) << *overridden;
    EXPECT_EQ(after->output, odd);
    EXPECT_EQ(after->seed, before->seed);
    EXPECT_EQ(after->samples, before->samples);
    EXPECT_EQ(after->states_per_sample, before->states_per_sample);
    EXPECT_EQ(after->resolution, before->resolution);
    EXPECT_EQ(after->noise, before->noise);
    EXPECT_EQ(after->bind, before->bind);
    EXPECT_EQ(after->max_attempts, before->max_attempts);
  }
  EXPECT_NE(with_output("seed = = 1", "run.toml", "x").error().message.find("run.toml:1:"), std::string::npos);
}

TEST(Planner, IsAPureFunctionOfTheConfiguration) {
  auto c = parse_run_config("seed = 3\nsamples = 5\nstates_per_sample = 4\n[testing]\npoison_samples = [2]", "t");
  ASSERT_TRUE(c);
  auto a = plan_run(*c);
  auto b = plan_run(*c);
  ASSERT_TRUE(a) << a.error().message;
  ASSERT_TRUE(b);
  ASSERT_EQ(a->jobs.size(), 20u);
  ASSERT_EQ(a->samples.size(), 5u);
  for (std::size_t i = 0; i < a->jobs.size(); ++i) {
    EXPECT_EQ(a->jobs[i].id, static_cast<std::int64_t>(i) + 1);
    EXPECT_EQ(a->jobs[i].recipe_json, b->jobs[i].recipe_json);
    EXPECT_EQ(a->jobs[i].render_seed, b->jobs[i].render_seed);
    EXPECT_EQ(a->jobs[i].mode, a->jobs[i].sample == 2 ? "poison" : "drape");
  }
  for (std::size_t i = 0; i < a->samples.size(); ++i) EXPECT_EQ(a->samples[i].alpha, b->samples[i].alpha);
  // Another seed, another plan.
  c->seed = 4;
  auto other = plan_run(*c);
  ASSERT_TRUE(other);
  EXPECT_NE(other->samples[0].alpha, a->samples[0].alpha);
  // A fallback recipe is never a drape recipe.
  for (int slot = 0; slot < 4; ++slot) {
    EXPECT_NE(fallback_recipe(*c, 4, slot).kind, sampler::RecipeKind::kDrape);
  }
}

}  // namespace
}  // namespace drapegen::coordinator
