#!/usr/bin/env python3
"""Solves the yield captures' specimens again, elastic and yielding, at the diagnosis's fitting mesh (32x32) and the
reality's (60x60), from each capture's own initial state (a benchmark tool: it reads the truth files). Shows how much
of the reality's yield effect the diagnosis's yield candidate can reproduce on its coarser mesh
(docs/DIAGNOSIS_RESULTS.md, "Session 52").

    scripts/yield_resolution.py DRAPEGEN RUN [--lagged-updates N] [--load-steps N]

RUN is a benchmark run (truth/ as drapegen_diagnosis_bench writes it); every truth/yield_NN.json (placement 0) is
solved four times with `drapegen simulate --coarse-start 0` (no cascade, as both the reality and the refits solve a
yielding drape). Prints one JSON line per case: the drape coefficient, fold count and last relative lagged change of
the elastic and the yielding drape at each resolution, and the yield's shift of the drape coefficient.
--lagged-updates and --load-steps are passed to every solve (drapegen simulate's options).
"""
import glob
import json
import math
import os
import subprocess
import sys


def solve(drapegen, truth, resolution, yield_curvature, extra):
    state = truth["initial_state"]
    command = [drapegen, "simulate", "--json", "--coarse-start", "0", "--resolution", str(resolution),
               "--alpha", ",".join(repr(a) for a in truth["alpha"]),
               "--beta=" + ",".join(repr(b) for b in truth["beta"]),
               "--density", repr(truth["density_g_per_m2"]), "--init", state["shape"], "--seed", str(state["seed"]),
               "--rotation", repr(math.degrees(state["rotation_rad"])),
               "--drift", ",".join(repr(d) for d in truth["drift_mm"])]
    if yield_curvature is not None:
        command += ["--effect", f"yield={yield_curvature!r}"]
    command += extra
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"{' '.join(command)} failed: {done.stderr.strip()}")
    d = json.loads(done.stdout)
    return {"dc": round(d["drape_coefficient"], 4), "folds": d["folds"], "lagged_change": round(d["lagged_change"], 2)}


def main(args):
    extra = []
    for option in ("--lagged-updates", "--load-steps"):
        if option in args:
            i = args.index(option)
            extra += [option, str(int(args[i + 1]))]
            del args[i:i + 2]
    if len(args) != 2:
        sys.exit(__doc__)
    drapegen, run = args
    files = sorted(glob.glob(os.path.join(run, "truth", "yield_[0-9][0-9].json")))
    if not files:
        sys.exit(f"no truth/yield_NN.json in {run}")
    for path in files:
        truth = json.load(open(path))
        strength = next(e["strength"] for e in truth["effects"] if e["name"] == "yield")
        row = {"case": os.path.basename(path)[:-5], "yield_per_m": round(strength, 2)}
        for resolution in (32, 60):
            elastic = solve(drapegen, truth, resolution, None, extra)
            yielding = solve(drapegen, truth, resolution, strength, extra)
            row[f"elastic_{resolution}"] = elastic
            row[f"yield_{resolution}"] = yielding
            row[f"shift_{resolution}"] = round(yielding["dc"] - elastic["dc"], 4)
        print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
