#pragma once
// A worker process's main loop (docs/SERVICE.md, "Worker"): connects a DEALER socket to the coordinator, registers,
// computes leased jobs on a separate thread while it keeps heartbeating, reconnects with exponential back-off when
// the coordinator goes silent (re-registering with a restarted one), and returns when told to shut down.

#include <atomic>
#include <string>

#include "drapegen/sim/expected.hpp"

namespace drapegen::worker {

struct WorkerOptions {
  std::string endpoint;          // e.g. tcp://127.0.0.1:5555
  std::string name;              // for logs and the manifest; default "HOST:PID"
  int heartbeat_ms = 1000;       // this worker's heartbeat interval
  int liveness = 5;              // coordinator silent for liveness x its interval: reconnect
  int backoff_initial_ms = 250;  // first reconnect delay (at most backoff_max_ms), doubled up to backoff_max_ms
  int backoff_max_ms = 8000;
  double give_up_s = 0.0;        // > 0: fail after this long without hearing from a coordinator
  std::string scratch_dir;       // temporary files; default a fresh directory under the system temp dir
  std::string server_key;        // CurveZMQ: the coordinator's public key (Z85 or a file); empty: plain TCP
  std::string key_file;          // CurveZMQ: this worker's secret key file (its public key must be authorised)
};

/// Why a worker returned.
enum class WorkerEnd {
  kRunOver,     // the coordinator said the run is over
  kRunStopped,  // the coordinator said the run stopped before its end (it will be resumed)
  kStopped,     // `stop` became true (SIGINT/SIGTERM)
};

/// Runs until the coordinator sends Shutdown, `stop` becomes true, or give_up_s passes without a coordinator (an
/// error). On `stop` it tells the coordinator it leaves (Leave), naming the job it holds, which is re-queued without
/// costing an attempt. A job still computing when the worker returns is abandoned; callers should exit the process
/// promptly (the computing thread cannot be interrupted).
[[nodiscard]] sim::Expected<WorkerEnd> run_worker(const WorkerOptions& options, const std::atomic<bool>& stop);

}  // namespace drapegen::worker
