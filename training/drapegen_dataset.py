"""A PyTorch Dataset over a drapegen run: the manifest (SQLite, read-only) and its OpenEXR files.

One item is one data point: the 4 depth views of one specimen orientation of one drape, as a float32 tensor of shape
(4, H, W) (camera-space z in metres, 0 where the camera saw nothing), and the drape's 6-D bending parameter target:
the features sign(k) ln|k| of (alpha warp, bias, weft, beta warp, bias, weft) normalised to 300 g/m^2 (as the
sampler works), standardised by a mean and std (by default those of the run's done samples; pass the training
set's to a validation set). Only done jobs are items. Schema: docs/SERVICE.md, "Manifest schema".

Needs python3-torch, python3-numpy and python3-openimageio (Debian).
"""

import hashlib
import math
import os
import stat
import sqlite3
import urllib.parse
import warnings

import numpy as np
import OpenImageIO as oiio
import torch
from torch.utils.data import Dataset

FEATURES = ("alpha_warp", "alpha_bias", "alpha_weft", "beta_warp", "beta_bias", "beta_weft")
STANDARD_DENSITY = 300.0  # g/m^2


def features(moduli, density):
    """sign(k) ln|k| of the six moduli at 300 g/m^2 (k * 300 / density)."""
    out = []
    for k in moduli:
        k = k * STANDARD_DENSITY / density
        out.append(math.copysign(1.0, k) * math.log(abs(k)))  # sign(k) ln|k|, negative where |k| < 1
    return out


def read_views(path):
    """The depth views of one drapegen EXR file: float32 array (views, H, W) over the full display window."""
    inp = oiio.ImageInput.open(path)
    if inp is None:
        raise IOError(f"cannot open {path}: {oiio.geterror()}")
    try:
        spec = inp.spec()
        names = list(spec.channelnames)
        pixels = inp.read_image("float")
        if pixels is None:
            raise IOError(f"cannot read {path}: {inp.geterror()}")
    finally:
        inp.close()
    full = np.zeros((spec.full_height, spec.full_width, spec.nchannels), dtype=np.float32)
    y0, x0 = spec.y - spec.full_y, spec.x - spec.full_x
    full[y0:y0 + spec.height, x0:x0 + spec.width, :] = pixels.reshape(spec.height, spec.width, spec.nchannels)
    order = sorted(range(len(names)), key=lambda i: names[i])  # view0.Z, view1.Z, ...
    return np.ascontiguousarray(np.transpose(full[:, :, order], (2, 0, 1)))


def open_manifest(manifest):
    """A read-only connection to a run's manifest, with errors that name the path.

    A WAL database is read through its shared-memory file, which SQLite creates beside it when no writer has: where
    this process cannot write that directory (another user's run, a read-only mount), only a run that has ended can
    be read, as an immutable file (the coordinator checkpoints its log into the file when it exits)."""
    if os.path.isdir(manifest):
        inside = os.path.join(manifest, "manifest.sqlite")
        hint = f"; the run's manifest is {inside}" if os.path.isfile(inside) else ""
        raise FileNotFoundError(f"{manifest}: a directory, not a manifest{hint}")
    try:
        mode = os.stat(manifest).st_mode
    except FileNotFoundError:
        raise FileNotFoundError(f"{manifest}: no such manifest") from None
    except OSError as e:  # a directory on the way that may not be entered, an I/O error: not "no such manifest"
        raise PermissionError(f"{manifest}: cannot be reached ({e.strerror})") from None
    if not stat.S_ISREG(mode):
        raise FileNotFoundError(f"{manifest}: no such manifest (not a regular file)")
    uri = "file:" + urllib.parse.quote(manifest)
    db = None
    try:
        db = sqlite3.connect(uri + "?mode=ro", uri=True)
        db.execute("SELECT count(*) FROM sqlite_master").fetchone()
        return db, False
    except sqlite3.OperationalError as e:
        if db is not None:
            db.close()
        if os.access(os.path.dirname(manifest), os.W_OK):
            raise ValueError(f"{manifest}: cannot be read as a manifest ({e})") from None
    except sqlite3.DatabaseError as e:
        if db is not None:
            db.close()
        raise ValueError(f"{manifest}: not a drapegen manifest ({e})") from None
    # Immutable reads the file alone: commits still in a log beside it (a live run, or one whose coordinator was
    # killed) would be missed.
    wal = manifest + "-wal"
    if os.path.exists(wal) and os.path.getsize(wal) > 0:
        raise PermissionError(f"{manifest}: the run is live or was not closed (its log {wal} holds commits), and this "
                              "process cannot write its directory, which reading it then needs; read it where it "
                              "can, or once it has ended (or resume it to an end)")
    try:
        return sqlite3.connect(uri + "?immutable=1", uri=True), True
    except sqlite3.Error as e:
        raise ValueError(f"{manifest}: cannot be read as a manifest ({e})") from None


class DrapeDataset(Dataset):
    """Data points of the done jobs of a run, in (job id, orientation) order."""

    def __init__(self, manifest, mean=None, std=None, verify_checksums=False):
        self.manifest = os.path.abspath(manifest)
        self.root = os.path.dirname(self.manifest)
        self.verify = verify_checksums
        db, immutable = open_manifest(self.manifest)
        try:
            # One snapshot for everything read here, the run's state too (a live run commits meanwhile; one
            # completing between the reads would leave the warning below about rows it does not describe).
            db.execute("BEGIN")
            try:
                row = db.execute("SELECT value FROM meta WHERE key = 'schema_version'").fetchone()
                state = db.execute("SELECT state FROM runs ORDER BY id LIMIT 1").fetchone()
            except sqlite3.DatabaseError as e:
                raise ValueError(f"{self.manifest}: not a drapegen manifest ({e})") from None
            if row is None or state is None:
                raise ValueError(f"{self.manifest}: not a drapegen manifest (no schema version or no run)")
            # Version 2 only added failure reasons, which this reader does not read.
            if row[0] not in ("1", "2"):
                raise ValueError(f"{self.manifest}: manifest schema version {row[0]}, this reader reads 1 and 2")
            self.run_state = state[0]
            self.read_immutable = immutable  # read as a finished file (its directory not writable here)
            # Streamed into flat arrays: a run of the default size has 576,000 items, which as Python objects took
            # about 1 GB, copied into every DataLoader worker as reference counts touched their pages. Features are
            # per sample, paths fixed-width bytes, checksums read only when they are verified.
            where = ("FROM jobs j JOIN files f ON f.job_id = j.id AND f.kind = 'exr' WHERE j.state = 'done'")
            count = db.execute("SELECT count(*) " + where).fetchone()[0]
            width = db.execute("SELECT coalesce(max(length(CAST(f.path AS BLOB))), 1) " + where).fetchone()[0]
            self.jobs = np.empty(count, dtype=np.int64)
            self.samples = np.empty(count, dtype=np.int64)
            self.slots = np.empty(count, dtype=np.int32)
            self.orientations = np.empty(count, dtype=np.int32)
            self.paths = np.empty(count, dtype=f"S{width}")
            self.checksums = np.empty(count, dtype="S64") if verify_checksums else None
            columns = "j.id, j.sample, j.slot, f.idx, f.path" + (", f.sha256" if verify_checksums else "")
            cursor = db.execute(f"SELECT {columns} {where} ORDER BY j.id, f.idx")
            i = 0
            while True:
                chunk = cursor.fetchmany(65536)
                if not chunk:
                    break
                for row in chunk:
                    self.jobs[i], self.samples[i], self.slots[i], self.orientations[i] = row[:4]
                    self.paths[i] = row[4].encode()
                    if verify_checksums:
                        self.checksums[i] = row[5].encode()
                    i += 1
            sample_rows = db.execute("SELECT sample, alpha_warp, alpha_bias, alpha_weft, beta_warp, beta_bias, "
                                     "beta_weft, density FROM samples ORDER BY sample").fetchall()
            db.execute("COMMIT")
        finally:
            db.close()
        if self.run_state != "complete":
            warnings.warn(f"{self.manifest}: the run is {self.run_state}: the dataset holds the jobs done so far "
                          "(and, by default, their mean and std)", stacklevel=2)
        sample_ids = np.array([r[0] for r in sample_rows], dtype=np.int64)
        table = np.array([features(r[1:7], r[7]) for r in sample_rows], dtype=np.float64).reshape(-1, len(FEATURES))
        self.sample_row = np.searchsorted(sample_ids, self.samples)  # each item's row of `table`
        self.sample_features = table
        raw = table[self.sample_row] if len(self.samples) else np.zeros((0, len(FEATURES)))
        self.mean = np.asarray(mean, dtype=np.float64) if mean is not None else (
            raw.mean(axis=0) if len(raw) else np.zeros(len(FEATURES)))
        if std is not None:
            self.std = np.asarray(std, dtype=np.float64)
        else:
            self.std = raw.std(axis=0) if len(raw) else np.ones(len(FEATURES))
            self.std[self.std == 0] = 1.0

    def __len__(self):
        return len(self.jobs)

    def item(self, i):
        """What item `i` is: its job, sample, slot, orientation, EXR path (relative to the manifest) and features."""
        return {"job": int(self.jobs[i]), "sample": int(self.samples[i]), "slot": int(self.slots[i]),
                "orientation": int(self.orientations[i]), "path": self.paths[i].decode(),
                "features": self.sample_features[self.sample_row[i]].tolist()}

    def __getitem__(self, i):
        path = os.path.join(self.root, self.paths[i].decode())
        if self.verify:
            with open(path, "rb") as f:
                digest = hashlib.sha256(f.read()).hexdigest()
            expected = self.checksums[i].decode()
            if digest != expected:
                raise IOError(f"{path}: checksum {digest} does not match the manifest's {expected}")
        views = torch.from_numpy(read_views(path))
        target = torch.tensor((self.sample_features[self.sample_row[i]] - self.mean) / self.std, dtype=torch.float32)
        return views, target

    def denormalise(self, target):
        """Standardised targets back to sign(k) ln|k| features."""
        return np.asarray(target) * self.std + self.mean
