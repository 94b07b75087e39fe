#pragma once
// The coordinator of a generation run (docs/SERVICE.md): plans the run (or resumes it from its manifest), serves its
// jobs to workers over a ZeroMQ ROUTER socket with heartbeats both ways and leases, writes every result atomically
// (files first, then the manifest transaction) and stops cleanly on request.

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "drapegen/coordinator/run_config.hpp"
#include "drapegen/sim/expected.hpp"

namespace drapegen::coordinator {

struct CoordinatorOptions {
  /// Bind here instead of the configured (or, on resume, the recorded) endpoint.
  std::string bind_override;
  /// Progress: a self-updating line on a terminal, or plain log lines; "auto" decides by isatty(stderr).
  enum class Progress { kAuto, kTerminal, kLog, kOff } progress = Progress::kAuto;
  /// CurveZMQ keys instead of the configuration's [security] files (deployment, not part of the run: a resumed run
  /// may use other keys).
  std::string server_secret_key;
  std::string authorized_keys;
  /// Also write the bound endpoint to this file (besides OUTPUT/endpoint).
  std::string endpoint_file;
  /// After the run completes, keep answering workers with Shutdown for this long (so reconnecting ones exit too).
  int shutdown_linger_ms = 1000;
  /// The drapegen command the coordinator runs under ("run" or "local"), named in the hints it gives.
  std::string command = "run";
  /// Its workers connect without CurveZMQ keys (drapegen local's own): CurveZMQ keys in the configuration, or
  /// `security.curve = true`, would lock them out, so they are refused at start.
  bool keyless_workers = false;
  /// Resume only: failed jobs are pending again, each with retry.max_attempts more attempts (after a cause outside
  /// the job is fixed: a broken node, a preemption by an older worker build that counted it).
  bool retry_failed = false;
};

enum class RunOutcome {
  kComplete,      // every job is done or failed
  kStopped,       // stop requested (SIGINT/SIGTERM); resume with --resume
  kStorageError,  // a result or the manifest could not be written; fix the cause, then resume
};

struct RunSummary {
  RunOutcome outcome = RunOutcome::kComplete;
  std::string message;               // the storage error, for kStorageError
  std::int64_t total = 0, done = 0, failed = 0;
  std::int64_t recorded_this_session = 0;
  std::int64_t rejected_messages = 0;  // undecodable, wrong version, stale or unknown results, ...
  double seconds = 0.0;
};

class Coordinator {
 public:
  /// A new run: parses and validates the configuration, plans it with the sampler, creates `output/manifest.sqlite`
  /// (atomically, with the whole plan) and binds. Fails if the manifest exists.
  [[nodiscard]] static sim::Expected<std::unique_ptr<Coordinator>> create(const std::string& config_text,
                                                                          const std::string& config_name,
                                                                          const CoordinatorOptions& options = {});
  /// Resumes the run of `manifest_path`: its stored configuration and plan, files not in the manifest removed,
  /// unfinished jobs pending again (failed ones too with `options.retry_failed`); binds the recorded endpoint if it
  /// can.
  [[nodiscard]] static sim::Expected<std::unique_ptr<Coordinator>> resume(const std::string& manifest_path,
                                                                          const CoordinatorOptions& options = {});
  ~Coordinator();

  /// The bound endpoint (with the real port when the configuration said "*").
  [[nodiscard]] const std::string& endpoint() const;
  [[nodiscard]] const std::string& manifest_path() const;
  [[nodiscard]] const RunConfig& config() const;

  /// The event loop: returns when the run is complete, `stop` becomes true, or a write fails.
  [[nodiscard]] RunSummary run(const std::atomic<bool>& stop);

  struct Impl;

 private:
  explicit Coordinator(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace drapegen::coordinator
