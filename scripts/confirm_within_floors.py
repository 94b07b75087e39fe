#!/usr/bin/env python3
"""Would confirming a candidate whose held-out placement lies within the floors change the verdicts? Reads the
report.json files of diagnosis runs made with three placements (placement 2 held out) and the benchmark's case names
(NAME = FAMILY_NN: the family is the truth). Exploratory, a derivation for a pre-registered test, not the diagnosis's
rule (docs/DIAGNOSIS_RESULTS.md, "Session 61").

Two rules, each an approximation of attribute() (attribution.cpp) from what a report holds:
- default: candidates ranked confirmed first, then the larger shrinkage, a physical effect before the sensor error,
  then the smaller refit objective, then the larger held-out shrinkage; near ties (attribution.near_tie.margin) to the
  smallest objective; a confirmed curl candidate that shrinks by the threshold first where the
  captures' folds are less alike; named if confirmed and shrinking by the threshold. Within the floors, or within
  them once the bending alone is refitted: none. It must reproduce every verdict as run (printed: MISMATCH if not).
- widened: the same, with a candidate also confirmed where its validated drape on the held-out capture is within the
  gate's floors (shape distance and stable term), however it compares with the reference there (`drapegen diagnose
  --confirm-within-floors`). The common bending is read off the report, never recomputed (see below).

A report of `drapegen diagnose --confirm-within-floors` (attribution.confirm_within_floors true; each candidate's
confirmed_by) ran the widened rule: it is checked against "widened", and the default's verdict is derived from it
(confirmed_by "held_out_score" alone confirms). The refits do not depend on the rule; the common bending does, and is
taken from the report where the default's confirmed candidates within the floors are the same as the report's (or
fewer than the count it asks: then none ran); otherwise the default's verdict is printed as UNKNOWN (run it).

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


def confirmed_by_score(candidate):
    """Confirmed by the default rule: the held-out score within the tolerance of the reference's."""
    return candidate.get("confirmed_by", "held_out_score" if candidate["confirmed"] else None) == "held_out_score"


def near_ties_first(ranked, margin):
    """attribution.cpp's near_ties_first on (candidate, confirmed) pairs in ranks_before's order."""
    if not ranked or not ranked[0][1] or margin <= 0:
        return
    if len(ranked) > 1 and ranked[1][1] and ranked[1][0]["shrinkage"] == ranked[0][0]["shrinkage"]:
        return
    lowest = ranked[0][0]["shrinkage"] - margin
    best = 0
    for i in range(1, len(ranked)):
        c, confirmed = ranked[i]
        if (confirmed and c["shrinkage"] >= THRESHOLD and c["shrinkage"] >= lowest
                and c["objective_mm"] < ranked[best][0]["objective_mm"]):
            best = i
    ranked.insert(0, ranked.pop(best))


def verdict(report, widened):
    """The verdict under a rule, or None where it needs a common bending the report did not run."""
    if report["within_floors"]:
        return "none"
    attribution = report["attribution"]
    floors = report["floors"]
    ran_widened = bool(attribution.get("confirm_within_floors"))
    ranked = []
    for c in attribution["candidates"]:
        confirmed = confirmed_by_score(c) or (widened and within_floors(c["validated"].get("held_out_capture"), floors))
        ranked.append((c, confirmed))
    bar = attribution["bending_refit_bar"]["validated"]
    if bar is not None and bar["excess_above_floors"] == 0:
        return "none"
    # The common bending: the confirmed candidates each within the floors, where there are enough of them.
    at_least = attribution.get("common_bending_effects") or 0
    shared = sorted(c["effect"] for c, confirmed in ranked if confirmed and c["validated"]["excess_above_floors"] == 0)
    common = attribution.get("common_bending")
    if at_least and len(shared) >= at_least:
        if common is None or sorted(common["effects"]) != shared:
            if widened == ran_widened:
                raise RuntimeError("the report's common bending does not match its own candidates")
            return None
        if common["within_floors"]:
            return "none"
    elif widened == ran_widened and report.get("within_floors_after_bending_refit"):
        raise RuntimeError("within the floors after the bending refit, but neither the bar nor a common bending is")
    ranked.sort(key=lambda t: (not t[1], -t[0]["shrinkage"], t[0]["effect"] == "sensor", t[0]["objective_mm"],
                               -t[0]["held_out_shrinkage"]))
    near_ties_first(ranked, (attribution.get("near_tie") or {}).get("margin", 0.0))
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
    total = reproduced = right_default = right_widened = unknown = 0
    for d in dirs:
        for path in sorted(glob.glob(os.path.join(d, "*.json"))):
            with open(path) as f:
                report = json.load(f)
            truth = os.path.basename(path)[:-5].split("_")[0]
            ran_widened = bool(report["attribution"].get("confirm_within_floors"))
            default, widened = verdict(report, False), verdict(report, True)
            total += 1
            as_run = widened if ran_widened else default
            # Rules U, A and E, where they set the verdict: the first one's record holds the refits' verdict.
            signature = report.get("turn_over") or report.get("alternation") or report.get("off_centre") or {}
            refits = signature.get("refits_verdict", report["verdict"])
            reproduced += as_run == refits
            if as_run != refits:
                print(f"MISMATCH {path}: run {refits}, recomputed {as_run}")
            for arm, value in (("default", default), ("widened", widened)):
                if value is None:
                    unknown += 1
                    print(f"UNKNOWN {path}: the {arm} rule's common bending is not the report's (truth {truth})")
            right_default += default == truth
            right_widened += widened == truth
            if None not in (default, widened) and widened != default:
                print(f"CHANGE {path}: {default} -> {widened} (truth {truth})")
    print(f"{total} reports; verdicts as run reproduced: {reproduced}; right by default: {right_default}; "
          f"right widened: {right_widened}{f'; {unknown} unknown (not counted right)' if unknown else ''}")
    return 0 if total > 0 and reproduced == total else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
