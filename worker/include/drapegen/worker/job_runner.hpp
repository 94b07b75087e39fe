#pragma once
// One job, computed: the drape simulated from its (parameters, recipe, seeds), its data points rendered and encoded
// as OpenEXR in memory, and the answer to the coordinator (a Result or a Failure with its reason). A job to simulate
// (JOB_MODE_SIMULATE, the gap diagnosis's drapes) returns the drape alone.

#include <map>
#include <memory>
#include <optional>
#include <string>

#include "drapegen/proto/codec.hpp"
#include "drapegen/renderer/renderer.hpp"
#include "drapegen/sim/drape.hpp"

namespace drapegen::worker {

/// The simulator's configuration of a job (what `drapegen simulate` would run). Errors: invalid parameters or
/// recipe. A kDrape recipe's source mesh is read from `source_mesh_path`.
[[nodiscard]] sim::Expected<sim::DrapeConfig> drape_config(const proto::v1::JobSpec& spec,
                                                           const std::string& source_mesh_path);

class JobRunner {
 public:
  /// `scratch_dir` holds the worker's temporary files (a drape job's source mesh and its PLY on the way to bytes);
  /// it is local to the worker, never shared with the coordinator.
  explicit JobRunner(std::string scratch_dir);
  JobRunner(JobRunner&&) noexcept;
  JobRunner& operator=(JobRunner&&) noexcept;
  ~JobRunner();

  /// Computes one attempt. Never throws: any error becomes a Failure envelope with its reason.
  [[nodiscard]] proto::v1::Envelope run(const proto::v1::Job& job);

 private:
  proto::v1::Envelope compute(const proto::v1::Job& job);
  /// JOB_MODE_SIMULATE: the drape of the job's Simulation, returned whatever its solve's outcome (a Failure only where
  /// it cannot be built).
  proto::v1::Envelope simulate(const proto::v1::Job& job);
  std::string scratch_;
  /// By JobSpec.renderer name, created on first use in the computing thread (an OSMesa context belongs to it).
  std::map<std::string, std::unique_ptr<renderer::Renderer>> renderers_;
};

}  // namespace drapegen::worker
