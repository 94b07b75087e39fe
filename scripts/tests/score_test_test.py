#!/usr/bin/env python3
"""scripts/score_test.py on a hand-written set: it scores the registered tests (docs/preregistrations/), so its counts
must be the ones the reports and truth files say."""
import contextlib
import importlib.util
import io
import json
import os
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, ".."))
spec = importlib.util.spec_from_file_location("score_test", os.path.join(HERE, "..", "score_test.py"))
score = importlib.util.module_from_spec(spec)
spec.loader.exec_module(score)


def report(verdict, c0, c1, c2, within=False, region="skirt", moved=False, offset_mm=1.0, ratio=0.5, rms=2.0,
           cpu=100.0, turn_over=None):
    j = {"verdict": verdict, "within_floors": within, "within_floors_after_bending_refit": within,
         "gap_tests": {"capture": {"drape_coefficient": c0}, "second_capture": {"drape_coefficient": c1},
                       "held_out_capture": {"drape_coefficient": c2},
                       "view_consistency": {"placements": [{"rms_mm": rms + 1.0}, {"rms_mm": rms}]}},
         "placements": [{"role": "capture", "face": "up"}, {"role": "second_capture", "face": "down"},
                        {"role": "held_out_capture", "face": "up"}],
         "localisation": {"region": region, "moved_by_offset": moved,
                          "feature_groups": {"off_centre": {"ratio": ratio, "difference_mm": offset_mm}}},
         "settings": {"turn_over_yield": 0.02}, "attribution": {}, "runtime": {"cpu_seconds": cpu}}
    if turn_over:
        j["turn_over"] = turn_over
    return j


def truth(family, effect=None, regions=()):
    return {"family": family, "effects": [{"name": effect or family, "strength": 1.5}] if family != "none" else [],
            "regions": list(regions)}


class ScoreTest(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        run = os.path.join(self.dir.name, "s1")
        os.makedirs(os.path.join(run, "diagnoses"))
        os.makedirs(os.path.join(run, "truth"))
        cases = {
            # A yield the turn-over named (the refits named none), within the floors, its region right.
            "yield_00": (report("yield", 0.30, 0.33, 0.31, within=True, cpu=200.0,
                                turn_over={"rise": 0.03, "floor": 0.02, "refits_verdict": "none"}),
                         truth("yield", regions=["skirt"])),
            # A misalignment rule O moved to the hem: named right, region right.
            "misalignment_00": (report("misalignment", 0.30, 0.30, 0.30, region="hem", moved=True, offset_mm=9.0,
                                       ratio=3.0, cpu=300.0),
                                truth("misalignment", effect="misalign", regions=["hem"])),
            # A shear named none above the floors, moved to the hem wrongly.
            "shear_00": (report("none", 0.30, 0.30, 0.30, region="hem", moved=True, offset_mm=7.0, cpu=400.0),
                         truth("shear", regions=["skirt"])),
            # A camera pose error named sensor, its views apart.
            "sensor_00": (report("sensor", 0.30, 0.30, 0.30, region="global", rms=4.5),
                          truth("sensor", effect="pose", regions=["global"])),
            "none_00": (report("none", 0.30, 0.30, 0.30, within=True), truth("none")),
            "none_01": (report("friction", 0.30, 0.305, 0.30), truth("none")),
        }
        for name, (j, t) in cases.items():
            with open(os.path.join(run, "diagnoses", name + ".json"), "w") as f:
                json.dump(j, f)
            with open(os.path.join(run, "truth", name + ".json"), "w") as f:
                json.dump(t, f)
        # A placement's own report is not a capture, though the bench writes a truth file for each placement too.
        with open(os.path.join(run, "diagnoses", "none_00.p2.json"), "w") as f:
            json.dump(report("none", 0.3, 0.3, 0.3), f)
        with open(os.path.join(run, "truth", "none_00.p2.json"), "w") as f:
            json.dump(truth("none"), f)
        self.rows = score.rows([run])
        self.run = run

    def tearDown(self):
        self.dir.cleanup()

    def test_rows_read_the_reports_and_truths(self):
        self.assertEqual(len(self.rows), 6)
        by = {r["name"]: r for r in self.rows}
        self.assertEqual(by["misalignment_00"]["family"], "misalignment")
        self.assertEqual(by["sensor_00"]["kind"], "pose")
        self.assertEqual(by["yield_00"]["signature"], "turn_over")
        self.assertEqual(by["yield_00"]["refits"], "none")
        self.assertAlmostEqual(by["yield_00"]["rise"], 0.03)
        self.assertAlmostEqual(by["yield_00"]["third"], 0.01)
        self.assertAlmostEqual(by["yield_00"]["alternation"], 0.025)
        self.assertEqual(by["sensor_00"]["view_rms"], 4.5)
        self.assertTrue(score.right(by["yield_00"]))
        self.assertFalse(score.right(by["shear_00"]))

    def test_the_last_signature_set_the_verdict_and_the_first_holds_the_refits(self):
        j = report("misalignment", 0.30, 0.31, 0.30, turn_over=None)
        j["alternation"] = {"alternation": 0.01, "floor": 0.015, "refits_verdict": "yield"}
        j["off_centre"] = {"ratio": 2.7, "floor": 2.5, "refits_verdict": "unexplained"}
        run = os.path.join(self.dir.name, "s2")
        os.makedirs(os.path.join(run, "diagnoses"))
        os.makedirs(os.path.join(run, "truth"))
        with open(os.path.join(run, "diagnoses", "misalignment_00.json"), "w") as f:
            json.dump(j, f)
        with open(os.path.join(run, "truth", "misalignment_00.json"), "w") as f:
            json.dump(truth("misalignment", effect="misalign", regions=["hem"]), f)
        (row,) = score.rows([run])
        self.assertEqual(row["signature"], "off_centre")
        self.assertEqual(row["refits"], "yield")

    def test_summary_counts(self):
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            score.summary(self.rows)
        text = out.getvalue()
        self.assertIn("top-1 3 of 4 effect captures", text)
        self.assertIn("above the floors at the gate: 2 of 3 named right; within them 1 (0 named no effect)", text)
        self.assertIn("controls: 1 of 2 named none, 1 within the floors at the gate; s1 none_01 named friction", text)
        self.assertIn("families: misalignment 1/1, sensor 1/1, shear 0/1, yield 1/1", text)
        self.assertIn("| none | 1 | 0 | 0 | 0 | 0 | 0 | 1 | 0 | 0 | 1/2 |", text)
        self.assertIn("| shear | 1 | 0 | 0 | 0 | 0 | 0 | 0 | 0 | 0 | 0/1 |", text)
        self.assertIn("| yield | 0 | 0 | 0 | 1 | 0 | 0 | 0 | 0 | 0 | 1/1 |", text)
        self.assertIn("region as run: 3 of 4", text)
        self.assertIn("CPU per effect capture, s1: median 250 s, max 400 s (4 captures)", text)
        self.assertIn("signature turn_over: set 1 verdicts, 1 right, 0 wrong", text)
        self.assertIn("rule O (moved_by_offset): moved 2 gaps, 1 right, 1 wrong: s1 shear_00 (shear); "
                      "without it (skirt) right: 1", text)
        self.assertIn("first rise >= 0.02: misalignment 0/1 (max below 0), none 0/2 (max below 0.005), "
                      "sensor 0/1 (max below 0), shear 0/1 (max below 0), yield 1/1", text)
        self.assertIn("smallest view RMS >= 4.0 mm: misalignment 0/1 (max below 2), none 0/2 (max below 2), "
                      "pose 1/1", text)

    def test_csv_rows_of_the_misses_and_the_named_controls(self):
        self.assertIsNone(self.rows[0]["seed"])  # no set.args: no seed, and the CSV rows are refused in main()
        with open(os.path.join(self.run, "set.args"), "w") as f:
            f.write("--families\nshear\n--seed\n7\n")
        rs = score.rows([self.run])
        self.assertEqual(score.misses(rs, 90), ["90,7,shear_00,shear,none,above,session90.tar.xz"])
        self.assertEqual(score.named_controls(rs, 90), ["90,7,none_01,friction,session90.tar.xz"])
        self.assertEqual(score.set_counts(rs, 90), ["90,7,yield,1,session90.tar.xz", "90,7,shear,1,session90.tar.xz",
                                                    "90,7,misalignment,1,session90.tar.xz",
                                                    "90,7,sensor,1,session90.tar.xz", "90,7,none,2,session90.tar.xz"])

    def test_table_marks_the_wrong_verdicts_and_moved_regions(self):
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            score.table(self.rows)
        lines = {line.split()[1]: line for line in out.getvalue().splitlines()[1:-1]}
        self.assertIn("none X", lines["shear_00"])
        self.assertIn("hem* skirt", lines["shear_00"])
        self.assertIn("hem* ok", lines["misalignment_00"])
        self.assertIn("yield (turn_over)", lines["yield_00"])
        self.assertNotIn(" X", lines["yield_00"])


if __name__ == "__main__":
    unittest.main()
