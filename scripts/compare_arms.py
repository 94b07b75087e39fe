#!/usr/bin/env python3
"""Two arms of a diagnosis benchmark on the same captures, capture by capture: the verdicts of the default run BASE
and of an arm ARM (a run of the same set with other diagnose options, its captures, truth and screen linked to
BASE's), the arm's placement drape test (gap_tests.placement_dc over placement_dc_floor; 0 without the test) and its
CPU seconds; then top-1 of each, the gains and losses (captures the arm names right and the default wrong, and the
reverse), and the controls each names; last, rule Z: the arm's verdict where the arm finds the gap above its floors,
the default's elsewhere (session 76: an arm on a finer fitting mesh), scored the same way. The truth files are read
only to score (docs/DIAGNOSIS_RESULTS.md, "Session 73").

    scripts/compare_arms.py out/p75/s91:out/p75/s91D out/p75/s92:out/p75/s92D
"""
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import diagnosis_rules as dr  # noqa: E402


def main(pairs):
    if not pairs or any(p.count(":") != 1 for p in pairs):
        sys.exit(__doc__)
    gain = loss = named0 = named1 = 0
    z = {"gain": 0, "loss": 0, "right": 0, "effects": 0, "named": 0}
    rows = []
    for pair in pairs:
        base, arm = pair.split(":")
        for name, family, j in dr.reports(base):
            path = os.path.join(arm, "diagnoses", name + ".json")
            if not os.path.exists(path):
                print(f"{arm}: no report of {name}")
                continue
            with open(path) as fh:
                d = json.load(fh)
            g = d["gap_tests"]
            term, floor = g.get("placement_dc", 0.0), g.get("placement_dc_floor", 0.0)
            v0, v1 = j["verdict"], d["verdict"]
            vz = v1 if not d.get("within_floors", True) else v0
            if family == "none":
                z["named"] += vz not in ("none", "unexplained")
            else:
                z["effects"] += 1
                z["right"] += vz == family
                z["gain"] += vz == family and v0 != family
                z["loss"] += v0 == family and vz != family
            if family == "none":
                named0 += v0 not in ("none", "unexplained")
                named1 += v1 not in ("none", "unexplained")
            else:
                gain += v1 == family and v0 != family
                loss += v0 == family and v1 != family
            ratio = term / floor if floor > 0 else float("nan")
            cpu = (d.get("runtime") or {}).get("cpu_seconds") or 0.0
            rows.append((os.path.basename(base), name, family, v0, v1, term, floor, ratio, cpu))
    print(f"{'set':5s} {'case':16s} {'truth':13s} {'default':13s} {'arm':13s} {'dc term':>8s} {'floor':>7s} "
          f"{'ratio':>6s} {'cpu s':>6s}")
    for r in rows:
        mark = " <-" if r[3] != r[4] else ""
        print(f"{r[0]:5s} {r[1]:16s} {r[2]:13s} {r[3]:13s} {r[4]:13s} {r[5]:8.4f} {r[6]:7.4f} {r[7]:6.2f} "
              f"{r[8]:6.0f}{mark}")
    effects = [r for r in rows if r[2] != "none"]
    controls = [r for r in rows if r[2] == "none"]
    print(f"top-1 default {sum(r[3] == r[2] for r in effects)}/{len(effects)}, arm "
          f"{sum(r[4] == r[2] for r in effects)}/{len(effects)}; gains {gain}, losses {loss}; controls named: default "
          f"{named0}, arm {named1}; within the floors: default {sum(r[3] == 'none' for r in controls)}, arm "
          f"{sum(r[4] == 'none' for r in controls)} of {len(controls)}")
    print(f"rule Z (the arm where it finds a gap, else the default): top-1 {z['right']}/{z['effects']}; gains "
          f"{z['gain']}, losses {z['loss']}; controls named {z['named']}")


if __name__ == "__main__":
    main(sys.argv[1:])
