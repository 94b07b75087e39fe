// drapegen stats' figures on manifests whose rows are set by hand.
#include "drapegen/coordinator/stats.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fmt/format.h>

#include "drapegen/storage/manifest.hpp"

namespace drapegen::coordinator {
namespace {

// A run stopped after its first session and resumed an hour later: jobs per hour are over the time with an attempt
// in flight (the union of the attempts' spans), not from the first lease to the last result; a failed job's last
// attempt is busy time of its worker.
/// A fresh directory for one test's manifest, and the run and samples every test here starts from.
class Stats : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::temp_directory_path() /
           fmt::format("drapegen_stats_test_{}_{}", ::getpid(), info->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    path_ = (dir_ / "manifest.sqlite").string();
    run_.config_toml = "samples = 1\nstates_per_sample = 4\n";
    run_.code_version = "test";
    samples_.resize(1);
    samples_[0].alpha = {1000, 1000, 1000};
    samples_[0].beta = {-1000, -1000, -1000};
    samples_[0].density_g_per_m2 = 300;
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::filesystem::path dir_;
  std::string path_;
  storage::RunRecord run_;
  std::vector<storage::SampleRecord> samples_;
};

TEST_F(Stats, ThroughputIsOverTheTimeAttemptsWereInFlight) {
  const std::string& path = path_;
  const auto& run = run_;
  const auto& samples = samples_;
  std::vector<storage::JobRecord> jobs(4);
  for (int i = 0; i < 4; ++i) {
    jobs[i].id = i + 1;
    jobs[i].slot = i;
    jobs[i].recipe_json = "{}";
  }
  {
    auto m = storage::Manifest::create(path, run, samples, jobs);
    ASSERT_TRUE(m) << m.error().message;
    ASSERT_TRUE(m->begin());
    // Session 1: two workers, overlapping attempts [100, 110] and [105, 115]; session 2 an hour later: [3700, 3710].
    const std::pair<double, double> spans[3] = {{100, 110}, {105, 115}, {3700, 3710}};
    for (int i = 0; i < 3; ++i) {
      storage::JobRecord j = jobs[i];
      j.attempts = 1;
      j.worker = i == 1 ? "w2" : "w1";
      j.started_at = spans[i].first;
      j.finished_at = spans[i].second;
      storage::ResultRecord r;
      r.outcome = "converged";
      ASSERT_TRUE(m->record_result(j, r, {}));
    }
    storage::JobRecord failed = jobs[3];  // its last attempt [3705, 3725], on w2
    failed.attempts = 1;
    failed.worker = "w2";
    failed.started_at = 3705;
    failed.finished_at = 3725;
    ASSERT_TRUE(m->record_failure(failed, {4, 1, "not_converged", "iteration limit", "w2", 3725}, true));
    ASSERT_TRUE(m->commit());
  }
  auto stats = compute_stats(path, {});
  ASSERT_TRUE(stats) << stats.error().message;
  const auto& t = (*stats)["throughput"];
  EXPECT_DOUBLE_EQ(t["wall_seconds_first_lease_to_last_result"].get<double>(), 3610.0);
  EXPECT_DOUBLE_EQ(t["active_seconds"].get<double>(), 15.0 + 25.0);  // [100, 115] and [3700, 3725]
  EXPECT_DOUBLE_EQ(t["jobs_per_hour"].get<double>(), 3600.0 * 3 / 40.0);
  EXPECT_DOUBLE_EQ(t["per_worker"]["w1"]["busy_seconds"].get<double>(), 20.0);
  EXPECT_DOUBLE_EQ(t["per_worker"]["w2"]["busy_seconds"].get<double>(), 10.0 + 20.0);
  EXPECT_EQ(t["per_worker"]["w2"]["jobs"].get<std::int64_t>(), 1);
  EXPECT_NE(format_stats(*stats).find("over 40.0 s with attempts in flight (3610.0 s from the first lease"),
            std::string::npos)
      << format_stats(*stats);
}

// Every count and distribution against rows whose values are known: job states and failure reasons, failed attempts
// (every failure row), files and bytes by kind, the drape coefficient's and the folds' quantiles (a no-op job's result
// not among them), the samples.
TEST_F(Stats, FiguresAreThoseOfTheRows) {
  samples_.resize(2, samples_[0]);
  samples_[1].sample = 1;
  std::vector<storage::JobRecord> jobs(6);
  for (int i = 0; i < 6; ++i) {
    jobs[i].id = i + 1;
    jobs[i].sample = i / 4;
    jobs[i].slot = i % 4;
    jobs[i].recipe_json = "{}";
  }
  jobs[4].mode = "noop";
  {
    auto m = storage::Manifest::create(path_, run_, samples_, jobs);
    ASSERT_TRUE(m) << m.error().message;
    ASSERT_TRUE(m->begin());
    const double dc[3] = {0.4, 0.1, 0.2};
    for (int i = 0; i < 3; ++i) {  // jobs 1-3 done: a mesh of 100 bytes and two views of 50 each
      storage::JobRecord j = jobs[i];
      j.attempts = 1;
      j.worker = "w1";
      j.started_at = 10.0 * i + 1;
      j.finished_at = 10.0 * i + 2 + i;
      storage::ResultRecord r;
      r.outcome = "converged";
      r.drape_coefficient = dc[i];
      r.folds = 4 + i;
      r.iterations = 10 * (i + 1);
      ASSERT_TRUE(m->record_result(j, r,
                                   {{0, "mesh", 0, fmt::format("data/{}.ply", i), "00", 100},
                                    {0, "exr", 0, fmt::format("data/{}_0.exr", i), "00", 50},
                                    {0, "exr", 1, fmt::format("data/{}_1.exr", i), "00", 50}}));
    }
    storage::JobRecord failed = jobs[3];  // job 4: diverged, retried, then failed for good as not converged
    failed.attempts = 1;
    ASSERT_TRUE(m->record_failure(failed, {4, 1, "diverged", "blew up", "w1", 40}, false));
    failed.attempts = 2;
    failed.started_at = 41;
    failed.finished_at = 45;
    ASSERT_TRUE(m->record_failure(failed, {4, 2, "not_converged", "limit", "w1", 45}, true));
    storage::JobRecord noop = jobs[4];  // job 5: a no-op, its figures not the drapes'
    noop.attempts = 1;
    storage::ResultRecord r;
    r.outcome = "noop";
    r.drape_coefficient = 9.0;
    ASSERT_TRUE(m->record_result(noop, r, {}));
    ASSERT_TRUE(m->commit());  // job 6 stays pending
  }
  auto stats = compute_stats(path_, {});
  ASSERT_TRUE(stats) << stats.error().message;
  const auto& s = *stats;
  EXPECT_EQ(s["run"]["samples"].get<int>(), 2);
  EXPECT_EQ(s["jobs"]["by_state"]["done"].get<int>(), 4);
  EXPECT_EQ(s["jobs"]["by_state"]["failed"].get<int>(), 1);
  EXPECT_EQ(s["jobs"]["by_state"]["pending"].get<int>(), 1);
  EXPECT_EQ(s["jobs"]["failed_by_reason"], nlohmann::json({{"not_converged", 1}}));
  EXPECT_EQ(s["jobs"]["failed_attempts_by_reason"], nlohmann::json({{"diverged", 1}, {"not_converged", 1}}));
  EXPECT_EQ(s["jobs"]["failed_attempts"].get<int>(), 2);
  EXPECT_EQ(s["storage"]["files"].get<int>(), 9);
  EXPECT_EQ(s["storage"]["bytes"].get<int>(), 600);
  EXPECT_EQ(s["storage"]["mesh_bytes"].get<int>(), 300);
  EXPECT_EQ(s["storage"]["exr_bytes"].get<int>(), 300);
  const auto& d = s["drape_coefficient"];
  EXPECT_EQ(d["count"].get<int>(), 3);
  EXPECT_DOUBLE_EQ(d["min"].get<double>(), 0.1);
  EXPECT_DOUBLE_EQ(d["median"].get<double>(), 0.2);
  EXPECT_DOUBLE_EQ(d["max"].get<double>(), 0.4);
  EXPECT_NEAR(d["mean"].get<double>(), 0.7 / 3, 1e-15);
  EXPECT_NEAR(d["p05"].get<double>(), 0.11, 1e-15);  // a tenth of the way from 0.1 to 0.2
  EXPECT_NEAR(d["p95"].get<double>(), 0.38, 1e-15);  // nine tenths of the way from 0.2 to 0.4
  EXPECT_DOUBLE_EQ(s["folds"]["median"].get<double>(), 5.0);
  EXPECT_DOUBLE_EQ(s["newton_iterations"]["max"].get<double>(), 30.0);
  // Seconds per job: the done drapes' 1, 2 and 3 s (the no-op's attempt has no times).
  EXPECT_DOUBLE_EQ(s["seconds_per_job"]["median"].get<double>(), 2.0);
  EXPECT_EQ(s["seconds_per_job"]["count"].get<int>(), 3);
}

}  // namespace
}  // namespace drapegen::coordinator
