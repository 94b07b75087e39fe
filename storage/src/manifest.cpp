#include "drapegen/storage/manifest.hpp"

#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fmt/format.h>
#include <unistd.h>

#include "drapegen/storage/atomic_file.hpp"
#include "schema.hpp"
#include "sqlite.hpp"

namespace drapegen::storage {

using detail::exec;
using detail::Statement;

std::string_view to_string(JobState state) {
  switch (state) {
    case JobState::kPending: return "pending";
    case JobState::kDone: return "done";
    case JobState::kFailed: return "failed";
  }
  return "pending";
}

std::optional<JobState> parse_job_state(std::string_view text) {
  if (text == "pending") return JobState::kPending;
  if (text == "done") return JobState::kDone;
  if (text == "failed") return JobState::kFailed;
  return std::nullopt;
}

namespace {

std::string u64_text(std::uint64_t v) { return std::to_string(v); }
std::uint64_t parse_u64(const std::string& s) {
  std::uint64_t v = 0;
  std::from_chars(s.data(), s.data() + s.size(), v);
  return v;
}

sim::Status sqlite_error(sqlite3* db, const std::string& what) {
  return sim::Error{fmt::format("manifest: {}: {}", what, db ? sqlite3_errmsg(db) : "out of memory"),
                    detail::file_system_error(db)};
}

/// Connection settings of every connection (writer and readers); they write nothing to the file.
sim::Status configure(sqlite3* db) {
  sqlite3_busy_timeout(db, 10000);
  return exec(db, "PRAGMA foreign_keys = ON");
}

/// The writer's settings, applied once the file is known to be a manifest (WAL mode is written into the file).
sim::Status configure_writer(sqlite3* db) {
  if (sim::Status s = exec(db, "PRAGMA journal_mode = WAL"); !s) return s;
  return exec(db, "PRAGMA synchronous = FULL");
}

/// The error for a path that is not a file: a run's output directory points to the manifest inside it.
sim::Error no_manifest_at(const std::string& path) {
  const auto inside = std::filesystem::path(path) / "manifest.sqlite";
  std::error_code ec;
  if (std::filesystem::is_regular_file(inside, ec)) {
    return sim::Error{fmt::format("no manifest at {}: a directory; the run's manifest is {}", path, inside.string())};
  }
  return sim::Error{fmt::format("no manifest at {}", path)};
}

/// The manifest's schema version (1 .. kSchemaVersion), or why the file is not a manifest this build reads.
sim::Expected<int> check_schema(sqlite3* db, const std::string& path) {
  Statement st(db, "SELECT value FROM meta WHERE key = 'schema_version'");
  // The first read of the file: where it fails, the file system may be the cause rather than the file.
  if (!st.ok() && detail::file_system_error(db))
    return sim::Error{fmt::format("cannot read manifest {}: {}", path, st.prepare_error()), /*io=*/true};
  if (!st.ok()) return sim::Error{fmt::format("{} is not a drapegen manifest ({})", path, st.prepare_error())};
  if (st.step() != SQLITE_ROW)
    return sim::Error{fmt::format("{} is not a drapegen manifest (no schema version)", path)};
  const std::string version = st.text(0);
  for (int v = 1; v <= kSchemaVersion; ++v) {
    if (version == std::to_string(v)) return v;
  }
  return sim::Error{fmt::format("{} has manifest schema version {}; this build reads versions 1 to {}", path, version,
                                kSchemaVersion)};
}

/// Brings a manifest of an older schema version to kSchemaVersion, in one transaction (all or nothing). Version 1
/// is the only older one.
sim::Status upgrade_tables(sqlite3* db, int version, const std::string& path) {
  if (version == kSchemaVersion) return {};
  if (sim::Status s = exec(db, "BEGIN IMMEDIATE"); !s) return s;
  sim::Status s = exec(db, detail::kUpgradeFrom1SetAsideSql);
  if (s) s = exec(db, detail::kFailuresSql);
  if (s) s = exec(db, detail::kUpgradeFrom1RefillSql);
  if (s) s = exec(db, "COMMIT");
  if (!s) {
    (void)exec(db, "ROLLBACK");
    return sim::Error{fmt::format("cannot upgrade manifest {} from schema version {}: {}", path, version,
                                  s.error().message),
                      s.error().io};
  }
  return {};
}

sim::Expected<sqlite3*> open_db(const std::string& path, int flags) {
  sqlite3* db = nullptr;
  if (sqlite3_open_v2(path.c_str(), &db, flags | SQLITE_OPEN_NOMUTEX, nullptr) != SQLITE_OK) {
    std::string message = db ? sqlite3_errmsg(db) : "out of memory";
    const bool io = detail::file_system_error(db);
    sqlite3_close(db);
    return sim::Error{fmt::format("cannot open manifest {}: {}", path, message), io};
  }
  sqlite3_extended_result_codes(db, 1);
  return db;
}

std::string directory_of(const std::string& path) {
  auto dir = std::filesystem::path(path).parent_path();
  return dir.empty() ? std::string(".") : dir.string();
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------------
// Reader

struct ManifestReader::Impl {
  sqlite3* db = nullptr;
  bool owns = false;
  ~Impl() {
    if (owns) sqlite3_close(db);
  }
};

ManifestReader::ManifestReader(std::unique_ptr<Impl> impl, std::string directory)
    : impl_(std::move(impl)), directory_(std::move(directory)) {}
ManifestReader::ManifestReader(ManifestReader&&) noexcept = default;
ManifestReader& ManifestReader::operator=(ManifestReader&&) noexcept = default;
ManifestReader::~ManifestReader() = default;

namespace {

/// SQLite's URI for reading `path` as an immutable file: no -shm to create, no lock to take.
std::string immutable_uri(const std::string& path) {
  std::error_code ec;
  const std::filesystem::path absolute = std::filesystem::absolute(path, ec);
  std::string uri = "file://";  // an empty authority, then the absolute path ("//host/x" would name a host)
  for (const char c : (ec ? std::filesystem::path(path) : absolute).string()) {
    if (c == '%' || c == '?' || c == '#') {
      uri += fmt::format("%{:02X}", static_cast<unsigned char>(c));
    } else {
      uri += c;
    }
  }
  return uri + "?immutable=1";
}

}  // namespace

sim::Expected<ManifestReader> ManifestReader::open(const std::string& path) {
  {
    std::error_code ec;
    const auto status = std::filesystem::status(path, ec);
    // Unreachable (a directory on the way that may not be entered, an I/O error): said as such, not as "no manifest".
    if (ec && ec != std::errc::no_such_file_or_directory && ec != std::errc::not_a_directory) {
      return sim::Error{fmt::format("cannot read manifest {}: {}", path, ec.message()), /*io=*/true};
    }
    if (!std::filesystem::is_regular_file(status)) return no_manifest_at(path);
  }
  auto open_as = [&](const std::string& name, int flags) -> sim::Expected<std::unique_ptr<Impl>> {
    auto db = open_db(name, flags);
    if (!db) return db.error();
    auto impl = std::make_unique<Impl>();
    impl->db = *db;
    impl->owns = true;
    if (sim::Status s = configure(impl->db); !s) return s.error();
    if (auto version = check_schema(impl->db, path); !version) return version.error();
    return impl;
  };
  auto impl = open_as(path, SQLITE_OPEN_READONLY);
  // A WAL database read where this user may not create its -shm (another user's run, a read-only mount) fails to
  // open. With no -wal beside it (the run's coordinator has closed it: every commit is in the file), the file is all
  // there is: read it as immutable. An empty -wal (left by readers, or by a checkpoint another connection outlived)
  // holds nothing either.
  std::error_code ec;
  const auto wal_size = std::filesystem::file_size(path + "-wal", ec);
  if (!impl && (ec || wal_size == 0)) {
    auto immutable = open_as(immutable_uri(path), SQLITE_OPEN_READONLY | SQLITE_OPEN_URI);
    if (immutable) impl = std::move(immutable);
  } else if (!impl && ::access(directory_of(path).c_str(), W_OK) != 0) {
    return sim::Error{fmt::format("cannot read manifest {}: the run is live or was not closed (its log {}-wal holds "
                                  "commits), and this process cannot write its directory, which reading it then "
                                  "needs; read it where it can, or once the run has ended (or resume it to an end)",
                                  path, path),
                      /*io=*/true};
  }
  if (!impl) return impl.error();
  return ManifestReader(std::move(*impl), directory_of(path));
}

sim::Expected<RunRecord> ManifestReader::run() const {
  Statement st(impl_->db,
               "SELECT id, created_at, seed, config_toml, code_version, total_jobs, state, endpoint FROM runs "
               "ORDER BY id LIMIT 1");
  if (!st.ok()) return sim::Error{"manifest: " + st.prepare_error()};
  if (st.step() != SQLITE_ROW) {
    return sim::Error{
        fmt::format("manifest in {}: no run recorded (not a manifest drapegen wrote whole?)", directory_)};
  }
  RunRecord r;
  r.id = st.int64(0);
  r.created_at = st.real(1);
  r.seed = parse_u64(st.text(2));
  r.config_toml = st.text(3);
  r.code_version = st.text(4);
  r.total_jobs = st.int64(5);
  r.state = st.text(6);
  r.endpoint = st.text(7);
  return r;
}

namespace {

/// Steps `st` to its end, handing each row to `row`; `what` names the table in an error.
template <class Read>
sim::Status each_row(sqlite3* db, Statement& st, const char* what, Read&& row) {
  if (!st.ok()) return sim::Error{"manifest: " + st.prepare_error()};
  int rc;
  while ((rc = st.step()) == SQLITE_ROW) row();
  if (rc != SQLITE_DONE) return sqlite_error(db, fmt::format("reading {}", what));
  return {};
}

/// A table's rows as a vector, through its visitor.
template <class Row, class ForEach>
sim::Expected<std::vector<Row>> collect(ForEach&& for_each) {
  std::vector<Row> out;
  if (sim::Status s = for_each([&](const Row& row) { out.push_back(row); }); !s) return s.error();
  return out;
}

}  // namespace

sim::Status ManifestReader::for_each_sample(const Visitor<SampleRecord>& visit) const {
  Statement st(impl_->db,
               "SELECT sample, alpha_warp, alpha_bias, alpha_weft, beta_warp, beta_bias, beta_weft, density "
               "FROM samples ORDER BY sample");
  SampleRecord s;
  return each_row(impl_->db, st, "samples", [&] {
    s.sample = st.int64(0);
    for (int i = 0; i < 3; ++i) {
      s.alpha[i] = st.real(1 + i);
      s.beta[i] = st.real(4 + i);
    }
    s.density_g_per_m2 = st.real(7);
    visit(s);
  });
}

sim::Status ManifestReader::for_each_job(const Visitor<JobRecord>& visit) const {
  Statement st(impl_->db,
               "SELECT id, sample, slot, recipe, render_seed, mode, state, attempts, worker, failure_reason, "
               "coalesce(started_at, 0), coalesce(finished_at, 0) FROM jobs ORDER BY id");
  JobRecord j;
  return each_row(impl_->db, st, "jobs", [&] {
    j.id = st.int64(0);
    j.sample = st.int64(1);
    j.slot = static_cast<int>(st.int64(2));
    j.recipe_json = st.text(3);
    j.render_seed = parse_u64(st.text(4));
    j.mode = st.text(5);
    j.state = parse_job_state(st.text(6)).value_or(JobState::kPending);
    j.attempts = static_cast<int>(st.int64(7));
    j.worker = st.text(8);
    j.failure_reason = st.text(9);
    j.started_at = st.real(10);
    j.finished_at = st.real(11);
    visit(j);
  });
}

sim::Status ManifestReader::for_each_result(const Visitor<ResultRecord>& visit) const {
  Statement st(impl_->db,
               "SELECT job_id, outcome, iterations, coarse_iterations, residual, energy, drape_coefficient, folds, "
               "self_intersections, sim_seconds, render_seconds, bytes FROM results ORDER BY job_id");
  ResultRecord r;
  return each_row(impl_->db, st, "results", [&] {
    r.job_id = st.int64(0);
    r.outcome = st.text(1);
    r.iterations = static_cast<int>(st.int64(2));
    r.coarse_iterations = static_cast<int>(st.int64(3));
    r.residual = st.real(4);
    r.energy = st.real(5);
    r.drape_coefficient = st.real(6);
    r.folds = static_cast<int>(st.int64(7));
    r.self_intersections = static_cast<int>(st.int64(8));
    r.sim_seconds = st.real(9);
    r.render_seconds = st.real(10);
    r.bytes = st.int64(11);
    visit(r);
  });
}

sim::Status ManifestReader::for_each_file(const Visitor<FileRecord>& visit) const {
  Statement st(impl_->db, "SELECT job_id, kind, idx, path, sha256, bytes FROM files ORDER BY job_id, kind, idx");
  FileRecord f;
  return each_row(impl_->db, st, "files", [&] {
    f.job_id = st.int64(0);
    f.kind = st.text(1);
    f.index = static_cast<int>(st.int64(2));
    f.path = st.text(3);
    f.sha256 = st.text(4);
    f.bytes = st.int64(5);
    visit(f);
  });
}

sim::Status ManifestReader::for_each_failure(const Visitor<FailureRecord>& visit) const {
  Statement st(impl_->db, "SELECT job_id, attempt, reason, message, worker, at FROM failures ORDER BY id");
  FailureRecord f;
  return each_row(impl_->db, st, "failures", [&] {
    f.job_id = st.int64(0);
    f.attempt = static_cast<int>(st.int64(1));
    f.reason = st.text(2);
    f.message = st.text(3);
    f.worker = st.text(4);
    f.at = st.real(5);
    visit(f);
  });
}

sim::Expected<std::vector<SampleRecord>> ManifestReader::samples() const {
  return collect<SampleRecord>([&](const auto& visit) { return for_each_sample(visit); });
}
sim::Expected<std::vector<JobRecord>> ManifestReader::jobs() const {
  return collect<JobRecord>([&](const auto& visit) { return for_each_job(visit); });
}
sim::Expected<std::vector<ResultRecord>> ManifestReader::results() const {
  return collect<ResultRecord>([&](const auto& visit) { return for_each_result(visit); });
}
sim::Expected<std::vector<FileRecord>> ManifestReader::files() const {
  return collect<FileRecord>([&](const auto& visit) { return for_each_file(visit); });
}
sim::Expected<std::vector<FailureRecord>> ManifestReader::failures() const {
  return collect<FailureRecord>([&](const auto& visit) { return for_each_failure(visit); });
}

sim::Status ManifestReader::in_one_snapshot(const std::function<sim::Status()>& read) const {
  // A reader on its own connection reads in one transaction; the writer's view (Manifest::reader) shares the
  // writer's connection, which sees its own state whole. Inside a snapshot already (nested), that one holds.
  const bool transaction = impl_->owns && sqlite3_get_autocommit(impl_->db) != 0;
  if (transaction) {
    if (sim::Status s = exec(impl_->db, "BEGIN"); !s) return s;
  }
  // Ended however `read` ends, a throw included: a read transaction left open would pin this reader to its commit
  // and keep the writer's log from being checkpointed.
  struct End {
    sqlite3* db;
    bool active;
    ~End() {
      if (active) (void)exec(db, "COMMIT");  // a read transaction: nothing to keep or lose
    }
  } end{impl_->db, transaction};
  return read();
}

sim::Expected<ManifestSnapshot> ManifestReader::snapshot() const {
  ManifestSnapshot snap;
  const sim::Status status = in_one_snapshot([&]() -> sim::Status {
    auto run_record = run();
    if (!run_record) return run_record.error();
    snap.run = std::move(run_record).value();
    auto take = [](auto got, auto& into) -> sim::Status {
      if (!got) return got.error();
      into = std::move(got).value();
      return {};
    };
    if (sim::Status s = take(samples(), snap.samples); !s) return s;
    if (sim::Status s = take(jobs(), snap.jobs); !s) return s;
    if (sim::Status s = take(results(), snap.results); !s) return s;
    if (sim::Status s = take(files(), snap.files); !s) return s;
    return take(failures(), snap.failures);
  });
  if (!status) return status.error();
  return snap;
}

sim::Expected<std::string> ManifestReader::integrity_check() const {
  Statement st(impl_->db, "PRAGMA integrity_check");
  if (!st.ok()) return sim::Error{"manifest: " + st.prepare_error()};
  std::string out;
  while (st.step() == SQLITE_ROW) {
    if (!out.empty()) out += "; ";
    out += st.text(0);
  }
  Statement fk(impl_->db, "PRAGMA foreign_key_check");
  if (fk.ok() && fk.step() == SQLITE_ROW) out += "; foreign key violation in table " + fk.text(0);
  return out;
}

// ---------------------------------------------------------------------------------------------------------------
// Writer

struct Manifest::Impl {
  sqlite3* db = nullptr;
  std::string path;
  int schema_version = kSchemaVersion;
  bool in_transaction = false;
  bool wrote = false;  // a write group was begun (a resume refused before it, on a live run's lock, writes nothing)
  Statement begin, commit, rollback, savepoint, release, rollback_to;
  Statement job_done, insert_result, insert_file, job_failed, job_attempt, insert_failure, update_recipe;
  Statement run_state, run_endpoint;

  ~Impl() {
    // Statements must be finalised before the connection closes.
    for (Statement* st : {&begin, &commit, &rollback, &savepoint, &release, &rollback_to, &job_done, &insert_result,
                          &insert_file, &job_failed, &job_attempt, &insert_failure, &update_recipe, &run_state,
                          &run_endpoint}) {
      *st = Statement();
    }
    // Every commit into the database file itself, the log emptied: closing copies the log in only when this is the
    // last connection, and a reader open meanwhile (stats, the training stage) left the run's results in the -wal
    // alone, so that the .sqlite copied or read without it looked empty. Best effort, a short wait for readers.
    // Only by a connection that wrote: one that opened a live run's manifest and was refused its lock must not hold
    // up that run's commits.
    sqlite3_busy_timeout(db, 2000);
    if (wrote && sqlite3_wal_checkpoint_v2(db, nullptr, SQLITE_CHECKPOINT_TRUNCATE, nullptr, nullptr) != SQLITE_OK) {
      (void)sqlite3_wal_checkpoint_v2(db, nullptr, SQLITE_CHECKPOINT_PASSIVE, nullptr, nullptr);
    }
    sqlite3_close(db);
  }

  sim::Status prepare() {
    struct Item {
      Statement* st;
      const char* sql;
    };
    const Item items[] = {
        {&begin, "BEGIN IMMEDIATE"},
        {&commit, "COMMIT"},
        {&rollback, "ROLLBACK"},
        {&savepoint, "SAVEPOINT record"},
        {&release, "RELEASE record"},
        {&rollback_to, "ROLLBACK TO record"},
        {&job_done,
         "UPDATE jobs SET state = 'done', attempts = ?2, worker = ?3, started_at = ?4, finished_at = ?5, "
         "failure_reason = '' WHERE id = ?1 AND state = 'pending'"},
        {&insert_result,
         "INSERT INTO results (job_id, outcome, iterations, coarse_iterations, residual, energy, drape_coefficient, "
         "folds, self_intersections, sim_seconds, render_seconds, bytes) "
         "VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12)"},
        {&insert_file,
         "INSERT INTO files (job_id, kind, idx, path, sha256, bytes) VALUES (?1, ?2, ?3, ?4, ?5, ?6)"},
        {&job_failed,
         "UPDATE jobs SET state = 'failed', attempts = ?2, worker = ?3, started_at = ?4, finished_at = ?5, "
         "failure_reason = ?6 WHERE id = ?1 AND state = 'pending'"},
        {&job_attempt, "UPDATE jobs SET attempts = ?2 WHERE id = ?1 AND state = 'pending'"},
        {&insert_failure,
         "INSERT INTO failures (job_id, attempt, reason, message, worker, at) VALUES (?1, ?2, ?3, ?4, ?5, ?6)"},
        {&update_recipe, "UPDATE jobs SET recipe = ?2 WHERE id = ?1 AND state = 'pending'"},
        {&run_state, "UPDATE runs SET state = ?1"},
        {&run_endpoint, "UPDATE runs SET endpoint = ?1"},
    };
    for (const auto& item : items) {
      *item.st = Statement(db, item.sql);
      if (!item.st->ok()) return sim::Error{"manifest: " + item.st->prepare_error()};
    }
    return {};
  }

  /// Runs `body` inside a savepoint: all of it or none of it.
  template <class F>
  sim::Status atomically(F&& body) {
    if (!in_transaction) return sim::Error{"manifest: write outside begin()/commit()"};
    if (sim::Status s = group_alive(); !s) return s;
    if (sim::Status s = savepoint.run(); !s) return s;
    sim::Status s = body();
    if (!s) {
      (void)rollback_to.run();
      (void)release.run();
      return s;
    }
    return release.run();
  }

  /// After some errors (a full disk, I/O, memory, a trigger's RAISE(ROLLBACK)) SQLite rolls the whole transaction
  /// back by itself: the group is gone, and a write now would commit alone, outside it.
  sim::Status group_alive() {
    if (!sqlite3_get_autocommit(db)) return {};
    return sim::Error{"manifest: the group was rolled back by SQLite after an earlier error; none of it is recorded",
                      /*io=*/true};
  }

  sim::Status expect_one_change(const char* what, std::int64_t job_id) {
    if (sqlite3_changes(db) != 1) {
      return sim::Error{fmt::format("manifest: {} of job {}: the job is not pending", what, job_id)};
    }
    return {};
  }
};

Manifest::Manifest(std::unique_ptr<Impl> impl, std::unique_ptr<ManifestReader> reader)
    : impl_(std::move(impl)), reader_(std::move(reader)) {}
Manifest::Manifest(Manifest&&) noexcept = default;
Manifest& Manifest::operator=(Manifest&&) noexcept = default;
Manifest::~Manifest() {
  if (impl_ && impl_->in_transaction) rollback();
  reader_.reset();
}

sim::Expected<Manifest> Manifest::create(const std::string& path, const RunRecord& run,
                                         const std::vector<SampleRecord>& samples,
                                         const std::vector<JobRecord>& jobs) {
  if (std::filesystem::exists(path)) {
    return sim::Error{fmt::format("{} exists already (use --resume to continue that run)", path)};
  }
  // A log or journal left by a manifest that is gone (deleted after a crash) would be replayed into the new one:
  // SQLite ties neither to its database. It is the user's to remove, not ours. (A -shm alone is rebuilt, harmless.)
  for (const char* suffix : {"-wal", "-journal"}) {
    if (std::filesystem::exists(path + suffix)) {
      return sim::Error{fmt::format("{}{} is left from a manifest that is no longer there; SQLite would replay it "
                                    "into a new one: remove it before starting a new run here",
                                    path, suffix)};
    }
  }
  const std::string tmp = path + ".tmp";
  for (const char* suffix : {"", "-wal", "-shm", "-journal"}) std::filesystem::remove(tmp + suffix);
  {
    auto opened = open_db(tmp, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE);
    if (!opened) return opened.error();
    sqlite3* db = *opened;
    auto fail = [&](sim::Status s) -> sim::Expected<Manifest> {
      // close_v2: the connection closes (and rolls the build back) once this block's statements are finalised;
      // sqlite3_close would refuse while they live and leave it open, its files held and its journal behind.
      sqlite3_close_v2(db);
      for (const char* suffix : {"", "-wal", "-shm", "-journal"}) std::filesystem::remove(tmp + suffix);
      return s.error();
    };
    // Build in rollback-journal mode with one fsync at the end, then switch to WAL for the run.
    if (sim::Status s = exec(db, "PRAGMA foreign_keys = ON; PRAGMA synchronous = FULL; BEGIN"); !s) return fail(s);
    if (sim::Status s = exec(db, detail::kSchemaSql); !s) return fail(s);
    if (sim::Status s = exec(db, detail::kFailuresSql); !s) return fail(s);
    {
      Statement meta(db, "INSERT INTO meta (key, value) VALUES (?1, ?2)");
      if (sim::Status s = meta.reset().bind(1, "schema_version").bind(2, std::to_string(kSchemaVersion)).run(); !s) {
        return fail(s);
      }
      if (sim::Status s = meta.reset().bind(1, "application").bind(2, "drapegen").run(); !s) return fail(s);
      Statement st(db,
                   "INSERT INTO runs (id, created_at, seed, config_toml, code_version, total_jobs, state, endpoint) "
                   "VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8)");
      if (sim::Status s = st.bind(1, run.id)
                              .bind(2, run.created_at)
                              .bind(3, u64_text(run.seed))
                              .bind(4, run.config_toml)
                              .bind(5, run.code_version)
                              .bind(6, static_cast<std::int64_t>(jobs.size()))
                              .bind(7, run.state)
                              .bind(8, run.endpoint)
                              .run();
          !s) {
        return fail(s);
      }
      Statement ss(db,
                   "INSERT INTO samples (run_id, sample, alpha_warp, alpha_bias, alpha_weft, beta_warp, beta_bias, "
                   "beta_weft, density) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9)");
      for (const auto& s : samples) {
        ss.reset().bind(1, run.id).bind(2, s.sample);
        for (int i = 0; i < 3; ++i) ss.bind(3 + i, s.alpha[i]).bind(6 + i, s.beta[i]);
        if (sim::Status r = ss.bind(9, s.density_g_per_m2).run(); !r) return fail(r);
      }
      Statement js(db,
                   "INSERT INTO jobs (id, run_id, sample, slot, recipe, render_seed, mode, state) "
                   "VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, 'pending')");
      for (const auto& j : jobs) {
        if (sim::Status r = js.reset()
                                .bind(1, j.id)
                                .bind(2, run.id)
                                .bind(3, j.sample)
                                .bind(4, j.slot)
                                .bind(5, j.recipe_json)
                                .bind(6, u64_text(j.render_seed))
                                .bind(7, j.mode)
                                .run();
            !r) {
          return fail(r);
        }
      }
    }
    if (sim::Status s = exec(db, "COMMIT"); !s) return fail(s);
    if (sim::Status s = exec(db, "PRAGMA journal_mode = WAL"); !s) return fail(s);
    sqlite3_close(db);  // the last connection: checkpoints and removes the -wal file
  }
  // Make the database durable under its temporary name, then publish it.
  {
    std::FILE* f = std::fopen(tmp.c_str(), "rb+");
    if (!f) return sim::Error{fmt::format("cannot reopen {}: {}", tmp, std::strerror(errno)), /*io=*/true};
    const bool synced = ::fsync(fileno(f)) == 0;
    std::fclose(f);
    if (!synced) return sim::Error{fmt::format("cannot sync {}: {}", tmp, std::strerror(errno)), /*io=*/true};
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) return sim::Error{fmt::format("cannot rename {} to {}: {}", tmp, path, ec.message()), /*io=*/true};
  if (sim::Status s = sync_directory(directory_of(path)); !s) return s.error();
  return open(path);
}

sim::Expected<Manifest> Manifest::open(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) return no_manifest_at(path);
  auto db = open_db(path, SQLITE_OPEN_READWRITE);
  if (!db) return db.error();
  auto impl = std::make_unique<Impl>();
  impl->db = *db;
  if (sim::Status s = configure(impl->db); !s) return s.error();
  auto version = check_schema(impl->db, path);  // before anything writes to the file
  if (!version) return version.error();
  if (sim::Status s = configure_writer(impl->db); !s) return s.error();
  impl->path = path;
  impl->schema_version = *version;
  if (sim::Status s = impl->prepare(); !s) return s.error();
  auto reader_impl = std::make_unique<ManifestReader::Impl>();
  reader_impl->db = impl->db;
  reader_impl->owns = false;
  auto reader = std::unique_ptr<ManifestReader>(new ManifestReader(std::move(reader_impl), directory_of(path)));
  return Manifest(std::move(impl), std::move(reader));
}

sim::Status Manifest::upgrade_schema() {
  if (impl_->in_transaction) return sim::Error{"manifest: schema upgrade inside a transaction"};
  if (sim::Status s = upgrade_tables(impl_->db, impl_->schema_version, impl_->path); !s) return s;
  impl_->schema_version = kSchemaVersion;
  return {};
}

int Manifest::schema_version() const { return impl_->schema_version; }

sim::Status Manifest::begin() {
  if (impl_->in_transaction) return {};
  if (sim::Status s = impl_->begin.run(); !s) return s;
  impl_->in_transaction = true;
  impl_->wrote = true;
  return {};
}

sim::Status Manifest::commit() {
  if (!impl_->in_transaction) return {};
  if (sim::Status s = impl_->group_alive(); !s) {
    impl_->in_transaction = false;
    return s;
  }
  sim::Status s = impl_->commit.run();
  if (!s) {
    rollback();
    return s;
  }
  impl_->in_transaction = false;
  return {};
}

void Manifest::rollback() {
  if (!impl_->in_transaction) return;
  (void)impl_->rollback.run();
  impl_->in_transaction = false;
}

bool Manifest::in_transaction() const { return impl_->in_transaction; }

sim::Status Manifest::record_result(const JobRecord& job, const ResultRecord& r, const std::vector<FileRecord>& files) {
  return impl_->atomically([&]() -> sim::Status {
    if (sim::Status s = impl_->job_done.reset()
                            .bind(1, job.id)
                            .bind(2, job.attempts)
                            .bind(3, job.worker)
                            .bind(4, job.started_at)
                            .bind(5, job.finished_at)
                            .run();
        !s) {
      return s;
    }
    if (sim::Status s = impl_->expect_one_change("result", job.id); !s) return s;
    if (sim::Status s = impl_->insert_result.reset()
                            .bind(1, job.id)
                            .bind(2, r.outcome)
                            .bind(3, r.iterations)
                            .bind(4, r.coarse_iterations)
                            .bind(5, r.residual)
                            .bind(6, r.energy)
                            .bind(7, r.drape_coefficient)
                            .bind(8, r.folds)
                            .bind(9, r.self_intersections)
                            .bind(10, r.sim_seconds)
                            .bind(11, r.render_seconds)
                            .bind(12, r.bytes)
                            .run();
        !s) {
      return s;
    }
    for (const auto& f : files) {
      if (sim::Status s = impl_->insert_file.reset()
                              .bind(1, job.id)
                              .bind(2, f.kind)
                              .bind(3, f.index)
                              .bind(4, f.path)
                              .bind(5, f.sha256)
                              .bind(6, f.bytes)
                              .run();
          !s) {
        return s;
      }
    }
    return {};
  });
}

sim::Status Manifest::record_failure(const JobRecord& job, const FailureRecord& f, bool final) {
  return impl_->atomically([&]() -> sim::Status {
    if (sim::Status s = impl_->insert_failure.reset()
                            .bind(1, job.id)
                            .bind(2, f.attempt)
                            .bind(3, f.reason)
                            .bind(4, f.message)
                            .bind(5, f.worker)
                            .bind(6, f.at)
                            .run();
        !s) {
      return s;
    }
    if (final) {
      if (sim::Status s = impl_->job_failed.reset()
                              .bind(1, job.id)
                              .bind(2, job.attempts)
                              .bind(3, job.worker)
                              .bind(4, job.started_at)
                              .bind(5, job.finished_at)
                              .bind(6, f.reason)
                              .run();
          !s) {
        return s;
      }
    } else {
      if (sim::Status s = impl_->job_attempt.reset().bind(1, job.id).bind(2, job.attempts).run(); !s) return s;
    }
    return impl_->expect_one_change("failure", job.id);
  });
}

sim::Status Manifest::update_recipe(std::int64_t job_id, const std::string& recipe_json) {
  return impl_->atomically([&]() -> sim::Status {
    if (sim::Status s = impl_->update_recipe.reset().bind(1, job_id).bind(2, recipe_json).run(); !s) return s;
    return impl_->expect_one_change("recipe update", job_id);
  });
}

sim::Expected<std::int64_t> Manifest::retry_failed() {
  std::int64_t changed = 0;
  sim::Status s = impl_->atomically([&]() -> sim::Status {
    constexpr const char* kRetry = "UPDATE jobs SET state = 'pending', failure_reason = '' WHERE state = 'failed'";
    if (sim::Status e = exec(impl_->db, kRetry); !e) return e;
    changed = sqlite3_changes(impl_->db);
    return {};
  });
  if (!s) return s.error();
  return changed;
}

sim::Status Manifest::set_run_state(const std::string& state) {
  return impl_->atomically([&] { return impl_->run_state.reset().bind(1, state).run(); });
}

sim::Status Manifest::set_endpoint(const std::string& endpoint) {
  return impl_->atomically([&] { return impl_->run_endpoint.reset().bind(1, endpoint).run(); });
}

}  // namespace drapegen::storage
