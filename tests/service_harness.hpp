#pragma once
// Helpers of the service's multi-process tests: start drapegen processes, kill them, wait for them, and check a
// manifest against its files.

#include <chrono>
#include <csignal>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <spawn.h>
#include <sstream>
#include <string>
#include <sys/wait.h>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "drapegen/storage/manifest_reader.hpp"
#include "drapegen/storage/sha256.hpp"

extern char** environ;

namespace drapegen::test {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

/// The value of a reader's answer, by value (range-for over `*reader->jobs()` would dangle).
template <class T>
T all(sim::Expected<T> answer) {
  EXPECT_TRUE(answer.has_value()) << (answer ? "" : answer.error().message);
  return answer ? std::move(answer).value() : T{};
}

/// A child process running the drapegen binary, its stdout and stderr in files.
class Process {
 public:
  Process() = default;
  Process(const std::vector<std::string>& args, const std::string& log_prefix) {
    std::vector<std::string> argv_s = {DRAPEGEN_BIN};
    argv_s.insert(argv_s.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (auto& a : argv_s) argv.push_back(a.data());
    argv.push_back(nullptr);
    out_ = log_prefix + ".out";
    err_ = log_prefix + ".err";
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, out_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addopen(&actions, 2, err_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (posix_spawn(&pid_, DRAPEGEN_BIN, &actions, nullptr, argv.data(), environ) != 0) pid_ = -1;
    posix_spawn_file_actions_destroy(&actions);
  }
  Process(Process&& o) noexcept { *this = std::move(o); }
  Process& operator=(Process&& o) noexcept {
    std::swap(pid_, o.pid_);
    std::swap(status_, o.status_);
    std::swap(out_, o.out_);
    std::swap(err_, o.err_);
    return *this;
  }
  ~Process() {
    if (pid_ > 0 && status_ < 0) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
  }

  [[nodiscard]] bool started() const { return pid_ > 0; }
  [[nodiscard]] pid_t pid() const { return pid_; }

  /// True while the process runs (reaps it when it has exited).
  bool running() {
    if (pid_ <= 0 || status_ >= 0) return false;
    int status = 0;
    if (::waitpid(pid_, &status, WNOHANG) == pid_) {
      status_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      return false;
    }
    return true;
  }
  /// The exit code (128 + signal if killed), or -1 on timeout.
  int wait(std::chrono::milliseconds timeout) {
    const auto until = std::chrono::steady_clock::now() + timeout;
    while (running()) {
      if (std::chrono::steady_clock::now() > until) return -1;
      std::this_thread::sleep_for(10ms);
    }
    return status_;
  }
  void kill9() {
    if (pid_ > 0 && status_ < 0) {
      ::kill(pid_, SIGKILL);
      int status = 0;
      ::waitpid(pid_, &status, 0);
      status_ = 128 + SIGKILL;
    }
  }
  [[nodiscard]] std::string out() const { return slurp(out_); }
  [[nodiscard]] std::string err() const { return slurp(err_); }

  static std::string slurp(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
  }

 private:
  pid_t pid_ = -1;
  int status_ = -1;
  std::string out_, err_;
};

/// A fresh directory for one test.
inline fs::path test_dir(const std::string& name) {
  const fs::path dir = fs::path(SERVICE_TEST_WORK) / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

inline void write_text(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

/// A small run: coarse meshes, few jobs, fast heartbeats.
inline std::string small_config(const fs::path& output, int samples, int states, const std::string& extra = "") {
  std::ostringstream c;
  c << "seed = 5\nsamples = " << samples << "\nstates_per_sample = " << states
    << "\norientations = 2\nresolution = 15\noutput = \"" << output.string() << "\"\n"
    << extra
    << "\n[solver]\nmax_self_intersections = 1000000\ncoarse_start_resolution = 0\n"
       "[network]\nbind = \"tcp://127.0.0.1:*\"\nheartbeat_ms = 100\nliveness = 4\n"
       "[progress]\ninterval_s = 1\n";
  return c.str();
}

/// Waits for OUTPUT/endpoint (written once the coordinator has bound and planned).
inline std::string wait_endpoint(const fs::path& output, Process& coordinator, std::chrono::milliseconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < until) {
    std::string text = Process::slurp((output / "endpoint").string());
    if (!text.empty() && text.back() == '\n') return text.substr(0, text.size() - 1);
    if (!coordinator.running()) return "";
    std::this_thread::sleep_for(20ms);
  }
  return "";
}

/// `drapegen run ARGS` that has announced its endpoint; `endpoint` is empty if it did not within 30 s.
struct Coordinator {
  Process process;
  std::string endpoint;
};
inline Coordinator start_coordinator(const std::vector<std::string>& args, const fs::path& output,
                                     const fs::path& log_prefix) {
  std::vector<std::string> command{"run"};
  command.insert(command.end(), args.begin(), args.end());
  Coordinator c{Process(command, log_prefix.string()), ""};
  c.endpoint = wait_endpoint(output, c.process, 30s);
  return c;
}

/// Worker w`k` (log under DIR/worker`k`).
inline Process start_worker(const std::string& endpoint, const fs::path& dir, int k) {
  const std::string number = std::to_string(k);
  return Process({"worker", "--connect", endpoint, "--name", std::string("w").append(number), "--heartbeat-ms", "100",
                  "--liveness", "4", "--backoff-max-ms", "500", "--give-up", "60"},
                 (dir / std::string("worker").append(number)).string());
}

/// `drapegen run --resume MANIFEST` with one worker (w`k`), run to the end: success if it exits 0.
inline ::testing::AssertionResult resume_to_completion(const fs::path& manifest, const fs::path& output,
                                                       const fs::path& dir, int k) {
  Coordinator resumed = start_coordinator({"--resume", manifest.string()}, output, dir / "resumed");
  if (resumed.endpoint.empty()) return ::testing::AssertionFailure() << "no endpoint: " << resumed.process.err();
  Process worker = start_worker(resumed.endpoint, dir, k);
  if (const int code = resumed.process.wait(120s); code != 0) {
    return ::testing::AssertionFailure() << "resume exited " << code << ": " << resumed.process.err();
  }
  return ::testing::AssertionSuccess();
}

/// The last line of a process's stderr (where a command's one-line error goes, after any log lines).
inline std::string last_line(const std::string& err) { return err.substr(err.rfind('\n', err.size() - 2) + 1); }

/// Jobs recorded (done or failed), read through the stable reader; -1 if the manifest cannot be read yet.
inline long recorded_jobs(const fs::path& manifest) {
  auto reader = storage::ManifestReader::open(manifest.string());
  if (!reader) return -1;
  auto jobs = reader->jobs();
  if (!jobs) return -1;
  long n = 0;
  for (const auto& j : *jobs) n += j.state != storage::JobState::kPending;
  return n;
}

/// Polls until at least `target` jobs are recorded or `timeout` passes; whether the target was reached.
inline bool wait_recorded(const fs::path& manifest, long target, std::chrono::milliseconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (recorded_jobs(manifest) < target && std::chrono::steady_clock::now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return recorded_jobs(manifest) >= target;
}

/// The checks every finished run must pass: integrity, each done job exactly one result with its files, every file
/// present with the recorded checksum and size, no file in data/ the manifest does not list, failed jobs with a
/// reason and no result.
inline void check_manifest(const fs::path& manifest, int orientations) {
  auto reader = storage::ManifestReader::open(manifest.string());
  ASSERT_TRUE(reader) << reader.error().message;
  EXPECT_EQ(*reader->integrity_check(), "ok");
  const auto jobs = *reader->jobs();
  const auto results = *reader->results();
  const auto files = *reader->files();
  std::map<std::int64_t, int> result_count, file_count;
  for (const auto& r : results) ++result_count[r.job_id];
  for (const auto& f : files) ++file_count[f.job_id];
  for (const auto& j : jobs) {
    if (j.state == storage::JobState::kDone) {
      EXPECT_EQ(result_count[j.id], 1) << "job " << j.id;
      if (j.mode != "noop") {
        EXPECT_EQ(file_count[j.id], 1 + orientations) << "job " << j.id;
      }
    } else {
      EXPECT_EQ(result_count[j.id], 0) << "job " << j.id;
      EXPECT_EQ(file_count[j.id], 0) << "job " << j.id;
      if (j.state == storage::JobState::kFailed) {
        EXPECT_FALSE(j.failure_reason.empty()) << "job " << j.id;
      }
    }
  }
  std::set<std::string> listed;
  for (const auto& f : files) {
    const fs::path path = manifest.parent_path() / f.path;
    listed.insert(path.filename().string());
    auto sha = storage::sha256_file(path.string());
    ASSERT_TRUE(sha) << sha.error().message;
    EXPECT_EQ(*sha, f.sha256) << f.path;
    EXPECT_EQ(static_cast<std::int64_t>(fs::file_size(path)), f.bytes) << f.path;
  }
  for (const auto& entry : fs::directory_iterator(manifest.parent_path() / "data")) {
    EXPECT_TRUE(listed.count(entry.path().filename().string())) << "orphan file " << entry.path();
  }
}

}  // namespace drapegen::test
