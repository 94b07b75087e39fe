#!/usr/bin/env python3
"""Re-scores a diagnosis benchmark run for other gate settings, to calibrate them on a calibration set (never on the
evaluation set): the shape floor F (the shape test of "within the floors") and the attribution's significance
threshold T (the least shrinkage that names an effect).

The run must have attributed every capture (`--diagnose-args "--shape-floor 0.001"`), so that report.json holds each
candidate's validated stable term, shape distance and held-out score; the verdicts for any F and T then follow from
them exactly as drapegen diagnose decides (docs/DIAGNOSIS.md, "Attribution"): the stable floor is the run's, the
reference is the better of the baseline's and the bending-only bar's validated drapes, a candidate counts only if its
held-out view is at most the run's held-out tolerance worse than the reference's (report.json
`attribution.held_out_tolerance`; 0, not worse at all, in reports made before session 23).

    scripts/diagnosis_calibration.py out/calib60_s2 --floors 1.0 1.15 1.3 --thresholds 0.15 0.25 0.35

With --multistability (a gap-only run whose report.json has gap_tests.validation_spread, branch diag-s7) it compares
the constant shape floor with per-capture floors from the validation drapes' spread among themselves (the
leave-one-out nearest-neighbour shape distances among them: docs/DIAGNOSIS_RESULTS.md, "Branch diag-s7"), prints
each case's fabric stiffness from the truth file, and with --rule applies one rule with fixed constants (for the
evaluation set):

    scripts/diagnosis_calibration.py out/calib_s7 --multistability
    scripts/diagnosis_calibration.py out/eval_s7 --multistability --rule floor --c0 0.8 --k 2.0

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
    # With a held-out capture (drapegen diagnose --held-out-capture) the gate's terms are the mean of both captures'
    # and the confirmation compares the held-out capture's all-view score; otherwise the capture's and its held-out
    # view's score.
    def terms(v):
        h = v.get("held_out_capture")
        if h:
            return 0.5 * (v["stable_mm"] + h["stable_mm"]), 0.5 * (v["shape"] + h["shape"]), h["all_views_score_mm"]
        return v["stable_mm"], v["shape"], v["held_out_score_mm"]

    bar_stable, bar_shape, bar_held = terms(a["bending_refit_bar"]["validated"])
    bar_excess = excess(bar_stable, bar_shape, sf, shape_floor)
    if bar_excess < base:
        ref_excess, ref_held = bar_excess, bar_held
    elif t.get("held_out_capture"):
        ref_excess, ref_held = base, t["held_out_capture"]["all_views_score_mm"]
    else:
        ref_excess, ref_held = base, d["gap_mm"]["held_out_view"]
    allowed = 1.0 + a.get("held_out_tolerance", 0.0)  # the run's confirmation: at most this x the reference's
    ranked = []
    for c in a["candidates"]:
        stable, shape, held_score = terms(c["validated"])
        e = excess(stable, shape, sf, shape_floor)
        shrink = 1.0 - e / ref_excess if ref_excess > 0 else 0.0
        held = 1.0 - held_score / ref_held if ref_held > 0 else 0.0
        ranked.append((held_score <= allowed * ref_held or not confirm, shrink, held, c["effect"]))
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


FAMILIES = ["yield", "shear", "curl", "friction", "misalignment", "sensor"]


def spearman(x, y):
    """Spearman's rank correlation (no ties expected: continuous values)."""
    def ranks(v):
        order = sorted(range(len(v)), key=lambda i: v[i])
        r = [0.0] * len(v)
        for k, i in enumerate(order):
            r[i] = float(k)
        return r
    rx, ry = ranks(x), ranks(y)
    n = len(x)
    mx, my = sum(rx) / n, sum(ry) / n
    sxy = sum((a - mx) * (b - my) for a, b in zip(rx, ry))
    sxx = sum((a - mx) ** 2 for a in rx)
    syy = sum((b - my) ** 2 for b in ry)
    return sxy / (sxx * syy) ** 0.5 if sxx > 0 and syy > 0 else 0.0


def spread_stats(d, truth):
    """The per-capture quantities of the multistability rules (docs/DIAGNOSIS_RESULTS.md, "Branch diag-s7")."""
    t = d["gap_tests"]
    v = t["validation_spread"]
    loo = v["nearest_other_shape"]
    pairs = [v["pairwise_shape"][i][j] for i in range(len(loo)) for j in range(i + 1, len(loo))]
    alpha = truth["alpha"]
    return {
        "c": t["shape"],                          # the gate's: the best validation drape (by fit score), all views
        "cmin": min(v["capture_shape"]),          # the nearest validation drape by shape distance
        "loo_med": statistics.median(loo),        # median leave-one-out nearest-neighbour distance
        "loo_max": max(loo),
        "pair_med": statistics.median(pairs),
        "ms_floor": max(d["floors"]["multistability_shape"]) if d["floors"]["multistability_shape"] else 0.0,
        "stiff": sum(alpha) / 3 / truth["density_g_per_m2"],  # mean alpha / density (the brief's stiffness)
        "stable_up": t["stable_mm"] > t["stable_floor_mm"],
    }


def rule_above(rule, q, c0=0.0, k=0.0, r=0.0):
    """Whether the shape test fails (the capture is above the shape floor) under a rule with fixed constants."""
    if rule == "const":
        return q["c"] > c0
    if rule == "ratio":          # c / median LOO distance above r
        return q["c"] > r * q["loo_med"]
    if rule == "floor":          # c above max(c0, k x median LOO distance)
        return q["c"] > max(c0, k * q["loo_med"])
    if rule == "floor_max":      # c above max(c0, k x largest LOO distance)
        return q["c"] > max(c0, k * q["loo_max"])
    if rule == "nearest_const":  # the nearest validation drape by shape distance (not by fit score) above c0
        return q["cmin"] > c0
    if rule == "nearest_ratio":  # the same over the median LOO distance above r
        return q["cmin"] > r * q["loo_med"]
    if rule == "offset":         # c above c0 + k x median LOO distance (the 60x60-vs-32x32 offset plus the spread)
        return q["c"] > c0 + k * q["loo_med"]
    raise SystemExit(f"unknown rule {rule}")


def score_rule(rows, rule, **const):
    """(controls within, {family: effect captures above the floors}) with the stable test as the gate has it."""
    within, total, above = 0, 0, {f: [0, 0] for f in FAMILIES}
    for name, fam, q in rows:
        up = q["stable_up"] or rule_above(rule, q, **const)
        if fam == "none":
            total += 1
            within += not up
        else:
            above[fam][0] += up
            above[fam][1] += 1
    return within, total, above


def fmt_above(above, shape_only_rows=None):
    cells = [f"{a}/{n}" for a, n in (above[f] for f in FAMILIES)]
    tot = sum(a for a, _ in above.values()), sum(n for _, n in above.values())
    return cells + [f"{tot[0]}/{tot[1]}"]


def calibrate(rows):
    """Each rule's constants from the controls: every control within the floor with a 10% margin (the diag-s5/s6
    rule, largest control + 10%); for the two-constant rules, k from a grid and c0 the smallest that keeps the
    controls k x spread does not cover. Returns [(rule, constants)]."""
    ctl = [q for _, fam, q in rows if fam == "none"]
    out = [("const", {"c0": 1.1 * max(q["c"] for q in ctl)}),
           ("ratio", {"r": 1.1 * max(q["c"] / q["loo_med"] for q in ctl)})]
    for rule, key in (("floor", "loo_med"), ("floor_max", "loo_max")):
        for k in [0.5, 0.75, 1.0, 1.25, 1.5, 2.0, 2.5, 3.0, 4.0]:
            uncovered = [1.1 * q["c"] for q in ctl if 1.1 * q["c"] > k * q[key]]
            out.append((rule, {"c0": max(uncovered) if uncovered else 0.0, "k": k}))
    out.append(("nearest_const", {"c0": 1.1 * max(q["cmin"] for q in ctl)}))
    out.append(("nearest_ratio", {"r": 1.1 * max(q["cmin"] / q["loo_med"] for q in ctl)}))
    for k in [0.25, 0.5, 0.75, 1.0, 1.5, 2.0]:
        out.append(("offset", {"c0": max(1.1 * q["c"] - k * q["loo_med"] for q in ctl), "k": k}))
    return out


def multistability(cases, truths, rule=None, consts=None, fixed_floor=1.17):
    rows = [(name, fam, spread_stats(d, truths[name])) for name, fam, d in cases]
    print("| case | family | stiffness (mean alpha / density) | shape (gate) | nearest by shape | LOO median | LOO max |"
          " pairs median | shape / LOO median | largest floor sample | stable above |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for name, fam, q in sorted(rows, key=lambda r: (FAMILIES.index(r[1]) + 1 if r[1] in FAMILIES else 0, r[0])):
        print(f"| {name} | {fam} | {q['stiff']:.3g} | {q['c']:.2f} | {q['cmin']:.2f} | {q['loo_med']:.2f} | "
              f"{q['loo_max']:.2f} | {q['pair_med']:.2f} | {q['c'] / q['loo_med']:.2f} | {q['ms_floor']:.2f} | "
              f"{'yes' if q['stable_up'] else ''} |")
    allq = [q for _, _, q in rows]
    ctl = [q for _, fam, q in rows if fam == "none"]
    print(f"\nSpearman, all {len(allq)} captures: stiffness vs LOO median {spearman([q['stiff'] for q in allq], [q['loo_med'] for q in allq]):+.2f}; "
          f"stiffness vs gate shape {spearman([q['stiff'] for q in allq], [q['c'] for q in allq]):+.2f}")
    print(f"Spearman, {len(ctl)} controls: stiffness vs LOO median {spearman([q['stiff'] for q in ctl], [q['loo_med'] for q in ctl]):+.2f}; "
          f"LOO median vs gate shape {spearman([q['loo_med'] for q in ctl], [q['c'] for q in ctl]):+.2f}; "
          f"stiffness vs gate shape {spearman([q['stiff'] for q in ctl], [q['c'] for q in ctl]):+.2f}\n")
    head = "| rule | constants | controls within | " + " | ".join(FAMILIES) + " | effect captures above |"
    print(head)
    print("|---" * (3 + len(FAMILIES) + 1) + "|")
    settings = [("const", {"c0": fixed_floor})]
    if rule:
        settings.append((rule, consts))
    else:
        settings += calibrate(rows)
    for r, c in settings:
        within, total, above = score_rule(rows, r, **c)
        cs = ", ".join(f"{k}={v:.3g}" for k, v in c.items())
        label = "const (given)" if (r, c) == settings[0] else r
        print(f"| {label} | {cs} | {within}/{total} | " + " | ".join(fmt_above(above)) + " |")
    if rule:
        print(f"\nPer case under {rule} ({consts}) and the constant floor {fixed_floor}:")
        for name, fam, q in rows:
            a = q["stable_up"] or rule_above(rule, q, **consts)
            b = q["stable_up"] or rule_above("const", q, c0=fixed_floor)
            print(f"  {name}: {'above' if a else 'within'} (constant floor: {'above' if b else 'within'})")


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
    p.add_argument("--multistability", action="store_true",
                   help="per-capture floors from the validation drapes' spread (gap-only run, branch diag-s7)")
    p.add_argument("--rule", choices=["const", "ratio", "floor", "floor_max", "offset", "nearest_const", "nearest_ratio"],
                   help="with --multistability: apply this rule with the constants given (else calibrate them)")
    p.add_argument("--c0", type=float, default=0.0)
    p.add_argument("--k", type=float, default=0.0)
    p.add_argument("--r", type=float, default=0.0)
    p.add_argument("--fixed-floor", type=float, default=1.17, help="the constant floor compared with")
    args = p.parse_args()
    cases, truths = [], {}
    for f in sorted((args.run / "diagnoses").glob("*.json")):
        truth = json.loads((args.run / "truth" / f.name).read_text())
        truths[f.stem] = truth
        cases.append((f.stem, truth["family"], json.loads(f.read_text())))
    if args.multistability:
        consts = {"const": {"c0": args.c0}, "ratio": {"r": args.r}, "floor": {"c0": args.c0, "k": args.k},
                  "floor_max": {"c0": args.c0, "k": args.k}, "offset": {"c0": args.c0, "k": args.k},
                  "nearest_const": {"c0": args.c0}, "nearest_ratio": {"r": args.r}}.get(args.rule)
        multistability(cases, truths, args.rule, consts, args.fixed_floor)
        return
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
