#!/usr/bin/env python3
"""The pooled figures of the registered diagnosis tests (docs/DIAGNOSIS.md: "Top-1 by family" and the confusion
matrix), summed from the three ledgers in docs/results/ rather than by hand:

- sets_*.csv: session, seed, family, captures, source: how many captures of each family each set held as scored;
- misses_*.csv: session, seed, capture, truth, verdict, floors, source: each effect capture not named right;
- controls_*.csv: session, seed, capture, verdict, source: each control (family "none") not named none.

    scripts/pooled.py docs/results/sets_80_126.csv docs/results/misses_80_126.csv docs/results/controls_80_126.csv

A family's right verdicts are its captures less its misses; the matrix's diagonal is those, its other cells the
misses (and the named controls) by verdict. The ledgers are checked against each other first: a miss or a named
control whose set and family the sets' ledger has no capture of, or more misses than captures, is an error (exit 1).
scripts/score_test.py --set-counts, --misses and --named-controls print a new test's rows of the three.
"""
import argparse
import csv
import sys

FAMILIES = ["yield", "shear", "curl", "friction", "misalignment", "sensor"]
VERDICTS = ["none", "unexplained"] + FAMILIES


def read(path, columns):
    """The rows of a ledger as dicts; an error naming the file where its header is not `columns`."""
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        if reader.fieldnames != columns:
            raise ValueError(f"{path}: header {','.join(reader.fieldnames or [])}, expected {','.join(columns)}")
        return list(reader)


def tally(sets, misses, controls):
    """(captures, cells, errors): captures per family, the matrix's cells {(truth, verdict): n}, and every
    inconsistency between the ledgers as a message."""
    errors = []
    held = {}
    for r in sets:
        key = (r["seed"], r["family"])
        if r["family"] not in FAMILIES + ["none"]:
            errors.append(f"sets: seed {r['seed']}: unknown family '{r['family']}'")
        if key in held:
            errors.append(f"sets: seed {r['seed']} family {r['family']} listed twice")
        held[key] = held.get(key, 0) + int(r["captures"])
    missed = {}
    cells = {}
    for r in misses:
        truth, verdict = r["truth"], r["verdict"]
        if verdict not in VERDICTS or truth == verdict:
            errors.append(f"misses: seed {r['seed']} {r['capture']}: verdict '{verdict}' for truth '{truth}'")
        missed[(r["seed"], truth)] = missed.get((r["seed"], truth), 0) + 1
        cells[(truth, verdict)] = cells.get((truth, verdict), 0) + 1
    for r in controls:
        if r["verdict"] not in VERDICTS or r["verdict"] == "none":
            errors.append(f"controls: seed {r['seed']} {r['capture']}: verdict '{r['verdict']}'")
        missed[(r["seed"], "none")] = missed.get((r["seed"], "none"), 0) + 1
        cells[("none", r["verdict"])] = cells.get(("none", r["verdict"]), 0) + 1
    for (seed, family), n in sorted(missed.items()):
        if n > held.get((seed, family), 0):
            errors.append(f"seed {seed}: {n} {family} captures not named right, "
                          f"but the sets' ledger holds {held.get((seed, family), 0)}")
    captures = {}
    for (_, family), n in held.items():
        captures[family] = captures.get(family, 0) + n
    for family in FAMILIES + ["none"]:
        right = captures.get(family, 0) - sum(n for (t, _), n in cells.items() if t == family)
        cells[(family, family)] = right
    return captures, cells, errors


def print_tables(captures, cells):
    effects = sum(captures.get(f, 0) for f in FAMILIES)
    right = sum(cells[(f, f)] for f in FAMILIES)
    print(f"top-1 {right} of {effects} effect captures ({100 * right / max(effects, 1):.1f}%); controls named none "
          f"{cells[('none', 'none')]} of {captures.get('none', 0)}\n")
    print("| family | right | captures |\n|---|---|---|")
    for f in FAMILIES:
        print(f"| {f} | {cells[(f, f)]} | {captures.get(f, 0)} |")
    print("\n| truth \\ verdict | " + " | ".join(VERDICTS) + " | captures |")
    print("|---" * (len(VERDICTS) + 2) + "|")
    for t in ["none"] + FAMILIES:
        row = [f"**{cells.get((t, v), 0)}**" if v == t else str(cells.get((t, v), 0)) for v in VERDICTS]
        label = "none (controls)" if t == "none" else t
        print(f"| {label} | " + " | ".join(row) + f" | {captures.get(t, 0)} |")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("sets", help="the sets' ledger (docs/results/sets_*.csv)")
    ap.add_argument("misses", help="the misses (docs/results/misses_*.csv)")
    ap.add_argument("controls", help="the controls not named none (docs/results/controls_*.csv)")
    args = ap.parse_args()
    try:
        sets = read(args.sets, ["session", "seed", "family", "captures", "source"])
        misses = read(args.misses, ["session", "seed", "capture", "truth", "verdict", "floors", "line"])
        controls = read(args.controls, ["session", "seed", "capture", "verdict", "line"])
    except (OSError, ValueError) as e:
        sys.exit(f"pooled: {e}")
    captures, cells, errors = tally(sets, misses, controls)
    if errors:
        print("\n".join(f"pooled: {e}" for e in errors), file=sys.stderr)
        sys.exit(1)
    print_tables(captures, cells)


if __name__ == "__main__":
    main()
