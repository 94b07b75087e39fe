#pragma once
// Drapes computed by a fleet of workers for a caller that needs them one at a time on several threads (the gap
// diagnosis's refits; docs/DIAGNOSIS.md, "Refits on workers"). The fleet binds a ZeroMQ ROUTER socket and speaks the
// coordinator's side of the worker protocol (docs/SERVICE.md): `drapegen worker --connect ENDPOINT` processes, on this
// machine or others, register, take one JOB_MODE_SIMULATE job at a time, heartbeat while they compute, and send the
// drape back. A worker that goes silent beyond its liveness (or registers again) loses its drape to the next free
// worker, and so does one that does not name its drape in its heartbeats two intervals after it was sent (it could
// not read the job; it gets no more). Nothing is written to disk and there is no manifest: a caller that stops loses
// only drapes in flight. As the coordinator, it binds an address other machines can reach only with CurveZMQ on.

#include <cstdint>
#include <memory>
#include <string>

#include "drapegen/sim/drape.hpp"
#include "drapegen/sim/expected.hpp"

namespace drapegen::coordinator {

struct FleetOptions {
  /// "*" as the port: any free one (endpoint() tells which). An address other machines can reach needs CurveZMQ.
  std::string bind = "tcp://127.0.0.1:*";
  /// CurveZMQ (both or neither): this side's secret key file and the workers' public keys it admits (drapegen keygen
  /// makes them; the workers connect with --server-key and --key), as `drapegen run` takes them.
  std::string server_secret_key;
  std::string authorized_keys;
  int heartbeat_ms = 1000;                 // this side's heartbeat interval
  int liveness = 5;                        // a worker silent for liveness x its interval is lost
  int max_attempts = 3;                    // a drape whose worker is lost this many times fails
  /// A drape fails when no worker that takes drapes has been connected for this long while it waited (none came,
  /// all left, or those left do not compute what they are sent).
  double wait_s = 600.0;
};

class SimulationFleet {
 public:
  /// Binds and starts serving (on a thread of its own). Errors: the endpoint cannot be bound, or is not a loopback
  /// one and CurveZMQ is off; unreadable keys; invalid options.
  [[nodiscard]] static sim::Expected<std::unique_ptr<SimulationFleet>> start(const FleetOptions& options);
  /// Tells the connected workers to shut down and stops serving; drapes still waiting fail.
  ~SimulationFleet();
  SimulationFleet(const SimulationFleet&) = delete;
  SimulationFleet& operator=(const SimulationFleet&) = delete;

  /// The bound endpoint, with the real port.
  [[nodiscard]] const std::string& endpoint() const;
  /// The drape of `config`, computed by the next free worker (the same drape, bit for bit, as a local solve where the
  /// worker runs the same build on the same BLAS kernels). Blocks; callable from any number of threads at once.
  /// Errors: a config the wire form cannot carry (proto/simulation.hpp), the worker's failure to build it, lost by
  /// max_attempts workers, no worker for wait_s, or the fleet stopping.
  [[nodiscard]] sim::Expected<sim::DrapeResult> simulate(const sim::DrapeConfig& config);
  /// Waits until at least `count` workers are registered or `timeout_s` passes; returns how many are.
  int wait_for_workers(int count, double timeout_s);

  struct Counters {
    std::int64_t simulated = 0;      // drapes returned
    std::int64_t lost_attempts = 0;  // attempts lost with their worker (re-queued or failed)
    std::int64_t rejected = 0;       // messages dropped (undecodable, stale, unknown)
    int workers = 0;                 // registered now
    int workers_seen = 0;            // distinct workers (by name) registered since the start
  };
  [[nodiscard]] Counters counters() const;

  struct Impl;

 private:
  explicit SimulationFleet(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace drapegen::coordinator
