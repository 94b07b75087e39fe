#include "drapegen/storage/manifest.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sqlite3.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <stdexcept>

namespace drapegen::storage {
namespace {

class ManifestTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("drapegen_manifest_test_" + std::to_string(::getpid()) + "_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    path_ = (dir_ / "manifest.sqlite").string();
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  Manifest make(int jobs = 4) {
    RunRecord run;
    run.seed = ~0ULL;  // the largest seed survives the round trip
    run.config_toml = "seed = 1\n";
    run.code_version = "test";
    std::vector<SampleRecord> samples(2);
    samples[1].sample = 1;
    samples[1].alpha = {1, 2, 3};
    samples[1].beta = {-4, -5, -6};
    std::vector<JobRecord> list;
    for (int i = 0; i < jobs; ++i) {
      JobRecord j;
      j.id = i + 1;
      j.sample = i % 2;
      j.slot = i / 2;
      j.recipe_json = "{}";
      j.render_seed = 1000 + i;
      list.push_back(j);
    }
    auto m = Manifest::create(path_, run, samples, list);
    EXPECT_TRUE(m) << (m ? "" : m.error().message);
    return std::move(m).value();
  }

  std::filesystem::path dir_;
  std::string path_;
};

TEST_F(ManifestTest, CreatesThePlanAtomicallyAndReadsItBack) {
  { auto m = make(); }
  EXPECT_FALSE(std::filesystem::exists(path_ + ".tmp"));
  auto reader = ManifestReader::open(path_);
  ASSERT_TRUE(reader) << reader.error().message;
  EXPECT_EQ(reader->run()->seed, ~0ULL);
  EXPECT_EQ(reader->run()->total_jobs, 4);
  EXPECT_EQ(reader->run()->state, "running");
  ASSERT_EQ(reader->samples()->size(), 2u);
  EXPECT_EQ((*reader->samples())[1].beta[2], -6);
  ASSERT_EQ(reader->jobs()->size(), 4u);
  EXPECT_EQ((*reader->jobs())[3].render_seed, 1003u);
  EXPECT_EQ(*reader->integrity_check(), "ok");
  // The file is in WAL mode (stored in the database itself), and stays so once a writer opens it again.
  auto writer = Manifest::open(path_);
  ASSERT_TRUE(writer);
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path_.c_str(), &db), SQLITE_OK);
  sqlite3_stmt* st = nullptr;
  sqlite3_prepare_v2(db, "PRAGMA journal_mode", -1, &st, nullptr);
  ASSERT_EQ(sqlite3_step(st), SQLITE_ROW);
  EXPECT_STREQ(reinterpret_cast<const char*>(sqlite3_column_text(st, 0)), "wal");
  sqlite3_finalize(st);
  sqlite3_close(db);
  // A second create refuses to overwrite.
  const auto again = Manifest::create(path_, RunRecord{}, {}, {});
  ASSERT_FALSE(again);
  EXPECT_NE(again.error().message.find("--resume"), std::string::npos);
}

int open_descriptors() {
  int n = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator("/proc/self/fd")) ++n;
  return n;
}

TEST_F(ManifestTest, AFailedCreateLeavesNoFileAndNoOpenConnection) {
  std::vector<JobRecord> jobs(2);
  for (auto& j : jobs) {
    j.id = 7;  // twice: the plan's second insert fails with its statements alive
    j.recipe_json = "{}";
  }
  const int before = open_descriptors();
  const auto m = Manifest::create(path_, RunRecord{}, {SampleRecord{}}, jobs);
  ASSERT_FALSE(m);
  EXPECT_NE(m.error().message.find("UNIQUE"), std::string::npos) << m.error().message;
  EXPECT_EQ(open_descriptors(), before);  // the connection closed: no database or journal held
  EXPECT_TRUE(std::filesystem::is_empty(dir_));  // no manifest, no temporary, no journal
}

TEST_F(ManifestTest, ReadsAManifestInADirectoryItCannotWrite) {
  // Another user's finished run, or a read-only mount: SQLite cannot create the WAL database's -shm beside it. With
  // no -wal left (the coordinator closed it), the reader reads the file as it is instead of calling it no manifest.
  if (::geteuid() != 0) GTEST_SKIP() << "needs root, to read as another user (nobody)";
  { auto m = make(); }
  ASSERT_FALSE(std::filesystem::exists(path_ + "-wal"));
  namespace fs = std::filesystem;
  fs::permissions(dir_, fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec |
                            fs::perms::others_read | fs::perms::others_exec);
  fs::permissions(path_, fs::perms::owner_read | fs::perms::group_read | fs::perms::others_read);
  fs::permissions(dir_, fs::perms::owner_read | fs::perms::owner_exec | fs::perms::group_read |
                            fs::perms::group_exec | fs::perms::others_read | fs::perms::others_exec);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {  // as nobody: the directory and the file read-only to it
    if (::setgid(65534) != 0 || ::setuid(65534) != 0) ::_exit(2);
    auto reader = ManifestReader::open(path_);
    ::_exit(reader && reader->jobs() && reader->jobs()->size() == 4 ? 0 : 1);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  fs::permissions(dir_, fs::perms::owner_all);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "1: not read; 2: could not become nobody";
}

// A reader connected while the writer closes (drapegen stats, the training stage during a run) kept SQLite from
// copying the log into the database file: the .sqlite alone, copied elsewhere, read as a run with nothing done.
TEST_F(ManifestTest, ClosingPutsEveryCommitIntoTheFileThoughAReaderIsOpen) {
  std::optional<ManifestReader> open_reader;
  {
    auto m = make();
    auto r = ManifestReader::open(path_);
    ASSERT_TRUE(r) << r.error().message;
    open_reader.emplace(std::move(r).value());
    ASSERT_TRUE(m.begin());
    ASSERT_TRUE(m.set_run_state("complete"));
    ASSERT_TRUE(m.commit());
    ASSERT_EQ(open_reader->run()->state, "complete");
  }  // the writer closes; the reader stays connected
  const std::filesystem::path copy = dir_ / "copy";
  std::filesystem::create_directories(copy);
  std::filesystem::copy_file(path_, copy / "manifest.sqlite");  // the database file alone
  auto copied = ManifestReader::open((copy / "manifest.sqlite").string());
  ASSERT_TRUE(copied) << copied.error().message;
  EXPECT_EQ(copied->run()->state, "complete");
  std::error_code ec;
  EXPECT_EQ(std::filesystem::file_size(path_ + "-wal", ec), 0u) << ec.message();
}

// A manifest in a directory that may not be entered is an unreadable manifest (an I/O error), not "no manifest".
TEST_F(ManifestTest, AManifestThatCannotBeReachedIsNotCalledMissing) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root, to read as another user (nobody)";
  { auto m = make(); }
  std::filesystem::permissions(dir_, std::filesystem::perms::owner_all);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    if (::setgid(65534) != 0 || ::setuid(65534) != 0) ::_exit(2);
    auto reader = ManifestReader::open(path_);
    ::_exit(!reader && reader.error().io && reader.error().message.find("Permission denied") != std::string::npos ? 0
                                                                                                                : 1);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "1: not an I/O error naming the cause; 2: could not become nobody";
}

// A log that holds commits, in a directory this user cannot write (a live or killed run's copy): SQLite cannot read
// it and said only "unable to open database file"; the reader says why.
TEST_F(ManifestTest, ALogItCannotReadIsExplained) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root, to read as another user (nobody)";
  namespace fs = std::filesystem;
  const fs::path copy = dir_ / "copy";
  {
    auto m = make();
    ASSERT_TRUE(m.begin());
    ASSERT_TRUE(m.set_run_state("stopped"));
    ASSERT_TRUE(m.commit());
    fs::create_directories(copy);
    fs::copy_file(path_, copy / "manifest.sqlite");
    fs::copy_file(path_ + "-wal", copy / "manifest.sqlite-wal");  // the log, not its shared-memory file
  }
  ASSERT_GT(fs::file_size(copy / "manifest.sqlite-wal"), 0u);
  fs::permissions(dir_, fs::perms::owner_all | fs::perms::others_read | fs::perms::others_exec);
  fs::permissions(copy, fs::perms::owner_all | fs::perms::others_read | fs::perms::others_exec);
  const std::string path = (copy / "manifest.sqlite").string();
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    if (::setgid(65534) != 0 || ::setuid(65534) != 0) ::_exit(2);
    auto reader = ManifestReader::open(path);
    ::_exit(!reader && reader.error().message.find("the run is live or was not closed") != std::string::npos ? 0 : 1);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "1: not explained; 2: could not become nobody";
}

TEST_F(ManifestTest, RecordsEachJobExactlyOnce) {
  auto m = make();
  JobRecord job;
  job.id = 2;
  job.attempts = 1;
  job.worker = "w1";
  ResultRecord r;
  r.outcome = "converged";
  r.drape_coefficient = 0.61;
  std::vector<FileRecord> files{{0, "mesh", 0, "data/a.ply", "00", 10}, {0, "exr", 0, "data/a_o00.exr", "11", 20}};
  ASSERT_TRUE(m.begin());
  ASSERT_TRUE(m.record_result(job, r, files));
  // The same job again fails, and leaves the first record whole.
  const auto twice = m.record_result(job, r, {{0, "mesh", 0, "data/b.ply", "22", 5}});
  EXPECT_FALSE(twice);
  ASSERT_TRUE(m.commit());
  EXPECT_EQ(m.reader().results()->size(), 1u);
  EXPECT_EQ(m.reader().files()->size(), 2u);
  EXPECT_EQ((*m.reader().jobs())[1].state, JobState::kDone);
  // A failure of a done job is refused too.
  FailureRecord f{2, 2, "diverged", "x", "w1", 0.0};
  ASSERT_TRUE(m.begin());
  EXPECT_FALSE(m.record_failure(job, f, true));
  // Retried failures, then the final one.
  JobRecord j3;
  j3.id = 3;
  j3.attempts = 1;
  ASSERT_TRUE(m.record_failure(j3, {3, 1, "diverged", "nan", "w1", 1.0}, false));
  j3.attempts = 2;
  ASSERT_TRUE(m.record_failure(j3, {3, 2, "diverged", "nan", "w2", 2.0}, true));
  // An unknown reason violates the schema.
  JobRecord j4;
  j4.id = 4;
  EXPECT_FALSE(m.record_failure(j4, {4, 1, "bad_luck", "", "", 0.0}, false));
  ASSERT_TRUE(m.commit());
  EXPECT_EQ(m.reader().failures()->size(), 2u);
  const auto jobs = *m.reader().jobs();
  EXPECT_EQ(jobs[2].state, JobState::kFailed);
  EXPECT_EQ(jobs[2].attempts, 2);
  EXPECT_EQ(jobs[2].failure_reason, "diverged");
  EXPECT_EQ(jobs[3].state, JobState::kPending);
  EXPECT_EQ(*m.reader().integrity_check(), "ok");
}

// A run started by a build of schema version 1 (whose failures could not say "worker_error" or "unspecified"): read
// as it is; resumed, upgraded in place with its failures kept.
TEST_F(ManifestTest, AVersion1ManifestIsReadAndUpgradedOnResume) {
  {
    auto m = make();
    JobRecord j1;
    j1.id = 1;
    j1.attempts = 1;
    ASSERT_TRUE(m.begin());
    ASSERT_TRUE(m.record_failure(j1, {1, 1, "timeout", "slow", "w1", 5.0}, false));
    ASSERT_TRUE(m.commit());
  }
  // Version 1's failures table, as that build created it, holding the row.
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path_.c_str(), &db), SQLITE_OK);
  const char* to_version_1 = R"sql(
    DROP INDEX failures_by_job;
    DROP INDEX failures_by_reason;
    ALTER TABLE failures RENAME TO failures_new;
    CREATE TABLE failures (
      id      INTEGER PRIMARY KEY,
      job_id  INTEGER NOT NULL REFERENCES jobs (id),
      attempt INTEGER NOT NULL,
      reason  TEXT    NOT NULL CHECK (reason IN ('not_converged', 'diverged', 'self_intersection', 'render_error',
                                                 'worker_lost', 'timeout', 'invalid_job')),
      message TEXT    NOT NULL,
      worker  TEXT    NOT NULL,
      at      REAL    NOT NULL
    );
    CREATE INDEX failures_by_job ON failures (job_id);
    CREATE INDEX failures_by_reason ON failures (reason);
    INSERT INTO failures SELECT * FROM failures_new;
    DROP TABLE failures_new;
    UPDATE meta SET value = '1' WHERE key = 'schema_version';)sql";
  char* error = nullptr;
  ASSERT_EQ(sqlite3_exec(db, to_version_1, nullptr, nullptr, &error), SQLITE_OK) << error;
  sqlite3_close(db);
  auto schema_version = [&] {
    sqlite3* d = nullptr;
    sqlite3_open(path_.c_str(), &d);
    sqlite3_stmt* st = nullptr;
    sqlite3_prepare_v2(d, "SELECT value FROM meta WHERE key = 'schema_version'", -1, &st, nullptr);
    std::string v = sqlite3_step(st) == SQLITE_ROW ? reinterpret_cast<const char*>(sqlite3_column_text(st, 0)) : "";
    sqlite3_finalize(st);
    sqlite3_close(d);
    return v;
  };
  {
    auto reader = ManifestReader::open(path_);  // a reader leaves the file as it is
    ASSERT_TRUE(reader) << reader.error().message;
    ASSERT_EQ(reader->failures()->size(), 1u);
  }
  EXPECT_EQ(schema_version(), "1");
  {
    auto m = Manifest::open(path_);
    ASSERT_TRUE(m) << m.error().message;
    EXPECT_EQ(m->schema_version(), 1);
    EXPECT_EQ(schema_version(), "1");  // opening writes nothing: the caller upgrades once it holds the run's lock
    ASSERT_TRUE(m->upgrade_schema());
    EXPECT_EQ(m->schema_version(), kSchemaVersion);
    EXPECT_EQ(schema_version(), std::to_string(kSchemaVersion));
    JobRecord j2;
    j2.id = 2;
    j2.attempts = 1;
    ASSERT_TRUE(m->begin());
    ASSERT_TRUE(m->record_failure(j2, {2, 1, "worker_error", "scratch full", "w2", 6.0}, false));
    ASSERT_TRUE(m->record_failure(j2, {2, 2, "unspecified", "(reason 42) later", "w2", 7.0}, false));
    ASSERT_TRUE(m->commit());
    const auto failures = *m->reader().failures();
    ASSERT_EQ(failures.size(), 3u);
    EXPECT_EQ(failures[0].reason, "timeout");
    EXPECT_EQ(failures[0].message, "slow");
    EXPECT_EQ(failures[1].reason, "worker_error");
    EXPECT_EQ(*m->reader().integrity_check(), "ok");
  }
  auto again = Manifest::open(path_);
  ASSERT_TRUE(again) << again.error().message;
  EXPECT_EQ(again->schema_version(), kSchemaVersion);
  EXPECT_TRUE(again->upgrade_schema());  // nothing left to do
  EXPECT_EQ(again->reader().failures()->size(), 3u);
}

// What a snapshot sees (the last commit; the writer's own pass on its connection) and that its read transaction ends
// (a reader left in one would never see another commit). A commit between its table reads:
// OneSnapshotIsNotMovedByACommitWithinIt.
TEST_F(ManifestTest, SnapshotsSeeTheLastCommitAndLetTheNextOneIn) {
  auto m = make();
  auto reader = ManifestReader::open(path_);
  ASSERT_TRUE(reader);
  JobRecord job;
  job.id = 1;
  job.attempts = 1;
  ASSERT_TRUE(m.begin());
  ASSERT_TRUE(m.record_result(job, ResultRecord{}, {{0, "mesh", 0, "data/a.ply", "00", 10}}));
  // The writer sees its own pass whole (no second transaction on its connection); another reader, the last commit.
  auto own = m.reader().snapshot();
  ASSERT_TRUE(own) << own.error().message;
  EXPECT_EQ(own->results.size(), 1u);
  EXPECT_EQ(own->jobs[0].state, JobState::kDone);
  auto before = reader->snapshot();
  ASSERT_TRUE(before) << before.error().message;
  EXPECT_EQ(before->results.size(), 0u);
  EXPECT_EQ(before->jobs[0].state, JobState::kPending);
  EXPECT_EQ(before->run.total_jobs, 4);
  EXPECT_EQ(before->samples.size(), 2u);
  ASSERT_TRUE(m.commit());
  // The reader's transaction ended with its snapshot: the next one sees the commit.
  auto after = reader->snapshot();
  ASSERT_TRUE(after) << after.error().message;
  EXPECT_EQ(after->results.size(), 1u);
  EXPECT_EQ(after->files.size(), 1u);
  EXPECT_EQ(after->jobs[0].state, JobState::kDone);
  EXPECT_TRUE(after->failures.empty());
}

// A commit that lands while a reader is inside one snapshot: the reader's later queries still see the commit before
// it (a reader outside one sees it at once), and the snapshot's transaction ends with it, error or not.
TEST_F(ManifestTest, OneSnapshotIsNotMovedByACommitWithinIt) {
  auto m = make();
  auto reader = ManifestReader::open(path_);
  ASSERT_TRUE(reader);
  auto count_done = [&] {
    int done = 0;
    EXPECT_TRUE(reader->for_each_job([&](const JobRecord& j) { done += j.state == JobState::kDone; }));
    return done;
  };
  auto count_files = [&] {
    int files = 0;
    EXPECT_TRUE(reader->for_each_file([&](const FileRecord&) { ++files; }));
    return files;
  };
  auto record = [&](std::int64_t id) {
    JobRecord job;
    job.id = id;
    job.attempts = 1;
    ASSERT_TRUE(m.begin());
    ASSERT_TRUE(m.record_result(job, ResultRecord{}, {{0, "mesh", 0, fmt::format("data/{}.ply", id), "00", 10}}));
  };

  record(1);
  ASSERT_TRUE(reader->in_one_snapshot([&]() -> sim::Status {
    EXPECT_EQ(count_done(), 0);
    EXPECT_TRUE(m.commit());
    EXPECT_EQ(count_files(), 0);  // the commit is after this snapshot
    EXPECT_EQ(count_done(), 0);
    return {};
  }));
  EXPECT_EQ(count_files(), 1);  // and the next read sees it

  // Outside a snapshot each query sees the last commit: the same reads disagree.
  record(2);
  EXPECT_EQ(count_done(), 1);
  ASSERT_TRUE(m.commit());
  EXPECT_EQ(count_files(), 2);

  // An error from within is returned, and the transaction still ends.
  record(3);
  const sim::Status failed = reader->in_one_snapshot([&]() -> sim::Status {
    EXPECT_EQ(count_done(), 2);
    return sim::Error{"stop here"};
  });
  ASSERT_FALSE(failed);
  EXPECT_EQ(failed.error().message, "stop here");
  ASSERT_TRUE(m.commit());
  EXPECT_EQ(count_done(), 3);

  // A visitor that throws: the transaction ends with it, and the reader sees later commits.
  record(4);
  EXPECT_THROW((void)reader->in_one_snapshot([&]() -> sim::Status {
    return reader->for_each_job([](const JobRecord&) { throw std::runtime_error("visitor failed"); });
  }),
               std::runtime_error);
  ASSERT_TRUE(m.commit());
  EXPECT_EQ(count_done(), 4);

  // Nested: the inner snapshot reads in the outer one (it was "cannot start a transaction within a transaction").
  ASSERT_TRUE(reader->in_one_snapshot([&]() -> sim::Status {
    auto inner = reader->snapshot();
    EXPECT_TRUE(inner) << inner.error().message;
    return {};
  }));
}

TEST_F(ManifestTest, UncommittedGroupsVanish) {
  {
    auto m = make();
    ASSERT_TRUE(m.begin());
    JobRecord job;
    job.id = 1;
    ASSERT_TRUE(m.record_result(job, ResultRecord{}, {}));
    // destroyed without commit (as in a crash)
  }
  auto reader = ManifestReader::open(path_);
  ASSERT_TRUE(reader);
  EXPECT_EQ(reader->results()->size(), 0u);
  EXPECT_EQ((*reader->jobs())[0].state, JobState::kPending);
}

// SQLite rolls the whole transaction back after some errors (a full disk; here a trigger's RAISE(ROLLBACK)): the
// group's later writes are refused, not committed one by one outside it.
TEST_F(ManifestTest, AGroupSQLiteRolledBackTakesNoMoreWrites) {
  auto m = make();
  {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(path_.c_str(), &db), SQLITE_OK);
    ASSERT_EQ(sqlite3_exec(db, "CREATE TRIGGER no_results BEFORE INSERT ON results BEGIN "
                               "SELECT RAISE(ROLLBACK, 'disk full'); END",
                           nullptr, nullptr, nullptr),
              SQLITE_OK);
    sqlite3_close(db);
  }
  ASSERT_TRUE(m.begin());
  FailureRecord failure;
  failure.job_id = 2;
  failure.attempt = 1;
  failure.reason = "timeout";
  JobRecord job;
  job.id = 2;
  job.attempts = 1;
  ASSERT_TRUE(m.record_failure(job, failure, /*final=*/false));
  job.id = 1;
  ASSERT_FALSE(m.record_result(job, ResultRecord{}, {}));  // rolls the group back, job 2's failure with it
  failure.job_id = job.id = 3;
  const auto after = m.record_failure(job, failure, /*final=*/false);
  ASSERT_FALSE(after);
  EXPECT_NE(after.error().message.find("rolled back"), std::string::npos) << after.error().message;
  EXPECT_FALSE(m.commit());
  auto reader = ManifestReader::open(path_);
  ASSERT_TRUE(reader);
  EXPECT_TRUE(reader->failures()->empty());  // neither job 2's nor job 3's
}

TEST_F(ManifestTest, RefusesToStartOverALogLeftByAManifestThatIsGone) {
  // A run killed with committed pages still in its log, whose manifest the user then deletes to start over.
  { auto m = make(); }
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path_.c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db, "PRAGMA wal_autocheckpoint = 0; UPDATE runs SET state = 'stopped'", nullptr, nullptr,
                         nullptr),
            SQLITE_OK);
  const std::string wal = path_ + "-wal";
  ASSERT_GT(std::filesystem::file_size(wal), 0u);
  const auto saved = dir_ / "saved-wal";
  std::filesystem::copy_file(wal, saved);  // what a kill leaves; closing would check it into the database
  sqlite3_close(db);
  std::filesystem::remove(path_);
  std::filesystem::copy_file(saved, wal);
  const auto again = Manifest::create(path_, RunRecord{}, {}, {});
  ASSERT_FALSE(again);
  EXPECT_NE(again.error().message.find(wal + " is left from a manifest"), std::string::npos)
      << again.error().message;
  EXPECT_FALSE(again.error().io);  // the user's to remove, not a file system failure: a command exits 1, not 3
  // A directory that is not there: SQLite cannot open the file, the file system's failure (exit 3).
  const auto nowhere = Manifest::create((dir_ / "missing" / "manifest.sqlite").string(), RunRecord{}, {}, {});
  ASSERT_FALSE(nowhere);
  EXPECT_TRUE(nowhere.error().io) << nowhere.error().message;
  EXPECT_TRUE(std::filesystem::exists(wal));  // not ours to delete
  EXPECT_FALSE(std::filesystem::exists(path_));
  std::filesystem::remove(wal);
  { auto m = make(); }  // once it is removed, the run starts
  auto reader = ManifestReader::open(path_);
  ASSERT_TRUE(reader) << reader.error().message;
  EXPECT_EQ(reader->run()->state, "running");
}

TEST_F(ManifestTest, RefusesForeignFilesAndOtherSchemaVersions) {
  EXPECT_FALSE(ManifestReader::open((dir_ / "missing.sqlite").string()));
  sqlite3* db = nullptr;
  const std::string other = (dir_ / "other.sqlite").string();
  ASSERT_EQ(sqlite3_open(other.c_str(), &db), SQLITE_OK);
  sqlite3_exec(db, "CREATE TABLE t (x)", nullptr, nullptr, nullptr);
  sqlite3_close(db);
  auto foreign = ManifestReader::open(other);
  ASSERT_FALSE(foreign);
  EXPECT_NE(foreign.error().message.find("not a drapegen manifest"), std::string::npos);
  // Refused for writing, a file is left as it was (no WAL mode written into someone else's database, no empty file
  // turned into one).
  auto bytes = [](const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  };
  const std::string other_bytes = bytes(other);
  EXPECT_FALSE(Manifest::open(other));
  EXPECT_EQ(bytes(other), other_bytes);  // WAL mode would rewrite header bytes 18-19, not the size
  const std::string empty = (dir_ / "empty.sqlite").string();
  { std::ofstream touch(empty); }
  EXPECT_FALSE(Manifest::open(empty));
  EXPECT_EQ(std::filesystem::file_size(empty), 0u);
  { auto m = make(); }
  ASSERT_EQ(sqlite3_open(path_.c_str(), &db), SQLITE_OK);
  sqlite3_exec(db, "UPDATE meta SET value = '99' WHERE key = 'schema_version'", nullptr, nullptr, nullptr);
  sqlite3_close(db);
  auto newer = Manifest::open(path_);
  ASSERT_FALSE(newer);
  EXPECT_NE(newer.error().message.find("schema version 99"), std::string::npos);
}

}  // namespace
}  // namespace drapegen::storage
