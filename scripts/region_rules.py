#!/usr/bin/env python3
"""Where the gap sits, under the localisation's rules, read off the report.json files of diagnosis benchmark runs
(`drapegen_diagnosis_bench`; the truth files are read only to score). docs/DIAGNOSIS_RESULTS.md, "Session 24".

- as_run: the report's `localisation.region`;
- largest: the region of the feature group (or the stable term) furthest above its floor, outline groups "hem", skirt
  groups "skirt", the stable term "global" (the rule before session 24);
- place_gap_24: the rule of session 24: the stable term "global" from 1.5 times its floor, else "top"; the hem's
  centre offset "hem"; the other outline groups "skirt" where the skirt's pixel residual is denser than the hem's,
  else "hem"; skirt groups "skirt";
- place_gap: the rule since session 25 (diagnosis/src/localisation.cpp, place_gap and stable_region): as
  place_gap_24 but the stable term placed by the rigid surfaces (stable_region below), and a lifted platform top
  (the stable term above its floor, stable_region "top") leading whatever else exceeds its floor; on reports before
  session 25 (no signed region means) it falls back to place_gap_24;
- place_gap_27: place_gap, but a platform top above its own floor and seen farther than the fitted cloth places the
  gap everywhere, and a stable term from lifted_scale times its floor places it by stable_region, whatever leads
  (pre-registered in session 27 before seed 19 was diagnosed);
- place_gap_27b: place_gap_27, and a platform top at least lifted_scale times its own floor placing the gap
  everywhere (pre-registered in session 27 before seed 20 was diagnosed);
- pixel_region, floor_region: the report's other two localisers (the most enriched region; the region furthest
  above its own floor, in reports since session 22);
- split_enrichment, split_floor_ratio (session 44): where the report placed the gap at the hem or the skirt, whichever
  of the two has the denser pixel residual (enrichment) or the residual further above its own floor (floor_ratio);
  any other region as run;
- skirt_floor_ratio (session 65, pre-registered, negative): a gap placed at the skirt moved to the hem where the hem's
  residual stands further above its own floor than the skirt's (floor_ratio); any other region as run;
- fold_depth (session 65, pre-registered for seeds 66-67): a gap placed at the skirt moved to the hem where the fold
  depth (feature group skirt_spread) stands more than --fold-depth times further above its floor than the skirt's
  mean height (skirt_height); any other region as run. Adopted in session 66 (place_gap, folds_deepen_at_hem): on
  reports of later builds "as run" already applies it.
- closure_groups, closure_regions (session 67, exploratory; reports since df9daf4, whose refits carry their own
  localisation): where the named effect closes the gap. closure_groups: the feature group (or the stable term) whose
  ratio to its floor the named candidate's validated drape lowers the most from the baseline's, placed as place_gap
  places a leading group (skirt groups the skirt, the centre offset the hem, the other outline groups the skirt or
  the hem by the baseline's enrichment, the stable term by stable_region); closure_regions: the region whose residual
  RMS over its floor (floor_ratio) it lowers the most. Where no effect is named, nothing is lowered, or the report
  has no refit localisation: the region as run (--closure-only counts only the reports that have one).
- multipath_floor (rule M, pre-registered in session 69 for seeds 75-77, out/p70/prereg.txt): where the report's
  multipath test fired (gap_tests.view_consistency.multipath; reports since 0a703f1), floor_region unless "global";
  any other region as run. The line under the table counts the captures where the test fired (controls apart) and
  rule M's gains and losses against the region as run there.
- lifted_top (rule T, registered in session 72 for seeds 88-89): as run, but a gap the stable term placed on the
  platform top while a feature group stands further above its floor stays there only if the top is lifted by at least
  --lifted-mm (default 1 mm: its mean residual at most -1 mm); else the leading group places it, as place_gap does.
- skirt_dense (rule S, registered in session 74, adopted in session 75: place_gap's since then): lifted_top's
  region, but a gap placed at the hem (not by the views) goes to the skirt where the skirt's pixel enrichment is at
  least --skirt-dense (1.3) times the hem's.
- hem_offset (rule O, an addendum to session 87's registration, written in session 85 from seeds 101-118: +10 -0
  there, in sample; +3 -0 on fresh seeds 119-120: adopted in session 85, localisation.cpp's place_gap since, so on
  reports of later builds "as run" already applies it): as run, but a gap a feature group placed at the skirt (not the
  views, not the rigid surfaces) goes to the hem where the hem's centre lies --hem-offset-mm (6.5, rule D2's floor) or
  more off the fitted drape's (localisation.feature_groups.off_centre.difference_mm): a specimen laid off centre makes
  the skirt's residual denser too (rule S's reading), but only a shifted placement moves the hem's centre.
- nearest_group (rule N, an addendum to session 88's registration, written in session 86 before any report of its
  sets existed): as run, but a gap nothing places (region "global", no feature group, stable term or camera above
  its floor, not the views) is placed by the feature group nearest its floor, as place_gap places a gap that group
  leads.

Per rule: the effect captures whose region is one of the effect's regions (the truth file's `regions`), per family.

With --ranking: verdicts of a region-aware attribution (an experiment, negative in session 24), top-1 and controls per
run: `tolerance` (the rule since session 23, applied to every report with --tolerance, default 0.1: confirmed first, then the shrinkage, then the smaller objective, as sessions 23-24 ranked),
`region_tie` (at equal shrinkage, an effect that acts where place_gap put the gap first) and `region_significant`
(among the confirmed candidates with a significant shrinkage, such an effect first).

    scripts/region_rules.py out/s24s11main_all [more runs ...]
    scripts/region_rules.py --lifted-scale 2 --skirt-denser 1.1 out/s23all       # place_gap with other constants
    scripts/region_rules.py --ranking out/s24s11main_all                          # the region-aware ranking
    scripts/region_rules.py out/p65/s64 out/p65/s65              # session 65 (diagnoses -> diag/NEW, the default)
    scripts/region_rules.py out/p66/s66 out/p66/s67              # session 66's test of fold_depth (diag/DEF)
    scripts/region_rules.py out/p68/s71 out/p68/s72              # closure_* on reports with refit localisations
    scripts/region_rules.py out/p70/s75 out/p70/s76 out/p70/s77  # session 69's test of multipath_floor (diag/DEF)
"""
import argparse
import collections
import glob
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from diagnosis_rules import (EFFECT_REGIONS, THRESHOLD, confirmation_rule,  # noqa: E402  (shared with it)
                             multipath_fired)

OUTLINE = {"harmonics", "off_centre", "sorted_radii", "hem_height"}
RULES = ["as_run", "largest", "place_gap_24", "place_gap", "place_gap_27", "place_gap_27b", "pixel_region",
         "floor_region", "split_enrichment", "split_floor_ratio", "skirt_floor_ratio", "fold_depth", "closure_groups",
         "closure_regions", "multipath_floor", "lifted_top", "skirt_dense", "hem_offset", "nearest_group"]


def leading(loc):
    """The feature group furthest above its floor, or "stable", or None (nothing above 1)."""
    best, lead = 1.0, None
    for name, g in loc["feature_groups"].items():
        if g["ratio"] > best:
            best, lead = g["ratio"], name
    return "stable" if loc["stable_ratio"] > best else lead


def group_region(loc, lead, skirt_denser=1.0):
    """Where place_gap puts a gap a feature group leads: an outline group follows the skirt where the skirt's residual
    is the denser (by skirt_denser), the centre's offset is the hem's, every other group the skirt's."""
    if lead not in OUTLINE:
        return "skirt"
    if lead == "off_centre":
        return "hem"
    enrichment = {r["region"]: r["enrichment"] for r in loc["regions"]}
    return "skirt" if enrichment.get("skirt", 0.0) > skirt_denser * enrichment.get("hem", 0.0) else "hem"


def largest(loc):
    lead = leading(loc)
    if lead is None or lead == "stable":
        return "global"
    return "hem" if lead in OUTLINE else "skirt"


def stable_region(loc, lifted_scale):
    """Where the stable term's excess sits, from the rigid regions' residuals (reports since session 25): the bare
    cylinder if the platform top is within its own floor; everywhere if the top is seen further than the fitted
    cloth (mean residual > 0: no cloth lies below the platform, a camera error does that); a lifted top (mean <= 0):
    the specimen's contact below lifted_scale times the stable floor, everywhere above."""
    regions = {r["region"]: r for r in loc["regions"]}
    top = regions["top"]
    if top["floor_ratio"] <= 1.0:
        return "cylinder"
    if top["mean_mm"] > 0.0:
        return "global"
    return "top" if loc["stable_ratio"] < lifted_scale else "global"


def place_gap(loc, sensor_scale, skirt_denser, lifted_scale=None):
    lead = leading(loc)
    signed = lifted_scale is not None and "mean_mm" in loc["regions"][0]
    if signed and loc["stable_ratio"] > 1.0 and stable_region(loc, lifted_scale) == "top":
        return "top"  # a lifted platform top leads whatever else exceeds its floor (session 25)
    if lead is None:
        return "global"
    if lead == "stable":
        if signed:
            return stable_region(loc, lifted_scale)
        return "global" if loc["stable_ratio"] >= sensor_scale else "top"
    return group_region(loc, lead, skirt_denser)


def split(loc, key):
    """The hem or the skirt as run, re-split by the two regions' `key` (enrichment, floor_ratio); else as run."""
    if loc["region"] not in ("hem", "skirt"):
        return loc["region"]
    share = {r["region"]: r.get(key, 0.0) for r in loc["regions"]}
    return "hem" if share.get("hem", 0.0) > share.get("skirt", 0.0) else "skirt"


def skirt_to_hem(loc, hem_side):
    """The region as run, but a gap placed at the skirt moved to the hem where hem_side(loc) holds."""
    return "hem" if loc["region"] == "skirt" and hem_side(loc) else loc["region"]


def folds_deeper_than_mean(loc, factor):
    """Session 65's rule Q: the folds' depth (skirt_spread) more than `factor` times further above its floor than the
    skirt's mean height (skirt_height)."""
    groups = loc["feature_groups"]
    return groups["skirt_spread"]["ratio"] > factor * groups["skirt_height"]["ratio"]


def named_localisation(report):
    """The named candidate's refit localisation (None: nothing named, or a report without refit localisations); the
    refit of the effect a signature named where one set the verdict (report.json turn_over or alternation: yield;
    off_centre or hem_tilt: misalignment)."""
    a = report.get("attribution") or {}
    if report["verdict"] in ("none", "unexplained", "not attributed") or not a.get("candidates"):
        return None
    if any(report.get(key) for key in ("turn_over", "alternation", "off_centre", "hem_tilt")):
        named = [c for c in a["candidates"] if c["effect"] == report["verdict"]]
        return named[0].get("localisation") if named else None
    return a["candidates"][0].get("localisation")


def closure_groups(loc, named, lifted_scale):
    """The region of the feature group (or the stable term) the named refit lowers the most (as run if none)."""
    if named is None:
        return loc["region"]
    drops = {g: loc["feature_groups"][g]["ratio"] - r for g, r in named["group_ratios"].items()}
    drops["stable"] = loc["stable_ratio"] - named["stable_ratio"]
    lead = max(drops, key=drops.get)
    if drops[lead] <= 0.0:
        return loc["region"]
    if lead == "stable":
        return stable_region(loc, lifted_scale)
    return group_region(loc, lead)


def closure_regions(loc, named):
    """The region whose floor ratio the named refit lowers the most (as run if none)."""
    if named is None:
        return loc["region"]
    base = {r["region"]: r["floor_ratio"] for r in loc["regions"]}
    drops = {r: base[r] - v for r, v in named["region_floor_ratios"].items() if r in base}
    lead = max(drops, key=drops.get) if drops else None
    return lead if lead is not None and drops[lead] > 0.0 else loc["region"]


def multipath_floor(report):
    """Rule M (pre-registered in session 69): where the multipath test fires, the region furthest above its own floor
    (floor_region) unless that is "global" or the rigid surfaces lead (dominant_feature "camera", as
    place_sensor_gap); else as run."""
    loc = report["localisation"]
    if (multipath_fired(report) and loc.get("floor_region", "global") != "global"
            and loc.get("dominant_feature") != "camera"):
        return loc["floor_region"]
    return loc["region"]


def lifted_top(loc, lifted_mm, fold_depth):
    """Rule T (registered in session 72, adopted in 73: localisation.cpp's place_gap, kLiftedTopContact, since then;
    on reports made before, the rule read off them): as run, but a gap placed on the platform top by the stable term
    where a feature group
    stands further above its floor (place_gap's "a lifted top leads whatever else exceeds its floor") stays there only
    if the top is lifted by at least lifted_mm (its mean residual at most -lifted_mm: cloth that slid rises in
    wrinkles over the top); otherwise the group furthest above its floor places it, as place_gap places a group's gap
    (an outline group follows the skirt where the skirt's residual is the denser; fold_depth's move to the hem)."""
    if loc["region"] != "top" or loc.get("dominant_feature") != "stable" or loc.get("placed_by_views"):
        return loc["region"]
    top = {r["region"]: r for r in loc["regions"]}["top"]
    lead = leading(loc)
    if top["mean_mm"] <= -lifted_mm or lead in (None, "stable"):
        return loc["region"]
    region = group_region(loc, lead)
    return "hem" if region == "skirt" and folds_deeper_than_mean(loc, fold_depth) else region


def skirt_dense(loc, region, factor):
    """Rule S (explored in session 74 on seeds 80-92): `region` (lifted_top's), but a gap an outline group or the fold
    depth put at the hem goes to the skirt where the skirt's pixel residual is at least `factor` times as dense as the
    hem's (enrichment): an edge band (a curled hem) leaves its residual at the hem, a change of the whole skirt (its
    shear, its yielding folds) leaves it denser above."""
    if region != "hem" or loc.get("placed_by_views"):
        return region
    enrichment = {r["region"]: r["enrichment"] for r in loc["regions"]}
    return "skirt" if enrichment.get("skirt", 0.0) >= factor * enrichment.get("hem", 0.0) else region


def hem_offset(loc, offset_mm):
    """Rule O: the region as run, but a gap a feature group placed at the skirt (not the views, not the stable term or
    the camera) is the hem's where the hem's centre lies offset_mm or more off the fitted drape's."""
    lead = loc.get("dominant_feature")
    if loc["region"] != "skirt" or loc.get("placed_by_views") or lead not in loc["feature_groups"]:
        return loc["region"]
    mm = loc["feature_groups"].get("off_centre", {}).get("difference_mm")
    return "hem" if mm is not None and mm >= offset_mm else loc["region"]


def nearest_group(loc):
    """Rule N (registered in session 86 for session 88's sets): the region as run, but a gap nothing places (the
    region "global" with no feature group, stable term or camera above its floor, and not the views) is placed by the
    feature group nearest its floor, as place_gap places a gap that group leads (group_region: an outline group
    follows the skirt where the skirt's residual is the denser, the centre's offset is the hem's, the others the
    skirt's). The report says no more than where the residual comes closest to standing out."""
    if loc["region"] != "global" or loc.get("dominant_feature") or loc.get("placed_by_views"):
        return loc["region"]
    groups = {name: g["ratio"] for name, g in loc["feature_groups"].items() if g.get("ratio") is not None}
    if not groups:
        return loc["region"]
    return group_region(loc, max(groups, key=groups.get))


def place_gap_27(loc, sensor_scale, skirt_denser, lifted_scale):
    """place_gap with the rigid surfaces placing the gap whatever leads (pre-registered in session 27 for seed 19):
    a platform top above its own floor and seen farther than the fitted cloth (no cloth lies inside the platform),
    or a stable term at least lifted_scale times its floor (more than a specimen's contact lifts it), is the rigid
    surfaces' gap, placed by stable_region; else place_gap."""
    if "mean_mm" in loc["regions"][0]:
        top = {r["region"]: r for r in loc["regions"]}["top"]
        if top["floor_ratio"] > 1.0 and top["mean_mm"] > 0.0:
            return "global"
        if loc["stable_ratio"] >= lifted_scale:
            return stable_region(loc, lifted_scale)
    return place_gap(loc, sensor_scale, skirt_denser, lifted_scale)


def place_gap_27b(loc, sensor_scale, skirt_denser, lifted_scale):
    """place_gap_27, and a platform top at least lifted_scale times its own floor (of either sign) is a camera's error,
    "global" whatever leads (pre-registered in session 27 before seed 20 was diagnosed)."""
    if "mean_mm" in loc["regions"][0]:
        top = {r["region"]: r for r in loc["regions"]}["top"]
        if top["floor_ratio"] >= lifted_scale:
            return "global"
    return place_gap_27(loc, sensor_scale, skirt_denser, lifted_scale)


def ranked_verdict(report, region, rule, tolerance):
    """The verdict of `rule` (tolerance, region_tie, region_significant) from the report's candidates, a candidate
    confirmed when its held-out shrinkage is at least -tolerance."""
    a = report["attribution"]
    if not a.get("candidates"):
        return report["verdict"]
    if rule == "tolerance":
        return confirmation_rule(report, tolerance, "objective")
    if report.get("within_floors_after_bending_refit", False):
        return "none"
    def key(c):
        unconfirmed = c["held_out_shrinkage"] < -tolerance
        elsewhere = region not in EFFECT_REGIONS[c["effect"]]
        if rule == "region_tie":
            return (unconfirmed, -c["shrinkage"], elsewhere, c["objective_mm"])
        return (unconfirmed, c["shrinkage"] < THRESHOLD, elsewhere, -c["shrinkage"], c["objective_mm"])

    top = min(a["candidates"], key=key)
    confirmed = top["held_out_shrinkage"] >= -tolerance and top["shrinkage"] >= THRESHOLD
    return top["effect"] if confirmed else "unexplained"


def ranking(runs, sensor_scale, skirt_denser, tolerance):
    rules = ["tolerance", "region_tie", "region_significant"]
    for run in runs:
        right = {r: 0 for r in rules}
        controls = {r: 0 for r in rules}
        effects = ncontrols = 0
        for path in sorted(glob.glob(os.path.join(run, "diagnoses", "*.json"))):
            name = os.path.basename(path)[:-len(".json")]
            if ".p" in name:
                continue
            family = name.rsplit("_", 1)[0]
            with open(path) as f:
                report = json.load(f)
            region = place_gap(report["localisation"], sensor_scale, skirt_denser)  # session 24's, as it was tested
            effects += family != "none"
            ncontrols += family == "none"
            for rule in rules:
                verdict = ranked_verdict(report, region, rule, tolerance)
                if family == "none":
                    controls[rule] += verdict == "none"
                else:
                    right[rule] += verdict == family
        print(run + ": " + ", ".join("%s %d/%d (controls %d/%d)" % (r, right[r], effects, controls[r], ncontrols)
                                     for r in rules))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="+", help="benchmark output directories (diagnoses/, truth/)")
    ap.add_argument("--sensor-scale", type=float, default=1.5, help="place_gap_24's stable ratio for 'global'")
    ap.add_argument("--lifted-scale", type=float, default=2.25,
                    help="place_gap: the stable ratio from which a lifted top is 'global' (kLiftedTopSensorRatio)")
    ap.add_argument("--skirt-denser", type=float, default=1.0, help="place_gap's skirt/hem enrichment factor")
    ap.add_argument("--fold-depth", type=float, default=1.5,
                    help="fold_depth: the skirt_spread/skirt_height ratio from which a skirt gap is the hem's")
    ap.add_argument("--lifted-mm", type=float, default=1.0,
                    help="lifted_top: how far (mm) the top must be lifted for a lifted top to lead (rule T)")
    ap.add_argument("--skirt-dense", type=float, default=1.3,
                    help="skirt_dense: the skirt/hem enrichment ratio from which a hem gap is the skirt's (rule S)")
    ap.add_argument("--hem-offset-mm", type=float, default=6.5,
                    help="hem_offset: the hem centre's offset (mm) from which a skirt gap is the hem's (rule O)")
    ap.add_argument("--ranking", action="store_true", help="the region-aware attribution's verdicts instead")
    ap.add_argument("--closure-only", action="store_true",
                    help="count only the reports whose named candidate carries its refit localisation")
    ap.add_argument("--tolerance", type=float, default=0.1,
                    help="--ranking: the held-out tolerance for every report (default 0.1, the default since session 23)")
    args = ap.parse_args()
    if args.ranking:
        ranking(args.runs, args.sensor_scale, args.skirt_denser, args.tolerance)
        return
    hits = {r: collections.Counter() for r in RULES}
    totals = collections.Counter()
    fired = collections.Counter()  # multipath tests fired: effect captures, controls; rule M's gains and losses
    for run in args.runs:
        for path in sorted(glob.glob(os.path.join(run, "diagnoses", "*.json"))):
            name = os.path.basename(path)[:-len(".json")]
            truth_path = os.path.join(run, "truth", name + ".json")
            if ".p" in name or not os.path.exists(truth_path):
                continue
            family = name.rsplit("_", 1)[0]
            with open(path) as f:
                report = json.load(f)
            if family == "none":
                fired["controls"] += multipath_fired(report)
                continue
            loc, named = report["localisation"], named_localisation(report)
            if args.closure_only and named is None:
                continue
            with open(truth_path) as f:
                regions = set(json.load(f)["regions"])
            region = {"as_run": loc["region"], "largest": largest(loc),
                      "place_gap_24": place_gap(loc, args.sensor_scale, args.skirt_denser),
                      "place_gap": place_gap(loc, args.sensor_scale, args.skirt_denser, args.lifted_scale),
                      "place_gap_27": place_gap_27(loc, args.sensor_scale, args.skirt_denser, args.lifted_scale),
                      "place_gap_27b": place_gap_27b(loc, args.sensor_scale, args.skirt_denser, args.lifted_scale),
                      "pixel_region": loc["pixel_region"], "floor_region": loc.get("floor_region"),
                      "split_enrichment": split(loc, "enrichment"), "split_floor_ratio": split(loc, "floor_ratio"),
                      "skirt_floor_ratio": skirt_to_hem(loc, lambda x: split(x, "floor_ratio") == "hem"),
                      "fold_depth": skirt_to_hem(loc, lambda x: folds_deeper_than_mean(x, args.fold_depth)),
                      "closure_groups": closure_groups(loc, named, args.lifted_scale),
                      "closure_regions": closure_regions(loc, named), "multipath_floor": multipath_floor(report),
                      "lifted_top": lifted_top(loc, args.lifted_mm, args.fold_depth)}
            region["skirt_dense"] = skirt_dense(loc, region["lifted_top"], args.skirt_dense)
            region["hem_offset"] = hem_offset(loc, args.hem_offset_mm)
            region["nearest_group"] = nearest_group(loc)
            totals[family] += 1
            if multipath_fired(report):
                fired["effect captures"] += 1
                was, now = region["as_run"] in regions, region["multipath_floor"] in regions
                fired["rule M gains"] += now and not was
                fired["rule M losses"] += was and not now
            for rule in RULES:
                hits[rule][family] += region[rule] in regions
    families = sorted(totals)
    print("%-17s %7s  " % ("rule", "all") + " ".join("%12s" % f for f in families))
    for rule in RULES:
        n = sum(hits[rule].values())
        print("%-17s %3d/%-3d  " % (rule, n, sum(totals.values())) +
              " ".join("%12s" % ("%d/%d" % (hits[rule][f], totals[f])) for f in families))
    print("multipath test fired: " + ", ".join("%s %d" % (k, fired[k]) for k in
                                               ("effect captures", "controls", "rule M gains", "rule M losses")))


if __name__ == "__main__":
    main()
