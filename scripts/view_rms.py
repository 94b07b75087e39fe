#!/usr/bin/env python3
"""The four views' disagreement per capture, read off the report.json files of diagnosis benchmark runs made with
three placements (gap_tests.view_consistency: each placement's cross-view slope and residual RMS); the truth files
are read only to label. A camera test's lead (docs/preregistrations/session70.md): the smallest RMS over the
placements at or above --threshold mm fires; it is counted per kind of capture (the sensor errors by kind).

    scripts/view_rms.py out/p72/s80 out/p72/s81 [--threshold 4.0]
"""
import argparse
import glob
import json
import os
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from diagnosis_rules import CAMERA_RMS_MM, placement_rms  # noqa: E402  (rule C reads the same)


def kind(truth):
    effects = truth.get("effects") or []
    if not effects:
        return "control", 0.0
    e = effects[0]
    return (e["name"] if truth.get("family") == "sensor" else truth.get("family", e["name"])), e.get("strength", 0.0)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="+", help="benchmark output directories (diagnoses/, truth/)")
    ap.add_argument("--threshold", type=float, default=CAMERA_RMS_MM,
                    help="mm: the smallest RMS from which the test fires")
    a = ap.parse_args()
    fired = {}
    print(f"{'capture':28} {'truth':>18} {'rms min':>8} {'mean':>6} {'slope min':>9} {'multipath':>9}  verdict")
    for run in a.runs:
        for path in sorted(glob.glob(os.path.join(run, "diagnoses", "*.json"))):
            name = os.path.basename(path)[:-5]
            with open(path) as f:
                report = json.load(f)
            with open(os.path.join(run, "truth", name + ".json")) as f:
                k, strength = kind(json.load(f))
            views = (report.get("gap_tests") or {}).get("view_consistency") or {}
            rms = placement_rms(report)
            if not rms:
                continue
            fires = min(rms) >= a.threshold
            n, m = fired.get(k, (0, 0))
            fired[k] = (n + fires, m + 1)
            print(f"{os.path.basename(run) + '/' + name:28} {k + ' ' + format(strength, '.3g'):>18} {min(rms):8.2f} "
                  f"{statistics.mean(rms):6.2f} {views.get('smallest_gain_mm', float('nan')):9.2f} "
                  f"{str(views.get('multipath', False)):>9}  {report.get('verdict')}")
    print(f"smallest RMS >= {a.threshold} mm fires on: " +
          ", ".join(f"{k} {n}/{m}" for k, (n, m) in sorted(fired.items())))


if __name__ == "__main__":
    main()
