#!/usr/bin/env python3
"""The first mesh's diagnoses out of a run with `drapegen diagnose --confirm-resolution N` (report.json
"mesh_confirmation"): for each ARM/diagnoses/NAME.json, OUT/diagnoses/NAME.json is the diagnosis the run made on its
first mesh, as a run without the option reports it (its own runtime), and OUT links ARM's build, captures, truth and
screen, so that `scripts/diagnosis_set.sh score OUT` and `scripts/compare_arms.py OUT:ARM` read it as the default
arm. A report without "mesh_confirmation" (the first mesh left the gap within its floors) is copied as it is.

    scripts/first_mesh.py out/p79/s99Z out/p79/s99
"""
import json
import os
import subprocess
import sys


def first_mesh(report):
    m = report.get("mesh_confirmation")
    if m is None:
        return report
    if m["reported"] == "confirming mesh":
        return m["other"]
    first = {k: v for k, v in report.items() if k != "mesh_confirmation"}
    runtime, other = dict(first["runtime"]), m["other"]["runtime"]
    for key in ("seconds", "cpu_seconds", "simulations_main_thread"):
        runtime[key] = runtime[key] - other[key]
    first["runtime"] = runtime
    return first


def main(arm, out):
    # OUT: an arm of ARM's set with no options added (its build, captures, truth and screen linked)
    setscript = os.path.join(os.path.dirname(os.path.abspath(__file__)), "diagnosis_set.sh")
    if subprocess.run([setscript, "arm", os.path.abspath(out), os.path.abspath(arm)]).returncode != 0:
        sys.exit(1)
    os.makedirs(os.path.join(out, "diagnoses"))
    n = 0
    for name in sorted(os.listdir(os.path.join(arm, "diagnoses"))):
        if not name.endswith(".json"):
            continue
        with open(os.path.join(arm, "diagnoses", name)) as fh:
            report = json.load(fh)
        with open(os.path.join(out, "diagnoses", name), "w") as fh:
            json.dump(first_mesh(report), fh, indent=2)
            fh.write("\n")
        n += 1
    print(f"first_mesh: {n} diagnoses of {arm} on their first mesh in {out}")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
