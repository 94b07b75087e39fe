#pragma once
// The manifest schema, version 2 (docs/SERVICE.md, "Manifest schema"). Private to drapegen::storage.

namespace drapegen::storage::detail {

inline constexpr const char* kSchemaSql = R"sql(
CREATE TABLE meta (
  key   TEXT PRIMARY KEY,
  value TEXT NOT NULL
);
CREATE TABLE runs (
  id           INTEGER PRIMARY KEY,
  created_at   REAL    NOT NULL,
  seed         TEXT    NOT NULL,
  config_toml  TEXT    NOT NULL,
  code_version TEXT    NOT NULL,
  total_jobs   INTEGER NOT NULL,
  state        TEXT    NOT NULL CHECK (state IN ('running', 'stopped', 'complete')),
  endpoint     TEXT    NOT NULL DEFAULT ''
);
CREATE TABLE samples (
  run_id     INTEGER NOT NULL REFERENCES runs (id),
  sample     INTEGER NOT NULL CHECK (sample >= 0),
  alpha_warp REAL NOT NULL,
  alpha_bias REAL NOT NULL,
  alpha_weft REAL NOT NULL,
  beta_warp  REAL NOT NULL,
  beta_bias  REAL NOT NULL,
  beta_weft  REAL NOT NULL,
  density    REAL NOT NULL,
  PRIMARY KEY (run_id, sample)
);
CREATE TABLE jobs (
  id             INTEGER PRIMARY KEY,
  run_id         INTEGER NOT NULL,
  sample         INTEGER NOT NULL,
  slot           INTEGER NOT NULL CHECK (slot >= 0),
  recipe         TEXT    NOT NULL,
  render_seed    TEXT    NOT NULL,
  mode           TEXT    NOT NULL CHECK (mode IN ('drape', 'noop', 'poison')),
  state          TEXT    NOT NULL CHECK (state IN ('pending', 'done', 'failed')),
  attempts       INTEGER NOT NULL DEFAULT 0,
  worker         TEXT    NOT NULL DEFAULT '',
  failure_reason TEXT    NOT NULL DEFAULT '',
  started_at     REAL,
  finished_at    REAL,
  UNIQUE (run_id, sample, slot),
  FOREIGN KEY (run_id, sample) REFERENCES samples (run_id, sample)
);
CREATE INDEX jobs_by_state ON jobs (state);
CREATE INDEX jobs_by_worker ON jobs (worker);
CREATE INDEX jobs_by_reason ON jobs (failure_reason) WHERE state = 'failed';
CREATE TABLE results (
  job_id             INTEGER PRIMARY KEY REFERENCES jobs (id),
  outcome            TEXT    NOT NULL,
  iterations         INTEGER NOT NULL,
  coarse_iterations  INTEGER NOT NULL,
  residual           REAL    NOT NULL,
  energy             REAL    NOT NULL,
  drape_coefficient  REAL    NOT NULL,
  folds              INTEGER NOT NULL,
  self_intersections INTEGER NOT NULL,
  sim_seconds        REAL    NOT NULL,
  render_seconds     REAL    NOT NULL,
  bytes              INTEGER NOT NULL
);
CREATE TABLE files (
  id     INTEGER PRIMARY KEY,
  job_id INTEGER NOT NULL REFERENCES results (job_id),
  kind   TEXT    NOT NULL CHECK (kind IN ('mesh', 'exr')),
  idx    INTEGER NOT NULL,
  path   TEXT    NOT NULL UNIQUE,
  sha256 TEXT    NOT NULL,
  bytes  INTEGER NOT NULL,
  UNIQUE (job_id, kind, idx)
);
)sql";

/// The failures table (part of the schema; also what the upgrade from version 1 builds). Version 2 added the reasons
/// 'worker_error' and 'unspecified'.
inline constexpr const char* kFailuresSql = R"sql(
CREATE TABLE failures (
  id      INTEGER PRIMARY KEY,
  job_id  INTEGER NOT NULL REFERENCES jobs (id),
  attempt INTEGER NOT NULL,
  reason  TEXT    NOT NULL CHECK (reason IN ('not_converged', 'diverged', 'self_intersection', 'render_error',
                                             'worker_lost', 'timeout', 'invalid_job', 'worker_error',
                                             'unspecified')),
  message TEXT    NOT NULL,
  worker  TEXT    NOT NULL,
  at      REAL    NOT NULL
);
CREATE INDEX failures_by_job ON failures (job_id);
CREATE INDEX failures_by_reason ON failures (reason);
)sql";

/// Version 1 -> 2, inside the caller's transaction: set the old failures table aside, create kFailuresSql's, refill
/// it with the old rows.
inline constexpr const char* kUpgradeFrom1SetAsideSql = R"sql(
DROP INDEX failures_by_job;
DROP INDEX failures_by_reason;
ALTER TABLE failures RENAME TO failures_v1;
)sql";
inline constexpr const char* kUpgradeFrom1RefillSql = R"sql(
INSERT INTO failures (id, job_id, attempt, reason, message, worker, at)
  SELECT id, job_id, attempt, reason, message, worker, at FROM failures_v1;
DROP TABLE failures_v1;
UPDATE meta SET value = '2' WHERE key = 'schema_version';
)sql";

}  // namespace drapegen::storage::detail
