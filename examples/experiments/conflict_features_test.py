"""Tests scripts/conflict_features.py on hand-made per-voxel rows with known scores.

Usage: conflict_features_test.py SCRIPT. Exit 77 (skipped) without numpy.
"""
import io
import os
import sys
import tempfile
import unittest
from contextlib import redirect_stdout

try:
    import numpy as np  # noqa: F401
except ImportError:
    sys.exit(77)

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from script_under_test import load, write_csv  # noqa: E402

cf = load("conflict_features")

CONTRA = "hits and misses each >= 20 %, >= 4 observations"
FRINGE = "the same, surface-fringe rule (no map-occupied neighbour)"


def voxel(x, y, z, hits, misses, truth=0, phantom=0, true_evidence=0, scene_occupied=0, fringe=0):
    return {"x": x, "y": y, "z": z, "scene_occupied": scene_occupied, "truth": truth, "phantom": phantom,
            "true_evidence": true_evidence, "observations": hits + misses, "map": 0, "hits": hits, "misses": misses,
            "hit_on_free": 0, "miss_on_occupied": 0, "pass_occupied": 0, "hit_behind_occupied": 0, "fringe": fringe}


class Scores(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        d = self.dir.name
        # Mirror: A and B contradict (flagged by CONTRA), A and C are true conflict voxels (implemented);
        # B has phantom and true evidence (the issue's truth), C does not.
        self.mirror = os.path.join(d, "specular_1.csv")
        write_csv(self.mirror, cf.COLUMNS, [
            voxel(0.025, 0.025, 0.025, 3, 3, truth=1, phantom=3),             # A
            voxel(0.075, 0.025, 0.025, 2, 6, phantom=2, true_evidence=6, fringe=1),  # B
            voxel(0.125, 0.025, 0.025, 1, 9, truth=1, phantom=1),             # C: hits 10 %: not flagged
            voxel(0.175, 0.025, 0.025, 1, 1),                                 # 2 observations: not flagged
        ])
        # Diffuse: one scene-occupied voxel; its neighbour E is an edge voxel and flagged, F is far away.
        self.diffuse = os.path.join(d, "diffuse_1.csv")
        write_csv(self.diffuse, cf.COLUMNS, [
            voxel(1.025, 1.025, 0.025, 10, 0, scene_occupied=1),  # an edge voxel itself, not flagged
            voxel(1.075, 1.025, 0.025, 4, 4),                     # E: edge, flagged
            voxel(2.025, 1.025, 0.025, 5, 5),                     # F: not an edge, flagged
        ])

    def tearDown(self):
        self.dir.cleanup()

    def test_precision_and_recall_against_both_ground_truths(self):
        rows = cf.score([self.mirror])
        r = rows[("specular", CONTRA, "implemented")]
        self.assertEqual(r["flagged"], [2])
        self.assertEqual(r["truth"], [2])
        self.assertEqual(r["precision"], [0.5])
        self.assertEqual(r["recall"], [0.5])
        issue = rows[("specular", CONTRA, "issue")]
        self.assertEqual(issue["truth"], [1])
        self.assertEqual(issue["recall"], [1.0])
        # The fringe rule drops B; a rule that flags nothing gives no precision.
        fr = rows[("specular", FRINGE, "issue")]
        self.assertEqual(fr["flagged"], [1])
        self.assertEqual(fr["recall"], [0.0])
        self.assertEqual(rows[("specular", "contradictions of the map's state >= 2", "issue")]["precision"], [])

    def test_edge_voxels_of_the_diffuse_room_flagged(self):
        r = cf.score([self.diffuse])[("diffuse", CONTRA, "implemented")]
        self.assertEqual(r["flagged"], [2])
        self.assertEqual(r["edge"], [0.5])  # two edge voxels (the occupied one and E), E flagged

    def test_the_table_shows_mean_and_sd_over_a_closet_s_files(self):
        second = os.path.join(self.dir.name, "specular_2.csv")
        write_csv(second, cf.COLUMNS, [voxel(0.025, 0.025, 0.025, 3, 3, truth=1, phantom=3)])
        out = io.StringIO()
        with redirect_stdout(out):
            cf.main([self.mirror, second])
        text = out.getvalue()
        self.assertIn(f"| specular | {CONTRA} | implemented | 2 | 2 ± 1 | 2 ± 1 | 0.750 ± 0.354 | 0.750 ± 0.354 | – |", text)

    def test_the_figure_is_a_png(self):
        try:
            import matplotlib  # noqa: F401
        except ImportError:
            self.skipTest("needs matplotlib")
        out = os.path.join(self.dir.name, "top.png")
        cf.main(["--figure", out, self.mirror])
        with open(out, "rb") as f:
            self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")
        with self.assertRaises(SystemExit):
            cf.main(["--figure", out])

    def test_a_file_with_other_columns_is_refused(self):
        bad = os.path.join(self.dir.name, "specular_3.csv")
        with open(bad, "w") as f:
            f.write("x,y\n1,2\n")
        with self.assertRaises(SystemExit) as e:
            cf.score([bad])
        self.assertIn("unexpected header", str(e.exception))


if __name__ == "__main__":
    unittest.main()
