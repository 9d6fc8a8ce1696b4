"""Tests scripts/credal_separation.py on a hand-made results.csv with known means.

Usage: credal_separation_test.py SCRIPT. Exit 77 (skipped) without numpy.
"""
import io
import os
import sys
import tempfile
import unittest
from contextlib import redirect_stdout

try:
    import numpy as np
except ImportError:
    sys.exit(77)

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from script_under_test import load, write_csv  # noqa: E402

sep = load("credal_separation")

FIELDS = ["platform", "surface", "update", "policies", "planner", "seed", "flagged_voxels", "flagged_band",
          "signature_voxels", "signature_band", "conflict_truth", "truth_band", "conflict_precision",
          "conflict_recall"]


def row(update, seed, flagged, band, precision, recall, surface="mirror", platform="mobile"):
    return {"platform": platform, "surface": surface, "update": update, "policies": "thesis", "planner": "plain",
            "seed": seed, "flagged_voxels": flagged, "flagged_band": band, "signature_voxels": flagged + 5,
            "signature_band": band, "conflict_truth": 100, "truth_band": 10, "conflict_precision": precision,
            "conflict_recall": recall}


class Separation(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        self.path = os.path.join(self.dir.name, "results.csv")
        rows = [row("interval-mean", s, 0, 0, 1.0, 0.0) for s in (1, 2, 3)]
        rows += [row("dirichlet-mean", s, 100, b, 0.2, 0.5) for s, b in ((1, 10), (2, 20), (3, 30))]
        rows += [row("bayes", 1, -1, -1, -1, -1), row("dirichlet-mean", 1, 50, 5, 0.1, 0.1, platform="arm")]
        write_csv(self.path, FIELDS, rows)

    def tearDown(self):
        self.dir.cleanup()

    def test_rows_without_scores_and_arm_rows_are_left_out_and_shares_derived(self):
        rows = sep.load(self.path)
        self.assertEqual(len(rows), 6)
        d = [r for r in rows if r["update"] == "dirichlet-mean"]
        self.assertEqual([r["flagged_share"] for r in d], [0.1, 0.2, 0.3])
        self.assertEqual([r["flagged_outside"] for r in d], [90, 80, 70])
        self.assertEqual(d[0]["label"], "dirichlet-mean")
        i = [r for r in rows if r["update"] == "interval-mean"]
        self.assertEqual(i[0]["label"], "interval-mean/thesis")
        self.assertTrue(np.isnan(i[0]["precision"]))  # flags nothing: no precision
        self.assertTrue(np.isnan(i[0]["flagged_share"]))

    def test_bootstrap_interval_contains_the_difference_of_means_and_is_seeded(self):
        a, b = np.array([10.0, 20.0, 30.0]), np.array([0.0, 0.0, 0.0])
        d1 = sep.bootstrap_diff(a, b, 2000, np.random.default_rng(1))
        d2 = sep.bootstrap_diff(a, b, 2000, np.random.default_rng(1))
        self.assertEqual(d1, d2)
        self.assertEqual(d1[0], 20.0)
        self.assertTrue(10.0 <= d1[1] <= 20.0 <= d1[2] <= 30.0)
        self.assertIsNone(sep.bootstrap_diff(a[:1], b, 100, np.random.default_rng(1)))

    def test_the_tables_show_mean_and_sd_and_the_difference(self):
        sys.argv = ["credal_separation.py", self.path, "--resamples", "500"]
        out = io.StringIO()
        with redirect_stdout(out):
            sep.main()
        text = out.getvalue()
        self.assertIn("| plain | mirror | dirichlet-mean | 3 | 20 ± 10 | 80 ± 10 | 0.20 ± 0.10 |", text)
        self.assertIn("| plain | mirror: dirichlet-mean − interval-mean/thesis | flagged in band | +20 |", text)


if __name__ == "__main__":
    unittest.main()
