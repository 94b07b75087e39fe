#pragma once
// The stable read interface of a manifest, for statistics and the training stage. Opens the database read-only
// (any number of readers may run while the coordinator writes; WAL gives each query, and each snapshot(), a consistent
// view of one commit).

#include <functional>
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

  /// Each row of a table, one at a time and in the order the vectors below hold them, none kept: a reader of a large
  /// run's manifest (millions of file rows) needs memory for what it keeps of them only.
  template <class Row>
  using Visitor = std::function<void(const Row&)>;
  [[nodiscard]] sim::Status for_each_sample(const Visitor<SampleRecord>& visit) const;
  [[nodiscard]] sim::Status for_each_job(const Visitor<JobRecord>& visit) const;
  [[nodiscard]] sim::Status for_each_result(const Visitor<ResultRecord>& visit) const;
  [[nodiscard]] sim::Status for_each_file(const Visitor<FileRecord>& visit) const;
  [[nodiscard]] sim::Status for_each_failure(const Visitor<FailureRecord>& visit) const;
  /// Runs `read` (calls of this reader) in one read transaction: every query in it sees the same commit, however
  /// many a coordinator makes meanwhile (the writer's own view, Manifest::reader, sees the writer's state, its pass
  /// included). What `read` returns is returned; the transaction ends however `read` ends, by an exception too. A
  /// snapshot within one (snapshot(), in_one_snapshot) reads in the outer one.
  [[nodiscard]] sim::Status in_one_snapshot(const std::function<sim::Status()>& read) const;

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
