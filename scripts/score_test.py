#!/usr/bin/env python3
"""A registered test's per-capture table and its summary, read off the report.json files of diagnosis sets made
under the protocol of sessions 59-88 (scripts/diagnosis_set.sh: three placements, turned over, `--second-placement`);
the truth files are read only to score. What docs/preregistrations/ score as "the default", "each signature's share",
"rule O's share" and "the record" (until session 88 a script in each test's out/ directory, lost with it once).

    scripts/score_test.py out/p90/s121 out/p90/s122            # the table, then the summary
    scripts/score_test.py --summary-only out/p90/s121 out/p90/s122
    scripts/score_test.py --misses 88 out/p90/s121 out/p90/s122 >> docs/results/misses_80_126.csv
    scripts/score_test.py --named-controls 88 out/p90/s121 out/p90/s122 >> docs/results/controls_80_126.csv
    scripts/score_test.py --set-counts 88 out/p90/s121 out/p90/s122 >> docs/results/sets_80_126.csv

Columns: the truth (the sensor error's kind; the effect's strength), the verdict as run (a signature's name where
one set it: turn_over = rule U, alternation = rule A, off_centre = rules E, D, D2, hem_tilt = rule H) and the refits'
verdict, whether the gap lay within the floors at the gate (`within`) or once the bending was refitted (`bend`), the
region as run against the truth's regions (`moved` where rule O moved it to the hem), the first and third placements'
rises of the drape coefficient and the alternation, the hem centre's ratio to its floor and its offset in mm, the
smallest view RMS over the placements (the camera reading) and the diagnosis's CPU seconds. The summary has the
confusion matrix as run (docs/DIAGNOSIS.md's, pooled). --misses SESSION and --named-controls SESSION print instead
the rows the pooled matrix's CSV files take (docs/results/README.md): each effect capture not named right, each
control not named none; --set-counts SESSION the rows of the sets' ledger: how many captures of each family each set
held (scripts/pooled.py sums the three files into the pooled family table and confusion matrix).
"""
import argparse
import glob
import json
import os
import re
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from diagnosis_rules import (ALTERNATION, CAMERA_RMS_MM, FAMILY, LATER, OFF_CENTRE, OFF_CENTRE_MM,  # noqa: E402
                             RISE, SIGNATURES, off_centre_mm, off_centre_ratio, placement_rms, print_matrix,
                             third_rise, turn_over_alternation, turn_over_rise)
from pooled import FAMILIES  # noqa: E402

NO_EFFECT = ("none", "unexplained")
PLACEMENT = re.compile(r"\.p\d+\.json$")  # a later placement's own report (the bench names it CASE.pK.json)


def capture(run, path):
    """One capture's row (a dict) from its report and truth; None where the truth file is missing."""
    name = os.path.basename(path)[:-len(".json")]
    truth_path = os.path.join(run, "truth", name + ".json")
    if not os.path.exists(truth_path):
        return None
    with open(path) as f:
        j = json.load(f)
    with open(truth_path) as f:
        truth = json.load(f)
    effects = truth.get("effects") or []
    family = FAMILY.get(truth.get("family"), truth.get("family")) or "none"
    if not effects:
        family = "none"
    kind = effects[0]["name"] if effects and family == "sensor" else ""
    # Where two signatures are recorded (rule A withdrew the refits' yield, then rule E or D named misalignment), the
    # last one set the verdict and the first one's record holds the refits' own.
    recorded = [key for key in SIGNATURES if j.get(key)]
    signature = recorded[-1] if recorded else None
    loc = j.get("localisation") or {}
    rms = placement_rms(j)
    return {
        "set": os.path.basename(os.path.normpath(run)), "name": name, "family": family, "kind": kind,
        "strength": effects[0].get("strength", 0.0) if effects else 0.0,
        "verdict": j["verdict"], "signature": signature,
        "refits": j[recorded[0]]["refits_verdict"] if recorded else j["verdict"],
        "within": bool(j.get("within_floors")), "bend": bool(j.get("within_floors_after_bending_refit")),
        "region": loc.get("region"), "regions": sorted(truth.get("regions") or []),
        "moved": bool(loc.get("moved_by_offset")),
        "rise": turn_over_rise(j), "third": third_rise(j), "alternation": turn_over_alternation(j),
        "ratio": off_centre_ratio(j), "offset_mm": off_centre_mm(j),
        "view_rms": min(rms) if rms else None,
        "cpu_s": ((j.get("runtime") or {}).get("cpu_seconds")),
        "hem_tilts": j.get("placement_hem_tilt_mm"),
    }


def seed_of(run):
    """The set's seed from its bench options (set.args, one word a line); None where it does not say."""
    try:
        with open(os.path.join(run, "set.args")) as f:
            words = f.read().split()
    except OSError:
        return None
    return words[words.index("--seed") + 1] if "--seed" in words[:-1] else None


def rows(runs):
    names = [os.path.basename(os.path.normpath(run)) for run in runs]
    if len(set(names)) != len(names):
        sys.exit("score_test: two sets share a name (" + " ".join(runs) + "): the per-set lines would merge them")
    out = []
    for run in runs:
        seed = seed_of(run)
        for path in sorted(glob.glob(os.path.join(run, "diagnoses", "*.json"))):
            if PLACEMENT.search(path):
                continue
            row = capture(run, path)
            if row:
                out.append(dict(row, seed=seed))
            else:
                print(f"score_test: {path} has no truth file: not scored", file=sys.stderr)
    return out


def right(row):
    return row["verdict"] == row["family"]


def region_right(row):
    return row["region"] in row["regions"]


def fmt(x, spec):
    return "-" if x is None else format(x, spec)


def table(rs):
    print(f"{'set':6s} {'capture':16s} {'truth':18s} {'verdict':24s} {'refits':13s} {'floors':11s} "
          f"{'region':22s} {'rise':>7s} {'third':>7s} {'alt':>7s} {'ratio':>5s} {'mm':>6s} {'view':>5s} {'cpu':>5s}")
    for r in rs:
        truth = r["family"] + (f" {r['kind']}" if r["kind"] else "") + (
            f" {r['strength']:.3g}" if r["family"] != "none" else "")
        verdict = r["verdict"] + (f" ({r['signature']})" if r["signature"] else "") + (
            "" if right(r) else " X")
        floors = ("within" if r["within"] else "above") + ("/bend" if r["bend"] and not r["within"] else "")
        region = f"{r['region']}{'*' if r['moved'] else ''} " + (
            "ok" if region_right(r) or r["family"] == "none" else "/".join(r["regions"]))
        print(f"{r['set']:6s} {r['name']:16s} {truth:18s} {verdict:24s} {r['refits']:13s} {floors:11s} {region:22s} "
              f"{fmt(r['rise'], '+.4f'):>7s} {fmt(r['third'], '+.4f'):>7s} {fmt(r['alternation'], '+.4f'):>7s} "
              f"{fmt(r['ratio'], '.2f'):>5s} {fmt(r['offset_mm'], '.2f'):>6s} {fmt(r['view_rms'], '.2f'):>5s} "
              f"{fmt(r['cpu_s'], '.0f'):>5s}")
    print("(X: named wrong; region *: moved to the hem by rule O; floors: within or above them at the gate, "
          "/bend: within once the bending was refitted)")


def count(rs, pred):
    return sum(1 for r in rs if pred(r))


def share(rs, pred, label):
    """`label`: how many of `rs` are right, with the wrong ones named."""
    wrong = [f"{r['set']} {r['name']} ({r['family']})" for r in rs if not pred(r)]
    return f"{label} {len(rs) - len(wrong)} right, {len(wrong)} wrong" + (f": {', '.join(wrong)}" if wrong else "")


def record(rs, key, floor):
    """Per kind of capture: how many reach `floor` on `key`, and the largest value of those that do not."""
    kinds = {}
    for r in rs:
        kinds.setdefault(r["family"], []).append(r[key])
    parts = []
    for family in sorted(kinds):
        values = [v for v in kinds[family] if v is not None]
        below = [v for v in values if v < floor]
        parts.append(f"{family} {sum(v >= floor for v in values)}/{len(kinds[family])}"
                     + (f" (max below {max(below):.4g})" if below else ""))
    return ", ".join(parts)


def summary(rs):
    effects = [r for r in rs if r["family"] != "none"]
    controls = [r for r in rs if r["family"] == "none"]
    above = [r for r in effects if not r["within"]]
    print(f"\ntop-1 {count(effects, right)} of {len(effects)} effect captures"
          + "".join(f"; {s} {count([r for r in effects if r['set'] == s], right)} of "
                    f"{count(effects, lambda r, s=s: r['set'] == s)}" for s in sorted({r['set'] for r in effects})))
    print(f"above the floors at the gate: {count(above, right)} of {len(above)} named right; within them "
          f"{len(effects) - len(above)} ({count(effects, lambda r: r['within'] and r['verdict'] in NO_EFFECT)} "
          f"named no effect)")
    families = sorted({r["family"] for r in effects})
    by_family = {f: [r for r in effects if r["family"] == f] for f in families}
    print("families: " + ", ".join(f"{f} {count(rs_f, right)}/{len(rs_f)}" for f, rs_f in by_family.items()))
    print("\nthe confusion matrix, as run (rows the truth):")
    print_matrix([(r["family"], r["verdict"]) for r in rs], top1=True)
    print()
    sensors = [r for r in effects if r["family"] == "sensor"]
    if sensors:
        print("sensor kinds: " + ", ".join(f"{r['set']} {r['name']} {r['kind']} -> {r['verdict']}" for r in sensors))
    if controls:
        print(f"controls: {count(controls, lambda r: r['verdict'] == 'none')} of {len(controls)} named none, "
              f"{count(controls, lambda r: r['within'])} within the floors at the gate"
              + "".join(f"; {r['set']} {r['name']} named {r['verdict']}" for r in controls if r["verdict"] != "none"))
    print(f"region as run: {count(effects, region_right)} of {len(effects)}")
    for s in sorted({r["set"] for r in effects}):
        cpu = [r["cpu_s"] for r in effects if r["set"] == s and r["cpu_s"] is not None]
        if cpu:
            print(f"CPU per effect capture, {s}: median {statistics.median(cpu):.0f} s, max {max(cpu):.0f} s "
                  f"({len(cpu)} captures)")
    cpu = [r["cpu_s"] for r in rs if r["cpu_s"] is not None]
    if cpu:
        print(f"CPU per capture, all: median {statistics.median(cpu):.0f} s, max {max(cpu):.0f} s")
    for key in SIGNATURES:
        set_by = [r for r in rs if r["signature"] == key]
        print(share(set_by, right, f"signature {key}: set {len(set_by)} verdicts,"))
    moved = [r for r in rs if r["moved"] and r["family"] != "none"]
    print(share(moved, region_right, f"rule O (moved_by_offset): moved {len(moved)} gaps,")
          + f"; without it (skirt) right: {count(moved, lambda r: 'skirt' in r['regions'])}"
          + f"; controls moved {count(controls, lambda r: r['moved'])}")
    print(f"first rise >= {RISE}: " + record(rs, "rise", RISE))
    print(f"alternation >= {ALTERNATION}: " + record(rs, "alternation", ALTERNATION))
    print(f"third placement's rise >= {LATER}: " + record(rs, "third", LATER))
    print(f"hem centre ratio >= {OFF_CENTRE}: " + record(rs, "ratio", OFF_CENTRE))
    print(f"hem centre offset >= {OFF_CENTRE_MM} mm: " + record(rs, "offset_mm", OFF_CENTRE_MM))
    camera = [dict(r, family=r["kind"] or r["family"]) for r in rs]
    print(f"smallest view RMS >= {CAMERA_RMS_MM} mm: " + record(camera, "view_rms", CAMERA_RMS_MM))


def floors(row):
    return "within" if row["within"] else ("above (within once refitted)" if row["bend"] else "above")


def misses(rs, session):
    """docs/results/misses_*.csv rows: session, seed, capture, truth, verdict, floors, where it is recorded."""
    return [f"{session},{r['seed']},{r['name']},{r['family']},{r['verdict']},{floors(r)},session{session}.tar.xz"
            for r in rs if r["family"] != "none" and not right(r)]


def named_controls(rs, session):
    """docs/results/controls_*.csv rows: session, seed, capture, verdict, where it is recorded."""
    return [f"{session},{r['seed']},{r['name']},{r['verdict']},session{session}.tar.xz"
            for r in rs if r["family"] == "none" and r["verdict"] != "none"]


ORDER = FAMILIES + ["none"]  # the ledger's order within a set, as scripts/pooled.py prints its tables


def set_counts(rs, session):
    """docs/results/sets_*.csv rows: session, seed, family, captures, where they are recorded (ORDER within a set)."""
    counts = {}
    for r in rs:
        counts[(r["seed"], r["family"])] = counts.get((r["seed"], r["family"]), 0) + 1
    seeds = sorted({seed for seed, _ in counts}, key=int)
    return [f"{session},{seed},{fam},{counts[(seed, fam)]},session{session}.tar.xz"
            for seed in seeds for fam in ORDER if (seed, fam) in counts]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="+", help="diagnosis sets (diagnoses/, truth/)")
    ap.add_argument("--summary-only", action="store_true", help="the summary without the per-capture table")
    rows_only = ap.add_mutually_exclusive_group()
    rows_only.add_argument("--misses", metavar="SESSION", help="only the misses' CSV rows (docs/results/misses_*.csv)")
    rows_only.add_argument("--named-controls", metavar="SESSION",
                           help="only the CSV rows of the controls not named none (docs/results/controls_*.csv)")
    rows_only.add_argument("--set-counts", metavar="SESSION",
                           help="only the sets' ledger rows, captures per family (docs/results/sets_*.csv)")
    args = ap.parse_args()
    rs = rows(args.runs)
    if not rs:
        sys.exit("score_test: no diagnosed capture with a truth file in " + " ".join(args.runs))
    if args.misses or args.named_controls or args.set_counts:
        if any(r["seed"] is None for r in rs):
            sys.exit("score_test: a set has no --seed in its set.args: its rows would have no seed")
        if args.misses:
            lines = misses(rs, args.misses)
        elif args.named_controls:
            lines = named_controls(rs, args.named_controls)
        else:
            lines = set_counts(rs, args.set_counts)
        for line in lines:
            print(line)
        return
    if not args.summary_only:
        table(rs)
    summary(rs)


if __name__ == "__main__":
    main()
