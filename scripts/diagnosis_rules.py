#!/usr/bin/env python3
"""Verdicts of alternative attribution rules, read off the report.json files of a diagnosis benchmark run made with
three placements (`drapegen_diagnosis_bench --placements 3 --second-placement`); the truth files are read only to
score. Hypotheses for the next evaluation, not the diagnosis's rule (docs/DIAGNOSIS_RESULTS.md, "Session 18"):

- current: the verdict as run;
- tie_objective: the verdict as run, but among confirmed candidates with the top shrinkage (in practice several
  within the floors, shrinkage 1) the smallest refit objective (the rule since session 19; before, the larger
  held-out shrinkage);
- no_bar: the reference is the baseline's validated drape (no bar, no "none once the bending is refitted"), the
  ranking and the confirmation otherwise as run;
- no_bar_unconfirmed: the same without the held-out confirmation;
- mean3: the shrinkage of the excess of the mean of the three placements' gap terms (the held-out one included),
  confirmed candidates only, against the run's reference;
- held_out_excess: the same on the held-out capture's terms alone;
- held_out_rank: among the confirmed candidates that shrink the gate's excess by the threshold, the largest held-out
  score shrinkage;
- tie_held_out_view (session 34): the verdict as run, but among the confirmed candidates tied exactly at the top
  shrinkage (physical effects before the sensor error) the smallest score on the capture's held-out view, which no
  refit sees, instead of the smallest refit objective (3 more right on seeds 17-32; pre-registered on fresh seed 33,
  it named one fewer: negative, not the diagnosis's rule);
- tie_held_out (rule H, session 71, pre-registered for fresh seeds 84-86: docs/preregistrations/session71.md): the
  verdict as run, but among the confirmed candidates tied exactly at the top shrinkage (physical effects before the
  sensor error) the largest held-out shrinkage (on the held-out placement, which no refit sees; else the held-out
  view) instead of the smallest refit objective (the tie rule before session 19, under the protocol with one
  placement); not where the run put curl, the sensor error or a near tie first (+1 in sample on seeds 80-83; on
  seeds 84-86 it named as the default: not adopted);
- no_near_tie (rule N, session 71, a lead for a later registration): the verdict as run, but where the run promoted
  a near tie (report.json attribution.near_tie.promoted; `--tie-margin`, default 0.1), the confirmed candidate it
  displaced: near ties as `--tie-margin 0` would leave them (the one promotion on seeds 80-86, seed 84's sensor_04,
  named a depth bias yield by a refit objective the sensor candidate's cannot match: it keeps the bending);
- common4 (session 46): the verdict with `--common-bending 4` (the common bending decides only where four or more
  effects are each within the floors), from reports made with the default 3; pre-registered on fresh seed 41
  (out/s48_prereg.txt);
- views_sensor (rule V, session 69, pre-registered for fresh seeds 78-79: out/p71/prereg.txt): "sensor" wherever the
  report's multipath test fired (the four views disagree, which no physical effect makes them), within the floors
  too; elsewhere the verdict as run;
- views_camera (rule C, session 70, pre-registered for fresh seeds 82-83: docs/preregistrations/session70.md):
  "sensor" wherever the smallest cross-view residual RMS over the placements reaches 4.0 mm (a camera pose error
  makes the views disagree; session 70's seeds 80-81: 4.05-4.92 mm on 4 pose errors, at most 3.70 on 4 depth biases
  and 3.36 on 18 physical captures and controls), within the floors too; elsewhere the verdict as run;
- tie_region (rule R, session 70, pre-registered for fresh seeds 82-83): where the named effect is tied at its
  shrinkage with other confirmed candidates and the gap's localised region is not where it acts but is where a tied
  one acts, that one (EFFECT_REGIONS); elsewhere the verdict as run;
- wide_tolerance (rule W, session 73, pre-registered for fresh seeds 91-92: docs/preregistrations/session73.md;
  adopted in session 74, the default since 926e8af: on reports since, the verdict as run):
  attribute()'s verdict recomputed with the held-out tolerance 0.2 (`--held-out-tolerance 0.2`) instead of the
  run's 0.1 (`reattribute`: the whole ranking, near ties and promotions as attribute() runs them; `--wide T` sets
  another tolerance; `--check-reattribute DIR...` checks that the run's own tolerance gives every verdict as run);
- rise_yield (rule U, session 78, pre-registered for fresh seeds 103-104: docs/preregistrations/session79.md; adopted
  in session 79, `drapegen diagnose --turn-over-yield 0.02` in the --fine preset: on reports since, the verdict as
  run, and on every rule's verdict where settings.turn_over_yield is set, `signatures_applied`): "yield" where the
  verdict as run names no effect (none or unexplained) and the first turn-over raised the drape coefficient by 0.02 or
  more (gap_tests.second_capture less gap_tests.capture, the second placement on the other face); elsewhere the
  verdict as run;
- rise_yield_015 (rule U15, session 79, pre-registered for fresh seeds 105-106: docs/preregistrations/session80.md):
  rule U with a rise of 0.015 instead of 0.02;
- rise_later_yield (rule U2, session 79, an addendum registered for seeds 105-106: docs/preregistrations/session80.md):
  rule U on the larger rise of the two later placements (the turned second capture, the held-out third face up again);
- yield_needs_rise (rule K, session 80, pre-registered for fresh seeds 107-108: docs/preregistrations/session81.md):
  "unexplained" where the verdict as run is yield and the first turn-over raised the drape coefficient by less than
  0.02; elsewhere the verdict as run;
- alternation_yield (rule A, registered in session 81 for seeds 109-110: docs/preregistrations/session82.md; adopted
  in session 82, `drapegen diagnose --turn-over-alternation 0.015` in the --fine preset until session 83, when it left
  it (docs/DIAGNOSIS_RESULTS.md, "Session 84"): on reports of sessions 83-84, the verdict
  as run, and on every rule's verdict where settings.turn_over_alternation is set, `signatures_applied`): rule U and
  rule K on the turn-over's alternation, the turned second capture's drape coefficient less the mean of the first and
  the third's, at 0.015;
- off_centre (rule E, registered in session 81 for seeds 109-110; adopted in session 82, `--off-centre-misalignment
  2.5` in the --fine preset): "misalignment" where the verdict names no effect, the run's rule U names no yield, and
  the hem's centre offset is 2.5 times its floor or more; else the verdict as run;
- later_yield (rule L, registered in session 82 for fresh seeds 111-112, an addendum:
  docs/preregistrations/session83.md; +1 -1 there, a misalignment named yield: not adopted): after the run's
  signatures (rules U, A and E as run), "yield" where the verdict names no effect and the third placement, laid on the
  capture's face again, drapes with a drape coefficient LATER or more above the capture's (gap_tests.held_out_capture
  less gap_tests.capture): the set two drapes leave stiffens the next one, an elastic fabric has no memory;
- alternation_veto (rule A2, registered in session 82 for fresh seeds 113-114: docs/preregistrations/session84.md):
  after the run's signatures, "unexplained" where the refits named yield and the verdict is still theirs, the
  turn-over's alternation is below VETO (0.02; rule A withdraws below 0.015) and the run's rule U names nothing
  (+0 -0 on seeds 113-114: not adopted);
- later_mean_yield (rule L2, written in session 83 before seeds 113-114 were read, not registered: a control of seed
  114 reached +0.0181): after the run's signatures, "yield" where the verdict names no effect and the turned second
  and the third placement drape LATER_MEAN (0.017) or more above the capture on average;
- off_centre_mm (rule D, registered in session 83 for fresh seeds 115-116: docs/preregistrations/session85.md): after
  the run's signatures, "misalignment" where the verdict names no effect and the hem's centre lies OFF_CENTRE_MM
  (6.5 mm) or more off the fitted drape's, whatever its floor;
- off_centre_mm_over_yield (rule D2, an addendum to session 85's registration; +0 -0 on seeds 115-116, +1 -0 on
  fresh seeds 117-118: adopted in session 85; its one verdict on seeds 119-120 wrong, a shear within the floors, so it
  left the --fine preset in the same session): rule D, and "misalignment" too where the verdict is the refits' yield,
  the run's rule U names nothing and the hem's centre lies OFF_CENTRE_MM or more off;
- lifted_top_friction (rule F, registered in session 84 for fresh seeds 117-118: docs/preregistrations/session86.md;
  +0 -0 there, not adopted): after the run's signatures, "friction" where the verdict is none, unexplained or yield
  and the rigid surfaces read the platform top lifted by LIFTED_TOP_MM (0.5 mm) or more;
- min_objective: the candidate whose refit objective (in-sample: the capture and the second capture) is the smallest;
  it ignores the held-out data, which the issue's attribution must use: a diagnostic of the refits, not a rule.

Two more recompute the held-out confirmation from each candidate's held-out shrinkage (session 23):
- strict: confirmed only if not worse than the reference on the held-out capture (held-out shrinkage >= 0; the rule
  before session 23);
- tolerance: confirmed if at most 10% worse (held-out shrinkage >= -0.1; AttributionSettings::held_out_tolerance, the
  rule since session 23; `--tolerance T` sets another);
both rank as attribute() does since session 25: confirmed first, then the shrinkage, then a physical effect before
the sensor error, then the smaller objective. Two more break the ties of equal shrinkage otherwise (session 25):
- objective_ties: the smaller objective alone (the tolerance rule as sessions 23-24 ran it);
- parsimony: fewer parameters first (candidate_effect.cpp, effect_space: sensor 9, misalignment 2, the others 1),
  then the smaller objective. The other rules
confirm as the run did (its report's `attribution.held_out_tolerance`, 0 in reports made before session 23).

Three more read reports made with `drapegen diagnose --ablation` (session 20; on reports without ablations they give
the main rule):
- without_ablation: the main rule (the bar or the baseline the reference, the objective breaking ties) recomputed
  from the validated drapes, as a run without --ablation names (checked against such runs on 12 captures);
- reach: the reference the smallest validated excess among the bar and every candidate's ablation (a bar that
  reaches the candidates' bending scales, chosen on the validation drapes);
- reach_objective: the reference the bending-only setup of the smallest refit objective among the bar and the
  ablations (chosen as the bar's own search would choose).

One more lists where session 29's common bending would be validated (it needs a simulation, so no verdict here):
- `--common DIR...`: per capture, the confirmed candidates that each bring the gate's excess to 0 (`common` when
  three or more, AttributionSettings::common_bending_effects), the verdict as run and whether it is right.
And one lists where near ties change the verdict as run (session 30's order, gone since session 31, and the order
near_ties_first names by since then):
- `--near-ties M DIR...`: among the confirmed candidates at least THRESHOLD and within M of the first's shrinkage, a
  physical effect before the sensor error, then the smaller refit objective, then the larger held-out shrinkage
  (not applied where the run put curl first, or named none);
- `--near-ties M --objective DIR...` (session 31's hypothesis, the default since): the same candidates, the smallest
  refit objective named, where the first is not tied exactly (exact ties keep the run's order);
- `--substitute EFFECT NEW OLD` (session 32): OLD's verdicts with EFFECT's candidate taken from NEW's reports of the
  same captures (a run with `--candidates EFFECT` under a changed refit), ranked as attribute() ranks;
- `--gate-terms DIR...` (session 33): the gate's shape term over its floor as run (two placements) and with the
  held-out capture averaged in, for controls, effect captures within the floors at the gate, and the rest;
- `--draw-noise DIR...`: how much the gate's excess changes, as a share of itself, when the second-best validation
  drape by fit score is taken instead of the best (the noise a shrinkage carries; the margin's scale).

    scripts/diagnosis_rules.py out/s18all [more runs ...]
    scripts/diagnosis_rules.py --common out/s28s19all out/s28s20      # where the common bending fires
    scripts/diagnosis_rules.py --matrix without_ablation out/s21all     # one rule's confusion matrix
    scripts/diagnosis_rules.py --matrix current --pooled out/s28s19all out/s30s22all   # one over several runs
    scripts/diagnosis_rules.py --tolerance 0.05 out/s23all               # the tolerance rule at 5%
    scripts/diagnosis_rules.py --check-reattribute out/p74/s88           # reattribute() reproduces the run
    scripts/diagnosis_rules.py --wide 0.3 out/p74/s88                    # rule W at another tolerance
    scripts/diagnosis_rules.py --near-ties 0.1 out/s28s20 out/s30s22all   # where a tie margin of 0.1 names otherwise
"""
import glob
import json
import os
import statistics
import sys

THRESHOLD = 0.25  # AttributionSettings::significant_shrinkage
TOLERANCE = 0.1  # AttributionSettings::held_out_tolerance (sessions 23-73; 0.2 since 74); --tolerance sets the rule's
RULES = ["current", "strict", "tolerance", "objective_ties", "parsimony", "tie_objective", "no_bar", "no_bar_unconfirmed",
         "mean3", "held_out_excess", "held_out_rank", "min_objective", "without_ablation", "reach", "reach_objective",
         "tie_held_out_view", "tie_held_out", "no_near_tie",
         "common4", "views_sensor", "views_camera", "tie_region", "wide_tolerance", "rise_yield", "rise_yield_015",
         "rise_later_yield", "yield_needs_rise", "alternation_yield", "off_centre", "later_yield", "alternation_veto",
         "later_mean_yield", "off_centre_mm", "off_centre_mm_over_yield", "lifted_top_friction"]
PARAMETERS = {"sensor": 9, "misalignment": 2}  # effect_space's dimension; the others have 1
# How each rule orders candidates of equal shrinkage before their objectives (confirmation_rule).
TIES = {"physical_first": lambda effect: effect == "sensor",  # attribute() since session 25 (needs_simulation)
        "objective": lambda effect: 0,
        "parsimony": lambda effect: PARAMETERS.get(effect, 1)}
FAMILY = {"pose": "sensor", "bias": "sensor", "multipath": "sensor", "misalign": "misalignment"}


def excess(stable, shape, stable_floor, shape_floor):
    return max(0.0, stable - stable_floor) / stable_floor + max(0.0, shape - shape_floor) / shape_floor


def shrink(before, after):
    return 1.0 - after / before if before > 0 else 0.0


def terms(v):
    """A validated drape's (stable term, shape distance) per placement."""
    return {"capture": (v["stable_mm"], v["shape"]),
            "second": (v["second_capture"]["stable_mm"], v["second_capture"]["shape"]),
            "held_out": (v["held_out_capture"]["stable_mm"], v["held_out_capture"]["shape"])}


def first_largest(pairs):
    """The effect of the first largest value (attribute()'s order breaks ties), or None."""
    best = None
    for value, effect in pairs:
        if best is None or value > best[0]:
            best = (value, effect)
    return best


def named(best, within):
    if within:
        return "none"
    return best[1] if best and best[0] >= THRESHOLD else "unexplained"


def run_tolerance(j):
    """The held-out tolerance the run confirmed with (0 before session 23, whose reports do not state it)."""
    return j["attribution"].get("held_out_tolerance", 0.0)


def confirmation(v):
    """A validated drape's confirmation score: the held-out capture's over all views, else the held-out view's."""
    return v["held_out_capture"]["all_views_score_mm"] if v.get("held_out_capture") else v["held_out_score_mm"]


def reference_rule(j, rule):
    """The verdict with the reference chosen by `rule` (without_ablation, reach, reach_objective); the ranking as
    attribute()'s: confirmed first, then the shrinkage, then the smaller objective."""
    g, a = j["gap_tests"], j["attribution"]
    allowed = 1.0 + run_tolerance(j)  # a confirmed candidate's held-out score: at most this x the reference's
    bar = a["bending_refit_bar"]
    base_excess, bar_excess = g["excess_above_floors"], bar["validated"]["excess_above_floors"]
    if bar_excess == 0:
        return "none"
    ref = (bar_excess, confirmation(bar["validated"])) if bar_excess < base_excess else (
        base_excess, confirmation(g))
    ablations = [c["ablated"] for c in a["candidates"] if c.get("ablated")]
    if rule == "reach":
        for ab in ablations:
            if ab["excess_above_floors"] < ref[0]:
                ref = (ab["excess_above_floors"], confirmation(ab))
    elif rule == "reach_objective":
        best = min([(bar["objective_mm"], bar["validated"])] +
                   [(ab["objective_mm"], ab) for ab in ablations if "objective_mm" in ab], key=lambda t: t[0])[1]
        if best["excess_above_floors"] == 0:
            return "none"
        if best["excess_above_floors"] < base_excess:
            ref = (best["excess_above_floors"], confirmation(best))
    if ref[0] == 0:
        return "none"
    ranked = sorted(a["candidates"], key=lambda c: (
        confirmation(c["validated"]) > allowed * ref[1], -shrink(ref[0], c["validated"]["excess_above_floors"]),
        c["objective_mm"]))
    top = ranked[0]
    ok = (confirmation(top["validated"]) <= allowed * ref[1] and
          shrink(ref[0], top["validated"]["excess_above_floors"]) >= THRESHOLD)
    return top["effect"] if ok else "unexplained"


def confirmation_rule(j, tolerance, ties="physical_first"):
    """The verdict with a candidate confirmed when its held-out shrinkage is at least -tolerance; candidates of equal
    shrinkage ordered by TIES[ties], then the smaller objective."""
    a = j["attribution"]
    if j.get("within_floors_after_bending_refit", False):
        return "none"
    ranked = sorted(a["candidates"], key=lambda c: (
        c["held_out_shrinkage"] < -tolerance, -c["shrinkage"], TIES[ties](c["effect"]),
        c["objective_mm"], -c["held_out_shrinkage"]))
    top = ranked[0]
    ok = top["held_out_shrinkage"] >= -tolerance and top["shrinkage"] >= THRESHOLD
    return top["effect"] if ok else "unexplained"


WIDE_TOLERANCE = 0.2  # rule W's held-out tolerance (docs/preregistrations/session73.md); --wide T sets another


def reattribute(j, tolerance):
    """attribute()'s verdict (attribution.cpp) recomputed from the report with another held-out tolerance: a candidate
    confirmed where its held-out shrinkage is at least -tolerance (or where the run confirmed it within the floors),
    ranked by ranks_before, then near_ties_first, the curl and the sensor promotions and the named test as attribute()
    runs them. "undetermined" where the candidates the common bending reads (confirmed and within the floors, three or
    more) differ from the run's: their shared bending would need a simulation. With the run's own tolerance it
    reproduces the verdict as run (checked by --check-reattribute)."""
    a = j["attribution"]
    cands = a.get("candidates") or []
    if not cands:
        return j["verdict"]

    def confirmed(c):
        return c["held_out_shrinkage"] >= -tolerance or c.get("confirmed_by") == "held_out_within_floors"

    def common(cs):
        shared = sorted(c["effect"] for c in cs if c["confirmed"] and c["validated"]["excess_above_floors"] == 0.0)
        at_least = a.get("common_bending_effects", 3)
        return shared if at_least > 0 and len(shared) >= at_least else []

    cs = [dict(c, confirmed=confirmed(c)) for c in cands]
    if common(cs) != common(cands):
        return "undetermined"
    if j.get("within_floors_after_bending_refit", False):
        return "none"
    cs.sort(key=lambda c: (not c["confirmed"], -c["shrinkage"], c["effect"] == "sensor", c["objective_mm"],
                           -c["held_out_shrinkage"]))
    significant = a.get("significant_shrinkage", THRESHOLD)
    margin = (a.get("near_tie") or {}).get("margin", 0.0)
    first = cs[0]
    exact_tie = len(cs) > 1 and cs[1]["confirmed"] and cs[1]["shrinkage"] == first["shrinkage"]
    if first["confirmed"] and margin > 0 and not exact_tie:  # near_ties_first
        best = first
        for c in cs[1:]:
            if (c["confirmed"] and c["shrinkage"] >= significant and c["shrinkage"] >= first["shrinkage"] - margin
                    and c["objective_mm"] < best["objective_mm"]):
                best = c
        cs.remove(best)
        cs.insert(0, best)
    g = j["gap_tests"]

    def promote(effect):
        for c in cs:
            if c["effect"] == effect and c["confirmed"] and c["shrinkage"] >= significant:
                cs.remove(c)
                cs.insert(0, c)
                return

    if (g.get("fold_repeatability") or {}).get("folds_less_alike"):
        promote("curl")
    if (a.get("sensor_first") or {}).get("multipath_first") and multipath_fired(j):
        promote("sensor")
    top = cs[0]
    return top["effect"] if top["confirmed"] and top["shrinkage"] >= significant else "unexplained"


def wide_tolerance(j):
    """Rule W (pre-registered in session 73 for fresh seeds 91-92: docs/preregistrations/session73.md): the verdict
    with the held-out tolerance WIDE_TOLERANCE instead of the run's 0.1 (`--held-out-tolerance 0.2`): a candidate
    that closes the gap on the two placements it was refitted on counts if the third placement, turned over, scores
    at most 20% worse than the reference's (session 23 set 10% under the protocol with one placement, on a held-out
    view)."""
    return reattribute(j, WIDE_TOLERANCE)


def check_reattribute(roots):
    """Every report's verdict as run against reattribute() with the run's own tolerance: they must agree."""
    bad = total = 0
    for root in roots:
        for name, _, j in reports(root):
            if not (j.get("attribution") or {}).get("candidates"):
                continue
            total += 1
            again = reattribute(j, run_tolerance(j))
            if again != j["verdict"]:
                bad += 1
                print(f"{root} {name}: as run {j['verdict']}, recomputed {again}")
    print(f"reattribute: {total - bad} of {total} attributed reports recomputed as run")
    return 1 if bad else 0


def common_at_least(j, k):
    """The verdict with `--common-bending K` from a report made with a count of at most K (the default 3): the
    candidates do not depend on the count, only the verdict does (none where the bar or the common bending is within
    the floors, else the first candidate if confirmed and significant, else unexplained). "undetermined" for a report
    made without the rule or with a larger count (its common bending would need a simulation)."""
    a = j["attribution"]
    ran_with = a.get("common_bending_effects", 3)  # recorded since session 46; the default 3 before
    if "common_bending" not in a or ran_with == 0 or ran_with > k:
        return "undetermined"  # made before session 29's rule, without it, or with a larger count
    cb = a["common_bending"]  # null where fewer effects were within the floors, or the bar was itself
    if not cb or not cb["within_floors"] or len(cb["effects"]) >= k:
        return j["verdict"]
    top = a["candidates"][0]
    return top["effect"] if top["confirmed"] and top["shrinkage"] >= a["significant_shrinkage"] else "unexplained"


def multipath_fired(report):
    """The report's multipath test fired (gap_tests.view_consistency, reports since 0a703f1; False without it)."""
    return bool(((report.get("gap_tests") or {}).get("view_consistency") or {}).get("multipath", False))


def views_sensor(j):
    """Rule V (pre-registered in session 69 for seeds 78-79): "sensor" where the report's multipath test fired, within
    the floors too; else the verdict as run."""
    return "sensor" if multipath_fired(j) else j["verdict"]


CAMERA_RMS_MM = 4.0  # rule C's threshold (docs/preregistrations/session70.md)


def placement_rms(report):
    """mm: each placement's cross-view residual RMS (gap_tests.view_consistency.placements[].rms_mm; [] without)."""
    views = ((report.get("gap_tests") or {}).get("view_consistency") or {}).get("placements") or []
    return [p["rms_mm"] for p in views]


def views_camera(j):
    """Rule C (pre-registered in session 70 for seeds 82-83: docs/preregistrations/session70.md): "sensor" where the
    smallest cross-view residual RMS over the placements (gap_tests.view_consistency.placements[].rms_mm) is at least
    CAMERA_RMS_MM, within the floors too: the views disagree, which a camera error makes them and no physical effect
    does; else the verdict as run."""
    rms = placement_rms(j)
    return "sensor" if rms and min(rms) >= CAMERA_RMS_MM else j["verdict"]


# Where each effect acts (candidate_effect.cpp, effect_regions; scripts/region_rules.py imports it).
EFFECT_REGIONS = {"yield": {"skirt"}, "shear": {"skirt"}, "curl": {"hem"}, "misalignment": {"hem"},
                  "friction": {"top", "rim"}, "sensor": {"global"}}


def tie_region(j):
    """Rule R (pre-registered in session 70 for seeds 82-83: docs/preregistrations/session70.md): where the verdict as
    run is a candidate tied at its shrinkage with other confirmed candidates, and the report's localised region
    (localisation.region, as run) is not where the named effect acts but is where a tied one acts, that one (the
    smallest refit objective among such); elsewhere the verdict as run."""
    named_effect = j["verdict"]
    cands = (j.get("attribution") or {}).get("candidates") or []
    named_c = next((c for c in cands if c["effect"] == named_effect), None)
    region = (j.get("localisation") or {}).get("region")
    if named_c is None or region is None or region in EFFECT_REGIONS.get(named_effect, set()):
        return named_effect
    tied = [c for c in cands if c is not named_c and c["confirmed"] and c["shrinkage"] == named_c["shrinkage"]
            and region in EFFECT_REGIONS.get(c["effect"], set())]
    return min(tied, key=lambda c: c["objective_mm"])["effect"] if tied else named_effect


RISE = 0.02  # rule U's rise of the drape coefficient (docs/preregistrations/session79.md)


def turn_over_rise(report):
    """The second capture's drape coefficient less the capture's (gap_tests.*.drape_coefficient, the outlines their
    views see), where the second capture lies on the other face (report placements[].face); None otherwise."""
    faces = {p["role"]: p["face"] for p in report.get("placements", [])}
    if "second_capture" not in faces or faces.get("capture") == faces["second_capture"]:
        return None
    g = report.get("gap_tests") or {}
    c0 = (g.get("capture") or {}).get("drape_coefficient")
    c1 = (g.get("second_capture") or {}).get("drape_coefficient")
    return None if c0 is None or c1 is None else c1 - c0


RISE_015 = 0.015  # rule U15's (docs/preregistrations/session80.md)


def yield_where_risen(j, rise, floor):
    """"yield" where the verdict as run names no effect (none or unexplained) and `rise` is at least `floor`; else the
    verdict as run: rules U, U15 and U2, which differ in the rise they read and its floor."""
    fires = j["verdict"] in ("none", "unexplained") and rise is not None and rise >= floor
    return "yield" if fires else j["verdict"]


def yield_unless_risen(j, rise, floor):
    """"unexplained" where the verdict as run is yield and `rise` is below `floor`; else the verdict as run: rules K
    and A's withdrawal, which differ in the rise they read and its floor."""
    withdrawn = j["verdict"] == "yield" and rise is not None and rise < floor
    return "unexplained" if withdrawn else j["verdict"]


def rise_yield_015(j):
    """Rule U15 (registered in session 79 for seeds 105-106: docs/preregistrations/session80.md): rule U with a rise of
    RISE_015 instead of RISE (the run's own rule U laid on it afterwards, as on every rule)."""
    return yield_where_risen(j, turn_over_rise(j), RISE_015)


def later_rise(report):
    """The larger of the second and the held-out capture's drape coefficients less the capture's, where the second lies
    on the other face (the turned placement, and the third laid as the first): None otherwise."""
    rise = turn_over_rise(report)
    c2 = ((report.get("gap_tests") or {}).get("held_out_capture") or {}).get("drape_coefficient")
    c0 = ((report.get("gap_tests") or {}).get("capture") or {}).get("drape_coefficient")
    if rise is None or c2 is None or c0 is None:
        return rise
    return max(rise, c2 - c0)


def rise_later_yield(j):
    """Rule U2 (registered in session 79 for seeds 105-106, an addendum: docs/preregistrations/session80.md): rule U on
    either later placement: "yield" where the verdict names no effect and the turned second capture or the third,
    laid face up again, drapes with a drape coefficient RISE or more above the capture's (the run's rule U laid on it
    afterwards, as on every rule)."""
    return yield_where_risen(j, later_rise(j), RISE)


def rise_yield(j):
    """Rule U (pre-registered in session 78 for seeds 103-104: docs/preregistrations/session79.md): "yield" where the
    verdict as run names no effect ("none", within the floors or once the bending is refitted, or "unexplained") and
    the first turn-over raised the drape coefficient by RISE or more: a plastic set makes the specimen, turned over,
    drape stiffer, which an elastic one does not (none of the 72 controls of seeds 80-102 rose by 0.02); else the
    verdict as run."""
    return yield_where_risen(j, turn_over_rise(j), RISE)


def yield_needs_rise(j):
    """Rule K (registered in session 80 for seeds 107-108: docs/preregistrations/session81.md): "unexplained" where
    the refits name yield, the second capture lies turned over and the first turn-over raised the drape coefficient by
    less than RISE: a plastic set stiffens the turned drape (46 of 60 yields over seeds 80-106 rose by RISE or more;
    the 9 yields the refits named yield on seeds 101-106 by +0.029 or more), while the 3 controls the refits named
    yield there rose by +0.010 to +0.016, the yield refit standing for a softer elastic fabric. Else the verdict as
    run (the refits', the run's turn-over laid on it afterwards, as on every rule)."""
    return yield_unless_risen(j, turn_over_rise(j), RISE)


ALTERNATION = 0.015  # rule A's floor (--turn-over-alternation in the --fine preset in sessions 82-83)


def turn_over_alternation(report):
    """The turned second capture's drape coefficient less the mean of the first and the third (both laid face up):
    the set a plastic fabric takes on one face stiffens the drape on the other and relaxes on the first again, while
    an elastic fabric's three drapes differ by the noise; None where the second capture is not turned or a placement
    lacks its drape coefficient or the third lies on the other face (drapegen diagnose --turn-over-alternation reads
    the same)."""
    rise = turn_over_rise(report)
    g = report.get("gap_tests") or {}
    c2 = (g.get("held_out_capture") or {}).get("drape_coefficient")
    c0 = (g.get("capture") or {}).get("drape_coefficient")
    faces = {p["role"]: p["face"] for p in report.get("placements", [])}
    if rise is None or c2 is None or faces.get("held_out_capture") != faces.get("capture"):
        return None
    return rise - (c2 - c0) / 2.0


def alternation_yield(j):
    """Rule A (a candidate for session 82): rule U on the turn-over's alternation (turn_over_alternation) at
    ALTERNATION instead of the first rise at RISE; where rule K's test withdraws a yield, on the alternation too."""
    alt = turn_over_alternation(j)
    if j["verdict"] == "yield":
        return yield_unless_risen(j, alt, ALTERNATION)
    return yield_where_risen(j, alt, ALTERNATION)


def run_turn_over_names(j):
    """Whether the run's rule U (settings.turn_over_yield > 0) names yield wherever a verdict names no effect: the
    first turn-over raised the drape coefficient by its floor or more."""
    floor = (j.get("settings") or {}).get("turn_over_yield", 0.0)
    rise = turn_over_rise(j)
    return floor > 0.0 and rise is not None and rise >= floor


OFF_CENTRE = 2.5  # rule E's ratio of the hem's centre offset to its floor (a candidate for session 82)


def off_centre_group(report):
    """The report's off-centre feature group (localisation.feature_groups.off_centre: the order-1 harmonic of the hem's
    radius and height, capture less model); {} where the report lacks it."""
    return ((report.get("localisation") or {}).get("feature_groups") or {}).get("off_centre") or {}


def off_centre_ratio(report):
    """The hem's centre offset against its noise floor (off_centre_group's ratio); None where the report lacks it."""
    return off_centre_group(report).get("ratio")


def refits_yield_stands(j, verdict):
    """Whether `verdict` is the refits' yield (`j`'s verdict, refits_report's; no signature set it) and the run's rule
    U would not name yield by itself (rule A2's and rule D2's condition)."""
    return verdict == "yield" and j["verdict"] == "yield" and not run_turn_over_names(j)


def off_centre_misalignment(j):
    """Rule E (a candidate for session 82): "misalignment" where the verdict names no effect (none or unexplained),
    the run's rule U does not name yield, and the hem's centre lies OFF_CENTRE times its floor or more off the model's:
    a specimen laid off centre hangs longer on one side, which no elastic fabric's drape on a centred specimen does
    (the 24 controls of seeds 101-106 reached 1.77; 10 of their 12 misalignments 2.5 or more); else the verdict."""
    if run_turn_over_names(j):
        return j["verdict"]
    ratio = off_centre_ratio(j)
    fires = j["verdict"] in ("none", "unexplained") and ratio is not None and ratio >= OFF_CENTRE
    return "misalignment" if fires else j["verdict"]


LATER = 0.02  # rule L's floor on the third placement's rise (docs/preregistrations/session83.md; not adopted)


def third_rise(report):
    """The held-out (third) capture's drape coefficient less the capture's where it lies on the capture's face; None
    otherwise."""
    faces = {p["role"]: p["face"] for p in report.get("placements", [])}
    g = report.get("gap_tests") or {}
    c0 = (g.get("capture") or {}).get("drape_coefficient")
    c2 = (g.get("held_out_capture") or {}).get("drape_coefficient")
    if c0 is None or c2 is None or faces.get("held_out_capture") != faces.get("capture"):
        return None
    return c2 - c0


def later_yield(j, verdict):
    """Rule L (an addendum registered in session 82 for seeds 111-112): laid after the run's signatures, on `verdict`
    (the default's with them): "yield" where it names no effect and the third placement rose LATER or more."""
    rise = third_rise(j)
    return "yield" if verdict in ("none", "unexplained") and rise is not None and rise >= LATER else verdict


VETO = 0.02  # rule A2's withdrawal floor on the alternation (docs/preregistrations/session84.md)


def alternation_veto(j, verdict):
    """Rule A2 (registered in session 82 for seeds 113-114): laid after the run's signatures, on `verdict` (the
    default's with them): "unexplained" where it is the refits' yield (`j`'s verdict, refits_report's), the turn-over's
    alternation is below VETO and the run's rule U does not name yield; else `verdict`. On seeds 101-112 the 17 yields
    the refits named alternated by +0.0257 or more, the 7 other captures they named yield by +0.0156 at most."""
    alternation = turn_over_alternation(j)
    vetoed = refits_yield_stands(j, verdict) and alternation is not None and alternation < VETO
    return "unexplained" if vetoed else verdict


LATER_MEAN = 0.017  # rule L2's floor on the later placements' mean rise (not registered)


def later_mean_rise(report):
    """The mean of the turned second and the third placement's drape coefficients less the capture's, where the second
    lies on the other face and the third on the capture's; None otherwise."""
    rise, third = turn_over_rise(report), third_rise(report)
    return None if rise is None or third is None else 0.5 * (rise + third)


def later_mean_yield(j, verdict):
    """Rule L2 (written in session 83, not registered: on seeds 113-114 a control reached +0.0181): laid after the
    run's signatures, on `verdict`: "yield" where it names no effect and the two later placements drape LATER_MEAN or
    more above the capture on average: the set every drape leaves stiffens each later one, on either face, while an
    elastic fabric's placements differ by their noise. Seeds 101-112 (in sample, read off them): 5 of the 11 yields
    the default left unnamed reached 0.0193 or more, no control (at most 0.0138) nor other unnamed capture (at most
    0.0148)."""
    rise = later_mean_rise(j)
    fires = verdict in ("none", "unexplained") and rise is not None and rise >= LATER_MEAN
    return "yield" if fires else verdict


OFF_CENTRE_MM = 6.5  # rule D's floor on the hem's centre offset in mm (docs/preregistrations/session85.md)


def off_centre_mm(report):
    """The hem's centre offset from the fitted drape's in mm (off_centre_group's difference_mm); None where the report
    lacks it."""
    return off_centre_group(report).get("difference_mm")


def off_centre_mm_misalignment(j, verdict):
    """Rule D (registered in session 83 for seeds 115-116): laid after the run's signatures, on `verdict`:
    "misalignment" where it names no effect and the hem's centre lies OFF_CENTRE_MM or more off the fitted drape's,
    whatever its floor (rule E reads the offset over its floor, which reached 4-6 mm where rule E missed). Seeds
    101-112 (in sample): 3 of the 5 misalignments the default left unnamed reached 8.6 mm or more, no control (at most
    4.84 mm) nor other unnamed capture (at most 3.69 mm)."""
    mm = off_centre_mm(j)
    fires = verdict in ("none", "unexplained") and mm is not None and mm >= OFF_CENTRE_MM
    return "misalignment" if fires else verdict


def off_centre_mm_over_yield(j, verdict):
    """Rule D2 (an addendum to session 85's registration): rule D, and also where `verdict` is the refits' yield (no
    signature set it) and the run's rule U would not name yield (the first rise below its floor): the yield refit can
    stand in for an off-centre drape, which the hem's centre shows. Seeds 101-114 (in sample): of the 31 captures the
    refits named yield, the 3 misalignments lay 6.71-8.60 mm off, the others at most 4.84 mm (a control; yields at
    most 4.47 mm)."""
    mm = off_centre_mm(j)
    if mm is not None and mm >= OFF_CENTRE_MM and refits_yield_stands(j, verdict):
        return "misalignment"
    return off_centre_mm_misalignment(j, verdict)


LIFTED_TOP_MM = 0.5  # rule F's floor on the platform top's lift (session 86's test: not adopted): any lift read


def top_lift_mm(report):
    """How far the cloth on the platform top lies above its contact offset where the rigid surfaces read it as lifted
    (rigid_surfaces.top_lift_mm: the bare side shows the camera where its calibration says; 0 where the offset is read
    as the camera's or under 0.5 mm); None where the report lacks it."""
    return (report.get("rigid_surfaces") or {}).get("top_lift_mm")


def lifted_top_friction(j, verdict):
    """Rule F (registered for session 86): laid after the run's signatures, on `verdict`: "friction" where it is
    none, unexplained or yield and the cloth on the platform top lies LIFTED_TOP_MM or more above its contact offset
    (the rigid surfaces read a lift from 0.5 mm, RigidPoseSettings::min_lift): a specimen held by friction alone slides
    on the top and buckles off it, where the fitted model's specimen (the adhesive boundary) lies on it. Seeds 101-114
    (in sample): 30 of the 31 frictions lifted 1.31-2.32 mm, none of the 241 other captures (72 controls, 15 sensors);
    +3 -0 on the default (rules U and E): seed 105's friction_02 (none) and seed 111's friction_01 and _03 (the refits'
    yield). Seeds 115-116 (read after it was written): the 4 frictions 1.12-1.66 mm, none of the 37 others."""
    lift = top_lift_mm(j)
    fires = verdict in ("none", "unexplained", "yield") and lift is not None and lift >= LIFTED_TOP_MM
    return "friction" if fires else verdict


# The rules laid on the default's verdict after the run's signatures (signatures_applied), reading it.
AFTER_SIGNATURES = {"later_yield": later_yield, "alternation_veto": alternation_veto,
                    "later_mean_yield": later_mean_yield, "off_centre_mm": off_centre_mm_misalignment,
                    "off_centre_mm_over_yield": off_centre_mm_over_yield,
                    "lifted_top_friction": lifted_top_friction}


# The columns that name yield from the placements' drape coefficients (signatures of their own, as rules U and A).
TURN_OVER_RULES = ("rise_yield", "rise_yield_015", "rise_later_yield", "alternation_yield")


# The rules read off the verdict as run and one more field of the report, with or without candidates.
REPORT_RULES = {"views_sensor": views_sensor, "views_camera": views_camera, "tie_region": tie_region,
                "wide_tolerance": wide_tolerance, "rise_yield": rise_yield, "rise_yield_015": rise_yield_015,
                "rise_later_yield": rise_later_yield, "yield_needs_rise": yield_needs_rise,
                "alternation_yield": alternation_yield, "off_centre": off_centre_misalignment}


def verdicts(j):
    g = j["gap_tests"]
    a = j["attribution"]
    cands = a.get("candidates", [])
    if not cands:
        v = {r: j["verdict"] for r in RULES}
        v.update({rule: f(j) for rule, f in REPORT_RULES.items()})
        return after_signatures(j, signatures_applied(j, v))
    sf, shf = g["stable_floor_mm"], g["shape_floor"]
    within = j.get("within_floors_after_bending_refit", False)
    v = {"current": j["verdict"], "strict": confirmation_rule(j, 0.0), "tolerance": confirmation_rule(j, TOLERANCE),
         "objective_ties": confirmation_rule(j, TOLERANCE, "objective"),
         "parsimony": confirmation_rule(j, TOLERANCE, "parsimony")}
    top = cands[0]
    tied = [c for c in cands if c["confirmed"] and c["shrinkage"] == top["shrinkage"]]
    v["tie_objective"] = min(tied, key=lambda c: c["objective_mm"])["effect"] if (
        j["verdict"] not in ("none", "unexplained") and tied) else j["verdict"]
    physical = [c for c in tied if c["effect"] != "sensor"] or tied  # attribute()'s order: physical effects first
    v["tie_held_out_view"] = min(physical, key=lambda c: c["held_out_score_mm"])["effect"] if (
        j["verdict"] not in ("none", "unexplained") and tied and not a.get("curl_first")) else j["verdict"]
    first_after = a.get("curl_first") or (a.get("sensor_first") or {}).get("promoted")  # applied after near ties
    near_tie = (a.get("near_tie") or {}).get("promoted")
    v["tie_held_out"] = max(physical, key=lambda c: c["held_out_shrinkage"])["effect"] if (
        j["verdict"] not in ("none", "unexplained") and tied and not (first_after or near_tie)) else j["verdict"]
    # Rule N: no near ties (--tie-margin 0): where the run promoted a near tie, the confirmed candidate it displaced,
    # the first by shrinkage (attribute()'s order: physical effects first among exact ties, then the objective).
    led = sorted((c for c in cands if c["confirmed"]),
                 key=lambda c: (-c["shrinkage"], c["effect"] == "sensor", c["objective_mm"]))
    v["no_near_tie"] = led[0]["effect"] if (near_tie and led and not first_after
                                            and j["verdict"] not in ("none", "unexplained")) else j["verdict"]
    e0 = g["excess_above_floors"]
    h0 = g["held_out_capture"]["all_views_score_mm"]

    def held(c):
        return c["validated"]["held_out_capture"]["all_views_score_mm"]

    def gate_shrink(c):
        return shrink(e0, c["validated"]["excess_above_floors"])

    ordered = sorted(cands, key=lambda c: (-gate_shrink(c), held(c)))  # attribute()'s order against the baseline
    allowed = 1.0 + run_tolerance(j)
    v["no_bar"] = named(first_largest((gate_shrink(c), c["effect"]) for c in ordered if held(c) <= allowed * h0),
                        False)
    v["no_bar_unconfirmed"] = named(first_largest((gate_shrink(c), c["effect"]) for c in ordered), False)
    baseline = {"capture": (g["capture"]["stable_mm"], g["capture"]["shape"]),
                "second": (g["second_capture"]["stable_mm"], g["second_capture"]["shape"]),
                "held_out": (g["held_out_capture"]["stable_mm"], g["held_out_capture"]["shape"])}
    bar = a["bending_refit_bar"]
    reference = terms(bar["validated"]) if bar["shrinkage"] > 0 else baseline

    def mean3(t):
        return excess(sum(x[0] for x in t.values()) / 3, sum(x[1] for x in t.values()) / 3, sf, shf)

    def held_out(t):
        return excess(*t["held_out"], sf, shf)

    for rule, ex in (("mean3", mean3), ("held_out_excess", held_out)):
        v[rule] = named(first_largest((shrink(ex(reference), ex(terms(c["validated"]))), c["effect"])
                                      for c in cands if c["confirmed"]), within)
    ok = [c for c in cands if c["confirmed"] and c["shrinkage"] >= THRESHOLD]
    v["held_out_rank"] = "none" if within else (
        max(ok, key=lambda c: c["held_out_shrinkage"])["effect"] if ok else "unexplained")
    v["min_objective"] = min(cands, key=lambda c: c["objective_mm"])["effect"]
    v["common4"] = common_at_least(j, 4)
    for rule in ("without_ablation", "reach", "reach_objective"):
        v[rule] = reference_rule(j, rule)
    v.update({rule: f(j) for rule, f in REPORT_RULES.items()})
    return after_signatures(j, signatures_applied(j, v))


COLUMNS = ["none", "unexplained", "not attributed", "yield", "shear", "curl", "friction", "misalignment", "sensor"]


# report.json's records of rules U, A and E (D and D2 too: off_centre) and H (hem_tilt) where they set the verdict,
# in the order diagnose() lays them.
SIGNATURES = ("turn_over", "alternation", "off_centre", "hem_tilt")


def refits_report(j):
    """The report with the refits' verdict as its verdict where a signature set the verdict (`drapegen diagnose
    --turn-over-yield`, rule U, report.json turn_over; `--turn-over-alternation`, rule A, alternation;
    `--off-centre-misalignment` and `--off-centre-mm`, rules E, D and D2, off_centre; `--hem-tilt-misalignment`,
    rule H, hem_tilt: the first one's refits_verdict), the reported one kept as verdict_reported: the rules
    recompute the refits' verdict, and verdicts() lays the signatures on every rule's as the run did."""
    for key in SIGNATURES:
        if j.get(key):
            return dict(j, verdict=j[key]["refits_verdict"], verdict_reported=j["verdict"])
    return j


def named_where_none(v, effect):
    """`v` with `effect` wherever a rule names no effect (none or unexplained): a signature laid on every rule."""
    return {r: effect if x in ("none", "unexplained") else x for r, x in v.items()}


def signatures_applied(j, v):
    """Every rule's verdict with the run's signatures laid on it as diagnose() does: the turn-over's
    (settings.turn_over_yield > 0), yield where the rule names no effect and the first turn-over raised the drape
    coefficient by the run's floor; then the alternation's (settings.turn_over_alternation > 0), yield where the rule
    names no effect and the alternation reaches the run's floor, unexplained where the rule names yield, the
    alternation is below it and the turn-over named nothing; then the hem's centre's (settings.off_centre_misalignment
    > 0), misalignment where the rule still names no effect and the hem's centre offset reaches the run's ratio, or
    (settings.off_centre_mm > 0) the run's offset in mm; with settings.off_centre_mm_over_yield also where the rule's
    own yield stands (the turn-over named nothing, the alternation withdrew nothing) and the offset reaches it; last
    the hem's tilt (settings.hem_tilt_misalignment > 0), misalignment whatever the rule names where each of the three
    placements' tilts (placement_hem_tilt_mm) reaches the run's floor."""
    settings = j.get("settings") or {}
    own = dict(v)
    turned = run_turn_over_names(j)
    if turned:
        v = named_where_none(v, "yield")
    alternation_floor = settings.get("turn_over_alternation", 0.0)
    alternation = turn_over_alternation(j)
    if alternation_floor > 0.0 and alternation is not None:
        if alternation >= alternation_floor:
            v = named_where_none(v, "yield")
        elif not turned:
            v = {r: "unexplained" if x == "yield" else x for r, x in v.items()}
    ratio_floor = settings.get("off_centre_misalignment", 0.0)
    ratio = off_centre_ratio(j)
    if ratio_floor > 0.0 and ratio is not None and ratio >= ratio_floor:
        v = named_where_none(v, "misalignment")
    mm_floor = settings.get("off_centre_mm", 0.0)
    mm = off_centre_mm(j)
    if mm_floor > 0.0 and mm is not None and mm >= mm_floor:
        v = named_where_none(v, "misalignment")
        if settings.get("off_centre_mm_over_yield", False) and not turned:
            # Over a refits' yield only, as diagnose(): a turn-over rule's column names yield from the placements,
            # which rule D2 leaves (it would have set report.json turn_over or alternation), unless the refits named it.
            v = {r: "misalignment" if x == "yield" and own[r] == "yield"
                 and (r not in TURN_OVER_RULES or j["verdict"] == "yield") else x for r, x in v.items()}
    tilt_floor = settings.get("hem_tilt_misalignment", 0.0)
    tilts = j.get("placement_hem_tilt_mm") or []
    if tilt_floor > 0.0 and len(tilts) == 3 and min(tilts) >= tilt_floor:
        v = {r: "misalignment" for r in v}
    return v


def after_signatures(j, v):
    """`v` with the AFTER_SIGNATURES rules' columns: each laid on the default's verdict with the run's signatures."""
    v.update({rule: f(j, v["current"]) for rule, f in AFTER_SIGNATURES.items()})
    return v


def reports(root, truth_root=None):
    """(name, family, report) of every diagnosis of a run, its truth file (in truth_root if given) read for the
    family alone."""
    for f in sorted(glob.glob(os.path.join(root, "diagnoses", "*.json"))):
        name = os.path.basename(f)[:-5]
        with open(f) as fh:
            j = json.load(fh)
        with open(os.path.join(truth_root or root, "truth", name + ".json")) as fh:
            truth = json.load(fh)
        yield name, FAMILY.get(truth["family"], truth["family"]) or "none", refits_report(j)


def within_floors(candidates):
    """The confirmed candidates that each bring the gate's excess to 0 (session 29's common bending counts them)."""
    return [c for c in candidates if c["confirmed"] and c["validated"]["excess_above_floors"] == 0.0]


def common(roots):
    """Where three or more confirmed candidates each bring the excess to 0 (session 29's common bending)."""
    fired = right = 0
    for root in roots:
        for name, family, j in reports(root):
            a = j.get("attribution") or {}
            if not a.get("ran"):
                continue
            within = within_floors(a["candidates"])
            verdict = j["verdict"]
            fires = len(within) >= 3 and not j.get("within_floors_after_bending_refit", False)
            fired += fires
            right += fires and verdict == family
            print(f"{root:14s} {name:16s} {family:12s} {verdict:13s} {'right' if verdict == family else 'wrong':5s} "
                  f"{'common' if fires else '      '} " +
                  " ".join(f"{c['effect']}@x{c['alpha_scale']:.2f}" for c in within))
    print(f"common bending fires on {fired} captures, {right} of them named right as run")


def gate_terms(roots):
    """The gate's shape term over its floor (the capture and the second capture's mean, as run) and the same with the
    held-out capture averaged in, for the controls, the effect captures within the floors at the gate, and the others:
    could a gate on all three placements tell the effects within the floors from the controls?"""
    classes = {"controls": [], "effects within the floors at the gate": [], "effects above them": []}
    for root in roots:
        for name, family, j in reports(root):
            g = j.get("gap_tests") or {}
            if "shape" not in g or not g.get("held_out_capture") or not g.get("second_capture"):
                continue
            def mean3(term):
                return sum(g[k][term] for k in ("capture", "second_capture", "held_out_capture")) / 3
            key = ("controls" if family == "none" else
                   "effects within the floors at the gate" if j["within_floors"] else "effects above them")
            classes[key].append((g["shape"] / g["shape_floor"], mean3("shape") / g["shape_floor"],
                                 mean3("stable_mm") / g["stable_floor_mm"]))
    for key, v in classes.items():
        if not v:
            continue
        two, three, stable = (sorted(x[k] for x in v) for k in range(3))
        print(f"{key} ({len(v)}): shape / floor, two placements: median {statistics.median(two):.2f}, max {two[-1]:.2f}; "
              f"three: median {statistics.median(three):.2f}, max {three[-1]:.2f}; stable / floor, three: "
              f"{stable[0]:.2f} .. {stable[-1]:.2f}")
    controls = sorted(x[1] for x in classes["controls"])
    within = [x[1] for x in classes["effects within the floors at the gate"]]
    if controls and within:
        # The three-placement threshold that keeps 90% of the controls below it, and what it would pass.
        cut = controls[int(0.9 * len(controls)) - 1]
        print(f"a three-placement gate at {cut:.2f} (90% of the controls below it) passes "
              f"{sum(y > cut for y in within)}/{len(within)} of the effects within the floors at the gate, "
              f"{sum(y > cut for y in controls)}/{len(controls)} controls")


def ranks_before_key(c):
    """attribute()'s order (ranks_before): confirmed first, the shrinkage, a physical effect before the sensor error,
    the smaller objective, the larger held-out shrinkage."""
    return (not c["confirmed"], -c["shrinkage"], TIES["physical_first"](c["effect"]), c["objective_mm"],
            -c["held_out_shrinkage"])


def tied_with_first(ranked, margin):
    """The confirmed significant candidates within `margin` of the first's shrinkage (ranked as ranks_before)."""
    first = ranked[0]
    return [c for c in ranked if c["confirmed"] and c["shrinkage"] >= THRESHOLD and
            c["shrinkage"] >= first["shrinkage"] - margin]


def objective_pick(ranked, tied):
    """near_ties_first since session 31: the smallest refit objective among `tied`, unless the first is tied exactly
    (then the first)."""
    exact = [c for c in tied if c["shrinkage"] == ranked[0]["shrinkage"]]
    return ranked[0] if len(exact) > 1 else min(tied, key=lambda c: c["objective_mm"])


def near_ties(margin, roots, order="physical_first"):
    """Where candidates within `margin` of the first's shrinkage, tied, name another effect than the run did. Order
    "physical_first" as session 30's near_ties_first ran (gone since session 31); "objective" as near_ties_first names
    since session 31: the smallest refit objective among them, exact ties left in the run's order."""
    changed = right = broken = 0
    for root in roots:
        for name, family, j in reports(root):
            a = j.get("attribution") or {}
            if not a.get("ran") or j["verdict"] in ("none", "unexplained") or a.get("curl_first"):
                continue
            first = a["candidates"][0]  # as ranked by the run (ranks_before)
            tied = tied_with_first(a["candidates"], margin)
            if order == "objective":
                pick = objective_pick(a["candidates"], tied)
            else:
                pick = min(tied, key=lambda c: (TIES["physical_first"](c["effect"]), c["objective_mm"],
                                                -c["held_out_shrinkage"]))
            if pick["effect"] == j["verdict"]:
                continue
            changed += 1
            right += pick["effect"] == family
            broken += j["verdict"] == family
            print(f"{root:14s} {name:16s} {family:12s} {j['verdict']:13s} -> {pick['effect']:13s} "
                  f"({first['effect']} {first['shrinkage']:.2f}, {pick['effect']} {pick['shrinkage']:.2f})")
    print(f"margin {margin} ({order}): {changed} verdicts change, {right} to the right effect, {broken} right ones lost")


def draw_noise(roots):
    """The gate's excess of the second-best validation drape (by fit score) against the best's, as a share of the
    excess, each paired with the second capture's terms as gap_terms pairs them: quartiles over the captures."""
    shares = []
    for root in roots:
        for _, _, j in reports(root):
            g = j["gap_tests"]
            if not g.get("second_capture") or not g["excess_above_floors"] > 0:
                continue
            second = g["second_capture"]

            def gate(d):
                return excess(0.5 * (d["stable_mm"] + second["stable_mm"]), 0.5 * (d["shape"] + second["shape"]),
                              g["stable_floor_mm"], g["shape_floor"])

            best, runner = sorted(g["validation_drapes"], key=lambda d: d["fit_score_mm"])[:2]
            shares.append(abs(gate(best) - gate(runner)) / g["excess_above_floors"])
    shares.sort()
    n = len(shares)
    if n:
        print(f"{n} captures above the floors: the share changes by {shares[n // 4]:.3f} / {statistics.median(shares):.3f} / "
              f"{shares[3 * n // 4]:.3f} (quartiles; the middle one the median)")


def substitute(effect, new_root, old_root):
    """The verdicts of old_root's reports with one candidate's refit taken from new_root's reports of the same
    captures (e.g. a run with `--candidates sensor` under a changed sensor refit; every other candidate refits
    deterministically, so the rest of the report stands): ranked as attribute() ranks (confirmed first, shrinkage,
    a physical effect before the sensor error, objective), then session 31's near ties by the refit objective.
    Captures where the run put curl first, or where the common bending's count of candidates within the floors
    crosses three, need a diagnosis (a simulation): they are flagged, their verdict left as run."""
    changed = right = broken = 0
    for name, family, new in reports(new_root, truth_root=old_root):
        with open(os.path.join(old_root, "diagnoses", name + ".json")) as fh:
            j = json.load(fh)
        a = j.get("attribution") or {}
        swapped = [c for c in (new.get("attribution") or {}).get("candidates", []) if c["effect"] == effect]
        if not a.get("ran") or not swapped:
            continue
        before = next((c for c in a["candidates"] if c["effect"] == effect), None)
        candidates = [c for c in a["candidates"] if c["effect"] != effect] + swapped
        within = [len(within_floors(cs)) >= 3 for cs in (a["candidates"], candidates)]
        verdict, note = j["verdict"], ""
        if a.get("curl_first") or within[0] != within[1]:
            note = "needs a diagnosis (curl first or the common bending)"
        elif not j.get("within_floors_after_bending_refit", False) and verdict != "none":
            ranked = sorted(candidates, key=ranks_before_key)
            if not ranked[0]["confirmed"] or ranked[0]["shrinkage"] < THRESHOLD:
                verdict = "unexplained"
            else:
                margin = (a.get("near_tie") or {}).get("margin", 0.1)
                verdict = objective_pick(ranked, tied_with_first(ranked, margin))["effect"]
        if verdict != j["verdict"]:
            changed += 1
            right += verdict == family
            broken += j["verdict"] == family
        was = f"{before['shrinkage']:.2f}" if before else "-"
        print(f"{name:16s} {family:12s} {j['verdict']:13s} -> {verdict:13s} {effect} {was} -> "
              f"{swapped[0]['shrinkage']:.2f} {note}")
    print(f"{effect} from {new_root}: {changed} verdicts change, {right} to the right effect, {broken} right ones lost")


def print_matrix(rows, top1=False):
    """A markdown confusion matrix of (family, verdict) rows, the controls first; with top1, a column of each
    family's right verdicts."""
    families = ["none"] + sorted({fam for fam, _ in rows if fam != "none"})
    print("| truth \\ verdict | " + " | ".join(COLUMNS) + (" | top-1 |" if top1 else " |"))
    print("|---" * (len(COLUMNS) + 1 + top1) + "|")
    for fam in families:
        got = [v for f, v in rows if f == fam]
        print(f"| {fam} | " + " | ".join(str(got.count(c)) for c in COLUMNS) +
              (f" | {got.count(fam)}/{len(got)} |" if top1 else " |"))


def pooled_matrix(rule, roots):
    """One confusion matrix of RULE over every root's captures, with the top-1 and the controls' share."""
    if not roots:
        sys.exit("--matrix RULE --pooled DIR...")
    rows = [(family, verdicts(j)[rule]) for root in roots for _, family, j in reports(root)]
    print(f"{len(roots)} runs, {len(rows)} captures, rule {rule}:\n")
    print_matrix(rows, top1=True)
    effects = [(f, v) for f, v in rows if f != "none"]
    controls = [v for f, v in rows if f == "none"]
    right = sum(f == v for f, v in effects)
    detected = [(f, v) for f, v in effects if v != "none"]
    print(f"\ntop-1 {right}/{len(effects)} ({100 * right / max(len(effects), 1):.0f}%); controls none "
          f"{controls.count('none')}/{len(controls)}; effect captures named none {len(effects) - len(detected)}, "
          f"of the others named correctly {right}/{len(detected)} ({100 * right / max(len(detected), 1):.0f}%)")


def main(roots):
    global TOLERANCE, WIDE_TOLERANCE
    if roots[:1] in (["--help"], ["-h"]):
        print(__doc__)
        return None
    if roots[:1] == ["--check-reattribute"]:
        return check_reattribute(roots[1:])
    if roots[:1] == ["--wide"]:
        if len(roots) < 3:
            sys.exit("--wide T DIR...")
        WIDE_TOLERANCE, roots = float(roots[1]), roots[2:]
    if roots[:1] == ["--substitute"]:
        if len(roots) != 4:
            sys.exit("--substitute EFFECT NEW_DIR OLD_DIR")
        return substitute(*roots[1:])
    if roots[:1] == ["--common"]:
        return common(roots[1:])
    if roots[:1] == ["--gate-terms"]:
        return gate_terms(roots[1:])
    if roots[:1] == ["--draw-noise"]:
        return draw_noise(roots[1:])
    if roots[:1] == ["--near-ties"]:
        order = "physical_first"
        if roots[2:3] == ["--objective"]:
            order, roots = "objective", roots[:2] + roots[3:]
        if len(roots) < 3:
            sys.exit("--near-ties M [--objective] DIR...")
        return near_ties(float(roots[1]), roots[2:], order)
    if roots[:1] == ["--tolerance"]:
        if len(roots) < 3:
            sys.exit("--tolerance T DIR...")
        TOLERANCE, roots = float(roots[1]), roots[2:]
    matrix_rule = None
    if roots[:1] == ["--matrix"]:
        if len(roots) < 3 or roots[1] not in RULES:
            sys.exit(f"--matrix RULE DIR...: RULE one of {', '.join(RULES)}")
        matrix_rule, roots = roots[1], roots[2:]
        if roots[:1] == ["--pooled"]:
            return pooled_matrix(matrix_rule, roots[1:])
    if not roots:
        sys.exit(__doc__)
    for root in roots:
        if not os.path.isdir(os.path.join(root, "diagnoses")):
            sys.exit(f"diagnosis_rules: {root} is not a benchmark run (no diagnoses/ in it)")
    for root in roots:
        rows = [(name, family, verdicts(j)) for name, family, j in reports(root)]
        if matrix_rule:
            print(f"{root}, rule {matrix_rule}:\n")
            print_matrix([(fam, v[matrix_rule]) for _, fam, v in rows])
            continue
        print(f"{root}: {len(rows)} diagnoses")
        print(f"{'case':16s} " + " ".join(f"{r:>18s}" for r in RULES))
        for name, family, v in rows:
            print(f"{name:16s} " + " ".join(f"{v[r]:>18s}" for r in RULES))
        for r in RULES:
            effects = [(fam, v[r]) for _, fam, v in rows if fam != "none"]
            controls = [v[r] for _, fam, v in rows if fam == "none"]
            wrong = sum(x not in (f, "none", "unexplained") for f, x in effects)
            print(f"{r:18s} top-1 {sum(f == x for f, x in effects)}/{len(effects)}, "
                  f"controls none {sum(x == 'none' for x in controls)}/{len(controls)}, "
                  f"named wrong: {sum(x not in ('none', 'unexplained') for x in controls)} controls, "
                  f"{wrong} effect captures")


if __name__ == "__main__":
    main(sys.argv[1:])
