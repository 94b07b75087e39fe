"""Reads a run generated in the test (drapegen local, tiny) through DrapeDataset.

Usage: dataset_test.py DRAPEGEN_BINARY WORK_DIR
"""

import math
import os
import shutil
import sqlite3
import subprocess
import sys
import warnings

import numpy as np
import torch

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from drapegen_dataset import DrapeDataset, features  # noqa: E402

drapegen, work = sys.argv[1], sys.argv[2]
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
config = os.path.join(work, "run.toml")
with open(config, "w") as f:
    f.write(f"""seed = 4
samples = 3
states_per_sample = 2
orientations = 2
resolution = 15
output = "{work}/run"
[solver]
max_self_intersections = 1000000
[testing]
poison_samples = [2]
[retry]
max_attempts = 1
""")
subprocess.run([drapegen, "local", "--workers", "2", "--config", config], check=True, capture_output=True)
manifest = os.path.join(work, "run", "manifest.sqlite")

ds = DrapeDataset(manifest, verify_checksums=True)
db = sqlite3.connect(manifest)
done = db.execute("SELECT count(*) FROM jobs WHERE state = 'done'").fetchone()[0]
failed = db.execute("SELECT count(*) FROM jobs WHERE state = 'failed'").fetchone()[0]
assert done == 4 and failed == 2, (done, failed)
assert len(ds) == done * 2, len(ds)  # 2 data points per done drape; failed jobs are no items

views, target = ds[0]
assert views.dtype == torch.float32 and tuple(views.shape) == (4, 180, 240), views.shape
assert torch.isfinite(views).all()
covered = (views > 0).float().mean(dim=(1, 2))
assert (covered > 0.01).all(), covered  # every view sees the drape
z = views[views > 0]
assert 0.3 < float(z.min()) and float(z.max()) < 1.5, (float(z.min()), float(z.max()))  # metres from the camera
assert tuple(target.shape) == (6,)

# Targets: the sample's moduli, as features, standardised over the dataset.
targets = torch.stack([ds[i][1] for i in range(len(ds))]).numpy()
assert np.allclose(targets.mean(axis=0), 0.0, atol=1e-5), targets.mean(axis=0)
row = db.execute("SELECT alpha_warp, alpha_bias, alpha_weft, beta_warp, beta_bias, beta_weft, density "
                 "FROM samples WHERE sample = ?", (ds.item(0)["sample"],)).fetchone()
assert np.allclose(ds.denormalise(target.numpy()), features(row[:6], row[6]), atol=1e-5)
# The feature map is the sampler's, sign(k) ln|k| at 300 g/m^2, also where |k| < 1 (ln|k| < 0).
assert np.allclose(features([0.5, -0.5, 2.0, -2.0, 600.0, 1.0], 300.0),
                   [math.log(0.5), -math.log(0.5), math.log(2.0), -math.log(2.0), math.log(600.0), 0.0])
assert np.allclose(features([0.5], 150.0), [0.0])  # at 150 g/m^2: k = 0.5 * 300 / 150 = 1 at 300 g/m^2
db.close()  # the last connection: no log or shared-memory file left beside the manifest, as after a finished run

# Two orientations of one drape differ (other table angles), the same item read twice does not.
a, _ = ds[0]
b, _ = ds[1]
assert ds.item(0)["job"] == ds.item(1)["job"] and not torch.equal(a, b)
assert torch.equal(a, ds[0][0])

loader = torch.utils.data.DataLoader(ds, batch_size=4, shuffle=False)
batch_views, batch_targets = next(iter(loader))
assert tuple(batch_views.shape) == (4, 4, 180, 240) and tuple(batch_targets.shape) == (4, 6)
assert ds.run_state == "complete", ds.run_state

# Clear errors that name the path: the run's directory, a file that is no manifest.
try:
    DrapeDataset(os.path.dirname(manifest))
    raise AssertionError("a directory was read as a manifest")
except FileNotFoundError as e:
    assert f"the run's manifest is {manifest}" in str(e), e
other = os.path.join(work, "other.sqlite")
with open(other, "w") as f:
    f.write("not a database at all")
try:
    DrapeDataset(other)
    raise AssertionError("a text file was read as a manifest")
except ValueError as e:
    assert "not a drapegen manifest" in str(e) and other in str(e), e

# A run that has not ended is read with a warning: the dataset holds what is done so far.
stopped = os.path.join(work, "stopped", "manifest.sqlite")
os.makedirs(os.path.dirname(stopped))
shutil.copy(manifest, stopped)
sql = sqlite3.connect(stopped)
sql.execute("UPDATE runs SET state = 'stopped'")
sql.commit()
sql.close()
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    assert DrapeDataset(stopped).run_state == "stopped"
assert any("the run is stopped" in str(w.message) for w in caught), [str(w.message) for w in caught]

# A live run commits while the dataset reads it: everything is read in one snapshot, so a commit between the count
# of the done jobs' files and the rows themselves (here one that changes a done job's state) leaves neither unfilled
# nor surplus rows: the dataset is the run as it was before the commit. (Read outside one snapshot, the rows no longer
# match the count: the test then fails on an index out of bounds.)
import drapegen_dataset  # noqa: E402

live_copy = os.path.join(work, "concurrent", "manifest.sqlite")
os.makedirs(os.path.dirname(live_copy))
shutil.copy(manifest, live_copy)
before = DrapeDataset(live_copy)


class CommitAfter:
    """The reader's connection, with another connection committing right after the first query naming `after`."""

    def __init__(self, db, after, commit):
        self.db, self.after, self.commit, self.committed = db, after, commit, False

    def execute(self, sql, *args):
        cursor = self.db.execute(sql, *args)
        if self.after in sql and not self.committed:
            self.committed = True
            self.commit()
        return cursor

    def __getattr__(self, name):
        return getattr(self.db, name)


def fail_one_done_job():
    writer = sqlite3.connect(live_copy)
    writer.execute("UPDATE jobs SET state = 'failed' WHERE id = (SELECT min(id) FROM jobs WHERE state = 'done')")
    writer.commit()
    writer.close()


opened = drapegen_dataset.open_manifest


def open_with_a_commit_after_the_count(path):
    db, immutable = opened(path)
    return CommitAfter(db, "SELECT count(*)", fail_one_done_job), immutable


drapegen_dataset.open_manifest = open_with_a_commit_after_the_count
try:
    during = DrapeDataset(live_copy)
finally:
    drapegen_dataset.open_manifest = opened
check = sqlite3.connect(live_copy)
assert check.execute("SELECT count(*) FROM jobs WHERE state = 'done'").fetchone()[0] == done - 1  # it committed
check.close()
assert len(during) == len(before) == done * 2, (len(during), len(before))
assert np.array_equal(during.jobs, before.jobs) and np.array_equal(during.paths, before.paths), (
    during.jobs, before.jobs)
assert len(DrapeDataset(live_copy)) == (done - 1) * 2  # read again: the commit seen

# Another user's finished run in a directory this process cannot write (no -shm can be made beside the WAL
# database): read as an immutable file. Root writes anywhere, so the reader runs as nobody where root can arrange it.
runuser = shutil.which("runuser")
if os.geteuid() == 0 and runuser:
    shared = os.path.join("/tmp", f"drapegen_dataset_ro_{os.getpid()}")
    shutil.rmtree(shared, ignore_errors=True)
    assert not os.path.exists(manifest + "-wal") and not os.path.exists(manifest + "-shm")
    shutil.copytree(os.path.join(work, "run"), os.path.join(shared, "run"))
    shutil.copy(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "drapegen_dataset.py"), shared)
    for root, dirs, files in os.walk(shared):
        for d in dirs:
            os.chmod(os.path.join(root, d), 0o555)
        for f in files:
            os.chmod(os.path.join(root, f), 0o444)
    os.chmod(shared, 0o555)
    probe = ("import sys; sys.path.insert(0, sys.argv[1]); from drapegen_dataset import DrapeDataset; "
             "ds = DrapeDataset(sys.argv[1] + '/run/manifest.sqlite', verify_checksums=True); "
             "v, t = ds[0]; print(len(ds), ds.run_state, ds.read_immutable, float(v.max()) > 0)")
    out = subprocess.run([runuser, "-u", "nobody", "--", sys.executable, "-c", probe, shared],
                         capture_output=True, text=True, env={"PATH": "/usr/bin:/bin", "HOME": "/tmp"})
    made_shm = os.path.exists(os.path.join(shared, "run", "manifest.sqlite-shm"))
    os.chmod(shared, 0o755)
    for root, dirs, files in os.walk(shared):
        for d in dirs:
            os.chmod(os.path.join(root, d), 0o755)
    assert out.returncode == 0 and out.stdout.split() == [str(len(ds)), "complete", "True", "True"], (
        out.stdout, out.stderr[-2000:])
    assert not made_shm
    # A run whose log still holds commits (live, or its coordinator killed): read through its shared-memory file where
    # that is left beside it (the log's commit seen, not a stale file); refused where it is not.
    live = os.path.join(work, "live")
    os.makedirs(live)
    shutil.copy(manifest, live)
    writer = sqlite3.connect(os.path.join(live, "manifest.sqlite"))
    writer.execute("PRAGMA wal_autocheckpoint = 0")
    writer.execute("UPDATE runs SET state = 'running'")
    writer.commit()
    for name in ("with_shm", "without_shm"):
        shutil.copytree(live, os.path.join(shared, name))  # as a kill leaves it
    writer.close()
    os.remove(os.path.join(shared, "without_shm", "manifest.sqlite-shm"))
    assert os.path.getsize(os.path.join(shared, "without_shm", "manifest.sqlite-wal")) > 0
    state = ("import sys, warnings; warnings.simplefilter('ignore'); sys.path.insert(0, sys.argv[1]); "
             "from drapegen_dataset import DrapeDataset; ds = DrapeDataset(sys.argv[2]); "
             "print(ds.run_state, ds.read_immutable)")
    results = {}
    for name in ("with_shm", "without_shm"):
        os.chmod(os.path.join(shared, name), 0o555)
        os.chmod(shared, 0o555)
        results[name] = subprocess.run(
            [runuser, "-u", "nobody", "--", sys.executable, "-c", state, shared,
             os.path.join(shared, name, "manifest.sqlite")],
            capture_output=True, text=True, env={"PATH": "/usr/bin:/bin", "HOME": "/tmp"})
        os.chmod(shared, 0o755)
        os.chmod(os.path.join(shared, name), 0o755)
    shutil.rmtree(shared)
    seen = results["with_shm"]
    assert seen.returncode == 0 and seen.stdout.split() == ["running", "False"], (seen.stdout, seen.stderr[-2000:])
    refused = results["without_shm"]
    assert refused.returncode != 0 and "holds commits" in refused.stderr, (refused.stdout, refused.stderr[-2000:])

print(f"dataset_test: ok ({len(ds)} items of 4 views 180x240 from {done} drapes)")
