#!/usr/bin/env python3
"""Diagnoses benchmark captures again with the baseline fit started at the true fabric (a benchmark tool: it reads the
truth files), and compares with the diagnoses as run (docs/DIAGNOSIS_RESULTS.md, "Session 20").

    scripts/fit_from_truth.py [--box F] [--out DIR] DRAPEGEN RUN CASE...

RUN is a benchmark run generated with three placements (captures/, truth/, diagnoses/ as drapegen_diagnosis_bench
writes them). Each CASE is diagnosed as the benchmark does (`--fine`, placement 1 the second capture, placement 2 held
out) but with `--start-alpha/--start-beta` the truth's bending:
- without --box: `--gap-only`, the fit free to leave the start: is there a fabric near the true one that explains the
  capture within the floors (the effect then is not identifiable from these captures by a gap test)?
- with --box F: the whole diagnosis with `--start-box F`, a bending known to within a factor F (an oracle for a
  cantilever test of that precision).
Reports are written to DIR/CASE.json (default RUN/from_truth or RUN/known_F) and reused if present. Prints per case:
the gate's excess and true over fitted mean alpha as run and from the truth, and the verdicts.
"""
import json
import math
import os
import subprocess
import sys


def gmean(values):
    return math.exp(sum(math.log(v) for v in values) / len(values))


def main(args):
    box = None
    out = None
    while args and args[0].startswith("--"):
        if args[0] == "--box" and len(args) > 1:
            box, args = args[1], args[2:]
        elif args[0] == "--out" and len(args) > 1:
            out, args = args[1], args[2:]
        else:
            sys.exit(__doc__)
    if len(args) < 3:
        sys.exit(__doc__)
    drapegen, run, cases = args[0], args[1], args[2:]
    out = out or os.path.join(run, f"known_{box}" if box else "from_truth")
    os.makedirs(out, exist_ok=True)
    print("| case | family | excess as run | true / fitted alpha as run | verdict as run | excess from the truth | "
          "true / fitted alpha | verdict |")
    print("|---|---|---|---|---|---|---|---|")
    for case in cases:
        with open(os.path.join(run, "truth", case + ".json")) as fh:
            truth = json.load(fh)
        with open(os.path.join(run, "diagnoses", case + ".json")) as fh:
            as_run = json.load(fh)
        report = os.path.join(out, case + ".json")
        if not os.path.exists(report):
            capture = os.path.join(run, "captures", case)
            cmd = [drapegen, "diagnose", "--capture", capture, "--second-capture", capture + ".p1",
                   "--held-out-capture", capture + ".p2", "--fine", "--json", "--jobs", "1",
                   "--start-alpha", ",".join(map(str, truth["alpha"])),
                   "--start-beta=" + ",".join(map(str, truth["beta"]))]
            cmd += ["--start-box", box] if box else ["--gap-only"]
            result = subprocess.run(cmd, capture_output=True, text=True)
            if result.returncode != 0:
                print(f"| {case} | error: {result.stderr.strip()} |")
                continue
            with open(report + ".tmp", "w") as fh:
                fh.write(result.stdout)
            os.replace(report + ".tmp", report)
        with open(report) as fh:
            again = json.load(fh)
        true_alpha = gmean(truth["alpha"])
        row = [case, truth["family"] or "none"]
        for j in (as_run, again):
            row += [f"{j['gap_tests']['excess_above_floors']:.3f}",
                    f"{true_alpha / gmean(j['baseline']['fitted']['alpha']):.2f}", j["verdict"]]
        print("| " + " | ".join(row) + " |")


if __name__ == "__main__":
    main(sys.argv[1:])
