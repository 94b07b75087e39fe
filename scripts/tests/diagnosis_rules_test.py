#!/usr/bin/env python3
"""The turn-over rules of scripts/diagnosis_rules.py (rules U, U15, U2, K and A) and rules E, D and D2 on hand-written
reports: they decide what is adopted (docs/preregistrations/), so a slip here would mislead a registered test."""
import importlib.util
import os
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
spec = importlib.util.spec_from_file_location("diagnosis_rules", os.path.join(HERE, "..", "diagnosis_rules.py"))
rules = importlib.util.module_from_spec(spec)
spec.loader.exec_module(rules)


def report(verdict, c0, c1, c2=None, second_face="down", turn_over=None, floor=0.0):
    """A report.json without candidates: the verdict, the placements' drape coefficients and faces, the run's rule U
    (settings.turn_over_yield) and, where it named yield, its turn_over record."""
    g = {"capture": {"drape_coefficient": c0}, "second_capture": {"drape_coefficient": c1}}
    if c2 is not None:
        g["held_out_capture"] = {"drape_coefficient": c2}
    j = {"verdict": verdict, "gap_tests": g, "attribution": {}, "settings": {"turn_over_yield": floor},
         "placements": [{"role": "capture", "face": "up"}, {"role": "second_capture", "face": second_face},
                        {"role": "held_out_capture", "face": "up"}]}
    if turn_over:
        j["turn_over"] = turn_over
    return j


class TurnOverRules(unittest.TestCase):
    def test_rise_needs_the_other_face(self):
        self.assertAlmostEqual(rules.turn_over_rise(report("none", 0.20, 0.23)), 0.03)
        self.assertIsNone(rules.turn_over_rise(report("none", 0.20, 0.23, second_face="up")))

    def test_rule_u_names_yield_only_where_no_effect_is_named(self):
        self.assertEqual(rules.rise_yield(report("none", 0.20, 0.225)), "yield")
        self.assertEqual(rules.rise_yield(report("unexplained", 0.20, 0.225)), "yield")
        self.assertEqual(rules.rise_yield(report("shear", 0.20, 0.225)), "shear")
        self.assertEqual(rules.rise_yield(report("none", 0.20, 0.219)), "none")
        self.assertEqual(rules.rise_yield(report("none", 0.20, 0.24, second_face="up")), "none")

    def test_u15_and_u2(self):
        self.assertEqual(rules.rise_yield_015(report("none", 0.20, 0.216)), "yield")
        self.assertEqual(rules.rise_yield_015(report("none", 0.20, 0.214)), "none")
        # U2: the larger of the two later rises (the third placement's here), not the first alone.
        self.assertEqual(rules.rise_later_yield(report("none", 0.20, 0.205, c2=0.225)), "yield")
        self.assertEqual(rules.rise_later_yield(report("none", 0.20, 0.205, c2=0.215)), "none")
        self.assertEqual(rules.rise_later_yield(report("curl", 0.20, 0.205, c2=0.25)), "curl")
        # Without a turn-over there is no later rise to read.
        self.assertEqual(rules.rise_later_yield(report("none", 0.20, 0.25, c2=0.25, second_face="up")), "none")

    def test_rule_k_withdraws_a_yield_without_the_rise(self):
        self.assertEqual(rules.yield_needs_rise(report("yield", 0.20, 0.21)), "unexplained")
        self.assertEqual(rules.yield_needs_rise(report("yield", 0.20, 0.19)), "unexplained")
        self.assertEqual(rules.yield_needs_rise(report("yield", 0.20, 0.225)), "yield")
        self.assertEqual(rules.yield_needs_rise(report("shear", 0.20, 0.20)), "shear")
        # Without a turn-over (both placements on one face) there is no rise to ask for.
        self.assertEqual(rules.yield_needs_rise(report("yield", 0.20, 0.20, second_face="up")), "yield")
        # A yield the run's turn-over named stays: the refits named no effect there.
        run = rules.refits_report(report("yield", 0.20, 0.23, floor=0.02,
                                         turn_over={"rise": 0.03, "floor": 0.02, "refits_verdict": "none"}))
        self.assertEqual(rules.verdicts(run)["yield_needs_rise"], "yield")

    def test_rule_a_reads_the_alternation(self):
        # c1 - (c0 + c2) / 2: 0.216 - 0.20 = 0.016 over a third placement back at 0.20.
        self.assertAlmostEqual(rules.turn_over_alternation(report("none", 0.20, 0.216, c2=0.20)), 0.016)
        self.assertEqual(rules.alternation_yield(report("none", 0.20, 0.216, c2=0.20)), "yield")
        # The same first rise with the third placement risen as far is no alternation.
        self.assertEqual(rules.alternation_yield(report("none", 0.20, 0.216, c2=0.216)), "none")
        # A yield the refits named without the alternation is withdrawn, with it kept; other verdicts stay.
        self.assertEqual(rules.alternation_yield(report("yield", 0.20, 0.21, c2=0.20)), "unexplained")
        self.assertEqual(rules.alternation_yield(report("yield", 0.20, 0.23, c2=0.21)), "yield")
        self.assertEqual(rules.alternation_yield(report("curl", 0.20, 0.25, c2=0.20)), "curl")
        # Without a turn-over or a third placement there is nothing to read.
        self.assertIsNone(rules.turn_over_alternation(report("none", 0.20, 0.25)))
        self.assertEqual(rules.alternation_yield(report("none", 0.20, 0.25, c2=0.20, second_face="up")), "none")

    def test_rule_e_names_misalignment_from_the_hem_centre(self):
        def off(verdict, ratio, c1=0.20, floor=0.0):
            j = report(verdict, 0.20, c1, c2=0.20, floor=floor)
            j["localisation"] = {"feature_groups": {"off_centre": {"ratio": ratio}}}
            return j
        self.assertEqual(rules.off_centre_misalignment(off("none", 2.5)), "misalignment")
        self.assertEqual(rules.off_centre_misalignment(off("unexplained", 3.0)), "misalignment")
        self.assertEqual(rules.off_centre_misalignment(off("none", 2.4)), "none")
        self.assertEqual(rules.off_centre_misalignment(off("curl", 5.0)), "curl")
        self.assertEqual(rules.off_centre_misalignment(report("none", 0.20, 0.20)), "none")  # no localisation
        # Where the run's rule U names yield, rule E leaves it (its verdict as run, then the turn-over laid on it).
        self.assertEqual(rules.off_centre_misalignment(off("none", 3.0, c1=0.23, floor=0.02)), "none")
        self.assertEqual(rules.verdicts(off("none", 3.0, c1=0.23, floor=0.02))["off_centre"], "yield")
        self.assertEqual(rules.off_centre_misalignment(off("none", 3.0, c1=0.23)), "misalignment")

    def test_a_run_with_rule_e_is_read_as_its_refits_then_the_hem_centre(self):
        # drapegen diagnose --off-centre-misalignment 2.5 named misalignment where the refits named none: every rule
        # starts from the refits' verdict and gets the hem's centre laid on it, reproducing the verdict as run.
        j = report("misalignment", 0.20, 0.20, c2=0.20)
        j["settings"]["off_centre_misalignment"] = 2.5
        j["localisation"] = {"feature_groups": {"off_centre": {"ratio": 3.0}}}
        j["off_centre"] = {"ratio": 3.0, "floor": 2.5, "refits_verdict": "none"}
        run = rules.refits_report(j)
        self.assertEqual(run["verdict"], "none")
        self.assertEqual(run["verdict_reported"], "misalignment")
        v = rules.verdicts(run)
        self.assertTrue(all(x == "misalignment" for x in v.values()), v)
        # The turn-over first: where the run's rule U names yield, the hem's centre finds no verdict without an effect.
        j["gap_tests"]["second_capture"]["drape_coefficient"] = 0.23
        j["settings"]["turn_over_yield"] = 0.02
        self.assertEqual(rules.verdicts(rules.refits_report(j))["current"], "yield")

    def test_a_run_with_rule_d_is_read_as_its_refits_then_the_hem_centre_in_mm(self):
        # drapegen diagnose --off-centre-mm 6.5 named misalignment where the refits named none (7 mm off, ratio 2):
        # every rule gets the offset laid on it; with --off-centre-mm-over-yield the refits' yield too, unless the
        # run's rule U names yield.
        j = report("misalignment", 0.20, 0.20, c2=0.20)
        j["settings"].update(off_centre_misalignment=2.5, off_centre_mm=6.5)
        j["localisation"] = {"feature_groups": {"off_centre": {"ratio": 2.0, "difference_mm": 7.0}}}
        j["off_centre"] = {"ratio": 2.0, "floor": 2.5, "offset_mm": 7.0, "offset_floor_mm": 6.5, "by": "offset",
                           "refits_verdict": "none"}
        self.assertEqual(rules.refits_report(j)["verdict"], "none")
        self.assertEqual(rules.verdicts(rules.refits_report(j))["current"], "misalignment")
        j["localisation"]["feature_groups"]["off_centre"]["difference_mm"] = 6.0
        self.assertEqual(rules.verdicts(rules.refits_report(j))["current"], "none")
        j = report("misalignment", 0.20, 0.21, c2=0.20)
        j["settings"].update(off_centre_mm=6.5, off_centre_mm_over_yield=True)
        j["localisation"] = {"feature_groups": {"off_centre": {"ratio": 2.0, "difference_mm": 7.0}}}
        j["off_centre"] = {"ratio": 2.0, "floor": 0.0, "offset_mm": 7.0, "offset_floor_mm": 6.5, "by": "offset",
                           "refits_verdict": "yield"}
        self.assertEqual(rules.refits_report(j)["verdict"], "yield")
        self.assertEqual(rules.verdicts(rules.refits_report(j))["current"], "misalignment")
        j["settings"]["off_centre_mm_over_yield"] = False
        self.assertEqual(rules.verdicts(rules.refits_report(j))["current"], "yield")
        j["settings"].update(off_centre_mm_over_yield=True, turn_over_yield=0.005)
        self.assertEqual(rules.verdicts(rules.refits_report(j))["current"], "yield")

    def test_rule_d2_leaves_a_yield_a_turn_over_column_names(self):
        # A --fine run (rules U at 0.02, E and D2) named misalignment by the offset where the refits named none; the
        # turned placement rose 0.017: rule U15's column names yield from the turn-over, which diagnose() would have
        # recorded as turn_over before rule D2, so the offset leaves it; the default's column is the run's verdict.
        j = report("misalignment", 0.20, 0.217, c2=0.20)
        j["settings"].update(turn_over_yield=0.02, off_centre_misalignment=2.5, off_centre_mm=6.5,
                             off_centre_mm_over_yield=True)
        j["localisation"] = {"feature_groups": {"off_centre": {"ratio": 2.0, "difference_mm": 7.0}}}
        j["off_centre"] = {"ratio": 2.0, "floor": 2.5, "offset_mm": 7.0, "offset_floor_mm": 6.5, "by": "offset",
                           "refits_verdict": "none"}
        v = rules.verdicts(rules.refits_report(j))
        self.assertEqual(v["current"], "misalignment")
        self.assertEqual(v["rise_yield_015"], "yield")
        self.assertEqual(v["rise_yield"], "misalignment")  # 0.017 is under its 0.02: nothing of its own

    def test_a_run_with_rule_a_is_read_as_its_refits_then_the_alternation(self):
        # drapegen diagnose --turn-over-alternation 0.015 named yield where the refits named none (alternation 0.016):
        # every rule starts from the refits' verdict and gets the alternation laid on it.
        j = report("yield", 0.20, 0.216, c2=0.20)
        j["settings"]["turn_over_alternation"] = 0.015
        j["alternation"] = {"alternation": 0.016, "floor": 0.015, "refits_verdict": "none"}
        run = rules.refits_report(j)
        self.assertEqual(run["verdict"], "none")
        v = rules.verdicts(run)
        self.assertTrue(all(x == "yield" for x in v.values()), v)
        # It withdrew the refits' yield (alternation 0.005): unexplained, unless the run's rule U names it again.
        j = report("unexplained", 0.20, 0.21, c2=0.21)
        j["settings"]["turn_over_alternation"] = 0.015
        j["alternation"] = {"alternation": 0.005, "floor": 0.015, "refits_verdict": "yield"}
        self.assertEqual(rules.refits_report(j)["verdict"], "yield")
        self.assertEqual(rules.verdicts(rules.refits_report(j))["current"], "unexplained")
        j["settings"]["turn_over_yield"] = 0.005
        self.assertEqual(rules.verdicts(rules.refits_report(j))["current"], "yield")
        # Then the hem's centre on the withdrawn yield: the first record holds the refits' verdict.
        j = report("misalignment", 0.20, 0.21, c2=0.21)
        j["settings"].update(turn_over_alternation=0.015, off_centre_misalignment=2.5)
        j["localisation"] = {"feature_groups": {"off_centre": {"ratio": 3.0}}}
        j["alternation"] = {"alternation": 0.005, "floor": 0.015, "refits_verdict": "yield"}
        j["off_centre"] = {"ratio": 3.0, "floor": 2.5, "refits_verdict": "unexplained"}
        self.assertEqual(rules.refits_report(j)["verdict"], "yield")
        self.assertEqual(rules.verdicts(rules.refits_report(j))["current"], "misalignment")
        # A third placement on the other face gives no alternation.
        j = report("none", 0.20, 0.216, c2=0.20)
        j["placements"][2]["face"] = "down"
        self.assertIsNone(rules.turn_over_alternation(j))

    def test_rule_l_names_yield_by_the_third_placement_after_the_signatures(self):
        # The third placement, face up again, 0.03 above the first: yield where nothing is named, after rule A.
        self.assertAlmostEqual(rules.third_rise(report("none", 0.20, 0.20, c2=0.23)), 0.03)
        self.assertEqual(rules.later_yield(report("none", 0.20, 0.20, c2=0.23), "none"), "yield")
        self.assertEqual(rules.later_yield(report("none", 0.20, 0.20, c2=0.219), "unexplained"), "unexplained")
        self.assertEqual(rules.later_yield(report("curl", 0.20, 0.20, c2=0.30), "curl"), "curl")
        # Laid on the default's verdict with the run's signatures: rule A's withdrawal does not undo it.
        j = report("none", 0.20, 0.20, c2=0.23)
        j["settings"]["turn_over_alternation"] = 0.015
        v = rules.verdicts(j)
        self.assertEqual(v["current"], "none")
        self.assertEqual(v["later_yield"], "yield")
        # Not with the third placement on the other face.
        j["placements"][2]["face"] = "down"
        self.assertIsNone(rules.third_rise(j))

    def test_rule_a2_withdraws_the_refits_yield_below_its_veto(self):
        # The refits named yield; the alternation 0.016: rule A (0.015) keeps it, rule A2 (0.02) withdraws it.
        j = report("yield", 0.20, 0.216, c2=0.20)
        j["settings"]["turn_over_alternation"] = 0.015
        v = rules.verdicts(j)
        self.assertEqual(v["current"], "yield")
        self.assertEqual(v["alternation_veto"], "unexplained")
        # At 0.02 or more it stays; a yield a signature named stays; rule U's rise protects it.
        self.assertEqual(rules.verdicts(report("yield", 0.20, 0.221, c2=0.20))["alternation_veto"], "yield")
        named = report("none", 0.20, 0.216, c2=0.20)
        named["settings"]["turn_over_alternation"] = 0.015
        self.assertEqual(rules.verdicts(named)["alternation_veto"], "yield")
        turned = report("yield", 0.20, 0.225, c2=0.215, floor=0.02)
        self.assertEqual(rules.verdicts(turned)["alternation_veto"], "yield")

    def test_rule_l2_names_yield_by_the_later_placements_mean_rise(self):
        # The turned second 0.01 and the third 0.025 above the first: mean 0.0175, yield where nothing is named.
        self.assertAlmostEqual(rules.later_mean_rise(report("none", 0.20, 0.21, c2=0.225)), 0.0175)
        self.assertEqual(rules.later_mean_yield(report("none", 0.20, 0.21, c2=0.225), "none"), "yield")
        self.assertEqual(rules.later_mean_yield(report("none", 0.20, 0.21, c2=0.222), "unexplained"), "unexplained")
        self.assertEqual(rules.later_mean_yield(report("curl", 0.20, 0.25, c2=0.25), "curl"), "curl")
        # Not without the turn-over (the second on the capture's face) nor with the third turned.
        self.assertIsNone(rules.later_mean_rise(report("none", 0.20, 0.23, c2=0.23, second_face="up")))
        turned_third = report("none", 0.20, 0.23, c2=0.23)
        turned_third["placements"][2]["face"] = "down"
        self.assertIsNone(rules.later_mean_rise(turned_third))
        # Laid on the default's verdict with the run's signatures: a column of verdicts().
        self.assertEqual(rules.verdicts(report("none", 0.20, 0.21, c2=0.225))["later_mean_yield"], "yield")

    def test_rule_d_names_misalignment_by_the_hem_centre_in_mm(self):
        j = report("unexplained", 0.20, 0.20, c2=0.20)
        j["localisation"] = {"feature_groups": {"off_centre": {"ratio": 1.5, "difference_mm": 8.6}}}
        self.assertEqual(rules.off_centre_mm(j), 8.6)
        self.assertEqual(rules.off_centre_mm_misalignment(j, "unexplained"), "misalignment")
        self.assertEqual(rules.off_centre_mm_misalignment(j, "shear"), "shear")
        self.assertEqual(rules.verdicts(j)["off_centre_mm"], "misalignment")
        self.assertEqual(rules.verdicts(j)["current"], "unexplained")  # rule E's ratio 1.5: not named as run
        j["localisation"]["feature_groups"]["off_centre"]["difference_mm"] = 6.4
        self.assertEqual(rules.verdicts(j)["off_centre_mm"], "unexplained")
        self.assertIsNone(rules.off_centre_mm(report("none", 0.20, 0.20)))

    def test_rule_d2_takes_the_refits_yield_too_unless_the_turn_over_names_it(self):
        j = report("yield", 0.20, 0.203, c2=0.20, floor=0.02)
        j["localisation"] = {"feature_groups": {"off_centre": {"ratio": 1.4, "difference_mm": 6.7}}}
        v = rules.verdicts(j)
        self.assertEqual(v["current"], "yield")
        self.assertEqual(v["off_centre_mm"], "yield")  # rule D leaves a named effect
        self.assertEqual(v["off_centre_mm_over_yield"], "misalignment")
        # Where the first turn-over rose past rule U's floor, the yield stays; below 6.5 mm too.
        j["gap_tests"]["second_capture"]["drape_coefficient"] = 0.225
        self.assertEqual(rules.verdicts(j)["off_centre_mm_over_yield"], "yield")
        j["gap_tests"]["second_capture"]["drape_coefficient"] = 0.203
        j["localisation"]["feature_groups"]["off_centre"]["difference_mm"] = 6.4
        self.assertEqual(rules.verdicts(j)["off_centre_mm_over_yield"], "yield")
        # Other named effects stay; no effect named: as rule D.
        shear = dict(j, verdict="shear")
        shear["localisation"] = {"feature_groups": {"off_centre": {"ratio": 1.4, "difference_mm": 9.0}}}
        self.assertEqual(rules.verdicts(shear)["off_centre_mm_over_yield"], "shear")
        none = dict(shear, verdict="none")
        self.assertEqual(rules.verdicts(none)["off_centre_mm_over_yield"], "misalignment")

    def test_rule_f_names_friction_where_the_platform_top_is_lifted(self):
        j = report("yield", 0.20, 0.21, c2=0.20)
        j["rigid_surfaces"] = {"top_lift_mm": 1.6}
        self.assertEqual(rules.top_lift_mm(j), 1.6)
        self.assertEqual(rules.verdicts(j)["lifted_top_friction"], "friction")  # over the refits' yield
        for verdict in ("none", "unexplained"):
            self.assertEqual(rules.lifted_top_friction(j, verdict), "friction")
        for verdict in ("curl", "sensor", "misalignment"):  # another named effect stays
            self.assertEqual(rules.lifted_top_friction(j, verdict), verdict)
        j["rigid_surfaces"]["top_lift_mm"] = 0.5  # the least lift the rigid surfaces read
        self.assertEqual(rules.verdicts(j)["lifted_top_friction"], "friction")
        j["rigid_surfaces"]["top_lift_mm"] = 0.0  # no lift read (under 0.5 mm)
        self.assertEqual(rules.verdicts(j)["lifted_top_friction"], "yield")
        self.assertIsNone(rules.top_lift_mm(report("none", 0.20, 0.20)))
        self.assertEqual(rules.lifted_top_friction(report("none", 0.20, 0.20), "none"), "none")

    def test_a_run_with_rule_u_is_read_as_its_refits_then_the_turn_over(self):
        # The run named yield from the turn-over: every rule starts from the refits' verdict and gets the turn-over
        # laid on it, so the verdict as run is reproduced.
        run = rules.refits_report(report("yield", 0.20, 0.23, floor=0.02,
                                         turn_over={"rise": 0.03, "floor": 0.02, "refits_verdict": "none"}))
        self.assertEqual(run["verdict"], "none")
        self.assertEqual(run["verdict_reported"], "yield")
        v = rules.verdicts(run)
        self.assertEqual(v["current"], "yield")
        self.assertTrue(all(x == "yield" for x in v.values()), v)
        # Below the run's floor nothing is laid on; a run without rule U (floor 0) lays nothing on either.
        below = rules.verdicts(rules.refits_report(report("none", 0.20, 0.21, floor=0.02)))
        self.assertEqual(below["current"], "none")
        self.assertEqual(below["rise_yield"], "none")
        off = rules.verdicts(rules.refits_report(report("none", 0.20, 0.23)))
        self.assertEqual(off["current"], "none")
        self.assertEqual(off["rise_yield"], "yield")

    def test_a_report_without_a_turn_over_is_unchanged(self):
        j = report("shear", 0.20, 0.23)
        self.assertIs(rules.refits_report(j), j)


if __name__ == "__main__":
    unittest.main()
