#!/usr/bin/env python3
"""scripts/pooled.py on hand-written ledgers: the pooled family table and confusion matrix of docs/DIAGNOSIS.md are
summed by it, so its sums and its refusals of inconsistent ledgers must be the ones the rows say."""
import contextlib
import importlib.util
import io
import os
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPT = os.path.join(HERE, "..", "pooled.py")
spec = importlib.util.spec_from_file_location("pooled", SCRIPT)
pooled = importlib.util.module_from_spec(spec)
spec.loader.exec_module(pooled)

SETS = [("90", "125", "yield", "3"), ("90", "125", "shear", "2"), ("90", "126", "yield", "3"),
        ("90", "126", "none", "4")]
MISSES = [("90", "125", "yield_01", "yield", "none", "within"), ("90", "126", "yield_02", "yield", "curl", "above"),
          ("90", "125", "shear_00", "shear", "unexplained", "above")]
CONTROLS = [("90", "126", "none_03", "yield")]


def rows(columns, values):
    return [dict(zip(columns, v + ("x",))) for v in values]


class PooledTest(unittest.TestCase):
    def tally(self, sets=SETS, misses=MISSES, controls=CONTROLS):
        return pooled.tally(rows(["session", "seed", "family", "captures", "source"], sets),
                            rows(["session", "seed", "capture", "truth", "verdict", "floors", "line"], misses),
                            rows(["session", "seed", "capture", "verdict", "line"], controls))

    def test_sums_the_families_and_the_matrix(self):
        captures, cells, errors = self.tally()
        self.assertEqual(errors, [])
        self.assertEqual(captures, {"yield": 6, "shear": 2, "none": 4})
        self.assertEqual(cells[("yield", "yield")], 4)
        self.assertEqual(cells[("yield", "none")], 1)
        self.assertEqual(cells[("yield", "curl")], 1)
        self.assertEqual(cells[("shear", "shear")], 1)
        self.assertEqual(cells[("none", "none")], 3)
        self.assertEqual(cells[("none", "yield")], 1)
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            pooled.print_tables(captures, cells)
        text = out.getvalue()
        self.assertIn("top-1 5 of 8 effect captures (62.5%); controls named none 3 of 4", text)
        self.assertIn("| none (controls) | **3** | 0 | 1 | 0 | 0 | 0 | 0 | 0 | 4 |", text)
        self.assertIn("| yield | 1 | 0 | **4** | 0 | 1 | 0 | 0 | 0 | 6 |", text)
        self.assertIn("| shear | 0 | 1 | 0 | **1** | 0 | 0 | 0 | 0 | 2 |", text)
        self.assertIn("| sensor | 0 | 0 | 0 | 0 | 0 | 0 | 0 | **0** | 0 |", text)

    def test_refuses_more_misses_than_captures_and_unknown_names(self):
        misses = MISSES + [("90", "126", "shear_00", "shear", "none", "within"),
                           ("90", "125", "yield_02", "yield", "yield", "above")]
        _, _, errors = self.tally(misses=misses, sets=SETS + [("90", "125", "wool", "1")])
        self.assertIn("seed 126: 1 shear captures not named right, but the sets' ledger holds 0", errors)
        self.assertIn("misses: seed 125 yield_02: verdict 'yield' for truth 'yield'", errors)
        self.assertIn("sets: seed 125: unknown family 'wool'", errors)
        _, _, errors = self.tally(controls=CONTROLS + [("90", "126", "none_00", "none")])
        self.assertEqual(errors, ["controls: seed 126 none_00: verdict 'none'"])

    def test_command_line_reads_the_files_and_fails_on_a_bad_header(self):
        with tempfile.TemporaryDirectory() as d:
            paths = []
            for name, header, values in [("sets", "session,seed,family,captures,source", SETS),
                                         ("misses", "session,seed,capture,truth,verdict,floors,line", MISSES),
                                         ("controls", "session,seed,capture,verdict,line", CONTROLS)]:
                paths.append(os.path.join(d, name + ".csv"))
                with open(paths[-1], "w") as f:
                    f.write(header + "\n" + "".join(",".join(v + ("x",)) + "\n" for v in values))
            run = subprocess.run([sys.executable, SCRIPT] + paths, capture_output=True, text=True)
            self.assertEqual(run.returncode, 0, run.stderr)
            self.assertIn("top-1 5 of 8 effect captures", run.stdout)
            run = subprocess.run([sys.executable, SCRIPT, paths[1], paths[1], paths[2]], capture_output=True, text=True)
            self.assertNotEqual(run.returncode, 0)
            self.assertIn("expected session,seed,family,captures,source", run.stderr)


if __name__ == "__main__":
    unittest.main()
