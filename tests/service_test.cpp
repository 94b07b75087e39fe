// The distributed generation service end to end (issue 5 acceptance 1, 2, 3, 5, 6): real coordinator and worker
// processes on 127.0.0.1 with ephemeral ports, coarse meshes.
#include <nlohmann/json.hpp>
#include <random>
#include <set>
#include <sqlite3.h>
#include <sys/prctl.h>
#include <sys/wait.h>

#include <cerrno>

#include "service_harness.hpp"

namespace drapegen::test {
namespace {

// Acceptance 1: two workers produce the manifest and the EXR files; checksums match; integrity ok.
TEST(Service, EndToEndWithTwoWorkers) {
  const fs::path dir = test_dir("end_to_end");
  const fs::path out = dir / "run";
  write_text(dir / "run.toml", small_config(out, 4, 2));
  auto [coordinator, endpoint] = start_coordinator({"--config", (dir / "run.toml").string()}, out, dir / "coordinator");
  ASSERT_FALSE(endpoint.empty()) << coordinator.err();
  EXPECT_EQ(endpoint.rfind("tcp://127.0.0.1:", 0), 0u);
  Process w1 = start_worker(endpoint, dir, 1), w2 = start_worker(endpoint, dir, 2);
  ASSERT_EQ(coordinator.wait(120s), 0) << coordinator.err();
  EXPECT_NE(coordinator.out().find("run complete: 8 done, 0 failed of 8 jobs"), std::string::npos)
      << coordinator.out();
  // Both workers are told to exit.
  EXPECT_EQ(w1.wait(10s), 0) << w1.err();
  EXPECT_EQ(w2.wait(10s), 0) << w2.err();
  check_manifest(out / "manifest.sqlite", 2);
  auto reader = storage::ManifestReader::open((out / "manifest.sqlite").string());
  ASSERT_TRUE(reader);
  EXPECT_EQ(reader->run()->state, "complete");
  std::set<std::string> workers;
  int exr = 0;
  for (const auto& j : all(reader->jobs())) workers.insert(j.worker);
  for (const auto& f : all(reader->files())) exr += f.kind == "exr";
  EXPECT_EQ(exr, 16);
  // Both workers joined; the jobs were done by them (on a loaded machine one may join after the other did most).
  EXPECT_NE(coordinator.err().find("(2 connected)"), std::string::npos) << coordinator.err();
  for (const auto& w : workers) EXPECT_TRUE(w == "w1" || w == "w2") << w;
  // stats reads it.
  Process stats({"stats", (out / "manifest.sqlite").string(), "--json", "--plots", (dir / "plots").string()},
                (dir / "stats").string());
  ASSERT_EQ(stats.wait(30s), 0) << stats.err();
  EXPECT_NE(stats.out().find("\"done\": 8"), std::string::npos) << stats.out();
  EXPECT_NE(stats.out().find("\"bending_model\": \"dihedral\""), std::string::npos) << stats.out();
  // A fabrics file named on the command line that cannot be read is an error, not a comparison quietly dropped.
  Process no_fabrics({"stats", (out / "manifest.sqlite").string(), "--fabrics", (dir / "missing.csv").string()},
                     (dir / "stats_no_fabrics").string());
  EXPECT_EQ(no_fabrics.wait(30s), 1) << no_fabrics.err();
  EXPECT_NE(no_fabrics.err().find("missing.csv"), std::string::npos) << no_fabrics.err();
  // The run's directory instead of its manifest: pointed to the file inside.
  Process on_directory({"stats", out.string()}, (dir / "stats_on_directory").string());
  EXPECT_EQ(on_directory.wait(30s), 1) << on_directory.err();
  EXPECT_NE(on_directory.err().find("the run's manifest is " + (out / "manifest.sqlite").string()), std::string::npos)
      << on_directory.err();
  // The run records the build that planned it, as `drapegen --version` names it (version, commit, local changes).
  Process version({"--version"}, (dir / "version").string());
  ASSERT_EQ(version.wait(10s), 0) << version.err();
  const std::string id = version.out().substr(0, version.out().find('\n')).substr(std::string("drapegen ").size());
  EXPECT_TRUE(id.starts_with(DRAPEGEN_PROJECT_VERSION)) << version.out();
  EXPECT_NE(stats.out().find("\"code_version\": \"" + id + "\""), std::string::npos) << id << "\n" << stats.out();
  EXPECT_TRUE(fs::exists(dir / "plots" / "drape_coefficient.svg"));
  // A second run into the same output refuses, naming --resume, in one line.
  Process again({"run", "--config", (dir / "run.toml").string()}, (dir / "again").string());
  EXPECT_EQ(again.wait(30s), 1);
  EXPECT_NE(again.err().find("drapegen run: error: "), std::string::npos);
  EXPECT_NE(again.err().find("--resume"), std::string::npos);
}

// Acceptance 2: workers killed with SIGKILL again and again (and new ones started): the run completes, every job
// is recorded exactly once, no orphan files.
TEST(Service, SurvivesWorkerKills) {
  const fs::path dir = test_dir("worker_kills");
  const fs::path out = dir / "run";
  write_text(dir / "run.toml", small_config(out, 12, 2, "[retry]\nmax_attempts = 20\n"));
  auto [coordinator, endpoint] = start_coordinator({"--config", (dir / "run.toml").string()}, out, dir / "coordinator");
  ASSERT_FALSE(endpoint.empty()) << coordinator.err();
  std::mt19937 rng(42);
  std::vector<Process> workers;
  int next = 0;
  for (; next < 2; ++next) workers.push_back(start_worker(endpoint, dir, next));
  int kills = 0;
  const auto deadline = std::chrono::steady_clock::now() + 150s;
  while (coordinator.running() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100 + rng() % 250));
    if (kills < 8 && coordinator.running()) {
      auto& victim = workers[rng() % workers.size()];
      victim.kill9();
      ++kills;
      victim = start_worker(endpoint, dir, next++);
    }
  }
  ASSERT_EQ(coordinator.wait(60s), 0) << coordinator.err();
  EXPECT_GE(kills, 3);
  check_manifest(out / "manifest.sqlite", 2);
  auto reader = storage::ManifestReader::open((out / "manifest.sqlite").string());
  ASSERT_TRUE(reader);
  int done = 0, lost = 0;
  for (const auto& j : all(reader->jobs())) done += j.state == storage::JobState::kDone;
  for (const auto& f : all(reader->failures())) {
    lost += f.reason == "worker_lost";
    EXPECT_TRUE(f.reason == "worker_lost" || f.reason == "timeout") << f.reason << ": " << f.message;
  }
  EXPECT_EQ(done, 24);
  EXPECT_EQ(reader->results()->size(), 24u);
  std::printf("[ info ] %d workers killed, %d leases lost with them\n", kills, lost);
  // The re-queue path was taken: a killed worker held a lease (every kill did in the runs seen: 8 of 8).
  EXPECT_GE(lost, 1);
}

// A scheduler's preemption (SIGTERM to a worker) is no fault of the job's: the stopped worker says which job it
// leaves, and the job is re-queued without costing an attempt. With one attempt per job, every job is done and no
// failure is recorded (before: each preempted lease was a failed attempt, worker_lost, and here a failed job).
TEST(Service, AWorkerStoppedBySigtermCostsItsJobNoAttempt) {
  const fs::path dir = test_dir("worker_sigterm");
  const fs::path out = dir / "run";
  write_text(dir / "run.toml", small_config(out, 16, 2, "[retry]\nmax_attempts = 1\n"));
  auto [coordinator, endpoint] = start_coordinator({"--config", (dir / "run.toml").string()}, out, dir / "coordinator");
  ASSERT_FALSE(endpoint.empty()) << coordinator.err();
  std::mt19937 rng(7);
  std::vector<Process> workers;
  int next = 0;
  for (; next < 2; ++next) workers.push_back(start_worker(endpoint, dir, next));
  int stopped = 0;
  const auto deadline = std::chrono::steady_clock::now() + 150s;
  while (coordinator.running() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(150 + rng() % 250));
    // Three stops at most: a job is given back three times per session, the fourth leave costs an attempt
    // (AJobIsForgivenThreeLeavesNotMore); a requeued job goes to the next worker first, so on a loaded machine one
    // slow job can be held by every stopped worker in turn (8 stops once failed job 6 so).
    if (stopped < 3 && coordinator.running()) {
      auto& victim = workers[rng() % workers.size()];
      ::kill(victim.pid(), SIGTERM);
      const int code = victim.wait(30s);
      // 4: stopped; 0 only if the run ended (told so) just before the signal.
      EXPECT_TRUE(code == 4 || (code == 0 && coordinator.wait(30s) == 0)) << code << ": " << victim.err();
      ++stopped;
      victim = start_worker(endpoint, dir, next++);
      // Not stopped before it has its signal thread (else SIGTERM's default action kills it, as a scheduler's would
      // before the program starts): once it has connected it has.
      const auto until = std::chrono::steady_clock::now() + 10s;
      while (victim.err().find("connected to") == std::string::npos && victim.running() && coordinator.running() &&
             std::chrono::steady_clock::now() < until) {
        std::this_thread::sleep_for(10ms);
      }
    }
  }
  ASSERT_EQ(coordinator.wait(60s), 0) << coordinator.err();
  EXPECT_GE(stopped, 3);
  check_manifest(out / "manifest.sqlite", 2);
  auto reader = storage::ManifestReader::open((out / "manifest.sqlite").string());
  ASSERT_TRUE(reader);
  int done = 0;
  for (const auto& j : all(reader->jobs())) done += j.state == storage::JobState::kDone;
  EXPECT_EQ(done, 32);
  for (const auto& f : all(reader->failures())) {
    ADD_FAILURE() << "job " << f.job_id << ": " << f.reason << ": " << f.message;
  }
  // The path was taken: stopped workers held leases.
  const std::string log = coordinator.err();
  int requeued = 0;
  for (auto at = log.find("the attempt is not counted"); at != std::string::npos;
       at = log.find("the attempt is not counted", at + 1)) {
    ++requeued;
  }
  std::printf("[ info ] %d workers stopped, %d leases given back\n", stopped, requeued);
  EXPECT_GE(requeued, 1);
}

// A done source drape whose file is gone (removed, a disk error) no longer stops the run at every resume (exit 3):
// the jobs that start from it fall back to their fallback recipe, as when a source fails, and the run completes.
TEST(Service, ASourceDrapeThatCannotBeReadIsFallenBackFrom) {
  const fs::path dir = test_dir("source_unreadable");
  const fs::path out = dir / "run";
  const fs::path manifest = out / "manifest.sqlite";
  write_text(dir / "run.toml", small_config(out, 8, 2));
  {
    auto [coordinator, endpoint] = start_coordinator({"--config", (dir / "run.toml").string()}, out, dir / "first");
    ASSERT_FALSE(endpoint.empty()) << coordinator.err();
    Process worker = start_worker(endpoint, dir, 0);
    ASSERT_EQ(coordinator.wait(120s), 0) << coordinator.err();
  }
  // The drape-recipe jobs made pending again (results and files forgotten), and the meshes of their sources that are
  // not drape-recipe jobs themselves removed.
  std::set<std::int64_t> dependents;
  std::map<std::int64_t, std::pair<std::int64_t, std::int64_t>> source_of;  // job -> (sample, slot)
  {
    auto reader = storage::ManifestReader::open(manifest.string());
    ASSERT_TRUE(reader);
    for (const auto& j : all(reader->jobs())) {
      const auto recipe = nlohmann::json::parse(j.recipe_json);
      if (recipe["kind"] != "drape") continue;
      dependents.insert(j.id);
      source_of[j.id] = {recipe["source"]["sample"].get<std::int64_t>(), recipe["source"]["slot"].get<std::int64_t>()};
    }
  }
  ASSERT_FALSE(dependents.empty()) << "the plan has no drape recipe: the test needs another seed";
  std::set<std::int64_t> sources;  // job ids (sample * 2 + slot + 1), the dependents among them excluded
  int expected_fallbacks = 0;
  for (const auto& [job, source] : source_of) {
    const std::int64_t id = source.first * 2 + source.second + 1;
    if (dependents.count(id)) continue;
    sources.insert(id);
    ++expected_fallbacks;
  }
  ASSERT_GT(expected_fallbacks, 0);
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(manifest.c_str(), &db), SQLITE_OK);
  for (std::int64_t id : dependents) {
    const std::string sql = "DELETE FROM files WHERE job_id = " + std::to_string(id) +
                            "; DELETE FROM results WHERE job_id = " + std::to_string(id) +
                            "; UPDATE jobs SET state = 'pending', attempts = 0 WHERE id = " + std::to_string(id);
    ASSERT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, nullptr), SQLITE_OK) << sqlite3_errmsg(db);
  }
  ASSERT_EQ(sqlite3_exec(db, "UPDATE runs SET state = 'stopped'", nullptr, nullptr, nullptr), SQLITE_OK);
  sqlite3_close(db);
  {
    auto reader = storage::ManifestReader::open(manifest.string());
    ASSERT_TRUE(reader);
    for (const auto& f : all(reader->files())) {
      if (f.kind == "mesh" && sources.count(f.job_id)) {
        ASSERT_TRUE(fs::remove(out / f.path)) << f.path;
      }
    }
  }

  Coordinator resumed = start_coordinator({"--resume", manifest.string()}, out, dir / "resumed");
  ASSERT_FALSE(resumed.endpoint.empty()) << resumed.process.err();
  Process worker = start_worker(resumed.endpoint, dir, 1);
  ASSERT_EQ(resumed.process.wait(120s), 0) << resumed.process.err();  // before: 3, at every resume
  const std::string log = resumed.process.err();
  int fallbacks = 0;
  for (auto at = log.find("its source drape cannot be read"); at != std::string::npos;
       at = log.find("its source drape cannot be read", at + 1)) {
    ++fallbacks;
  }
  EXPECT_EQ(fallbacks, expected_fallbacks) << log;
  auto reader = storage::ManifestReader::open(manifest.string());
  ASSERT_TRUE(reader);
  int fell_back = 0;
  for (const auto& j : all(reader->jobs())) {
    EXPECT_EQ(j.state, storage::JobState::kDone) << j.id;
    if (!dependents.count(j.id)) continue;
    const auto recipe = nlohmann::json::parse(j.recipe_json);
    fell_back += recipe["kind"] != "drape";
  }
  EXPECT_EQ(fell_back, expected_fallbacks);
}

struct RunSnapshot {
  std::vector<std::string> jobs;     // id, sample, slot, recipe, render seed, mode, state
  std::vector<std::string> samples;  // every parameter, exactly
  std::map<std::string, std::string> checksums;  // file -> sha256
};

RunSnapshot snapshot(const fs::path& manifest) {
  RunSnapshot s;
  auto reader = storage::ManifestReader::open(manifest.string());
  EXPECT_TRUE(reader);
  if (!reader) return s;
  for (const auto& j : all(reader->jobs())) {
    std::ostringstream line;
    line << j.id << " " << j.sample << " " << j.slot << " " << j.recipe_json << " " << j.render_seed << " " << j.mode
         << " " << storage::to_string(j.state);
    s.jobs.push_back(line.str());
  }
  for (const auto& p : all(reader->samples())) {
    char line[512];
    std::snprintf(line, sizeof line, "%lld %a %a %a %a %a %a %a", static_cast<long long>(p.sample), p.alpha[0],
                  p.alpha[1], p.alpha[2], p.beta[0], p.beta[1], p.beta[2], p.density_g_per_m2);
    s.samples.emplace_back(line);
  }
  for (const auto& f : all(reader->files())) s.checksums[f.path] = f.sha256;
  return s;
}

// Acceptance 3: the coordinator killed with SIGKILL at random moments, then resumed: the run completes, and its
// jobs, parameters, initial states (and, since jobs replay bit for bit, its files) equal an uninterrupted run's.
TEST(Service, ResumesAfterCoordinatorKills) {
  const fs::path dir = test_dir("coordinator_kills");
  // The uninterrupted reference.
  const fs::path ref = dir / "reference";
  write_text(dir / "reference.toml", small_config(ref, 8, 2));
  Process reference({"local", "--workers", "2", "--config", (dir / "reference.toml").string()},
                    (dir / "reference").string());
  ASSERT_EQ(reference.wait(120s), 0) << reference.err();

  const fs::path out = dir / "killed";
  write_text(dir / "killed.toml", small_config(out, 8, 2));
  const fs::path manifest = out / "manifest.sqlite";
  std::mt19937 rng(7);
  std::vector<Process> workers;
  std::string worker_endpoint;
  int kills = 0, starts = 0;
  int code = -1;
  long recorded_before = 0;
  for (int round = 0; round < 20 && code != 0; ++round) {
    const bool resume = fs::exists(manifest);
    fs::remove(out / "endpoint");
    Process coordinator(resume ? std::vector<std::string>{"run", "--resume", manifest.string()}
                               : std::vector<std::string>{"run", "--config", (dir / "killed.toml").string()},
                        (dir / ("coordinator" + std::to_string(round))).string());
    ++starts;
    if (kills == 0) {
      // The first kill lands while the run is planned and its manifest created (or just after).
      std::this_thread::sleep_for(std::chrono::milliseconds(rng() % 80));
      if (coordinator.running()) {
        coordinator.kill9();
        ++kills;
        std::printf("[ info ] kill %d (planning): manifest %s\n", kills, fs::exists(manifest) ? "exists" : "absent");
        continue;
      }
    }
    const std::string endpoint = wait_endpoint(out, coordinator, 30s);
    if (endpoint.empty()) {
      code = coordinator.wait(60s);
      ASSERT_EQ(code, 0) << coordinator.err();
      break;
    }
    if (endpoint != worker_endpoint) {  // the first start, or a kill before the endpoint was recorded
      workers.clear();
      for (int k = 0; k < 2; ++k) workers.push_back(start_worker(endpoint, dir, 10 * round + k));
      worker_endpoint = endpoint;
    }
    if (kills < 5) {
      // Later kills land mid-run: after 1-3 more results, at a random moment (between results or in a commit).
      const long target = recorded_before + 1 + static_cast<long>(rng() % 3);
      const auto until = std::chrono::steady_clock::now() + 30s;
      while (coordinator.running() && recorded_jobs(manifest) < target && std::chrono::steady_clock::now() < until) {
        std::this_thread::sleep_for(5ms);
      }
      // The workers must find the resumed coordinator and make progress (a stalled lease would show here).
      ASSERT_TRUE(!coordinator.running() || recorded_jobs(manifest) >= target)
          << "no progress within 30 s after start " << starts << ": " << coordinator.err();
      std::this_thread::sleep_for(std::chrono::milliseconds(rng() % 150));
      if (coordinator.running()) {
        coordinator.kill9();
        ++kills;
        recorded_before = recorded_jobs(manifest);
        std::printf("[ info ] kill %d: %ld of 16 jobs recorded\n", kills, recorded_before);
        continue;
      }
    }
    code = coordinator.wait(120s);
    ASSERT_EQ(code, 0) << coordinator.err();
  }
  ASSERT_EQ(code, 0);
  std::printf("[ info ] coordinator killed %d times, started %d times\n", kills, starts);
  EXPECT_GE(kills, 4);
  check_manifest(manifest, 2);
  const auto a = snapshot(ref / "manifest.sqlite");
  const auto b = snapshot(manifest);
  EXPECT_EQ(a.jobs, b.jobs);
  EXPECT_EQ(a.samples, b.samples);
  EXPECT_EQ(a.checksums, b.checksums);
  EXPECT_EQ(a.jobs.size(), 16u);
}

// Acceptance 5: a poison job (its simulation diverges) ends as failed with its reason after the retry limit; the
// run completes.
TEST(Service, PoisonJobFailsAfterTheRetryLimit) {
  const fs::path dir = test_dir("poison");
  const fs::path out = dir / "run";
  write_text(dir / "run.toml", small_config(out, 3, 2, "[retry]\nmax_attempts = 3\n[testing]\npoison_samples = [1]\n"));
  Process local({"local", "--workers", "2", "--config", (dir / "run.toml").string()}, (dir / "local").string());
  ASSERT_EQ(local.wait(120s), 0) << local.err();
  EXPECT_NE(local.out().find("run complete: 4 done, 2 failed of 6 jobs"), std::string::npos) << local.out();
  EXPECT_NE(local.out().find("2 diverged"), std::string::npos) << local.out();  // the stats
  check_manifest(out / "manifest.sqlite", 2);
  auto reader = storage::ManifestReader::open((out / "manifest.sqlite").string());
  ASSERT_TRUE(reader);
  std::map<std::int64_t, int> attempts_failed;
  for (const auto& f : all(reader->failures())) {
    EXPECT_EQ(f.reason, "diverged") << f.message;
    ++attempts_failed[f.job_id];
  }
  for (const auto& j : all(reader->jobs())) {
    if (j.sample == 1) {
      EXPECT_EQ(j.state, storage::JobState::kFailed);
      EXPECT_EQ(j.failure_reason, "diverged");
      EXPECT_EQ(j.attempts, 3);
      EXPECT_EQ(attempts_failed[j.id], 3);
      EXPECT_EQ(j.mode, "poison");
    } else {
      EXPECT_EQ(j.state, storage::JobState::kDone) << "job " << j.id;
      EXPECT_EQ(j.recipe_json.find("\"source\":{\"sample\":1"), std::string::npos)
          << "a drape recipe from the failed sample must fall back: " << j.recipe_json;
    }
  }
}

// Acceptance 6: the output directory becomes unwritable: the coordinator stops with a clear error and nothing
// half-written; after the fix, --resume completes the run with nothing lost.
TEST(Service, StopsOnAnUnwritableOutputAndResumes) {
  const fs::path dir = test_dir("storage_fault");
  const fs::path out = dir / "run";
  write_text(dir / "run.toml", small_config(out, 8, 2));
  const fs::path manifest = out / "manifest.sqlite";
  auto [coordinator, endpoint] = start_coordinator({"--config", (dir / "run.toml").string()}, out, dir / "coordinator");
  ASSERT_FALSE(endpoint.empty()) << coordinator.err();
  Process worker = start_worker(endpoint, dir, 1);
  ASSERT_TRUE(wait_recorded(manifest, 3, 60s));
  // data/ turns into a regular file: every write under it fails (ENOTDIR), even for root.
  fs::rename(out / "data", dir / "data.saved");
  write_text(out / "data", "not a directory");
  ASSERT_EQ(coordinator.wait(60s), 3) << coordinator.err();
  const std::string err = coordinator.err();
  const std::string last = last_line(err);
  EXPECT_EQ(last.rfind("drapegen run: error: cannot ", 0), 0u) << err;
  EXPECT_NE(last.find("Not a directory"), std::string::npos) << err;
  EXPECT_NE(last.find("drapegen run --resume"), std::string::npos) << err;
  const long recorded = recorded_jobs(manifest);
  EXPECT_LT(recorded, 16);
  // The count it reports is what the manifest holds (a pass rolled back on the fault is not counted).
  EXPECT_NE(last.find("(stopped with " + std::to_string(recorded) + " of 16 jobs recorded"), std::string::npos) << err;
  EXPECT_EQ(worker.wait(10s), 5) << worker.err();  // told the run stopped before its end
  // Fix it and resume.
  fs::remove(out / "data");
  fs::rename(dir / "data.saved", out / "data");
  ASSERT_TRUE(resume_to_completion(manifest, out, dir, 2));
  check_manifest(manifest, 2);
  auto reader = storage::ManifestReader::open(manifest.string());
  ASSERT_TRUE(reader);
  EXPECT_EQ(reader->results()->size(), 16u);
  EXPECT_EQ(reader->run()->state, "complete");
}

// One result's file cannot be written (its name taken by a directory, so the rename fails: EISDIR) while the rest of
// data/ can: the coordinator stops naming that path; what it recorded before stays; once the directory is gone, resume
// completes.
TEST(Service, StopsOnOneUnwritableResultAndResumes) {
  const fs::path dir = test_dir("one_file_fault");
  const fs::path out = dir / "run";
  const fs::path blocker = out / "data" / "s000003_k01_o01.exr";
  fs::create_directories(blocker / "inside");
  write_text(dir / "run.toml", small_config(out, 8, 2));
  const fs::path manifest = out / "manifest.sqlite";
  auto [coordinator, endpoint] = start_coordinator({"--config", (dir / "run.toml").string()}, out, dir / "coordinator");
  ASSERT_FALSE(endpoint.empty()) << coordinator.err();
  Process worker = start_worker(endpoint, dir, 1);
  ASSERT_EQ(coordinator.wait(60s), 3) << coordinator.err();
  const std::string err = coordinator.err();
  const std::string last = last_line(err);
  EXPECT_NE(last.find("cannot rename to " + blocker.string() + ": Is a directory"), std::string::npos) << err;
  EXPECT_NE(last.find("drapegen run --resume"), std::string::npos) << err;
  const long recorded = recorded_jobs(manifest);
  EXPECT_GE(recorded, 0);
  EXPECT_LT(recorded, 16);
  EXPECT_EQ(worker.wait(10s), 5) << worker.err();
  fs::remove_all(blocker);
  ASSERT_TRUE(resume_to_completion(manifest, out, dir, 2));
  check_manifest(manifest, 2);
  EXPECT_EQ(recorded_jobs(manifest), 16);
}

// Acceptance 6, the disk-full half: the output directory is a small tmpfs that fills up during the run; the
// coordinator stops with a clear error; after the filesystem grows, --resume completes the run. Needs the right to
// mount (root); skipped otherwise.
TEST(Service, StopsOnAFullDiskAndResumes) {
  // A mount left behind by an interrupted earlier run would keep test_dir from clearing the directory.
  (void)!std::system(
      ("umount " + (fs::path(SERVICE_TEST_WORK) / "disk_full" / "run").string() + " 2> /dev/null").c_str());
  const fs::path dir = test_dir("disk_full");
  const fs::path out = dir / "run";
  fs::create_directories(out);
  const std::string mount = "mount -t tmpfs -o size=400k drapegen-test " + out.string() + " 2> /dev/null";
  if (std::system(mount.c_str()) != 0) GTEST_SKIP() << "cannot mount a tmpfs here (not root?)";
  struct Unmount {
    std::string path;
    ~Unmount() { (void)!std::system(("umount " + path + " 2> /dev/null").c_str()); }
  } unmount{out.string()};
  write_text(dir / "run.toml", small_config(out, 8, 2));
  const fs::path manifest = out / "manifest.sqlite";
  auto [coordinator, endpoint] = start_coordinator({"--config", (dir / "run.toml").string()}, out, dir / "coordinator");
  ASSERT_FALSE(endpoint.empty()) << coordinator.err();
  Process worker = start_worker(endpoint, dir, 1);
  ASSERT_EQ(coordinator.wait(120s), 3) << coordinator.err();
  const std::string err = coordinator.err();
  const std::string last = last_line(err);
  EXPECT_EQ(last.rfind("drapegen run: error: ", 0), 0u) << err;
  EXPECT_TRUE(last.find("No space left on device") != std::string::npos ||
              last.find("disk is full") != std::string::npos)
      << last;
  EXPECT_NE(last.find("drapegen run --resume"), std::string::npos) << err;
  const long recorded = recorded_jobs(manifest);
  std::printf("[ info ] disk full after %ld of 16 jobs: %s", recorded, last.c_str());
  EXPECT_LT(recorded, 16);
  EXPECT_EQ(worker.wait(10s), 5) << worker.err();
  // More space, then resume.
  ASSERT_EQ(std::system(("mount -o remount,size=64m " + out.string()).c_str()), 0);
  ASSERT_TRUE(resume_to_completion(manifest, out, dir, 2));
  check_manifest(manifest, 2);
  EXPECT_EQ(recorded_jobs(manifest), 16);
}

// SIGTERM (as SIGINT): the coordinator commits, marks the run stopped, shuts the workers down (they exit 5) and exits
// with 4;
// --resume completes the run.
TEST(Service, StopsCleanlyOnSigterm) {
  const fs::path dir = test_dir("sigterm");
  const fs::path out = dir / "run";
  write_text(dir / "run.toml", small_config(out, 8, 2));
  const fs::path manifest = out / "manifest.sqlite";
  auto [coordinator, endpoint] = start_coordinator({"--config", (dir / "run.toml").string()}, out, dir / "coordinator");
  ASSERT_FALSE(endpoint.empty()) << coordinator.err();
  Process worker = start_worker(endpoint, dir, 1);
  wait_recorded(manifest, 2, 60s);  // SIGTERM mid-run; the test holds whether or not two were recorded by then
  ::kill(coordinator.pid(), SIGTERM);
  ASSERT_EQ(coordinator.wait(30s), 4) << coordinator.err();
  EXPECT_NE(coordinator.err().find("drapegen run --resume"), std::string::npos) << coordinator.err();
  // Told the run stopped before its end: 5, not the 0 of a finished run (which completes a Kubernetes Job whose
  // workers the resumed run still needs).
  EXPECT_EQ(worker.wait(10s), 5) << worker.err();
  {
    auto reader = storage::ManifestReader::open(manifest.string());
    ASSERT_TRUE(reader);
    EXPECT_EQ(reader->run()->state, "stopped");
  }
  check_manifest(manifest, 2);
  ASSERT_TRUE(resume_to_completion(manifest, out, dir, 2));
  check_manifest(manifest, 2);
  EXPECT_EQ(recorded_jobs(manifest), 16);
}

// One coordinator per output directory: a second one, `--resume` of the live run included, is refused before it
// removes anything (resume removes the files the manifest does not record, which for a live run are files it is
// writing or about to commit); once the first has stopped, the resume proceeds.
TEST(Service, ASecondCoordinatorOnALiveOutputIsRefused) {
  const fs::path dir = test_dir("second_coordinator");
  const fs::path out = dir / "run";
  write_text(dir / "run.toml", small_config(out, 2, 1));
  const fs::path manifest = out / "manifest.sqlite";
  auto [first, endpoint] = start_coordinator({"--config", (dir / "run.toml").string()}, out, dir / "first");
  ASSERT_FALSE(endpoint.empty()) << first.err();
  const fs::path unrecorded = out / "data" / "in_flight.exr";  // as a file the live run is about to commit
  write_text(unrecorded, "not yet recorded");

  Process resume({"run", "--resume", manifest.string()}, (dir / "resume").string());
  ASSERT_EQ(resume.wait(30s), 1) << resume.err();
  EXPECT_NE(resume.err().find(out.string() + " is in use by another coordinator (pid " + std::to_string(first.pid())),
            std::string::npos)
      << resume.err();
  EXPECT_TRUE(fs::exists(unrecorded));
  // A new run with the same configuration, while the first is live: refused the same way.
  Process again({"run", "--config", (dir / "run.toml").string()}, (dir / "again").string());
  ASSERT_EQ(again.wait(30s), 1) << again.err();
  EXPECT_NE(again.err().find("is in use by another coordinator"), std::string::npos) << again.err();
  EXPECT_TRUE(first.running());

  ::kill(first.pid(), SIGTERM);
  ASSERT_EQ(first.wait(30s), 4) << first.err();
  // The lock went with the process: the resume runs, and removes the file no run recorded. As if the run had been
  // planned by another build, the resume says whose code computes its remaining jobs.
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(manifest.c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db, "UPDATE runs SET code_version = '0.1-older'", nullptr, nullptr, nullptr), SQLITE_OK);
  sqlite3_close(db);
  {
    Coordinator resumed = start_coordinator({"--resume", manifest.string()}, out, dir / "resumed");
    ASSERT_FALSE(resumed.endpoint.empty()) << resumed.process.err();
    Process worker = start_worker(resumed.endpoint, dir, 1);
    ASSERT_EQ(resumed.process.wait(120s), 0) << resumed.process.err();
    EXPECT_NE(resumed.process.err().find("planned by drapegen 0.1-older and is resumed by"), std::string::npos)
        << resumed.process.err();
  }
  EXPECT_FALSE(fs::exists(unrecorded));
  check_manifest(manifest, 2);
  EXPECT_EQ(recorded_jobs(manifest), 2);
  // With no coordinator left, a new run on that output is told to resume instead.
  Process after({"run", "--config", (dir / "run.toml").string()}, (dir / "after").string());
  ASSERT_EQ(after.wait(30s), 1) << after.err();
  EXPECT_NE(after.err().find(manifest.string() + " exists already: continue it with drapegen run --resume"),
            std::string::npos)
      << after.err();
  // With the manifest gone, its results are files no manifest lists: a new run is refused rather than mixed with them.
  for (const char* suffix : {"", "-wal", "-shm", "-journal"}) fs::remove(manifest.string() + suffix);
  Process orphaned({"run", "--config", (dir / "run.toml").string()}, (dir / "orphaned").string());
  ASSERT_EQ(orphaned.wait(30s), 1) << orphaned.err();
  EXPECT_NE(orphaned.err().find((out / "data").string() + " holds files that no manifest lists"), std::string::npos)
      << orphaned.err();
  EXPECT_FALSE(fs::exists(manifest));
}

// Sends `signal` to every child of `parent` (drapegen local's workers) every `every` until it exits, at most 60 s;
// the signals delivered. A child is listed under the thread that started it (restarts: the supervisor's), so every
// thread's list is read.
int signal_children_until_exit(Process& parent, int signal, std::chrono::milliseconds every) {
  const fs::path tasks = fs::path("/proc") / std::to_string(parent.pid()) / "task";
  int delivered = 0;
  const auto until = std::chrono::steady_clock::now() + 60s;
  while (parent.running() && std::chrono::steady_clock::now() < until) {
    std::error_code ec;
    for (const auto& task : fs::directory_iterator(tasks, ec)) {
      std::istringstream pids(Process::slurp((task.path() / "children").string()));
      for (pid_t pid = 0; pids >> pid;) delivered += ::kill(pid, signal) == 0;
    }
    std::this_thread::sleep_for(every);
  }
  return delivered;
}

// `drapegen local` restarts a worker that dies, up to 3 x N times over the run; once every worker has died and no
// restart is left it stops the run (exit 4, the cause named) instead of waiting for workers that never come.
TEST(Service, LocalStopsWhenEveryWorkerHasDiedAndNoRestartIsLeft) {
  const fs::path dir = test_dir("local_workers_die");
  const fs::path out = dir / "run";
  write_text(dir / "run.toml", small_config(out, 40, 2));
  const fs::path manifest = out / "manifest.sqlite";
  Process local({"local", "--workers", "1", "--config", (dir / "run.toml").string()}, (dir / "local").string());
  ASSERT_FALSE(wait_endpoint(out, local, 30s).empty()) << local.err();
  // Kill the worker process (local's only child) each time one runs: the first and its 3 restarts.
  const int kills = signal_children_until_exit(local, SIGKILL, 20ms);
  ASSERT_EQ(local.wait(1s), 4) << local.err();
  EXPECT_GE(kills, 4);
  EXPECT_NE(local.err().find("every worker has died and the 3 restarts are spent"), std::string::npos) << local.err();
  EXPECT_NE(local.err().find("drapegen local --resume " + manifest.string()), std::string::npos) << local.err();
  check_manifest(manifest, 2);
}

// Workers stopped by SIGTERM exit 4 and are not restarted; once none is left, `drapegen local` stops the run with 4
// instead of waiting for workers that will not come, and names itself in the resume hint.
TEST(Service, LocalStopsWhenItsWorkersAreStoppedBySignals) {
  const fs::path dir = test_dir("local_workers_stopped");
  const fs::path out = dir / "run";
  write_text(dir / "run.toml", small_config(out, 40, 2));
  const fs::path manifest = out / "manifest.sqlite";
  Process local({"local", "--workers", "2", "--config", (dir / "run.toml").string()}, (dir / "local").string());
  ASSERT_FALSE(wait_endpoint(out, local, 30s).empty()) << local.err();
  const int stopped = signal_children_until_exit(local, SIGTERM, 100ms);
  ASSERT_EQ(local.wait(1s), 4) << local.err();
  EXPECT_GE(stopped, 2);
  EXPECT_NE(local.err().find("was stopped by a signal; not restarted"), std::string::npos) << local.err();
  EXPECT_EQ(local.err().find("starting another"), std::string::npos) << local.err();
  EXPECT_NE(local.err().find("no worker is left (2 stopped by a signal, 0 could not be restarted)"), std::string::npos)
      << local.err();
  EXPECT_NE(local.err().find("drapegen local --resume " + manifest.string()), std::string::npos) << local.err();
  check_manifest(manifest, 2);
}

// A worker that cannot start (the third of three, testing.fail_worker_start) fails `drapegen local` at once, naming
// the resume command, and the two it started are stopped and reaped, not left running until they give up. This test
// process adopts orphans (a child subreaper): a worker left behind would be its child once local exits.
TEST(Service, LocalStopsTheWorkersItStartedWhenALaterOneCannotStart) {
  ASSERT_EQ(::prctl(PR_SET_CHILD_SUBREAPER, 1), 0);
  const fs::path dir = test_dir("local_worker_cannot_start");
  const fs::path out = dir / "run";
  write_text(dir / "run.toml", small_config(out, 4, 1, "[testing]\nfail_worker_start = 2\n"));
  {
    Process local({"local", "--workers", "3", "--config", (dir / "run.toml").string()}, (dir / "local").string());
    ASSERT_EQ(local.wait(30s), 1) << local.err();
    EXPECT_NE(local.err().find("cannot start a worker: local-2"), std::string::npos) << local.err();
    EXPECT_NE(local.err().find("drapegen local --resume " + (out / "manifest.sqlite").string()), std::string::npos)
        << local.err();
  }
  // Local has exited and been reaped: any worker it left is now this process's child (alive or not yet reaped).
  std::vector<pid_t> left;
  for (const auto& task : fs::directory_iterator(fs::path("/proc/self/task"))) {
    std::istringstream pids(Process::slurp((task.path() / "children").string()));
    for (pid_t child = 0; pids >> child;) left.push_back(child), ::kill(child, SIGKILL);
  }
  while (::waitpid(-1, nullptr, 0) > 0) {
  }
  EXPECT_EQ(errno, ECHILD);
  EXPECT_TRUE(left.empty()) << left.size() << " worker(s) of drapegen local left behind";
  ::prctl(PR_SET_CHILD_SUBREAPER, 0);
}

// `drapegen local` starts its workers without keys: a configuration with CurveZMQ keys would lock them out (each
// would give up after a minute), so it is refused at once.
TEST(Service, LocalRefusesAConfigurationWithKeys) {
  const fs::path dir = test_dir("local_keys");
  for (const std::string security : {"curve = true\n", "server_secret_key = \"s.key\"\nauthorized_keys = \"a\"\n"}) {
    write_text(dir / "run.toml", small_config(dir / "run", 2, 1, "[security]\n" + security));
    Process local({"local", "--workers", "1", "--config", (dir / "run.toml").string()}, (dir / "local").string());
    ASSERT_EQ(local.wait(30s), 1) << local.err();
    EXPECT_NE(local.err().find("drapegen local starts its workers without CurveZMQ keys"), std::string::npos)
        << local.err();
    EXPECT_FALSE(fs::exists(dir / "run")) << "refused before the output is touched";
  }
}

// An output that cannot be created (its parent a regular file) is the file system's failure: exit 3, as a result
// that cannot be written mid-run, not 1 (bad input); nothing is left behind.
TEST(Service, AnOutputThatCannotBeCreatedExitsWith3) {
  const fs::path dir = test_dir("output_not_creatable");
  write_text(dir / "file", "a regular file");
  const fs::path out = dir / "file" / "run";
  write_text(dir / "run.toml", small_config(out, 2, 1));
  Process run({"run", "--config", (dir / "run.toml").string()}, (dir / "run").string());
  ASSERT_EQ(run.wait(30s), 3) << run.err();
  EXPECT_NE(run.err().find("cannot create " + (out / "data").string()), std::string::npos) << run.err();
  Process local({"local", "--workers", "1", "--config", (dir / "run.toml").string()}, (dir / "local").string());
  ASSERT_EQ(local.wait(30s), 3) << local.err();
}

}  // namespace
}  // namespace drapegen::test
