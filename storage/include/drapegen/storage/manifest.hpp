#pragma once
// The manifest writer: the coordinator's SQLite database of a run (docs/SERVICE.md, "Manifest schema"). WAL
// journal, synchronous=FULL, foreign keys on. Only the coordinator writes; everything else uses ManifestReader.
//
// Writes are grouped: begin() ... commit() around any number of record_* calls (the coordinator commits once per
// pass of its event loop). A crash before commit() loses the whole group and nothing else.

#include <memory>
#include <string>
#include <vector>

#include "drapegen/sim/expected.hpp"
#include "drapegen/storage/manifest_reader.hpp"
#include "drapegen/storage/records.hpp"

namespace drapegen::storage {

class Manifest {
 public:
  /// Creates the manifest of a new run with its whole plan, atomically: the database is built as `path + ".tmp"`,
  /// checkpointed, synced and renamed to `path`, so `path` either does not exist or holds the complete plan. Fails
  /// if `path` exists.
  [[nodiscard]] static sim::Expected<Manifest> create(const std::string& path, const RunRecord& run,
                                                      const std::vector<SampleRecord>& samples,
                                                      const std::vector<JobRecord>& jobs);
  /// Opens an existing manifest for writing (resume). Checks the schema version (1 .. kSchemaVersion); writes
  /// nothing until the caller does (an older version stays as it is until upgrade_schema()).
  [[nodiscard]] static sim::Expected<Manifest> open(const std::string& path);

  Manifest(Manifest&&) noexcept;
  Manifest& operator=(Manifest&&) noexcept;
  ~Manifest();

  /// Brings a manifest of an older schema version to kSchemaVersion in one transaction, its rows kept (no-op when
  /// current). Call it holding the run's output lock: a build of the older version then refuses the file.
  [[nodiscard]] sim::Status upgrade_schema();
  [[nodiscard]] int schema_version() const;

  [[nodiscard]] sim::Status begin();
  [[nodiscard]] sim::Status commit();
  /// Discards the open group (after an error).
  void rollback();
  [[nodiscard]] bool in_transaction() const;

  /// A done job: its result, its files and the job row (state done, attempts, worker, times).
  [[nodiscard]] sim::Status record_result(const JobRecord& job, const ResultRecord& result,
                                          const std::vector<FileRecord>& files);
  /// A failed attempt; with `final` the job becomes failed (job.failure_reason, attempts, worker, times).
  [[nodiscard]] sim::Status record_failure(const JobRecord& job, const FailureRecord& failure, bool final);
  /// Replaces a pending job's recipe (a kDrape job whose source failed falls back to sine or fold).
  [[nodiscard]] sim::Status update_recipe(std::int64_t job_id, const std::string& recipe_json);
  /// Every failed job pending again (its failures kept; its attempts count on); returns how many.
  [[nodiscard]] sim::Expected<std::int64_t> retry_failed();
  [[nodiscard]] sim::Status set_run_state(const std::string& state);
  [[nodiscard]] sim::Status set_endpoint(const std::string& endpoint);

  /// Reads through the writer's connection (sees its own uncommitted writes).
  [[nodiscard]] const ManifestReader& reader() const { return *reader_; }

  struct Impl;

 private:
  explicit Manifest(std::unique_ptr<Impl> impl, std::unique_ptr<ManifestReader> reader);
  std::unique_ptr<Impl> impl_;
  std::unique_ptr<ManifestReader> reader_;
};

}  // namespace drapegen::storage
