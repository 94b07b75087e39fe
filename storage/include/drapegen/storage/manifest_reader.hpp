#pragma once
// The stable read interface of a manifest, for statistics and the training stage. Opens the database read-only
// (any number of readers may run while the coordinator writes; WAL gives each query, and each snapshot(), a consistent
// view of one commit).

#include <memory>
#include <string>
#include <vector>

#include "drapegen/sim/expected.hpp"
#include "drapegen/storage/records.hpp"

namespace drapegen::storage {

/// Every table of a manifest as of one commit.
struct ManifestSnapshot {
  RunRecord run;
  std::vector<SampleRecord> samples;
  std::vector<JobRecord> jobs;
  std::vector<ResultRecord> results;
  std::vector<FileRecord> files;
  std::vector<FailureRecord> failures;
};

class ManifestReader {
 public:
  /// Opens `path` read-only. Errors: missing file, not SQLite, not a drapegen manifest, a schema version newer than
  /// this build's.
  [[nodiscard]] static sim::Expected<ManifestReader> open(const std::string& path);

  ManifestReader(ManifestReader&&) noexcept;
  ManifestReader& operator=(ManifestReader&&) noexcept;
  ~ManifestReader();

  [[nodiscard]] sim::Expected<RunRecord> run() const;
  [[nodiscard]] sim::Expected<std::vector<SampleRecord>> samples() const;
  [[nodiscard]] sim::Expected<std::vector<JobRecord>> jobs() const;
  [[nodiscard]] sim::Expected<std::vector<ResultRecord>> results() const;
  [[nodiscard]] sim::Expected<std::vector<FileRecord>> files() const;
  [[nodiscard]] sim::Expected<std::vector<FailureRecord>> failures() const;
  /// All of the above in one read transaction: while a coordinator commits, the separate calls can each see another
  /// commit (more jobs done than results read), the snapshot cannot.
  [[nodiscard]] sim::Expected<ManifestSnapshot> snapshot() const;
  /// `PRAGMA integrity_check`: "ok" or SQLite's findings.
  [[nodiscard]] sim::Expected<std::string> integrity_check() const;
  /// The directory holding the manifest (file paths are relative to it).
  [[nodiscard]] const std::string& directory() const { return directory_; }

  struct Impl;

 private:
  friend class Manifest;
  explicit ManifestReader(std::unique_ptr<Impl> impl, std::string directory);
  std::unique_ptr<Impl> impl_;
  std::string directory_;
};

}  // namespace drapegen::storage
