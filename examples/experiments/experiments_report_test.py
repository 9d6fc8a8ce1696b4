"""Tests scripts/experiments_report.py on a hand-made results.csv whose means are known.

Usage: experiments_report_test.py SCRIPT. Exit 77 (skipped) without numpy or matplotlib.
"""
import csv
import io
import os
import sys
import tempfile
import unittest
from contextlib import redirect_stdout

try:
    import numpy as np
    import matplotlib  # noqa: F401
except ImportError:
    sys.exit(77)

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from script_under_test import load, write_csv  # noqa: E402

rep = load("experiments_report")

FIELDS = ["platform", "surface", "update", "utility", "policies", "floor", "gain", "planner", "seed", "steps",
          "termination", "completed", "known", "wrongly_occupied", "wrongly_free", "band_wrongly_occupied",
          "band_wrongly_free", "band_voxels", "region_voxels", "collision_poses", "collision_segments", "views_to_80",
          "coverage_curve", "unobserved"]


def mobile(planner, seed, steps, band_occ, collided, completed=True, policies="thesis", floor="removed"):
    return {"platform": "mobile", "surface": "specular", "update": "interval-mean", "utility": "max-entropy",
            "policies": policies, "floor": floor, "gain": "unknown", "planner": planner, "seed": seed, "steps": steps,
            "termination": "explored" if completed else "budget", "completed": int(completed), "known": 0.99,
            "wrongly_occupied": 100, "wrongly_free": 50, "band_wrongly_occupied": band_occ, "band_wrongly_free": 10,
            "band_voxels": 1000, "region_voxels": 100000, "collision_poses": int(collided), "collision_segments": 0,
            "views_to_80": -1, "coverage_curve": "", "unobserved": "unknown"}


def arm(seed, curve):
    return {"platform": "arm", "surface": "part", "update": "interval-mean", "utility": "max-entropy",
            "policies": "thesis", "floor": "kept", "gain": "unknown", "planner": "conflict-aware", "seed": seed,
            "steps": len(curve), "termination": "budget", "completed": 0, "known": curve[-1], "wrongly_occupied": 1,
            "wrongly_free": 2, "band_wrongly_occupied": 0, "band_wrongly_free": 0, "band_voxels": 0,
            "region_voxels": 10, "collision_poses": 0, "collision_segments": 0,
            "views_to_80": next((i + 1 for i, c in enumerate(curve) if c >= 0.8), -1),
            "coverage_curve": ";".join(str(c) for c in curve), "unobserved": "unknown"}


class Report(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        self.path = os.path.join(self.dir.name, "results.csv")
        # Plain: 20 steps and 100 band voxels wrongly occupied on average; conflict-aware: 10 and 80.
        rows = [mobile("plain", s, st, b, True) for s, st, b in ((1, 18, 90), (2, 20, 100), (3, 22, 110))]
        rows += [mobile("conflict-aware", s, st, b, s == 3, completed=s != 2)
                 for s, st, b in ((1, 9, 80), (2, 10, 80), (3, 11, 80))]
        # Another condition: must be left out.
        rows += [mobile("plain", 1, 99, 999, True, policies="clamped"), mobile("plain", 1, 99, 999, True, floor="kept")]
        rows += [arm(1, [0.5, 0.85]), arm(2, [0.2, 0.3])]
        write_csv(self.path, FIELDS, rows)

    def tearDown(self):
        self.dir.cleanup()

    def run_main(self, *extra):
        sys.argv = ["experiments_report.py", self.path, "--resamples", "500", *extra]
        out = io.StringIO()
        with redirect_stdout(out):
            rep.main()
        return out.getvalue()

    def test_rows_of_other_conditions_are_left_out(self):
        rows = rep.load(self.path, "thesis", "removed", "unknown")
        self.assertEqual(len(rows), 8)
        self.assertEqual(len(rep.load(self.path, "clamped", "removed", "unknown")), 1)

    def test_rows_of_the_third_editions_rooms_rules_and_sensors_are_left_out(self):
        path = os.path.join(self.dir.name, "third.csv")
        lab = mobile("plain", 1, 20, 100, False)
        rows = [dict(lab, room="lab", rules="thesis", sensor="plain"), dict(lab, seed=2, room="annex", rules="thesis", sensor="plain"),
                dict(lab, seed=3, room="lab", rules="library", sensor="plain"), dict(lab, seed=4, room="lab", rules="thesis", sensor="glint")]
        write_csv(path, FIELDS + ["room", "rules", "sensor"], rows)
        self.assertEqual([r["seed"] for r in rep.load(path, "thesis", "removed", "unknown")], ["1"])

    def test_the_targets_report_the_measured_values(self):
        text = self.run_main()
        self.assertIn("completes ≥ 9 of 10 runs | 2 of 3 (plain: 3 of 3) | – | no |", text)
        # 1 - 10/20 = 50 % fewer steps, 1 - 80/100 = 20 % fewer wrongly occupied band voxels.
        self.assertIn("fewer steps than plain interval-mean + max-entropy | reduction +50.0 % (10.0 vs 20.0)", text)
        self.assertIn("closet band | reduction +20.0 % (80.0 vs 100.0)", text)
        self.assertIn("zero runs with a collision | 1 of 3 (plain: 3 of 3) | – | no |", text)
        self.assertIn("within 12 views | 1 of 2 runs; coverage after the last view 57.5 ± 38.9 %", text)
        self.assertIn("| mobile | specular | interval-mean + max-entropy | 3 | 3 | 20.0 ± 2.0 |", text)
        self.assertIn("| – | specular: steps, interval-mean + max-entropy conflict-aware − plain | -10.0 |", text)

    def test_a_target_whose_errors_are_zero_in_both_groups_is_not_measurable(self):
        with open(self.path, newline="") as f:
            rows = list(csv.DictReader(f))
        for r in rows:
            r["band_wrongly_occupied"] = 0
        write_csv(self.path, FIELDS, rows)
        text = self.run_main()
        self.assertIn("closet band | none: 0 in every run of both (0.0 vs 0.0) | – | not measurable |", text)

    def test_reduction_interval_is_seeded_and_brackets_the_estimate(self):
        a, b = np.array([9.0, 10.0, 11.0]), np.array([18.0, 20.0, 22.0])
        r1 = rep.bootstrap(a, b, rep.relative_reduction, 2000, np.random.default_rng(3))
        r2 = rep.bootstrap(a, b, rep.relative_reduction, 2000, np.random.default_rng(3))
        self.assertEqual(r1, r2)
        self.assertAlmostEqual(r1[0], 0.5)
        self.assertTrue(r1[1] <= 0.5 <= r1[2])
        # The extremes: 1 - 11/18 and 1 - 9/22.
        self.assertTrue(1 - 11 / 18 - 1e-12 <= r1[1] and r1[2] <= 1 - 9 / 22 + 1e-12)

    def test_collisions_are_listed_by_object_when_the_file_has_them(self):
        self.assertNotIn("Where the collisions lie", self.run_main())  # no collision_objects column
        with open(self.path, newline="") as f:
            rows = list(csv.DictReader(f))
        for r in rows:
            collided = int(r["collision_poses"]) > 0
            r["collision_objects"] = ("closet=1/0;cabinet=2/1" if r["seed"] == "1" else "closet=1/0") if collided else ""
        write_csv(self.path, FIELDS + ["collision_objects"], rows)
        text = self.run_main()
        self.assertIn("Where the collisions lie", text)
        # Plain: all three runs met the closet (1 pose each), seed 1 also the cabinet (2 poses).
        self.assertIn("| specular | interval-mean + max-entropy | 3 of 3 | closet 3 (3), cabinet 1 (2) |", text)
        self.assertIn("| specular | interval-mean + max-entropy, conflict-aware | 1 of 3 | closet 1 (1) |", text)

    def test_charts_are_written(self):
        charts = os.path.join(self.dir.name, "charts")
        text = self.run_main("--charts", charts)
        for name in ("steps.png", "wrongly_occupied.png", "collisions.png", "completed.png", "arm_coverage.png"):
            path = os.path.join(charts, name)
            self.assertGreater(os.path.getsize(path), 5000, name)
            with open(path, "rb") as f:
                self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")
            self.assertIn(name, text)


if __name__ == "__main__":
    unittest.main()
