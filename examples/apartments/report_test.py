"""Tests scripts/apartments_report.py on a hand-made results.csv whose counts, means and ratios
are known.

Usage: report_test.py SCRIPT. Exit 77 (skipped) without numpy or matplotlib.
"""
import io
import os
import sys
import tempfile
import unittest
from contextlib import redirect_stdout

try:
    import numpy  # noqa: F401
    import matplotlib  # noqa: F401
except ImportError:
    sys.exit(77)

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "experiments"))
from script_under_test import load, write_csv  # noqa: E402

rep = load("apartments_report")

FIELDS = ["seed", "world", "planner", "rig", "update", "rooms", "kinds", "floor_area", "termination", "completed", "steps",
          "distance", "known", "collision_poses", "collision_segments", "first_collision", "met", "met_lying"]
TIMING_FIELDS = ["seed", "world", "planner", "rig", "update", "seconds_per_plan", "seconds_per_insert", "seconds_total"]


def row(seed, planner, known, steps, collided=False, completed=True, world="lying", met="-"):
    return {"seed": seed, "world": world, "planner": planner, "rig": "eight", "update": "interval-mean", "rooms": 2,
            "kinds": "wall-mirror;black-furniture", "floor_area": 20.0,
            "termination": "explored" if completed else "budget", "completed": int(completed), "steps": steps,
            "distance": 10.0, "known": known, "collision_poses": 3 if collided else 0, "collision_segments": 0,
            "first_collision": 4 if collided else -1, "met": met, "met_lying": int("mirror" in met)}


class Report(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        self.path = os.path.join(self.dir.name, "results.csv")
        # Four worlds. The oracle: 1.0 known, 10 views, all complete. Safe: 0.8 known, 15 views, 2 of
        # 4 complete, one collision at the mirror. Plain: 0.9 known, 12 views, 3 collisions (one
        # at a black sofa only, two at the mirror).
        rows = []
        for s in (10001, 10002, 10003, 10004):
            rows.append(row(s, "oracle", 1.0, 10))
            rows.append(row(s, "safe", 0.8, 15, collided=s == 10001, completed=s <= 10002,
                            met="wall_mirror_0:wall-mirror;wall_south:wall" if s == 10001 else "-"))
            mirror = s in (10001, 10002)
            rows.append(row(s, "plain", 0.9, 12, collided=s != 10004,
                            met="wall_mirror_0:wall-mirror" if mirror else ("black_sofa:black-furniture" if s == 10003 else "-")))
            rows.append(row(s, "plain", 0.95, 11, world="honest"))
        write_csv(self.path, FIELDS, rows)
        write_csv(os.path.join(self.dir.name, "timings.csv"), TIMING_FIELDS,
                  [{k: r[k] for k in TIMING_FIELDS[:5]} | {"seconds_per_plan": 0.5, "seconds_per_insert": 0.25,
                                                            "seconds_total": 9.0} for r in rows])

    def tearDown(self):
        self.dir.cleanup()

    def report(self, *extra):
        out = io.StringIO()
        argv = sys.argv
        sys.argv = ["apartments_report.py", self.path, "--resamples", "200", *extra]
        try:
            with redirect_stdout(out):
                self.assertEqual(rep.main(), 0)
        finally:
            sys.argv = argv
        return out.getvalue()

    def line(self, text, planner, world="apartments"):
        for line in text.splitlines():
            if line.startswith(f"| {world} | {planner} |"):
                return line
        self.fail(f"no row for {world}/{planner}")

    def test_counts_means_and_ratios_against_the_oracle(self):
        text = self.report()
        safe = self.line(text, "safe")
        self.assertIn("1 of 4 (25.0 %", safe)   # runs with a collision
        self.assertIn("2 of 4 (50.0 %", safe)   # completed
        self.assertIn("80.0 ± 0.0", safe)        # floor known
        self.assertIn("| 0.80 (0.80–0.80) |", safe)  # floor known / oracle's
        self.assertIn("| 1.50 (1.50–1.50) |", safe)  # views / oracle's
        self.assertIn("| -0.50 (", safe)         # completed − oracle's
        plain = self.line(text, "plain")
        self.assertIn("3 of 4 (75.0 %", plain)
        self.assertIn("| 0.90 (0.90–0.90) |", plain)
        twin = self.line(text, "plain", "honest twins")
        self.assertIn("0 of 4 (0.0 %", twin)
        self.assertIn("| 0.95 (0.95–0.95) |", twin)  # against the oracle in the apartments
        oracle = self.line(text, "oracle")
        self.assertIn("| – | – | – |", oracle)

    def test_kinds_met_count_runs_per_kind_against_worlds_holding_it(self):
        text = self.report()
        plain = [l for l in text.splitlines() if l.startswith("| eight | interval-mean | plain | 4 |")][0]
        cells = [c.strip() for c in plain.strip("|").split("|")]
        kinds = rep.KINDS
        self.assertEqual(cells[4 + kinds.index("wall-mirror")], "2/4")
        self.assertEqual(cells[4 + kinds.index("black-furniture")], "1/4")
        self.assertEqual(cells[-1], "0")  # no collision met diffuse things only

    def test_charts_are_written(self):
        charts = os.path.join(self.dir.name, "charts")
        self.report("--charts", charts)
        for name in ("apartments_collisions.png", "apartments_floor.png"):
            self.assertTrue(os.path.getsize(os.path.join(charts, name)) > 1000)


if __name__ == "__main__":
    unittest.main()
