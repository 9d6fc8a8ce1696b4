"""scripts/map_rules_summary.py: the rows it reads from map_rules' output, the exact interval of a
collision rate (scripts/bootstrap.py, which the report scripts share) against its closed forms, and
the pooled table."""

import contextlib
import io
import pathlib
import tempfile
import unittest

from helpers import load_script


# map_rules' own row format (printf "%-13s %4d  %-22s %5d %7.1f %8.1f %7s  %s%s").
OUTPUT_A = """lab room, closet mirror, eight camera(s), interval-mean + max-entropy, 0.050 m, 30 steps at most, 1 frame(s) per scan, seeds 1-3
planner       seed  termination            steps  known%   dist_m          met (poses)
explained hazards    1  explored                  21   100.0     65.2          -
explained hazards    2  budget                    30    79.1     20.8          closet:19 desk_island:2 
library          1  no reachable frontier     12    99.7     28.6          -
library          2  no reachable frontier     11    99.9     33.2          closet:3 closet_front:3   (mirrors told: 2)

| planner | runs with a collision | objects met (runs) | steps | floor known % | m driven | ended before the budget |
|---|---:|---|---:|---:|---:|---:|
| explained hazards | 1 of 2 | closet 1 | 25.5 ± 6.4 | 89.5 ± 14.7 | 43.0 ± 31.4 | 1 |
"""
OUTPUT_B = """planner       seed  termination            steps  known%   dist_m   annex%  met (poses)
explained hazards    3  blocked                    4    60.0     10.0       87  -
"""



class MapRulesSummary(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.s = load_script("map_rules_summary.py")
        cls.stats = load_script("bootstrap.py")

    def test_every_run_row_is_read_with_its_termination_annex_and_objects_and_nothing_else(self):
        rows = self.s.parse(OUTPUT_A + OUTPUT_B)
        self.assertEqual([(r["planner"], r["seed"]) for r in rows],
                         [("explained hazards", 1), ("explained hazards", 2), ("library", 1), ("library", 2),
                          ("explained hazards", 3)])
        self.assertEqual(rows[1]["termination"], "budget")
        self.assertEqual(rows[1]["met"], {"closet": 19, "desk_island": 2})
        self.assertEqual(rows[2]["termination"], "no reachable frontier")
        self.assertEqual(rows[3]["met"], {"closet": 3, "closet_front": 3})
        self.assertEqual(rows[4]["annex"], 87.0)
        self.assertIsNone(rows[0]["annex"])
        self.assertEqual((rows[0]["steps"], rows[0]["known"], rows[0]["distance"]), (21, 100.0, 65.2))

    def test_the_exact_interval_meets_its_closed_forms_at_the_ends_and_is_symmetric(self):
        cp = self.stats.clopper_pearson
        self.assertEqual(self.s.clopper_pearson.__code__.co_filename, cp.__code__.co_filename)  # the summary uses it
        for n in (1, 10, 40):
            lo, hi = cp(0, n)
            self.assertEqual(lo, 0.0)
            self.assertAlmostEqual(hi, 1 - 0.025 ** (1 / n), places=9)  # (1 - p)^n = alpha / 2
            lo, hi = cp(n, n)
            self.assertAlmostEqual(lo, 0.025 ** (1 / n), places=9)
            self.assertEqual(hi, 1.0)
        for k in range(11):
            lo, hi = cp(k, 10)
            rlo, rhi = cp(10 - k, 10)
            self.assertAlmostEqual(lo, 1 - rhi, places=9)
            self.assertAlmostEqual(hi, 1 - rlo, places=9)
            self.assertLessEqual(lo, k / 10)
            self.assertGreaterEqual(hi, k / 10)
        # The tails at the bounds hold alpha / 2 each (1 of 10).
        lo, hi = cp(1, 10)
        self.assertAlmostEqual(1 - self.stats.binomial_cdf(0, 10, lo), 0.025, places=9)
        self.assertAlmostEqual(self.stats.binomial_cdf(1, 10, hi), 0.025, places=9)
        with self.assertRaises(ValueError):
            cp(3, 2)

    def test_files_of_one_label_are_pooled_per_planner_and_a_seed_twice_is_refused(self):
        with tempfile.TemporaryDirectory() as d:
            a, b = pathlib.Path(d, "a.txt"), pathlib.Path(d, "b.txt")
            a.write_text(OUTPUT_A, encoding="utf-8")
            b.write_text(OUTPUT_B, encoding="utf-8")
            out = io.StringIO()
            with contextlib.redirect_stdout(out):
                self.assertEqual(self.s.main([f"mirror={a},{b}", "--planner", "explained hazards"]), 0)
            table = out.getvalue()
            self.assertIn("| mirror | explained hazards | 3 | 1 of 3 (", table)
            self.assertIn("closet 1, desk_island 1", table)
            self.assertIn("| 18.3 ± 13.2 [", table)  # steps 21, 30, 4 (sd: sqrt(348.67 / 2))
            # Floor known 100.0, 79.1 and 60.0: two runs under 90 %; seed 2 used the budget.
            self.assertIn("| runs < 90 % known |", table)
            self.assertTrue(table.rstrip().endswith("| 79.7 ± 20.0 | 2 | 2 |"), table)
            self.assertNotIn("library", table)
            out = io.StringIO()
            with contextlib.redirect_stdout(out):
                self.s.main([f"mirror={a},{b}", "--planner", "explained hazards", "--known-below", "70"])
            self.assertTrue(out.getvalue().rstrip().endswith("| 1 | 2 |"), out.getvalue())
            with contextlib.redirect_stderr(io.StringIO()), self.assertRaises(SystemExit):
                self.s.main([f"mirror={a}", "--known-below", "101"])
            with self.assertRaises(ValueError):
                self.s.pooled([("twice", [str(a), str(a)])], None)
            # Two labels and the ratio of their mean steps.
            out = io.StringIO()
            with contextlib.redirect_stdout(out):
                self.s.main([f"x={a}", f"y={b}", "--planner", "explained hazards", "--ratio", "x", "y"])
            self.assertIn("too few runs", out.getvalue())  # y holds one run
            out = io.StringIO()
            with contextlib.redirect_stdout(out):
                self.s.main([f"x={a}", f"y={a}", "--ratio", "x", "y"])
            self.assertIn("steps ratio x / y: 1.00", out.getvalue())


if __name__ == "__main__":
    unittest.main()
