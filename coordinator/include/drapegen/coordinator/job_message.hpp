#pragma once
// The Job message of one attempt, built from the manifest's rows and the run's configuration: everything a worker
// needs to compute the job bit for bit (the coordinator sends it; benchmarks replay jobs with it).

#include <cstdint>
#include <string>

#include "drapegen/coordinator/run_config.hpp"
#include "drapegen/proto/codec.hpp"
#include "drapegen/storage/records.hpp"

namespace drapegen::coordinator {

/// Errors: an unreadable recipe. `source_mesh` is the source drape's PLY for a drape recipe (else empty).
[[nodiscard]] sim::Expected<proto::v1::Job> make_job_message(const RunConfig& config,
                                                             const storage::SampleRecord& sample,
                                                             const storage::JobRecord& job, int attempt,
                                                             std::string source_mesh);

/// The file name stem of a job's results: "sSSSSSS_kKK" (data/STEM.ply, data/STEM_oOO.exr).
[[nodiscard]] std::string result_stem(std::int64_t sample, int slot);

}  // namespace drapegen::coordinator
