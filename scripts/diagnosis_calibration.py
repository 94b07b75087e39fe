#!/usr/bin/env python3
"""Re-scores a diagnosis benchmark run for other gate settings, to calibrate them on a calibration set (never on the
evaluation set): the shape floor F (the shape test of "within the floors") and the attribution's significance
threshold T (the least shrinkage that names an effect).

The run must have attributed every capture (`--diagnose-args "--shape-floor 0.001"`), so that report.json holds each
candidate's validated stable term, shape distance and held-out score; the verdicts for any F and T then follow from
them exactly as drapegen diagnose decides (docs/DIAGNOSIS.md, "Attribution"): the stable floor is the run's, the
reference is the better of the baseline's and the bending-only bar's validated drapes, a candidate counts only if its
held-out view does not get worse than the reference's.

    scripts/diagnosis_calibration.py out/calib60_s2 --floors 1.0 1.15 1.3 --thresholds 0.15 0.25 0.35

With --gap-only the run need not have attributed (e.g. `--diagnose-args "--shape-floor 50"`): it prints each case's
validated shape distance and stable term, the calibrated shape floor (the largest control's shape distance plus 10%,
the rule of docs/DIAGNOSIS.md, "Floors"), and which captures are above the floors at that floor and at --floors.
"""
import argparse
import json
import statistics
from pathlib import Path


def excess(stable, shape, stable_floor, shape_floor):
    e = 0.0
    if stable > stable_floor:
        e += (stable - stable_floor) / stable_floor
    if shape > shape_floor:
        e += (shape - shape_floor) / shape_floor
    return e


def verdict(d, shape_floor, threshold, confirm=True):
    """(verdict, shrinkage of the named effect or 0) for one diagnosis at these settings."""
    t = d["gap_tests"]
    sf = t["stable_floor_mm"]
    base = excess(t["stable_mm"], t["shape"], sf, shape_floor)
    if base == 0.0:
        return "none", 0.0
    a = d["attribution"]
    if not a.get("ran"):
        raise SystemExit(f"{d['capture']}: attribution did not run; rerun with --shape-floor 0.001")
    bar = a["bending_refit_bar"]["validated"]
    bar_excess = excess(bar["stable_mm"], bar["shape"], sf, shape_floor)
    if bar_excess < base:
        ref_excess, ref_held = bar_excess, bar["held_out_score_mm"]
    else:
        ref_excess, ref_held = base, d["gap_mm"]["held_out_view"]
    ranked = []
    for c in a["candidates"]:
        v = c["validated"]
        e = excess(v["stable_mm"], v["shape"], sf, shape_floor)
        shrink = 1.0 - e / ref_excess if ref_excess > 0 else 0.0
        held = 1.0 - v["held_out_score_mm"] / ref_held if ref_held > 0 else 0.0
        ranked.append((v["held_out_score_mm"] <= ref_held or not confirm, shrink, held, c["effect"]))
    ranked.sort(key=lambda r: (not r[0], -r[1], -r[2]))
    confirmed, shrink, _, effect = ranked[0]
    if confirmed and shrink >= threshold:
        return effect, shrink
    return "unexplained", 0.0


def gap_only(cases, floors):
    """The gate alone: which captures are above the floors, for the calibrated floor and the given ones."""
    controls = sorted(d["gap_tests"]["shape"] for _, fam, d in cases if fam == "none")
    if not controls:
        raise SystemExit("no controls in the run")
    calibrated = 1.1 * controls[-1]
    print(f"{len(controls)} controls; shape distances {', '.join(f'{x:.2f}' for x in controls)} (median "
          f"{statistics.median(controls):.2f}); calibrated floor (largest + 10%): {calibrated:.2f}")
    print("| case | family | shape | stable / floor (mm) | " + " | ".join(f"above {F:.2f}" for F in [calibrated] + floors)
          + " |")
    print("|---|---|---|---|" + "---|" * (1 + len(floors)))
    above = {F: [0, 0, 0] for F in [calibrated] + floors}  # controls above, effects above, effects
    for name, fam, d in cases:
        t = d["gap_tests"]
        cells = []
        for F in [calibrated] + floors:
            up = excess(t["stable_mm"], t["shape"], t["stable_floor_mm"], F) > 0.0
            cells.append("yes" if up else "")
            above[F][0 if fam == "none" else 1] += up
            above[F][2] += fam != "none"
        print(f"| {name} | {fam} | {t['shape']:.2f} | {t['stable_mm']:.1f} / {t['stable_floor_mm']:.1f} | "
              + " | ".join(cells) + " |")
    for F, (c, e, n) in above.items():
        print(f"floor {F:.2f}: controls above {c}/{len(controls)}, effect captures above {e}/{n}")


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("run", type=Path, help="benchmark directory (diagnoses/, truth/)")
    p.add_argument("--floors", type=float, nargs="+", default=[1.15])
    p.add_argument("--thresholds", type=float, nargs="+", default=[0.25])
    p.add_argument("--cases", action="store_true", help="print each case's verdict at every setting")
    p.add_argument("--confirm", type=int, nargs="+", default=[1],
                   help="1: a candidate counts only if the held-out view confirms it (drapegen diagnose); 0: any")
    p.add_argument("--gap-only", action="store_true",
                   help="the gate alone (no attribution needed): the calibrated floor and the captures above it")
    args = p.parse_args()
    cases = []
    for f in sorted((args.run / "diagnoses").glob("*.json")):
        truth = json.loads((args.run / "truth" / f.name).read_text())
        cases.append((f.stem, truth["family"], json.loads(f.read_text())))
    if args.gap_only:
        gap_only(cases, [F for F in args.floors if F > 0])
        return
    print(f"{len(cases)} cases; control shape distances: "
          + ", ".join(f"{d['gap_tests']['shape']:.2f}" for _, fam, d in cases if fam == "none"))
    print("| held-out confirmation | shape floor | threshold | controls within | top-1 | median shrinkage | named wrongly |")
    print("|---|---|---|---|---|---|---|")
    for C in args.confirm:
        for F in args.floors:
            for T in args.thresholds:
                controls = within = effects = correct = wrong = 0
                shrinks = []
                lines = []
                for name, fam, d in cases:
                    v, s = verdict(d, F, T, bool(C))
                    lines.append(f"  {name}: {v} {100 * s:.0f}%")
                    if fam == "none":
                        controls += 1
                        within += v == "none"
                    else:
                        effects += 1
                        correct += v == fam
                        wrong += v not in ("none", "unexplained", fam)
                        shrinks.append(s)
                med = statistics.median(shrinks) if shrinks else 0.0
                print(f"| {'yes' if C else 'no'} | {F:g} | {T:g} | {within}/{controls} | {correct}/{effects} | "
                      f"{100 * med:.0f}% | {wrong} |")
                if args.cases:
                    print("\n".join(lines))


if __name__ == "__main__":
    main()
