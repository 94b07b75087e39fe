#!/usr/bin/env python3
"""Would confirming a candidate whose held-out placement lies within the floors change the verdicts? Reads the
report.json files of diagnosis runs made with three placements (placement 2 held out) and the benchmark's case names
(NAME = FAMILY_NN: the family is the truth). Exploratory, a derivation for a pre-registered test, not the diagnosis's
rule (docs/DIAGNOSIS_RESULTS.md, "Session 61").

Two rules, each an approximation of attribute() (attribution.cpp) from what a report holds:
- as run: candidates ranked confirmed first, then the larger shrinkage, a physical effect before the sensor error,
  then the smaller refit objective; a confirmed curl candidate that shrinks by the threshold first where the
  captures' folds are less alike; named if confirmed and shrinking by the threshold. Within the floors, or within
  them once the bending alone is refitted: none. It must reproduce every verdict as run (printed: MISMATCH if not).
- widened: the same, with a candidate also confirmed where its validated drape on the held-out capture is within the
  gate's floors (shape distance and stable term), however it compares with the reference there. Not recomputed: the
  common bending (more confirmed candidates within the floors could trigger it).

Usage: confirm_within_floors.py DIR... (each holding NAME.json reports)
"""
import glob
import json
import os
import sys

THRESHOLD = 0.25  # AttributionSettings::significant_shrinkage


def within_floors(held_out, floors):
    return (held_out is not None and held_out["shape"] <= floors["shape"]
            and held_out["stable_mm"] <= floors["stable_mm"])


def verdict(report, widened):
    if report["within_floors"] or report.get("within_floors_after_bending_refit"):
        return "none"
    floors = report["floors"]
    ranked = []
    for c in report["attribution"]["candidates"]:
        confirmed = c["confirmed"] or (widened and within_floors(c["validated"].get("held_out_capture"), floors))
        ranked.append((c, confirmed))
    ranked.sort(key=lambda t: (not t[1], -t[0]["shrinkage"], t[0]["effect"] == "sensor", t[0]["objective_mm"]))
    if report["gap_tests"].get("fold_repeatability", {}).get("folds_less_alike"):
        for entry in ranked:
            c, confirmed = entry
            if c["effect"] == "curl" and confirmed and c["shrinkage"] >= THRESHOLD:
                ranked.remove(entry)
                ranked.insert(0, entry)
                break
    c, confirmed = ranked[0]
    return c["effect"] if confirmed and c["shrinkage"] >= THRESHOLD else "unexplained"


def main(dirs):
    total = reproduced = right_run = right_widened = 0
    for d in dirs:
        for path in sorted(glob.glob(os.path.join(d, "*.json"))):
            with open(path) as f:
                report = json.load(f)
            truth = os.path.basename(path)[:-5].split("_")[0]
            as_run, widened = verdict(report, False), verdict(report, True)
            total += 1
            reproduced += as_run == report["verdict"]
            if as_run != report["verdict"]:
                print(f"MISMATCH {path}: run {report['verdict']}, recomputed {as_run}")
            right_run += as_run == truth
            right_widened += widened == truth
            if widened != as_run:
                print(f"CHANGE {path}: {as_run} -> {widened} (truth {truth})")
    print(f"{total} reports; verdicts as run reproduced: {reproduced}; right as run: {right_run}; "
          f"right widened: {right_widened}")
    return 0 if total > 0 else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
