#!/usr/bin/env python3
"""How the bending yield moves the drape coefficient at the diagnosis's fitting mesh (32x32) and the reality's
(60x60), on sampled fabrics (docs/PHYSICS.md, "Bending plasticity"). No truth files needed.

    scripts/yield_mesh_probe.py DRAPEGEN [--n 6] [--seed 7]

Samples N fabrics (`drapegen sample --n N --seed SEED`, at 300 g/m^2), gives fabric k the yield curvature
10, 15, 20, 25, 12, 18 /m (in turn) and the sine start of seed 700 + k, and solves each elastic and yielding at both
resolutions (`--coarse-start 0`). Prints one line per fabric: the yield's shift of the drape coefficient on each mesh.
"""
import argparse
import csv
import json
import os
import subprocess
import sys
import tempfile

YIELDS = [10, 15, 20, 25, 12, 18]


def simulate(drapegen, alpha, beta, seed, resolution, yield_curvature):
    command = [drapegen, "simulate", "--json", "--alpha", alpha, "--beta=" + beta, "--init", "sine", "--seed",
               str(seed), "--coarse-start", "0", "--resolution", str(resolution)]
    if yield_curvature is not None:
        command += ["--effect", f"yield={yield_curvature}"]
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"{' '.join(command)} failed: {done.stderr.strip()}")
    return json.loads(done.stdout)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("drapegen")
    parser.add_argument("--n", type=int, default=6)
    parser.add_argument("--seed", type=int, default=7)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as scratch:
        table = os.path.join(scratch, "fabrics.csv")
        subprocess.run([args.drapegen, "sample", "--n", str(args.n), "--seed", str(args.seed), "--out", table],
                       check=True, capture_output=True)
        rows = list(csv.DictReader(open(table)))
    for k, row in enumerate(rows):
        alpha = ",".join(row[c] for c in ("alpha_warp", "alpha_bias", "alpha_weft"))
        beta = ",".join(row[c] for c in ("beta_warp", "beta_bias", "beta_weft"))
        yield_curvature = YIELDS[k % len(YIELDS)]
        shift = {}
        for resolution in (32, 60):
            elastic = simulate(args.drapegen, alpha, beta, 700 + k, resolution, None)
            plastic = simulate(args.drapegen, alpha, beta, 700 + k, resolution, yield_curvature)
            shift[resolution] = plastic["drape_coefficient"] - elastic["drape_coefficient"]
        print(json.dumps({"fabric": k, "yield_per_m": yield_curvature, "shift_32": round(shift[32], 4),
                          "shift_60": round(shift[60], 4)}), flush=True)


if __name__ == "__main__":
    main()
