#pragma once
// The rows of the manifest (docs/SERVICE.md, "Manifest schema") as plain values: what the coordinator writes and
// what readers (statistics, the training stage) get back.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace drapegen::storage {

/// The manifest schema this build writes (meta.schema_version). It reads every version from 1; opening an older
/// manifest for writing (a resumed run) upgrades it.
inline constexpr int kSchemaVersion = 2;

enum class JobState { kPending, kDone, kFailed };
[[nodiscard]] std::string_view to_string(JobState state);
[[nodiscard]] std::optional<JobState> parse_job_state(std::string_view text);

/// One run (one manifest holds one run).
struct RunRecord {
  std::int64_t id = 1;
  double created_at = 0.0;     // unix seconds
  std::uint64_t seed = 0;
  std::string config_toml;     // the configuration as given (resume re-reads it from here)
  std::string code_version;    // build id of the drapegen that planned the run (`drapegen --version`)
  std::int64_t total_jobs = 0;
  std::string state = "running";  // running, stopped, complete
  std::string endpoint;        // the coordinator's bound endpoint (resume binds it again)
};

/// One parameter vector of the run (at the run's density, paper units).
struct SampleRecord {
  std::int64_t sample = 0;
  std::array<double, 3> alpha{};  // warp, bias, weft; g*mm^2/s^2
  std::array<double, 3> beta{};   // g*mm^3/s^2
  double density_g_per_m2 = 300.0;
};

/// One drape to compute: (parameter vector, initial-state recipe, seeds) describe it completely.
struct JobRecord {
  std::int64_t id = 0;
  std::int64_t sample = 0;
  int slot = 0;
  std::string recipe_json;      // sampler::to_json(InitialStateRecipe)
  std::uint64_t render_seed = 0;
  std::string mode = "drape";   // drape, noop, poison
  JobState state = JobState::kPending;
  int attempts = 0;             // attempts that ended (result or failure) and were recorded
  std::string worker;           // worker of the recorded outcome
  std::string failure_reason;   // failed jobs: the taxonomy reason of the last attempt
  double started_at = 0.0;      // unix seconds: lease of the recorded attempt
  double finished_at = 0.0;
};

/// The outcome of a done job.
struct ResultRecord {
  std::int64_t job_id = 0;
  std::string outcome;          // sim::SolveOutcome as text
  int iterations = 0;
  int coarse_iterations = 0;
  double residual = 0.0;
  double energy = 0.0;
  double drape_coefficient = 0.0;
  int folds = 0;
  int self_intersections = 0;
  double sim_seconds = 0.0;
  double render_seconds = 0.0;
  std::int64_t bytes = 0;       // all files of the job
};

/// One file of a done job, relative to the manifest's directory.
struct FileRecord {
  std::int64_t job_id = 0;
  std::string kind;             // "mesh" (PLY) or "exr" (one data point)
  int index = 0;                // exr: orientation index; mesh: 0
  std::string path;             // relative to the manifest's directory
  std::string sha256;           // lowercase hex of the file's bytes
  std::int64_t bytes = 0;
};

/// One failed attempt (every attempt that failed, also those retried).
struct FailureRecord {
  std::int64_t job_id = 0;
  int attempt = 0;
  std::string reason;           // not_converged, diverged, self_intersection, render_error, worker_lost, timeout,
                                // invalid_job, worker_error, unspecified (none given, or unknown to this build)
  std::string message;
  std::string worker;
  double at = 0.0;              // unix seconds
};

}  // namespace drapegen::storage
