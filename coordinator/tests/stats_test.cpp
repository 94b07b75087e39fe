// drapegen stats' throughput on a manifest whose attempts' times are set by hand.
#include "drapegen/coordinator/stats.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "drapegen/storage/manifest.hpp"

namespace drapegen::coordinator {
namespace {

// A run stopped after its first session and resumed an hour later: jobs per hour are over the time with an attempt
// in flight (the union of the attempts' spans), not from the first lease to the last result; a failed job's last
// attempt is busy time of its worker.
TEST(Stats, ThroughputIsOverTheTimeAttemptsWereInFlight) {
  const auto dir = std::filesystem::temp_directory_path() / ("drapegen_stats_test_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "manifest.sqlite").string();
  storage::RunRecord run;
  run.config_toml = "samples = 1\nstates_per_sample = 4\n";
  run.code_version = "test";
  std::vector<storage::SampleRecord> samples(1);
  samples[0].alpha = {1000, 1000, 1000};
  samples[0].beta = {-1000, -1000, -1000};
  samples[0].density_g_per_m2 = 300;
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
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace drapegen::coordinator
