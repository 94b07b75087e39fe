#!/usr/bin/env python3
"""scripts/hem_tilt_rule.py (rule H, the hem's tilt on every placement) on a hand-written set and probe CSV: the
verdicts it changes and its tally must be the ones the tilts, reports and truth files say."""
import json
import os
import subprocess
import sys
import tempfile
import unittest

SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "hem_tilt_rule.py")

CASES = {  # name: (truth family, verdict as run, the three placements' tilts in mm)
    "misalignment_00": ("misalign", "unexplained", (12.0, 9.5, 15.0)),  # every placement tilted: named, right
    "misalignment_01": ("misalign", "misalignment", (20.0, 18.0, 8.5)),  # already right: unchanged
    "misalignment_02": ("misalign", "none", (14.0, 7.9, 16.0)),  # one placement below the floor: unchanged
    "curl_00": ("curl", "curl", (15.0, 3.0, 12.0)),  # one placement tilted by its curl: unchanged
    "none_00": ("none", "yield", (8.0, 8.2, 9.0)),  # a control tilted on every placement: named, wrong
}


def write_set(run, cases):
    """A set directory with each case's report and truth file: cases {name: (report, truth family)}."""
    os.makedirs(os.path.join(run, "diagnoses"))
    os.makedirs(os.path.join(run, "truth"))
    for name, (report, family) in cases.items():
        with open(os.path.join(run, "diagnoses", name + ".json"), "w") as f:
            json.dump(report, f)
        with open(os.path.join(run, "truth", name + ".json"), "w") as f:
            # As the bench writes it: an effect capture's effect, none for a control.
            effects = [] if family == "none" else [{"name": family, "strength": 20.0}]
            json.dump({"family": family, "effects": effects}, f)


class HemTiltRuleTest(unittest.TestCase):
    def run_rule(self, *extra):
        with tempfile.TemporaryDirectory() as d:
            run = os.path.join(d, "s7")
            # A later placement's own report and truth file are not captures.
            write_set(run, {**{name: ({"verdict": verdict}, family) for name, (family, verdict, _) in CASES.items()},
                            "none_00.p2": ({"verdict": "misalignment"}, "none")})
            lines = ["set,capture,placement,hem_tilt_mm,outline_offset_mm"]
            for name, (_, _, tilt) in CASES.items():
                lines += [f"s7,{name},{p},{t},1.0" for p, t in enumerate(tilt)]
            tilt_csv = os.path.join(d, "tilt.csv")
            with open(tilt_csv, "w") as f:
                f.write("\n".join(lines) + "\n")
            return subprocess.run([sys.executable, SCRIPT, "--tilt", tilt_csv, run, *extra], capture_output=True,
                                  text=True)

    def test_names_misalignment_where_every_placement_tilts(self):
        out = self.run_rule()
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertIn("right: s7 misalignment_00 (misalignment): unexplained -> misalignment, smallest tilt 9.50 mm",
                      out.stdout)
        self.assertIn("wrong: s7 none_00 (none): yield -> misalignment, smallest tilt 8.00 mm", out.stdout)
        self.assertIn("rule H (tilt >= 8 mm on every placement): +1 -1 over 5 captures", out.stdout)
        self.assertIn("misalignment: smallest placement's tilt 7.90-9.50 mm, 2 of 3 reach 8", out.stdout)
        self.assertIn("curl: smallest placement's tilt 3.00-3.00 mm, 0 of 1 reach 8", out.stdout)
        self.assertNotIn("curl_00", out.stdout)
        self.assertNotIn("misalignment_02", out.stdout)

    def test_floor_option(self):
        out = self.run_rule("--floor", "7.5")
        self.assertIn("right: s7 misalignment_02 (misalignment): none -> misalignment, smallest tilt 7.90 mm",
                      out.stdout)
        self.assertIn("+2 -1 over 5 captures", out.stdout)

    def test_reads_the_reports_own_tilts_without_the_probe(self):
        with tempfile.TemporaryDirectory() as d:
            run = os.path.join(d, "s9")
            write_set(run, {"misalignment_00": ({"verdict": "friction", "placement_hem_tilt_mm": [9.0, 11.0, 12.0]},
                                                "misalign"),
                            "none_00": ({"verdict": "none", "placement_hem_tilt_mm": [2.0, 9.0, 3.0]}, "none")})
            out = subprocess.run([sys.executable, SCRIPT, run], capture_output=True, text=True)
            self.assertEqual(out.returncode, 0, out.stderr)
            self.assertIn("right: s9 misalignment_00 (misalignment): friction -> misalignment", out.stdout)
            self.assertIn("+1 -0 over 2 captures", out.stdout)
            with open(os.path.join(run, "diagnoses", "none_00.json"), "w") as f:
                json.dump({"verdict": "none"}, f)  # an older build's report
            out = subprocess.run([sys.executable, SCRIPT, run], capture_output=True, text=True)
            self.assertNotEqual(out.returncode, 0)
            self.assertIn("has no placement_hem_tilt_mm", out.stderr)

    def test_refuses_a_capture_without_tilts(self):
        with tempfile.TemporaryDirectory() as d:
            run = os.path.join(d, "s8")
            write_set(run, {"none_00": ({"verdict": "none"}, "none")})
            tilt_csv = os.path.join(d, "tilt.csv")
            with open(tilt_csv, "w") as f:
                f.write("set,capture,placement,hem_tilt_mm,outline_offset_mm\n")
            out = subprocess.run([sys.executable, SCRIPT, "--tilt", tilt_csv, run], capture_output=True, text=True)
            self.assertNotEqual(out.returncode, 0)
            self.assertIn("none_00 has a report but no tilt", out.stderr)


if __name__ == "__main__":
    unittest.main()
