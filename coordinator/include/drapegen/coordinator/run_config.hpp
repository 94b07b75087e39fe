#pragma once
// The configuration of a generation run (a TOML file; every key is documented in docs/SERVICE.md, "Configuration").

#include <cstdint>
#include <string>
#include <vector>

#include "drapegen/sim/expected.hpp"

namespace drapegen::coordinator {

struct RunConfig {
  // What to generate.
  std::uint64_t seed = 0;
  int samples = 6000;            // parameter vectors
  int states_per_sample = 8;     // initial states per vector
  int orientations = 12;         // data points (specimen orientations, 4 views each) per drape
  int resolution = 100;          // vertices per side of the 300 mm specimen
  std::string noise = "kinect";  // kinect | none
  std::string renderer = "osmesa";  // osmesa | software (docs/RENDERER.md)
  double density = 300.0;        // g/m^2 the sampled moduli are simulated at
  std::string bending_model = "dihedral";  // dihedral (paper Eq. 1-3, per hinge) | triangle (per-triangle curvature)
  std::string output = "drapegen-run";  // output directory (manifest.sqlite, data/)
  std::string model;             // VAE model file; empty: the one committed with the source
  // [recipes]
  double weight_sine = 1.0, weight_fold = 1.0, weight_drape = 1.0;
  double max_drift_mm = 3.0;
  // [solver]
  int max_iterations = 600;
  double tolerance = 1e-3;
  int coarse_start_resolution = 25;
  int max_self_intersections = 0;
  // [network]
  std::string bind = "tcp://127.0.0.1:5555";
  int heartbeat_ms = 1000;
  int liveness = 5;
  double lease_s = 900.0;
  // [security]
  bool curve = false;               // refuse to bind without CurveZMQ keys, loopback too (keys turn it on anywhere)
  std::string server_secret_key;    // the coordinator's secret key file (drapegen keygen)
  std::string authorized_keys;      // worker public keys, one per line
  // [retry]
  int max_attempts = 3;
  // [progress]
  double progress_interval_s = 10.0;
  // [testing]
  std::string mode = "drape";    // drape | noop
  std::vector<std::int64_t> poison_samples;  // these samples' jobs run in poison mode (diverge)
  int fail_worker_start = -1;  // drapegen local: the worker of this index cannot start (-1: none)
};

/// What is wrong with a ZeroMQ endpoint to bind or connect ("" if nothing): tcp://HOST:PORT with PORT 1 .. 65535 or
/// * (any free port), or ipc://PATH. (ZeroMQ itself took port 70000 as 4464, its value modulo 65536.)
[[nodiscard]] std::string endpoint_problem(const std::string& endpoint);

/// Parses and validates a TOML configuration. Unknown keys, wrong types and out-of-range values are errors that
/// name the key, e.g. "run.toml: samples: must be between 1 and 10000000".
[[nodiscard]] sim::Expected<RunConfig> parse_run_config(const std::string& toml_text, const std::string& source_name);

/// The checks a new run's configuration must also pass (not a stored one that an earlier build planned, which a resume
/// reads back): at most 2,000,000 jobs (the plan is built in memory), a coarse start of 0 or at least 3, a bind
/// endpoint with a valid port. Errors name the key, as parse_run_config's.
[[nodiscard]] sim::Status check_new_run(const RunConfig& config, const std::string& source_name);

/// The configuration with its top-level `output` set to `output` (any characters; the file's own, if any, replaced),
/// as TOML text again (comments and layout are not kept). Errors: the text does not parse.
[[nodiscard]] sim::Expected<std::string> with_output(const std::string& toml_text, const std::string& source_name,
                                                     const std::string& output);

/// The embedded default configuration of `drapegen local`: a small run with coarse meshes (about a minute on two
/// cores with two workers).
[[nodiscard]] const std::string& default_config_toml();

}  // namespace drapegen::coordinator
