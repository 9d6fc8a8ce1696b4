"""Explained free space from Python: the same classes and evidence as C++ semantics demand, the grid
untouched, a planted mirror's phantoms suspect, bad input refused."""

import os
import tempfile
import unittest

import numpy as np

import intervox as iv


def wall_scan(origin, wall_x=2.0):
    """Returns from origin on a grid of points of the wall x = wall_x."""
    ys, zs = np.meshgrid(np.arange(-2.0, 2.0, 0.02), np.arange(-0.5, 0.5, 0.05))
    ends = np.stack([np.full(ys.size, wall_x), ys.ravel(), zs.ravel()], axis=1)
    return np.asarray(origin, dtype=float), ends


class ExplainedSpaceFromPython(unittest.TestCase):
    def test_the_grid_is_updated_as_by_its_own_insertion(self):
        rng = np.random.default_rng(4)
        ends = rng.uniform(-2, 2, size=(3000, 3))
        hits = rng.uniform(size=3000) > 0.2
        plain, grid = iv.BayesGrid(0.1), iv.BayesGrid(0.1)
        space = iv.ExplainedSpace(grid.resolution, grid.origin)
        a = plain.insert_beams(np.zeros(3), ends, hits, max_range=2.5)
        b, classes = space.insert_beams(grid, np.zeros(3), ends, hits, max_range=2.5)
        self.assertEqual((a.rays, a.hits, a.misses), (b.rays, b.hits, b.misses))
        self.assertEqual(b.beams_trusted + b.beams_suspect + b.beams_no_return, b.rays)
        self.assertEqual(b.beams_no_return, int(np.count_nonzero(~hits)))
        self.assertEqual(classes.dtype, np.uint8)
        pts = rng.uniform(-2, 2, size=(500, 3))
        np.testing.assert_array_equal(plain.probability(pts), grid.probability(pts))

    def test_a_phantom_seen_before_the_wall_is_revised_to_suspect(self):
        # The phantom first: trusted on arrival, as nothing is known behind it.
        grid = iv.BayesGrid(0.05)
        space = iv.ExplainedSpace(0.05, revision_interval=1)
        behind = np.array([[2.8, 0.31 * 2.8 / 3.5, 0.07 * 2.8 / 3.5]])
        stats, classes = space.insert_beams(grid, np.zeros(3), np.array([[3.5, 0.31, 0.07]]), max_range=6.0)
        self.assertEqual(stats.beams_trusted, 1)
        self.assertEqual(space.state(behind)[0], int(iv.ExplainedState.FREE))
        for _ in range(2):
            for y0 in (-1.0, 0.0, 1.0):
                o, ends = wall_scan((0.0, y0, 0.0))
                space.insert_beams(grid, o, ends, max_range=6.0)
        # Once the wall is supported, the ledger classes the phantom again: its space is unexplained.
        self.assertEqual(space.revision_stats["to_suspect"], 1)
        self.assertEqual(space.state(behind)[0], int(iv.ExplainedState.UNEXPLAINED))
        ledger = space.ledger
        self.assertEqual(ledger["scans"], 7)
        self.assertLessEqual(ledger["bytes"], ledger["budget"])
        # Without a ledger the phantom keeps its arrival class.
        off = iv.ExplainedSpace(0.05, ledger_bytes=0)
        grid = iv.BayesGrid(0.05)
        off.insert_beams(grid, np.zeros(3), np.array([[3.5, 0.31, 0.07]]), max_range=6.0)
        for _ in range(2):
            for y0 in (-1.0, 0.0, 1.0):
                o, ends = wall_scan((0.0, y0, 0.0))
                off.insert_beams(grid, o, ends, max_range=6.0)
        off.revise()
        self.assertEqual(off.revision_stats["to_suspect"], 0)
        self.assertEqual(off.state(behind)[0], int(iv.ExplainedState.FREE))
        with self.assertRaises(ValueError):
            iv.ExplainedSpace(0.05, revision_interval=0)

    def test_a_phantom_behind_a_seen_wall_is_suspect_and_its_space_unexplained(self):
        grid = iv.BayesGrid(0.05)
        space = iv.ExplainedSpace(0.05)
        for _ in range(2):
            for y0 in (-1.0, 0.0, 1.0):
                o, ends = wall_scan((0.0, y0, 0.0))
                stats, classes = space.insert_beams(grid, o, ends, max_range=6.0)
                self.assertEqual(stats.beams_suspect, 0)
        # A phantom: a return 1.5 m behind the wall, straight through it.
        phantom_end = np.array([[3.5, 0.31, 0.07]])
        self.assertEqual(space.classify(np.zeros(3), phantom_end, max_range=6.0)[0], int(iv.BeamClass.SUSPECT))
        stats, classes = space.insert_beams(grid, np.zeros(3), phantom_end, max_range=6.0)
        self.assertEqual(stats.beams_suspect, 1)
        behind = np.array([[2.8, 0.31 * 2.8 / 3.5, 0.07 * 2.8 / 3.5]])
        self.assertEqual(space.state(behind)[0], int(iv.ExplainedState.UNEXPLAINED))
        ev = space.evidence(behind)[0]
        self.assertEqual(ev[1], 0)   # no trusted miss
        self.assertEqual(ev[3], 1)   # one suspect miss
        free, occupied, conflict = space.belief(behind)[0]
        self.assertAlmostEqual(free, 0.1 * 0.4)  # the suspect class's reliability times one miss
        self.assertEqual(occupied, 0.0)
        # In front of the wall: explained free.
        self.assertEqual(space.state(np.array([[1.0, 0.0, 0.0]]))[0], int(iv.ExplainedState.FREE))
        box = space.trusted_extent
        self.assertIsNotNone(box)
        self.assertLessEqual(box[1][0], 40)  # keys: the wall at x = 2 m is key 40; the phantom never grew it
        self.assertGreater(space.size(), 0)
        self.assertGreater(space.memory_bytes(), 0)

    def test_a_beam_without_a_return_through_a_seen_wall_is_suspect_within_the_sensor_range(self):
        grid = iv.BayesGrid(0.05)
        space = iv.ExplainedSpace(0.05)
        for _ in range(2):
            for y0 in (-1.0, 0.0, 1.0):
                o, ends = wall_scan((0.0, y0, 0.0))
                space.insert_beams(grid, o, ends, max_range=6.0)
        origin = np.array([0.0, 0.01, 0.01])
        direction = np.array([1.0, 0.1, 0.02]) / np.linalg.norm([1.0, 0.1, 0.02])
        # The end of a beam without a return is the sensor's range: 4 m passes the wall at 2 m, 1.9 m does not.
        ends = origin + np.outer([4.0, 1.9], direction)
        classes = space.classify(origin, ends, np.array([False, False]), max_range=6.0)
        self.assertEqual(list(classes), [int(iv.BeamClass.SUSPECT), int(iv.BeamClass.NO_RETURN)])
        # Met at a flatter angle than no_return_crossing_angle: no crossing.
        steep_only = iv.ExplainedSpace(0.05, no_return_crossing_angle=89.0)
        for _ in range(2):
            for y0 in (-1.0, 0.0, 1.0):
                o, wall = wall_scan((0.0, y0, 0.0))
                steep_only.insert_beams(iv.BayesGrid(0.05), o, wall, max_range=6.0)
        self.assertEqual(steep_only.classify(origin, ends[:1], np.array([False]), max_range=6.0)[0],
                         int(iv.BeamClass.NO_RETURN))
        with self.assertRaisesRegex(ValueError, "no_return_crossing_angle"):
            iv.ExplainedSpace(0.05, no_return_crossing_angle=95.0)

    def test_the_inside_rule_trusts_a_beam_that_passes_a_walls_edge(self):
        # The wall x = 2 seen up to z = 0.45 m (its top row of voxels z 0.40-0.45 m); a beam that
        # passes that row onto unseen space is suspect by default, trusted with returned_crossing_inside.
        edge_origin, edge_end = np.array([0.0, 0.0, 0.43]), np.array([[3.0, 0.0, 0.435]])
        classes = {}
        for inside in (False, True):
            space = iv.ExplainedSpace(0.05, returned_crossing_inside=inside)
            for _ in range(2):
                for y0 in (-1.0, 0.0, 1.0):
                    o, wall = wall_scan((0.0, y0, 0.0))
                    space.insert_beams(iv.BayesGrid(0.05), o, wall, max_range=6.0)
            classes[inside] = space.classify(edge_origin, edge_end, max_range=6.0)[0]
            # Through the wall's inside it is suspect either way.
            through = space.classify(np.zeros(3), np.array([[3.0, 0.01, 0.02]]), max_range=6.0)[0]
            self.assertEqual(through, int(iv.BeamClass.SUSPECT))
        self.assertEqual(classes[False], int(iv.BeamClass.SUSPECT))
        self.assertEqual(classes[True], int(iv.BeamClass.TRUSTED))
        planner = iv.MobilePlannerParams()
        self.assertFalse(planner.returned_crossing_inside)
        planner.returned_crossing_inside = True
        self.assertTrue(planner.returned_crossing_inside)

    def test_classify_then_add_equals_insert_beams(self):
        o, ends = wall_scan((0.0, 0.0, 0.0))
        a, b = iv.ExplainedSpace(0.05), iv.ExplainedSpace(0.05)
        classes = a.classify(o, ends, max_range=5.0, threads=2)
        a.add(o, ends, None, classes, max_range=5.0)
        b.insert_beams(iv.BayesGrid(0.05), o, ends, max_range=5.0)
        pts = np.random.default_rng(1).uniform(-0.5, 2.5, size=(2000, 3)) * np.array([1, 1, 0.2])
        np.testing.assert_array_equal(a.evidence(pts), b.evidence(pts))

    def test_bad_input_is_refused_with_a_reason(self):
        with self.assertRaisesRegex(ValueError, "crossing_tolerance"):
            iv.ExplainedSpace(0.05, crossing_tolerance=-1.0)
        with self.assertRaisesRegex(ValueError, "suspect_reliability"):
            iv.ExplainedSpace(0.05, suspect_reliability=2.0)
        space = iv.ExplainedSpace(0.05)
        with self.assertRaisesRegex(ValueError, "geometry"):
            space.insert_beams(iv.BayesGrid(0.1), np.zeros(3), np.ones((2, 3)))
        with self.assertRaisesRegex(ValueError, "classes"):
            space.add(np.zeros(3), np.ones((2, 3)), None, np.zeros(3, dtype=np.uint8))
        with self.assertRaisesRegex(ValueError, "no BeamClass"):
            space.add(np.zeros(3), np.ones((2, 3)), None, np.array([0, 7]))
        with self.assertRaisesRegex(ValueError, "NaN"):
            space.state(np.array([[np.nan, 0, 0]]))
        space.clear()
        self.assertIsNone(space.trusted_extent)

    def test_a_scan_over_the_budget_of_the_channels_scratch_is_refused_before_the_grid_changes(self):
        grid = iv.BayesGrid(0.05)
        space = iv.ExplainedSpace(grid.resolution, grid.origin)
        rng = np.random.default_rng(3)
        ends = rng.uniform(0.2, 0.5, size=(20000, 3))  # short rays: the grid's own budget holds
        with self.assertRaisesRegex(ValueError, r"20000 beams.*max_grid_bytes"):
            space.insert_beams(grid, np.zeros(3), ends, max_range=2.0, max_grid_bytes=1 << 20)
        self.assertEqual(grid.observed_count(), 0)
        stats, _ = space.insert_beams(grid, np.zeros(3), ends, max_range=2.0)
        self.assertEqual(stats.beams_trusted, 20000)

    def test_a_grid_that_is_not_an_intervox_grid_is_named_as_the_problem(self):
        # Duck-typed grids: the attribute or the result that is wrong is named, not pybind11's
        # "Unable to cast Python instance to C++ type".
        class Looks:
            resolution = 0.05
            origin = (0.0, 0.0, 0.0)

            def insert_beams(self, *args, **kwargs):
                return {"rays": 2}

        class NoOrigin:
            resolution = 0.05

        class BadResolution:
            resolution = "5 cm"
            origin = (0.0, 0.0, 0.0)

        space = iv.ExplainedSpace(0.05)
        ends = np.array([[1.0, 0.0, 0.0], [1.0, 0.2, 0.0]])
        for grid, message in ((Looks(), "grid.insert_beams returned dict, not InsertStats"),
                              (NoOrigin(), "has no 'origin'"),
                              (BadResolution(), "'resolution' is a str, expected a number")):
            with self.assertRaises(TypeError) as caught:
                space.insert_beams(grid, np.zeros(3), ends, max_range=2.0)
            self.assertIn(message, str(caught.exception))
            self.assertNotIn("Unable to cast", str(caught.exception))
        self.assertEqual(space.evidence(ends).sum(), 0)


    def test_evidence_round_trips_through_a_file_and_colours_the_3d_page(self):
        grid = iv.BayesGrid(0.1)
        space = iv.ExplainedSpace(0.1)
        for _ in range(3):
            for y0 in (-0.5, 0.0, 0.5):
                o, ends = wall_scan((0.0, y0, 0.0))
                space.insert_beams(grid, o, ends, max_range=6.0)
        ys = np.linspace(-0.5, 0.5, 21)
        phantoms = np.stack([np.full(21, 3.5), ys, np.zeros(21)], axis=1)
        for _ in range(4):
            space.insert_beams(grid, np.zeros(3), phantoms, max_range=6.0)
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "map.ivxe")
            space.save(path)
            back = iv.ExplainedSpace.load(path)
            pts = np.random.default_rng(2).uniform(-0.5, 4.0, size=(3000, 3)) * np.array([1, 1, 0.1])
            np.testing.assert_array_equal(back.evidence(pts), space.evidence(pts))
            self.assertEqual(np.asarray(back.trusted_extent).tolist(), np.asarray(space.trusted_extent).tolist())
            with self.assertRaises(iv.IoError):
                iv.ExplainedSpace.load(os.path.join(d, "missing.ivxe"))

            # The page: every observed voxel but the free ones the evidence explains; the free
            # class holds the phantoms' unexplained free space.
            v = grid.observed_voxels()
            state = space.state(v["centers"])
            free = v["occupancy"] == int(iv.Occupancy.FREE)
            kept = ~(free & (state == int(iv.ExplainedState.FREE)))
            self.assertGreater(int(np.count_nonzero(free & (state == int(iv.ExplainedState.UNEXPLAINED)))), 0)
            page_path = os.path.join(d, "explained.html")
            s = grid.write_html_view(page_path, explained=space)
            self.assertEqual(s["selected"], int(np.count_nonzero(kept)))
            with open(page_path, encoding="utf-8") as f:
                page = f.read()
            self.assertIn("explained occupied", page)
            self.assertIn("free in the grid, not explained", page)
            # The caller's voxels still rule: occupied voxels only.
            s = grid.write_html_view(page_path, explained=space, voxels="occupied")
            self.assertEqual(s["selected"], int(np.count_nonzero(v["occupancy"] == int(iv.Occupancy.OCCUPIED))))
            with self.assertRaises(ValueError):
                iv.BayesGrid(0.2).write_html_view(page_path, explained=space)


if __name__ == "__main__":
    unittest.main()
