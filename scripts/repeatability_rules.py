#!/usr/bin/env python3
"""Fold repeatability against the gate, read off report.json files (docs/DIAGNOSIS_RESULTS.md, "Session 26"; the truth
files are read only to score). Each report carries `gap_tests.fold_repeatability`: the fold correlation (the hem's
fold content at the best turn) of every pair of the capture's placements and of every pair of the fitted model's
drapes from the validation states' sine states.

Two rules of "the capture's placements fold less alike than the fitted model's drapes", each counted per family
among the captures the gate passed as within the floors and among the rest:
- `scale S`: 1 - min(capture pairs) > S x (1 - min(model pairs));
- `repeat_excess` (pre-registered in session 26 before seed 18 was diagnosed): every capture pair below the model
  pairs' 10th percentile (sorted model_pairs[floor(0.1 n)]) minus 0.1.
- `below T` (session 65, the turned protocol; pre-registered for seeds 66-68 in out/p66/prereg_fold.txt): every pair of
  the capture's placements below T (capture_min < T), whatever the model: on seeds 58-65 the 12 controls' placements
  fold alike (0.85-0.98), an elastic specimen's one stable drape and its mirror image face down. Its "within" counts
  the captures within the floors at the gate or once the bending alone is refitted (the other rules': at the gate).

    scripts/repeatability_rules.py DIR [DIR ...]            # DIR: a benchmark run (diagnoses/, truth/) or a directory
                                                            # of NAME.json reports beside a run's truth/ (--truth)
    scripts/repeatability_rules.py --truth out/run/truth --scale 1.5 2 3 out/gaponly
    scripts/repeatability_rules.py --candidates out/run          # the candidates' own repeatability (session 27)
    scripts/repeatability_rules.py out/p65/s64 out/p65/s65 --below 0.75      # the absolute rule (session 65)

With --candidates (reports since session 27, attribution run): per capture the mean of its placements' pairs, the
fitted model's best drapes' on the three placements (`model_placement_pairs`), and each candidate's (its best drapes
on the three placements, `placement_pairs`; a yielding one laid again from its set) with the 10th percentile of its
drapes' pairs (`drape_pairs`); `closest`: the confirmed candidate whose placements' mean is nearest the capture's;
and the rule `repeat_closest` (pre-registered in session 27 before seed 20): where repeat_excess fires and two or more
candidates are confirmed with a shrinkage of at least 0.25, the verdict is the one of them whose placements' mean is
nearest the capture's; elsewhere the verdict as run; and `repeat_curl` (pre-registered likewise): where repeat_excess
fires and the curl candidate is confirmed with a shrinkage of at least 0.25, curl; elsewhere the verdict as run.
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


def mean(values):
    return sum(values) / len(values) if values else float("nan")


def model_q10(f):
    """The model pairs' 10th percentile (sorted, element floor(0.1 n)), as folds_less_alike takes it."""
    model = sorted(f["model_pairs"])
    return model[int(0.1 * len(model))]


def repeat_excess(f):
    """Every capture pair below the model pairs' 10th percentile minus 0.1 (session 26; folds_less_alike)."""
    return bool(f["model_pairs"]) and max(f["capture_pairs"]) < model_q10(f) - 0.1


def candidates(runs, truth_dir):
    short = {"yield": "yld", "shear": "shr", "curl": "crl", "friction": "frc", "misalignment": "mis", "sensor": "sen"}
    right = collections.Counter()
    total = collections.Counter()
    as_run = collections.Counter()
    closest_rule = collections.Counter()
    curl_rule = collections.Counter()
    for run in runs:
        for name, r, truth in reports(run, truth_dir):
            f = r["gap_tests"].get("fold_repeatability") or {}
            cands = [c for c in r["attribution"].get("candidates", []) if "fold_repeatability" in c]
            if not cands or not f.get("capture_pairs"):
                continue
            capture = mean(f["capture_pairs"])
            cells = []
            confirmed = []
            for c in cands:
                fr = c["fold_repeatability"]
                placed = mean(fr["placement_pairs"])
                drapes = sorted(fr["drape_pairs"])
                q10 = drapes[int(0.1 * len(drapes))] if drapes else float("nan")
                mark = "*" if c["confirmed"] and c["shrinkage"] >= 0.25 else " "
                cells.append(f"{short[c['effect']]}{mark}{placed:5.2f}/{q10:4.2f}")
                if mark == "*":
                    confirmed.append((abs(placed - capture), c["effect"]))
            closest = min(confirmed)[1] if confirmed else "-"
            fires = repeat_excess(f)
            rule = closest if fires and len(confirmed) >= 2 else r["verdict"]
            curl_ok = any(c["effect"] == "curl" and c["confirmed"] and c["shrinkage"] >= 0.25 for c in cands)
            curl = "curl" if fires and curl_ok else r["verdict"]
            family = truth["family"] or "none"
            total[family] += 1
            right[family] += closest == family
            as_run[family] += r["verdict"] == family
            closest_rule[family] += rule == family
            curl_rule[family] += curl == family
            print(f"{name:<16} {r['verdict']:<12} cap {capture:5.2f} model {mean(f.get('model_placement_pairs', [])):5.2f} "
                  + " ".join(cells) + f"  closest {closest}" + (f"  repeat_excess -> {rule} (repeat_curl {curl})" if fires else ""))
    print("closest right: " + ", ".join(f"{fam} {right[fam]}/{total[fam]}" for fam in sorted(total)))
    print("as run right: " + ", ".join(f"{fam} {as_run[fam]}/{total[fam]}" for fam in sorted(total)))
    print("repeat_closest right: " + ", ".join(f"{fam} {closest_rule[fam]}/{total[fam]}" for fam in sorted(total)))
    print("repeat_curl right: " + ", ".join(f"{fam} {curl_rule[fam]}/{total[fam]}" for fam in sorted(total)))
    print("(captures whose attribution ran; a control is right when named none)")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("runs", nargs="+")
    parser.add_argument("--truth", help="truth directory (default: RUN/truth)")
    parser.add_argument("--scale", type=float, nargs="+", default=[1.5, 2.0, 3.0])
    parser.add_argument("--candidates", action="store_true", help="the candidates' own repeatability")
    parser.add_argument("--below", type=float, nargs="+", default=[0.75],
                        help="the rule `below T`: every pair of the capture's placements below T")
    args = parser.parse_args()
    if args.candidates:
        candidates(args.runs, args.truth)
        return
    rows = []
    within_any = {}  # case: within the floors at the gate or once the bending alone is refitted
    for run in args.runs:
        for name, r, truth in reports(run, args.truth):
            f = r["gap_tests"].get("fold_repeatability")
            if not f or f["capture_min"] is None or f["model_min"] is None:
                continue
            q10 = model_q10(f)
            excess = repeat_excess(f)
            rows.append((os.path.basename(os.path.normpath(run)) + "/" + name, truth["family"], r["within_floors"],
                         r["verdict"], f["capture_min"], f["model_min"], max(f["capture_pairs"]), q10, excess))
            within_any[rows[-1][0]] = r["within_floors"] or r.get("within_floors_after_bending_refit", False)
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
    for threshold in args.below:  # "within": at the gate or once the bending alone is refitted
        fired = collections.defaultdict(lambda: [0, 0, 0, 0])
        for case, family, _, _, cap, *_ in rows:
            k = 0 if within_any[case] else 2
            fired[family][k + 1] += 1
            fired[family][k] += cap < threshold
        print(f"below {threshold:g}: " + ", ".join(f"{fam} {v[0]}/{v[1]} within, {v[2]}/{v[3]} above"
                                                  for fam, v in sorted(fired.items())))


if __name__ == "__main__":
    main()
