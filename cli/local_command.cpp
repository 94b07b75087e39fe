// drapegen local: a coordinator plus N worker processes on this machine, then the run's statistics.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <fmt/format.h>
#include <iostream>
#include <memory>
#include <mutex>
#include <spawn.h>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>
#include <vector>

#include "commands.hpp"
#include "failure.hpp"
#include "drapegen/coordinator/coordinator.hpp"
#include "drapegen/coordinator/logging.hpp"
#include "drapegen/coordinator/run_config.hpp"
#include "drapegen/coordinator/stats.hpp"
#include "drapegen/storage/read_file.hpp"
#include "signals.hpp"

extern char** environ;

namespace drapegen::cli {

int report_run(const coordinator::RunSummary& s, const std::string& manifest, const char* sub);

namespace {

struct LocalOptions {
  int workers = 2;
  std::string config;
  std::string resume;
  std::string output;
  bool print_config = false;
  bool retry_failed = false;
};

const Failure fail{"local"};

/// The worker processes: started after the coordinator binds, restarted if one dies before the run ends (at most
/// kRestartsPerWorker x N restarts over the run; a worker the coordinator told the run is over (exit 0) or stopped
/// before its end (exit 5), or one stopped by SIGINT/SIGTERM (exit 4, or killed by it), is not restarted). halt() is
/// the flag the coordinator runs until: set by SIGINT/SIGTERM (`signal_stop`), or when no worker is left and none will
/// be restarted, since no worker would ever come again.
class WorkerPool {
 public:
  static constexpr int kRestartsPerWorker = 3;
  /// `fail_start`: the worker of this index cannot start (RunConfig::fail_worker_start, tests; -1: none).
  WorkerPool(std::string endpoint, int count, const std::atomic<bool>& signal_stop, int fail_start = -1)
      : endpoint_(std::move(endpoint)), count_(count), signal_stop_(signal_stop), fail_start_(fail_start) {}

  [[nodiscard]] const std::atomic<bool>& halt() const { return halt_; }
  /// The pool halted the run: no worker was left (every one died with the restarts spent, or stopped).
  [[nodiscard]] bool exhausted() const { return exhausted_; }

  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;
  /// Workers still running (a later one failed to start, or the pool was never finished) are stopped and reaped.
  ~WorkerPool() {
    finishing_ = true;
    if (supervisor_.joinable()) supervisor_.join();
    for (pid_t& pid : pids_) {
      if (pid <= 0) continue;
      ::kill(pid, SIGTERM);
      ::waitpid(pid, nullptr, 0);
      pid = -1;
    }
  }

  sim::Status start() {
    for (int k = 0; k < count_; ++k) {
      auto pid = spawn(k);
      if (!pid) return pid.error();  // the ones started are stopped when the pool goes
      pids_.push_back(*pid);
    }
    supervisor_ = std::thread([this] { supervise(); });
    return {};
  }

  /// Waits for the workers to exit (they were told to shut down), then terminates any left.
  void finish() {
    finishing_ = true;
    if (supervisor_.joinable()) supervisor_.join();
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(5);
    for (pid_t& pid : pids_) {
      while (pid > 0) {
        if (::waitpid(pid, nullptr, WNOHANG) == pid) {
          pid = -1;
          break;
        }
        if (std::chrono::steady_clock::now() > until) {
          ::kill(pid, SIGTERM);
          ::waitpid(pid, nullptr, 0);
          pid = -1;
          break;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
    }
  }

 private:
  sim::Expected<pid_t> spawn(int k) {
    const std::string self = "/proc/self/exe";
    const std::string name = fmt::format("local-{}", k);
    if (k == fail_start_) return sim::Error{fmt::format("cannot start a worker: {} (testing.fail_worker_start)", name)};
    std::vector<std::string> args = {"drapegen", "worker", "--connect", endpoint_, "--name", name, "--give-up", "60",
                                     "--log-level", "warn"};
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    // The worker starts with SIGINT/SIGTERM unblocked (this process blocks them for its signal thread).
    posix_spawnattr_t attributes;
    posix_spawnattr_init(&attributes);
    const sigset_t mask = child_signal_mask();
    posix_spawnattr_setsigmask(&attributes, &mask);
    posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGMASK);
    pid_t pid = 0;
    const int rc = ::posix_spawn(&pid, self.c_str(), nullptr, &attributes, argv.data(), environ);
    posix_spawnattr_destroy(&attributes);
    if (rc != 0) return sim::Error{fmt::format("cannot start a worker: {}", std::strerror(rc))};
    return pid;
  }

  void supervise() {
    int restarts = 0;
    while (!finishing_) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      if (signal_stop_) halt_ = true;
      for (std::size_t k = 0; k < pids_.size() && !finishing_; ++k) {
        int status = 0;
        if (pids_[k] <= 0 || ::waitpid(pids_[k], &status, WNOHANG) != pids_[k]) continue;
        pids_[k] = -1;
        // The coordinator told it the run is over, or stopped (a storage error): it is finishing.
        const bool clean_exit =
            WIFEXITED(status) && (WEXITSTATUS(status) == kExitOk || WEXITSTATUS(status) == kExitRunStopped);
        // SIGINT/SIGTERM: handled (exit 4), or before the worker installed its handlers (killed by it)
        const bool stopped = (WIFEXITED(status) && WEXITSTATUS(status) == kExitStopped) ||
                             (WIFSIGNALED(status) && (WTERMSIG(status) == SIGTERM || WTERMSIG(status) == SIGINT));
        const std::string how = WIFSIGNALED(status) ? fmt::format("signal {}", WTERMSIG(status))
                                                    : fmt::format("status {}", WEXITSTATUS(status));
        if (finishing_) continue;
        if (clean_exit) {
          run_over_ = true;
          continue;
        }
        if (stopped) {  // someone stopped it: not restarted
          coordinator::logger()->warn("worker local-{} was stopped by a signal; not restarted", k);
          ++stopped_;
          continue;
        }
        if (restarts >= kRestartsPerWorker * count_) {
          coordinator::logger()->warn("worker local-{} exited ({}); no restart left", k, how);
          continue;
        }
        coordinator::logger()->warn("worker local-{} exited ({}); starting another", k, how);
        ++restarts;
        if (auto pid = spawn(static_cast<int>(k))) {
          pids_[k] = *pid;
        } else {
          coordinator::logger()->error("worker local-{}: {}", k, pid.error().message);
          ++lost_;
        }
      }
      // None left and none to come (a restart happens above, at once, or never): the run cannot go on. Not once a
      // worker was told the run is over (the coordinator is finishing), nor on a Ctrl-C, which reaches the workers
      // and this process alike (the stop is the user's, not a lost pool).
      const bool none_left = std::all_of(pids_.begin(), pids_.end(), [](pid_t pid) { return pid <= 0; });
      if (!finishing_ && !halt_ && !signal_stop_ && !run_over_ && none_left &&
          (restarts >= kRestartsPerWorker * count_ || stopped_ > 0 || lost_ > 0)) {
        if (restarts >= kRestartsPerWorker * count_) {
          coordinator::logger()->error("every worker has died and the {} restarts are spent: stopping the run",
                                       kRestartsPerWorker * count_);
        } else {
          coordinator::logger()->error("no worker is left ({} stopped by a signal, {} could not be restarted): "
                                       "stopping the run",
                                       stopped_, lost_);
        }
        exhausted_ = true;
        halt_ = true;
      }
    }
  }

  std::string endpoint_;
  int count_;
  const std::atomic<bool>& signal_stop_;
  int fail_start_;
  std::vector<pid_t> pids_;
  std::thread supervisor_;
  std::atomic<bool> finishing_{false};
  std::atomic<bool> halt_{false};
  std::atomic<bool> exhausted_{false};
  int stopped_ = 0;        // workers stopped by a signal (the supervisor's own counts)
  int lost_ = 0;           // restarts that could not be started
  bool run_over_ = false;  // a worker was told the run is over or stopped: the coordinator is finishing
};

}  // namespace

Runner add_local_command(CLI::App& app) {
  auto o = std::make_shared<LocalOptions>();
  app.add_option("--workers", o->workers, "Worker processes to start")
      ->check(CLI::Range(1, 1024))
      ->capture_default_str();
  auto* config = app.add_option("--config", o->config, "Run configuration (TOML); default: the embedded small run");
  auto* resume = app.add_option("--resume", o->resume, "Continue the run of this manifest instead");
  config->excludes(resume);
  app.add_flag("--retry-failed", o->retry_failed,
               "With --resume: failed jobs are pending again, each with retry.max_attempts more attempts (their "
               "failures stay recorded)")
      ->needs(resume);
  app.add_option("--output", o->output, "Override the configuration's output directory (a new run only)")
      ->excludes(resume);
  app.add_flag("--print-config", o->print_config, "Print the embedded default configuration and exit");
  return [o]() -> int {
    if (o->print_config) {
      std::cout << coordinator::default_config_toml();
      return kExitOk;
    }
    const auto& stop = install_stop_signals();
    coordinator::CoordinatorOptions options;
    options.bind_override = "tcp://127.0.0.1:*";  // local workers only; any free port
    options.command = "local";
    options.keyless_workers = true;
    options.retry_failed = o->retry_failed;
    sim::Expected<std::unique_ptr<coordinator::Coordinator>> c = sim::Error{""};
    if (!o->resume.empty()) {
      c = coordinator::Coordinator::resume(o->resume, options);
    } else {
      std::string text = coordinator::default_config_toml();
      std::string name = "the embedded default configuration";
      if (!o->config.empty()) {
        auto file = storage::read_file(o->config);
        if (!file) return fail(file.error().message);
        text = *file;
        name = o->config;
      }
      if (!o->output.empty()) {
        auto overridden = coordinator::with_output(text, name, o->output);
        if (!overridden) return fail(overridden.error().message);
        text = std::move(overridden).value();
        name += " with --output";
      }
      c = coordinator::Coordinator::create(text, name, options);
    }
    if (!c) return fail(c.error());
    WorkerPool pool((*c)->endpoint(), o->workers, stop, (*c)->config().fail_worker_start);
    if (sim::Status s = pool.start(); !s) {
      return fail(fmt::format("{} (the run is planned; continue it with drapegen local --resume {})",
                              s.error().message, (*c)->manifest_path()));
    }
    const auto summary = (*c)->run(pool.halt());
    pool.finish();
    if (pool.exhausted() && summary.outcome == coordinator::RunOutcome::kStopped) {
      std::cerr << "drapegen local: error: no worker is left (the log above says how each ended); find the cause "
                   "before resuming\n";
    }
    const int code = report_run(summary, (*c)->manifest_path(), "local");
    if (summary.outcome == coordinator::RunOutcome::kComplete) {
      auto stats = coordinator::compute_stats((*c)->manifest_path(), {});
      if (!stats) return fail(stats.error());
      std::cout << coordinator::format_stats(*stats);
    }
    return code;
  };
}

}  // namespace drapegen::cli
