#pragma once
// What a manifest holds (drapegen stats): job counts by state and failure reason, throughput per worker and overall,
// time per job, the sampled parameters against the measured fabrics, drape coefficient and fold distributions,
// storage used; as JSON, as text, and as SVG histograms.

#include <nlohmann/json.hpp>
#include <string>

#include "drapegen/sim/expected.hpp"

namespace drapegen::coordinator {

struct StatsOptions {
  /// The measured fabrics (fabrics618.csv); empty: the copy committed with the source (sampler/data), whose absence
  /// (an installed binary without the source) only drops the comparison. A file named here that cannot be read is
  /// an error.
  std::string fabrics_csv;
  /// Also write SVG histograms into this directory (created), from the same read of the manifest as the figures:
  /// drape_coefficient.svg, folds.svg, job_seconds.svg and one per parameter feature (run against measured
  /// fabrics); the statistics' "plots" lists the files. Empty: none.
  std::string plots_directory;
};

/// Reads the manifest (read-only; safe while a coordinator writes) and computes the statistics.
[[nodiscard]] sim::Expected<nlohmann::json> compute_stats(const std::string& manifest_path,
                                                          const StatsOptions& options);
/// A few lines a person can read.
[[nodiscard]] std::string format_stats(const nlohmann::json& stats);


}  // namespace drapegen::coordinator
