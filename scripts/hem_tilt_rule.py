#!/usr/bin/env python3
"""Rule H, the hem's tilt (docs/DIAGNOSIS_RESULTS.md, "Session 90"): misalignment wherever the hem's height has a first
harmonic of at least --floor mm (8) on every placement of the specimen (the capture, the second, the held-out), laid on
the reports of diagnosis sets as a record. The tilts come from the reports (placement_hem_tilt_mm, builds since
session 88) or, for sets diagnosed before, from bench/hem_tilt_probe.cpp, which reads the captures only:

    build/bin/drapegen_hem_tilt_probe out/p92/s125 out/p92/s126 > out/p92/hem_tilt.csv
    scripts/hem_tilt_rule.py --tilt out/p92/hem_tilt.csv out/p92/s125 out/p92/s126
    scripts/hem_tilt_rule.py out/p93/s127 out/p93/s128      # the reports' own tilts

A specimen laid off the axis hangs more cloth, and its hem lower, on one side each time it is laid, whichever way it
was turned; a centred elastic one tilts only as far as its folds do, and an effect that tilts one placement (a curled
edge, a camera error) need not tilt the others. Prints each verdict the rule changes (right or wrong against the
truth files, read only to score), its tally, and per family the smallest placement's tilt (its range, and how many
reach the floor).
"""
import argparse
import csv
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import score_test  # noqa: E402


def tilts(path):
    """{(set, capture): [tilt of placement 0, 1, 2]} from the probe's CSV; the set is the set directory's name."""
    out = {}
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        if reader.fieldnames != ["set", "capture", "placement", "hem_tilt_mm", "outline_offset_mm"]:
            raise ValueError(f"{path}: not drapegen_hem_tilt_probe's CSV (header {reader.fieldnames})")
        for r in reader:
            out.setdefault((r["set"], r["capture"]), {})[int(r["placement"])] = float(r["hem_tilt_mm"])
    return {k: [v[p] for p in sorted(v)] for k, v in out.items()}


def rows(sets, tilt):
    """scripts/score_test.py's rows (a report and a truth file each) with the placements' tilts: the probe's where
    `tilt` is given, else the report's own; their count and the smallest."""
    out = []
    for r in score_test.rows(sets):
        if tilt is None:
            placements = r["hem_tilts"]
            if placements is None:
                raise ValueError(f"{r['set']}: {r['name']}'s report has no placement_hem_tilt_mm (an older build's): "
                                 "give --tilt with drapegen_hem_tilt_probe's CSV")
        else:
            placements = tilt.get((r["set"], r["name"]))
            if placements is None:
                raise ValueError(f"{r['set']}: {r['name']} has a report but no tilt in the probe's CSV")
        out.append(dict(r, placements=len(placements), tilt=min(placements)))
    return out


def rule(row, floor):
    """Rule H's verdict: misalignment where every placement's hem tilts by `floor` mm or more (all three seen)."""
    return "misalignment" if row["placements"] >= 3 and row["tilt"] >= floor else row["verdict"]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("sets", nargs="+", help="diagnosis sets (diagnoses/, truth/)")
    ap.add_argument("--tilt", help="drapegen_hem_tilt_probe's CSV over these sets (default: the reports' "
                    "placement_hem_tilt_mm)")
    ap.add_argument("--floor", type=float, default=8.0, help="the smallest placement's tilt that names misalignment "
                    "(mm; default 8)")
    args = ap.parse_args()
    try:
        rs = rows(args.sets, tilts(args.tilt) if args.tilt else None)
    except (OSError, ValueError) as e:
        sys.exit(f"hem_tilt_rule: {e}")
    if not rs:
        sys.exit("hem_tilt_rule: no diagnosed capture with a truth file in " + " ".join(args.sets))
    gained, lost = [], []
    for r in rs:
        v = rule(r, args.floor)
        if v == r["verdict"]:
            continue
        line = f"{r['set']} {r['name']} ({r['family']}): {r['verdict']} -> {v}, smallest tilt {r['tilt']:.2f} mm"
        (gained if v == r["family"] else lost).append(line)
    for line in gained:
        print("right: " + line)
    for line in lost:
        print("wrong: " + line)
    print(f"rule H (tilt >= {args.floor:g} mm on every placement): +{len(gained)} -{len(lost)} "
          f"over {len(rs)} captures")
    for fam in sorted({r["family"] for r in rs}):
        t = sorted(r["tilt"] for r in rs if r["family"] == fam)
        reach = sum(x >= args.floor for x in t)
        print(f"{fam}: smallest placement's tilt {t[0]:.2f}-{t[-1]:.2f} mm, {reach} of {len(t)} reach {args.floor:g}")


if __name__ == "__main__":
    main()
