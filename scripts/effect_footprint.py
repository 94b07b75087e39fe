#!/usr/bin/env python3
"""Where each physical effect capture of benchmark sets differs from its specimen without the effect, and whether the
region the diagnosis placed its gap in lies there.

For each physical effect capture (placement 0: the capture the diagnosis localises) of each set made by
`scripts/diagnosis_set.sh generate`, reruns `drapegen reality` from the truth file (fabric, density, resolution, seed,
effect, turned protocol) into SET/footprint/NAME, checks that its four views are byte for byte the set's capture (the
same generator and inputs), and reads the regenerated truth's `effect_footprint` (since session 72: the drape with the
effect against the same specimen's drape without it, classified as the localisation classifies a fit's residual;
docs/DIAGNOSIS.md, "Reality generator"). Sets generated before session 72 gain the measured truth this way; later sets
already carry it, and are only read (their truth files hold the footprint).

Prints per capture: the verdict, the region as run (the report's localisation.region), the regions where the effect
acts (`mechanism_regions`, the generator's fixed table) and where its drape differs (`regions`), whether the region
as run is among each; then the counts per family.

    scripts/effect_footprint.py out/p73/s85 out/p73/s86 out/p73/s87
    scripts/effect_footprint.py --jobs 2 --drapegen build/bin/drapegen out/p73/s85
"""
import argparse
import concurrent.futures
import filecmp
import json
import os
import subprocess
import sys

PHYSICAL = ("yield", "shear", "curl", "friction", "misalignment")


def reality_args(truth):
    """The `drapegen reality` arguments that made the capture of this truth file."""
    effects = []
    for e in truth["effects"]:
        value = f"{e['name']}={e['strength']!r}"
        if "width_mm" in e:
            value += f",{e['width_mm']!r}"
        effects += ["--effect", value]
    args = ["--alpha", ",".join(repr(x) for x in truth["alpha"]),
            "--beta=" + ",".join(repr(x) for x in truth["beta"]),
            "--density", repr(truth["density_g_per_m2"]), "--resolution", str(truth["resolution"]),
            "--seed", str(truth["seed"]), "--placement", str(truth["placement"])] + effects
    if truth["placement"] > 0 or truth.get("face") == "down":
        args.append("--turn-over")
    return args


def footprint_truth(drapegen, set_dir, name, turned):
    """The truth with the effect's footprint: the set's own if it has one, else regenerated (and checked)."""
    truth = json.load(open(os.path.join(set_dir, "truth", name + ".json")))
    if "effect_footprint" in truth:
        return truth, "read"
    out = os.path.join(set_dir, "footprint", name)
    regenerated = os.path.join(out, "truth.json")
    if not os.path.exists(regenerated):
        args = [drapegen, "reality"] + reality_args(truth) + ["--out", out]
        if turned and "--turn-over" not in args:
            args.append("--turn-over")
        done = subprocess.run(args, capture_output=True, text=True)
        if done.returncode != 0:
            raise RuntimeError(f"{name}: drapegen reality failed: {done.stderr.strip()}")
    for v in range(4):
        a, b = os.path.join(out, f"view{v}.exr"), os.path.join(set_dir, "captures", name, f"view{v}.exr")
        if not filecmp.cmp(a, b, shallow=False):
            raise RuntimeError(f"{name}: the regenerated view{v}.exr differs from the set's capture (another build?)")
    return json.load(open(regenerated)), "regenerated"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("sets", nargs="+", help="set directories (scripts/diagnosis_set.sh generate OUT)")
    ap.add_argument("--drapegen", default="build/bin/drapegen",
                    help="a drapegen binary with the footprint (session 72 on), default %(default)s")
    ap.add_argument("--jobs", type=int, default=1, help="regenerations at a time")
    args = ap.parse_args()

    rows = []
    for set_dir in args.sets:
        drapegen = args.drapegen
        set_args = open(os.path.join(set_dir, "set.args")).read() if os.path.exists(
            os.path.join(set_dir, "set.args")) else ""
        turned = "--turn-over" in set_args
        cases = {c["case"]: c for c in json.load(open(os.path.join(set_dir, "cases.json")))}
        names = sorted(n for n, c in cases.items() if c.get("family") in PHYSICAL)
        with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
            truths = list(pool.map(lambda n: footprint_truth(drapegen, set_dir, n, turned), names))
        for name, (truth, how) in zip(names, truths):
            c = cases[name]
            fp = truth["effect_footprint"]
            rows.append({
                "set": os.path.basename(os.path.normpath(set_dir)), "case": name, "family": c["family"],
                "verdict": c.get("verdict", "?"), "as_run": c.get("region", "?"),
                "mechanism": truth["mechanism_regions"], "measured": truth["regions"], "how": how,
                "enrichment": {k: v["enrichment"] for k, v in fp.items() if isinstance(v, dict)},
                "rms_mm": fp["rms_mm"]})

    print("| set | capture | verdict | region as run | mechanism | measured (enrichment hem/skirt/top/rim/cyl) | "
          "match mech. | match meas. |")
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        e = r["enrichment"]
        enr = "/".join(f"{e.get(k, 0):.2f}" for k in ("hem", "skirt", "top", "rim", "cylinder"))
        print(f"| {r['set']} | {r['case']} | {r['verdict']} | {r['as_run']} | {','.join(r['mechanism'])} | "
              f"{','.join(r['measured'])} ({enr}; {r['rms_mm']:.1f} mm) | {r['as_run'] in r['mechanism']} | "
              f"{r['as_run'] in r['measured']} |")
    print()
    for fam in PHYSICAL + ("all",):
        sel = [r for r in rows if fam == "all" or r["family"] == fam]
        if not sel:
            continue
        mech = sum(r["as_run"] in r["mechanism"] for r in sel)
        meas = sum(r["as_run"] in r["measured"] for r in sel)
        print(f"{fam}: {len(sel)} captures; region as run among the mechanism's {mech}, among the measured {meas}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
