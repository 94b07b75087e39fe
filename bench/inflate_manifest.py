#!/usr/bin/env python3
"""Makes a large manifest out of a small one, for measuring what reading a manifest costs (drapegen stats, the
training stage's index) at a run's real size without computing its drapes.

Copies SOURCE to DEST and appends COPIES - 1 copies of its samples, jobs, results, files and failures, each with
fresh ids and file paths (the files themselves are not copied: the rows name files that do not exist). The run's
total_jobs is set to the new count. The schema, meta and run rows are the source's own, so the result is whatever
manifest version wrote SOURCE. The copies keep the source's times (leases, results, failures), so the time figures
of `drapegen stats` on the result (jobs per hour, busy seconds) are meaningless; its counts, distributions and its
own memory and time are what it is for.

  bench/inflate_manifest.py out/local-run/manifest.sqlite /tmp/big/manifest.sqlite --copies 1200
"""
import argparse
import os
import shutil
import sqlite3
import sys


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("source", help="a manifest drapegen wrote (left unchanged)")
    parser.add_argument("dest", help="the manifest to write (must not exist)")
    parser.add_argument("--copies", type=int, required=True, help="how many times the source's rows appear (>= 1)")
    args = parser.parse_args()
    if args.copies < 1:
        parser.error("--copies must be at least 1")
    if os.path.exists(args.dest):
        parser.error(f"{args.dest} exists; name a new file")
    if not os.path.isfile(args.source):
        parser.error(f"no manifest at {args.source}")

    # Fold the source's log into it first (read-only connections cannot; a copy of the file alone would lose it).
    os.makedirs(os.path.dirname(os.path.abspath(args.dest)), exist_ok=True)
    src = sqlite3.connect(f"file:{os.path.abspath(args.source)}?mode=ro", uri=True)
    dst = sqlite3.connect(args.dest)
    src.backup(dst)
    src.close()

    cur = dst.cursor()
    (samples,) = cur.execute("SELECT coalesce(max(sample), -1) + 1 FROM samples").fetchone()
    (jobs,) = cur.execute("SELECT coalesce(max(id), 0) FROM jobs").fetchone()
    (files,) = cur.execute("SELECT coalesce(max(id), 0) FROM files").fetchone()
    (failures,) = cur.execute("SELECT coalesce(max(id), 0) FROM failures").fetchone()
    cur.execute("BEGIN")
    for k in range(1, args.copies):
        cur.execute("INSERT INTO samples SELECT run_id, sample + ?1, alpha_warp, alpha_bias, alpha_weft, beta_warp, "
                    "beta_bias, beta_weft, density FROM samples WHERE sample < ?2", (samples * k, samples))
        cur.execute("INSERT INTO jobs SELECT id + ?1, run_id, sample + ?2, slot, recipe, render_seed, mode, state, "
                    "attempts, worker, failure_reason, started_at, finished_at FROM jobs WHERE id <= ?3",
                    (jobs * k, samples * k, jobs))
        cur.execute("INSERT INTO results SELECT job_id + ?1, outcome, iterations, coarse_iterations, residual, energy, "
                    "drape_coefficient, folds, self_intersections, sim_seconds, render_seconds, bytes FROM results "
                    "WHERE job_id <= ?2", (jobs * k, jobs))
        cur.execute("INSERT INTO files SELECT id + ?1, job_id + ?2, kind, idx, 'copy' || ?3 || '/' || path, sha256, "
                    "bytes FROM files WHERE id <= ?4", (files * k, jobs * k, k, files))
        cur.execute("INSERT INTO failures SELECT id + ?1, job_id + ?2, attempt, reason, message, worker, at "
                    "FROM failures WHERE id <= ?3", (failures * k, jobs * k, failures))
    cur.execute("UPDATE runs SET total_jobs = (SELECT count(*) FROM jobs)")
    dst.commit()
    (count,) = cur.execute("SELECT count(*) FROM jobs").fetchone()
    (file_count,) = cur.execute("SELECT count(*) FROM files").fetchone()
    dst.close()
    print(f"{args.dest}: {count} jobs, {file_count} file rows ({os.path.getsize(args.dest) / 1e6:.0f} MB)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
