// drapegen worker: computes jobs for a coordinator (docs/SERVICE.md, "Worker").
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "drapegen/coordinator/logging.hpp"
#include "drapegen/worker/worker.hpp"
#include "failure.hpp"
#include "signals.hpp"

namespace drapegen::cli {

Runner add_worker_command(CLI::App& app) {
  auto o = std::make_shared<worker::WorkerOptions>();
  app.add_option("--connect", o->endpoint, "The coordinator's endpoint, e.g. tcp://HOST:PORT")->required();
  app.add_option("--name", o->name, "Name in logs and the manifest (default HOST:PID)");
  app.add_option("--heartbeat-ms", o->heartbeat_ms, "Heartbeat interval, ms")
      ->check(CLI::Range(10, 600000))
      ->capture_default_str();
  app.add_option("--liveness", o->liveness, "Reconnect after this many silent coordinator intervals")
      ->check(CLI::Range(2, 1000))
      ->capture_default_str();
  app.add_option("--backoff-max-ms", o->backoff_max_ms, "Longest reconnect delay, ms (exponential back-off)")
      ->check(CLI::Range(10, 3600000))
      ->capture_default_str();
  app.add_option("--give-up", o->give_up_s,
                 "Exit with an error after this many seconds without a coordinator that accepts this worker (0: "
                 "never); checked when a connection is dropped (after --liveness of the coordinator's heartbeat "
                 "intervals of silence), so the exit can come that much later, plus up to --backoff-max-ms")
      ->check(CLI::Range(0.0, 1e9))
      ->capture_default_str();
  app.add_option("--server-key", o->server_key, "CurveZMQ: the coordinator's public key (Z85, or a .pub file)");
  app.add_option("--key", o->key_file, "CurveZMQ: this worker's secret key file (drapegen keygen)");
  auto level = std::make_shared<std::string>("info");
  app.add_option("--log-level", *level, "Log level: debug, info, warn, error")
      ->check(CLI::IsMember({"debug", "info", "warn", "error"}))
      ->capture_default_str();
  return [o, level]() -> int {
    // CLI::Range lets NaN through (no comparison with it is true): a worker that never gives up.
    if (!std::isfinite(o->give_up_s)) return Failure{"worker"}("--give-up: must be a number of seconds");
    coordinator::logger()->set_level(spdlog::level::from_str(*level));
    const auto& stop = install_stop_signals();
    const auto end = worker::run_worker(*o, stop);
    // 0: the coordinator said the run is over; 4: stopped by SIGINT/SIGTERM (drapegen local does not restart it);
    // 5: the coordinator said the run stopped before its end (a Kubernetes Job restarts it, to serve the resumption).
    int code = kExitStopped;
    if (!end) {
      code = Failure{"worker"}(end.error().message);
    } else if (!stop.load() && *end == worker::WorkerEnd::kRunOver) {
      code = kExitOk;
    } else if (!stop.load() && *end == worker::WorkerEnd::kRunStopped) {
      code = kExitRunStopped;
    }
    // A computation still running cannot be interrupted: leave without waiting for it.
    std::fflush(stdout);
    std::fflush(stderr);
    std::_Exit(code);
  };
}

}  // namespace drapegen::cli
