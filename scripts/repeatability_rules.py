#!/usr/bin/env python3
"""Fold repeatability against the gate, read off report.json files (docs/DIAGNOSIS.md, "Session 26"; the truth
files are read only to score). Each report carries `gap_tests.fold_repeatability`: the fold correlation (the hem's
fold content at the best turn) of every pair of the capture's placements and of every pair of the fitted model's
drapes from the validation states' sine states.

Two rules of "the capture's placements fold less alike than the fitted model's drapes", each counted per family
among the captures the gate passed as within the floors and among the rest:
- `scale S`: 1 - min(capture pairs) > S x (1 - min(model pairs));
- `repeat_excess` (pre-registered in session 26 before seed 18 was diagnosed): every capture pair below the model
  pairs' 10th percentile (sorted model_pairs[floor(0.1 n)]) minus 0.1.

    scripts/repeatability_rules.py DIR [DIR ...]            # DIR: a benchmark run (diagnoses/, truth/) or a directory
                                                            # of NAME.json reports beside a run's truth/ (--truth)
    scripts/repeatability_rules.py --truth out/run/truth --scale 1.5 2 3 out/gaponly
"""
import argparse
import collections
import glob
import json
import os


def reports(directory, truth_dir):
    """(name, report, truth) for every report in DIRECTORY/diagnoses or DIRECTORY."""
    folder = os.path.join(directory, "diagnoses")
    folder = folder if os.path.isdir(folder) else directory
    truth_dir = truth_dir or os.path.join(directory, "truth")
    for path in sorted(glob.glob(os.path.join(folder, "*.json"))):
        name = os.path.basename(path)[:-5]
        truth_path = os.path.join(truth_dir, name + ".json")
        if not os.path.exists(truth_path):
            continue
        with open(path) as f, open(truth_path) as t:
            yield name, json.load(f), json.load(t)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("runs", nargs="+")
    parser.add_argument("--truth", help="truth directory (default: RUN/truth)")
    parser.add_argument("--scale", type=float, nargs="+", default=[1.5, 2.0, 3.0])
    args = parser.parse_args()
    rows = []
    for run in args.runs:
        for name, r, truth in reports(run, args.truth):
            f = r["gap_tests"].get("fold_repeatability")
            if not f or f["capture_min"] is None or f["model_min"] is None:
                continue
            model = sorted(f["model_pairs"])
            q10 = model[int(0.1 * len(model))]
            excess = max(f["capture_pairs"]) < q10 - 0.1
            rows.append((os.path.basename(os.path.normpath(run)) + "/" + name, truth["family"], r["within_floors"],
                         r["verdict"], f["capture_min"], f["model_min"], max(f["capture_pairs"]), q10, excess))
    print(f"{'case':<32} {'family':<13} {'within':>6} {'verdict':<13} {'cap_min':>7} {'mod_min':>7} {'ratio':>6} "
          f"{'cap_max':>7} {'mod_q10':>7} repeat_excess")
    for case, family, within, verdict, cap, mod, cap_max, q10, excess in rows:
        ratio = (1 - cap) / max(1e-9, 1 - mod)
        print(f"{case:<32} {family:<13} {str(within):>6} {verdict:<13} {cap:7.2f} {mod:7.2f} {ratio:6.2f} "
              f"{cap_max:7.2f} {q10:7.2f} {'fires' if excess else ''}")
    for scale in args.scale:
        fired = collections.defaultdict(lambda: [0, 0, 0, 0])  # within: fired, of; above: fired, of
        for _, family, within, _, cap, mod, *_ in rows:
            k = 0 if within else 2
            fired[family][k + 1] += 1
            fired[family][k] += (1 - cap) > scale * (1 - mod)
        text = ", ".join(f"{fam} {v[0]}/{v[1]} within, {v[2]}/{v[3]} above" for fam, v in sorted(fired.items()))
        print(f"scale {scale:g}: {text}")
    fired = collections.defaultdict(lambda: [0, 0, 0, 0])
    for _, family, within, *_, excess in rows:
        k = 0 if within else 2
        fired[family][k + 1] += 1
        fired[family][k] += excess
    print("repeat_excess: " + ", ".join(f"{fam} {v[0]}/{v[1]} within, {v[2]}/{v[3]} above"
                                        for fam, v in sorted(fired.items())))


if __name__ == "__main__":
    main()
