#!/usr/bin/env python3
"""Verdicts with one candidate's refit replaced: diagnoses made again with only that candidate
(`drapegen diagnose ... --candidates EFFECT`, e.g. with `--yield-trade 5`) are ranked together with the other
candidates of a full benchmark run's report.json, against the new run's reference (the baseline fit, floors and bar
are the same computation; the script checks that the gate's excess agrees). The truth files are read only to score.
Session 19's yield-trade table (docs/DIAGNOSIS.md) was made with

    scripts/swap_candidate.py out/ytrade s17=out/s17all s18=out/s18all s19=out/s19all s20=out/s20all

where out/ytrade holds LABEL_CASE.json (e.g. s19_yield_02.json) and each LABEL=RUN names the run (diagnoses/ and
truth/) the case belongs to. The ranking is attribute()'s (confirmed, shrinkage, physical before sensor, near ties
by the refit objective); where the common bending or curl first decided, or would now, the verdict needs the full
diagnosis and is printed as "undetermined". Captures within the floors at the gate, or once the bending alone is
refitted (the bar; the common bending depends on the candidates), are "none" either way: a run's capture of that
kind needs no new report (any other does).
"""
import glob
import json
import math
import os
import sys

THRESHOLD = 0.25  # AttributionSettings::significant_shrinkage
TIE_MARGIN = 0.1  # AttributionSettings::tie_margin
COMMON_BENDING = 3  # AttributionSettings::common_bending_effects
FAMILY = {"pose": "sensor", "bias": "sensor", "multipath": "sensor", "misalign": "misalignment"}


def shrink(before, after):
    return 1 - after / before if before > 0 else 0.0


def held_out(c):
    return c["validated"]["held_out_capture"]["all_views_score_mm"]


def main(args):
    if len(args) < 2:
        sys.exit(__doc__)
    runs = dict(a.split("=", 1) for a in args[1:])
    print("| label, capture | truth (true / fitted alpha) | verdict as run | with the new refit | refit as run: scale, "
          "parameters, shrinkage | new refit |")
    print("|---|---|---|---|---|---|")
    score = {}
    files = sorted(glob.glob(os.path.join(args[0], "*.json")))
    # The candidate refitted again (captures within the floors at the gate have none to tell it).
    effects = {c["effect"] for f in files for c in json.load(open(f))["attribution"]["candidates"]}
    if len(effects) != 1:
        sys.exit(f"{args[0]}: candidates {sorted(effects)} (one effect expected: --candidates EFFECT)")
    effect = effects.pop()

    def score_none(label, case, family, verdict_as_run, why):
        """A capture whose verdict is "none" whatever the candidate does: its row and its count."""
        print(f"| {label} {case} | {family} | {verdict_as_run} | none ({why}) | - | - |")
        s = score.setdefault(family == effect, [0, 0, 0])
        s[0] += 1
        s[1] += verdict_as_run == family
        s[2] += family == "none"

    for f in files:
        label, case = os.path.basename(f)[:-5].split("_", 1)
        if label not in runs:
            continue
        new = json.load(open(f))
        old = json.load(open(os.path.join(runs[label], "diagnoses", case + ".json")))
        truth = json.load(open(os.path.join(runs[label], "truth", case + ".json")))
        family = FAMILY.get(truth["family"], truth["family"]) or "none"
        g, a = new["gap_tests"], new["attribution"]
        if abs(g["excess_above_floors"] - old["gap_tests"]["excess_above_floors"]) > 1e-9:
            sys.exit(f"{f}: the gate's excess differs from the run's (another baseline fit)")
        if new["within_floors"]:
            # Within the floors at the gate: no candidate is refitted, the verdict is "none" either way.
            score_none(label, case, family, old["verdict"], "within the floors")
            continue
        if len(a["candidates"]) != 1:
            sys.exit(f"{f}: {len(a['candidates'])} candidates (one expected: --candidates EFFECT)")
        swapped = a["candidates"][0]
        bar = a["bending_refit_bar"]
        bar_is_reference = bar["shrinkage"] > 0
        e0 = bar["validated"]["excess_above_floors"] if bar_is_reference else g["excess_above_floors"]
        h0 = (bar["validated"]["held_out_capture"] if bar_is_reference else g["held_out_capture"])["all_views_score_mm"]
        # The new run's held-out tolerance (0 before session 23) confirms the old run's candidates too.
        allowed = 1.0 + a.get("held_out_tolerance", 0.0)
        ranked, before = [], None
        for c in old["attribution"]["candidates"]:
            entry = dict(effect=c["effect"], shrinkage=shrink(e0, c["validated"]["excess_above_floors"]),
                         confirmed=held_out(c) <= allowed * h0, objective=c["objective_mm"],
                         held_out=1 - held_out(c) / h0, c=c)
            if c["effect"] == swapped["effect"]:
                before = entry
            else:
                ranked.append(entry)
        ranked.append(dict(effect=swapped["effect"], shrinkage=swapped["shrinkage"], confirmed=swapped["confirmed"],
                           objective=swapped["objective_mm"], held_out=swapped["held_out_shrinkage"], c=swapped))
        # ranks_before (attribution.hpp): confirmed, shrinkage, a physical effect before the sensor error, objective,
        # held-out shrinkage.
        ranked.sort(key=lambda c: (not c["confirmed"], -c["shrinkage"], c["effect"] == "sensor", c["objective"],
                                   -c["held_out"]))
        top = ranked[0]
        significant = [c for c in ranked if c["confirmed"] and c["shrinkage"] >= THRESHOLD]
        at_zero = [c for c in ranked if c["confirmed"] and c["c"]["validated"]["excess_above_floors"] == 0]
        if new["within_floors_after_bending_refit"]:
            verdict = "none"
        elif len(at_zero) >= COMMON_BENDING or old["attribution"].get("common_bending") or \
                old["attribution"].get("curl_first"):
            # The common bending (validated again at the median of the new scales) or curl first: not computed here.
            verdict = "undetermined"
        elif top in significant:
            tied = [c for c in significant if c["shrinkage"] == top["shrinkage"]]
            if len(tied) == 1:  # near ties (near_ties_first): the smallest refit objective within the margin
                top = min((c for c in significant if top["shrinkage"] - c["shrinkage"] <= TIE_MARGIN),
                          key=lambda c: c["objective"])
            verdict = top["effect"]
        else:
            verdict = "unexplained"
        ratio = math.exp(sum(math.log(t / f) for t, f in zip(truth["alpha"], old["baseline"]["fitted"]["alpha"])) / 3)
        strengths = ", ".join(f"{e['name']} {e.get('strength', 0):.3g}" for e in truth.get("effects", []))
        truth_text = f"{family} ({strengths + '; ' if strengths else ''}x{ratio:.1f})"

        def refit(e):
            params = ", ".join(f"{v:.2f}" for v in e["c"]["parameters"].values())
            return (f"x{e['c']['alpha_scale']:.2f}, {params}, {e['shrinkage']:.2f}"
                    + ("" if e["confirmed"] else " (not confirmed)"))

        print(f"| {label} {case} | {truth_text} | {old['verdict']} | {verdict} | "
              f"{refit(before) if before else '-'} | {refit(ranked[[r['c'] for r in ranked].index(swapped)])} |")
        s = score.setdefault(family == swapped["effect"], [0, 0, 0])
        s[0] += 1
        s[1] += old["verdict"] == family
        s[2] += verdict == family
    # A run's captures without a new report: within the floors at the gate, or once the bending alone was refitted (the
    # bar, not the common bending, which depends on the candidates), the verdict is "none" whatever the candidate does
    # (the same computation), so they need not be run again.
    covered = {os.path.basename(f)[:-5] for f in files}
    missing = []
    for label, run in sorted(runs.items()):
        for path in sorted(glob.glob(os.path.join(run, "diagnoses", "*.json"))):
            case = os.path.basename(path)[:-5]
            if f"{label}_{case}" in covered:
                continue
            old = json.load(open(path))
            bar = old["attribution"].get("bending_refit_bar") or {}
            if not (old["within_floors"] or (bar.get("validated") or {}).get("excess_above_floors") == 0):
                missing.append(f"{label}_{case}")
                continue
            truth = json.load(open(os.path.join(run, "truth", case + ".json")))
            family = FAMILY.get(truth["family"], truth["family"]) or "none"
            score_none(label, case, family, old["verdict"], "within the floors as run; not rerun")
    for own, (n, was, now) in sorted(score.items()):
        print(f"{'its own family' if own else 'other captures'}: {n}, correct as run {was}, with the new refit {now}")
    if missing:
        sys.exit(f"no new report for {', '.join(missing)} (above the floors as run: diagnose them with the candidate)")


if __name__ == "__main__":
    main(sys.argv[1:])
