#!/usr/bin/env python3
"""Measures of a drape PLY written by `drapegen simulate --out` (binary x y z u v per vertex, metres) that the
diagnosis docs quote (docs/DIAGNOSIS.md, "Curl, friction and misalignment, measured again"):

- centre offset: the mean horizontal position minus rest position of the vertices within 40 mm of the specimen's
  centre (with --drift DX,DY in mm, as given to simulate, also the slide beyond the placement drift: the specimen
  sliding on the platform under finite friction; 0 with adhesion);
- hem: mean height and radius of the boundary vertices;
- edge band: mean chord from each boundary vertex to the vertex 30 mm inside it (rest), away from the corners
  (30 mm when the band hangs straight, less when it rolls).

Needs numpy. Assumes the simulate default rotation 0 (rest and world axes agree)."""
import argparse
import sys

import numpy as np

HALF = 0.15   # the specimen's half size, m
BAND = 0.03   # m


def read_vertices(path):
    with open(path, "rb") as f:
        count, fmt = None, None
        while True:
            line = f.readline()
            if not line:
                sys.exit(f"{path}: no end_header: not a PLY file")
            line = line.decode("ascii", "replace").strip()
            if line.startswith("format"):
                fmt = line.split()[1]
            if line.startswith("element vertex"):
                count = int(line.split()[-1])
            if line == "end_header":
                break
        if fmt != "binary_little_endian" or count is None:
            sys.exit(f"{path}: expected a binary little-endian PLY with vertices (drapegen simulate --out)")
        data = np.frombuffer(f.read(count * 40), dtype="<f8")
        if data.size != count * 5:
            sys.exit(f"{path}: truncated vertex data")
        return data.reshape(count, 5)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("ply")
    p.add_argument("--drift", default="0,0", help="placement drift DX,DY in mm (simulate --drift)")
    a = p.parse_args()
    v = read_vertices(a.ply)
    pos, rest = v[:, :3], v[:, 3:5]
    centre = np.hypot(rest[:, 0], rest[:, 1]) < 0.04
    offset = (pos[centre, :2] - rest[centre]).mean(axis=0) * 1e3
    slide = offset - np.array([float(s) for s in a.drift.split(",")])
    boundary = np.abs(rest).max(axis=1) > HALF - 1e-6
    chords = []
    for i in np.flatnonzero(boundary):
        r = rest[i]
        if np.abs(r).min() > HALF - BAND - 0.01:
            continue  # a corner
        axis = int(np.argmax(np.abs(r)))
        target = r.copy()
        target[axis] -= np.sign(r[axis]) * BAND
        j = int(np.argmin(((rest - target) ** 2).sum(axis=1)))
        chords.append(np.linalg.norm(pos[i] - pos[j]))
    print(f"centre offset {offset[0]:.1f}, {offset[1]:.1f} mm; slide beyond the drift {slide[0]:.1f}, "
          f"{slide[1]:.1f} mm (|slide| {np.hypot(*slide):.1f} mm)")
    print(f"hem: mean z {pos[boundary, 2].mean() * 1e3:.1f} mm, mean radius "
          f"{np.hypot(pos[boundary, 0], pos[boundary, 1]).mean() * 1e3:.1f} mm; edge band chord "
          f"{np.mean(chords) * 1e3:.1f} mm over {BAND * 1e3:.0f} mm")


if __name__ == "__main__":
    main()
