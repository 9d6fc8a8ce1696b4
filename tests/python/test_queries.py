"""Vectorised queries: shapes, dtypes, agreement with observed_voxels, cast_ray."""

import unittest

import numpy as np

import intervox as iv
from helpers import random_cloud


def wall_grid(cls=iv.BayesGrid):
    """A wall of occupied voxels at x in [1.0, 1.1), seen from the origin."""
    g = cls(0.1)
    ys, zs = np.meshgrid(np.arange(-1, 1, 0.1) + 0.05, np.arange(-1, 1, 0.1) + 0.05)
    pts = np.stack([np.full(ys.size, 1.05), ys.ravel(), zs.ravel()], axis=1)
    for _ in range(5):
        g.insert_point_cloud(pts, (0.05, 0.05, 0.05))
    return g


class Shapes(unittest.TestCase):
    def test_results_keep_the_leading_shape_and_have_fixed_dtypes(self):
        for cls in iv.GRID_TYPES:
            g = cls(0.1, bounds=((-2, -2, -2), (2, 2, 2)))
            g.insert_point_cloud(random_cloud(1, n=100, spread=1.5), (0, 0, 0))
            pts = random_cloud(2, n=12, spread=1.5).reshape(3, 4, 3)
            self.assertEqual(g.probability(pts).shape, (3, 4))
            self.assertEqual(g.probability(pts).dtype, np.float64)
            self.assertEqual(g.interval(pts).shape, (3, 4, 2))
            self.assertEqual(g.occupancy(pts).dtype, np.uint8)
            self.assertEqual(g.utility(pts).shape, (3, 4))
            self.assertEqual(g.is_observed(pts).dtype, np.bool_)
            self.assertEqual(g.probability(pts[0, 0]).shape, ())
            self.assertEqual(g.probability(np.zeros((0, 3))).shape, (0,))

    def test_queries_agree_with_the_observed_voxels(self):
        for cls in iv.GRID_TYPES:
            g = cls(0.1, bounds=((-3, -3, -3), (3, 3, 3)))
            g.insert_point_cloud(random_cloud(3, n=500, spread=2.5), (0, 0, 0), max_range=2.0)
            v = g.observed_voxels()
            m = len(v["keys"])
            self.assertGreater(m, 100)
            self.assertEqual(v["centers"].shape, (m, 3))
            np.testing.assert_array_equal(g.probability(v["centers"]), v["probability"])
            np.testing.assert_array_equal(g.interval(v["centers"]), v["interval"])
            np.testing.assert_array_equal(g.occupancy(v["centers"]), v["occupancy"])
            np.testing.assert_array_equal(g.utility(v["centers"]), v["utility"])
            self.assertTrue(g.is_observed(v["centers"]).all())
            np.testing.assert_array_equal(g.keys(v["centers"]), v["keys"])
            self.assertTrue(np.all(v["interval"][:, 0] <= v["interval"][:, 1]))

    def test_observed_voxels_in_a_box_are_those_of_all_that_meet_the_box(self):
        for cls in iv.GRID_TYPES:
            for bounded in ((True,) if cls.storage == "dense" else (False, True)):
                g = cls(0.1, bounds=((-3, -3, -3), (3, 3, 3))) if bounded else cls(0.1)
                g.insert_point_cloud(random_cloud(4, n=800, spread=2.5), (0, 0, 0), max_range=2.0)
                everything = g.observed_voxels()
                box = np.array([[-0.73, -1.17, -0.04], [0.88, 0.31, 1.43]])
                inside = g.observed_voxels(bounds=box)
                # Brute force: the voxels whose cube [corner, corner + 0.1] meets the box.
                lo = everything["centers"] - 0.05
                meets = np.all((lo + 0.1 >= box[0]) & (lo <= box[1]), axis=1)
                want = {tuple(k) for k in everything["keys"][meets]}
                got = [tuple(k) for k in inside["keys"]]
                self.assertEqual(len(got), len(set(got)))
                self.assertEqual(set(got), want)
                self.assertGreater(len(want), 20)
                np.testing.assert_array_equal(g.probability(inside["centers"]), inside["probability"])
                self.assertEqual(len(g.observed_voxels(bounds=((-1e300,) * 3, (1e300,) * 3))["keys"]),
                                 len(everything["keys"]))
                with self.assertRaises(ValueError):
                    g.observed_voxels(bounds=((1, 1, 1), (0, 2, 2)))

    def test_change_detection_records_the_voxels_whose_class_changed(self):
        for cls in iv.GRID_TYPES:
            g = cls(0.1, bounds=((-3, -3, -3), (3, 3, 3)))
            self.assertFalse(g.change_detection_enabled)
            g.insert_point_cloud(random_cloud(5, n=300, spread=2.5), (0, 0, 0), max_range=2.0)
            self.assertEqual(g.changed_count(), 0)
            before = g.observed_voxels()
            g.enable_change_detection()
            g.insert_point_cloud(random_cloud(6, n=300, spread=2.5), (0, 0, 0), max_range=2.0, threads=2)
            after = g.observed_voxels()
            # Brute force: voxels newly observed, or whose class changed.
            old = {tuple(k): c for k, c in zip(before["keys"], before["occupancy"])}
            want = {tuple(k) for k, c in zip(after["keys"], after["occupancy"]) if old.get(tuple(k), -1) != c}
            got = [tuple(k) for k in g.changed_keys()]
            self.assertEqual(len(got), len(set(got)))
            self.assertEqual(set(got), want)
            self.assertEqual(g.changed_count(), len(want))
            self.assertGreater(len(want), 50)
            g.reset_change_detection()
            self.assertEqual(g.changed_keys().shape, (0, 3))
            self.assertTrue(g.change_detection_enabled)

    def test_coarse_queries_summarise_the_cube_of_each_point(self):
        for cls in iv.GRID_TYPES:
            g = cls(0.1, bounds=((-3, -3, -3), (3, 3, 3)))
            g.insert_point_cloud(random_cloud(7, n=600, spread=2.5), (0, 0, 0), max_range=2.0)
            v = g.observed_voxels()
            pts = np.concatenate([v["centers"][::7], random_cloud(8, n=60, spread=3.5)])
            unobserved_p = g.probability(np.array([[50.0, 50, 50]]))[0]
            for level in (0, 2, 3, 4, 6):
                got = g.coarse_query(pts, level)
                self.assertEqual(got["observed"].shape, (len(pts),))
                self.assertEqual(got["observed"].dtype, np.uint64)
                # Brute force: the observed voxels whose keys agree with the point's key >> level.
                cube = g.keys(pts) >> level
                member = np.all((v["keys"] >> level)[None, :, :] == cube[:, None, :], axis=2)
                occupied = v["occupancy"] == int(iv.Occupancy.OCCUPIED)
                np.testing.assert_array_equal(got["observed"], member.sum(axis=1))
                np.testing.assert_array_equal(got["occupied"], (member & occupied[None, :]).sum(axis=1))
                want_max = np.where(member, v["probability"][None, :], -np.inf).max(axis=1)
                want_max[member.sum(axis=1) == 0] = unobserved_p
                np.testing.assert_array_equal(got["max_probability"], want_max)
                want_upper = np.where(member, v["interval"][None, :, 1], -np.inf).max(axis=1)
                seen = member.sum(axis=1) > 0
                np.testing.assert_array_equal(got["max_upper"][seen], want_upper[seen])
                self.assertTrue(seen.any())
                if level <= 3:  # coarser cubes all hold an observed voxel of this small map
                    self.assertFalse(seen.all())
            cubes = g.coarse_cubes(4)
            self.assertEqual(int(cubes["observed"].sum()), len(v["keys"]))
            self.assertAlmostEqual(cubes["edge"], 1.6)
            np.testing.assert_array_equal(cubes["min_keys"] % 16, 0)
            back = g.coarse_query(cubes["centers"], 4)
            np.testing.assert_array_equal(back["observed"], cubes["observed"])
            np.testing.assert_array_equal(back["max_probability"], cubes["max_probability"])
            with self.assertRaisesRegex(ValueError, "level must lie"):
                g.coarse_query(pts, 24)
            with self.assertRaisesRegex(ValueError, "level must lie"):
                g.coarse_cubes(2)
            with self.assertRaisesRegex(ValueError, "NaN"):
                g.coarse_query(np.array([[np.nan, 0, 0]]), 3)

    def test_unobserved_points_answer_with_the_prior(self):
        g = iv.IntervalGrid(0.1)
        np.testing.assert_allclose(g.interval(np.array([[5.0, 5, 5]])), [[0.05, 0.95]], rtol=1e-6)
        self.assertAlmostEqual(g.utility(np.array([[5.0, 5, 5]]))[0], 1.0)  # max entropy over [0.05, 0.95]
        self.assertEqual(g.occupancy(np.array([[5.0, 5, 5]]))[0], int(iv.Occupancy.UNKNOWN))

    def test_nan_query_raises_value_error(self):
        with self.assertRaisesRegex(ValueError, "point 1 has a NaN"):
            iv.BayesGrid(0.1).probability(np.array([[0, 0, 0], [0, np.inf, 0]]))
        with self.assertRaisesRegex(ValueError, r"shape \(N, 3\)"):
            iv.BayesGrid(0.1).occupancy(np.zeros(4))


class CastRay(unittest.TestCase):
    def test_cast_ray_stops_at_the_wall(self):
        g = wall_grid()
        r = g.cast_ray((0.05, 0.05, 0.05), (1, 0, 0), max_range=5.0)
        self.assertTrue(r.hit)
        self.assertEqual(r.status, iv.CastStatus.OCCUPIED)
        self.assertEqual(r.key, (10, 0, 0))
        np.testing.assert_allclose(r.center, [1.05, 0.05, 0.05])
        self.assertAlmostEqual(r.distance, 0.95)
        r = g.cast_ray((0.05, 0.05, 0.05), (-1, 0, 0), max_range=2.0)
        self.assertEqual(r.status, iv.CastStatus.MAX_RANGE)
        r = g.cast_ray((0.05, 0.05, 0.05), (-1, 0, 0), max_range=2.0, stop_at_unknown=True)
        self.assertEqual(r.status, iv.CastStatus.UNKNOWN)
        self.assertEqual(g.cast_ray((0, 0, 0), (0, 0, 0), max_range=1.0).status, iv.CastStatus.INVALID)

    def test_cast_rays_equals_cast_ray_per_ray(self):
        g = wall_grid(iv.IntervalGrid)
        dirs = random_cloud(4, n=50, spread=1.0)
        status, keys, dist = g.cast_rays((0.05, 0.05, 0.05), dirs, max_range=3.0)
        for i, d in enumerate(dirs):
            r = g.cast_ray((0.05, 0.05, 0.05), d, max_range=3.0)
            self.assertEqual(status[i], int(r.status))
            self.assertEqual(tuple(keys[i]), r.key)
            self.assertEqual(dist[i], r.distance)
        self.assertIn(int(iv.CastStatus.OCCUPIED), status.tolist())


if __name__ == "__main__":
    unittest.main()
