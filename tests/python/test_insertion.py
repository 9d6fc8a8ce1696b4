"""Insertion from numpy: the same map as the C++ API, closed forms, statistics, bad input."""

import math
import sys
import threading
import time
import unittest

import numpy as np

import intervox as iv
from helpers import (assert_same_grid, camera_pose_looking_x, logit, oracle_cloud, oracle_depth,
                     random_cloud, sigmoid)


class PointCloudMatchesCpp(unittest.TestCase):
    def test_bayes_cloud_equals_the_cpp_insertion_of_the_same_points(self):
        pts = random_cloud(1)
        origin = (0.1, -0.2, 0.3)
        g = iv.BayesGrid(0.1)
        stats = g.insert_point_cloud(pts, origin, max_range=2.5)
        self.assertEqual(stats.rays, len(pts))
        self.assertGreater(stats.truncated, 0)
        assert_same_grid(self, g, oracle_cloud("bayes", 0.1, pts, origin, max_range=2.5))

    def test_interval_cloud_equals_the_cpp_insertion_of_the_same_points(self):
        pts = random_cloud(2)
        g = iv.IntervalGrid(0.1)
        g.insert_point_cloud(pts, (0, 0, 0))
        g.insert_point_cloud(pts[:500] * 0.5, (0, 0, 0))
        ref = oracle_cloud("interval", 0.1, pts, (0, 0, 0))
        ref.insert_point_cloud(pts[:500] * 0.5, (0, 0, 0))
        assert_same_grid(self, g, ref)

    def test_float32_points_equal_their_float64_values(self):
        pts32 = random_cloud(3).astype(np.float32)
        g = iv.BayesGrid(0.05)
        g.insert_point_cloud(pts32, (0, 0, 0))
        assert_same_grid(self, g, oracle_cloud("bayes", 0.05, pts32.astype(np.float64), (0, 0, 0)))

    def test_non_contiguous_fortran_and_unaligned_arrays_give_the_same_map(self):
        pts = random_cloud(4, n=3000)
        a, b, c = iv.BayesGrid(0.1), iv.BayesGrid(0.1), iv.BayesGrid(0.1)
        a.insert_point_cloud(np.ascontiguousarray(pts[::3]), (0, 0, 0))
        b.insert_point_cloud(pts[::3], (0, 0, 0))
        c.insert_point_cloud(np.asfortranarray(pts[::3]), (0, 0, 0))
        assert_same_grid(self, a, b)
        assert_same_grid(self, a, c)
        raw = b"\0" + np.ascontiguousarray(pts[::3]).tobytes()
        unaligned = np.frombuffer(raw, dtype=np.float64, offset=1).reshape(-1, 3)  # misaligned view
        self.assertFalse(unaligned.flags.aligned)
        d = iv.BayesGrid(0.1)
        d.insert_point_cloud(unaligned, (0, 0, 0))
        assert_same_grid(self, a, d)

    def test_thread_count_does_not_change_the_map(self):
        pts = random_cloud(5, n=20000, spread=6.0)
        ref = iv.IntervalGrid(0.05)
        ref.insert_point_cloud(pts, (0, 0, 0), max_range=4.0, threads=1)
        for threads in (0, 2, 3):
            g = iv.IntervalGrid(0.05)
            s = g.insert_point_cloud(pts, (0, 0, 0), max_range=4.0, threads=threads)
            self.assertEqual(s.rays, len(pts))
            assert_same_grid(self, g, ref)

    def test_scan_inserter_reuses_scratch_and_gives_the_same_map(self):
        ins = iv.ScanInserter(max_range=3.0, threads=2)
        a, b = iv.BayesGrid(0.1), iv.BayesGrid(0.1)
        for seed in range(3):
            pts = random_cloud(10 + seed)
            ins.insert_point_cloud(a, pts, (0, 0, 0))
            b.insert_point_cloud(pts, (0, 0, 0), max_range=3.0)
        self.assertGreater(ins.scratch_bytes(), 0)
        assert_same_grid(self, a, b)


class DepthImageMatchesCpp(unittest.TestCase):
    def test_depth_image_equals_the_cpp_insertion(self):
        k = iv.PinholeIntrinsics.from_fov(64, 48, math.radians(60), math.radians(45))
        rng = np.random.default_rng(7)
        depth = rng.uniform(0.5, 3.0, size=(48, 64)).astype(np.float32)
        depth[0, :5] = np.inf   # no return: free up to max range
        depth[1, :5] = np.nan   # invalid
        depth[2, :5] = 0.0      # invalid
        pose = camera_pose_looking_x(0.2, 0.1, 0.5)
        for policy, cls in (("bayes", iv.BayesGrid), ("interval", iv.IntervalGrid)):
            g = cls(0.05)
            s = g.insert_depth_image(depth, k, pose, max_range=2.0)
            self.assertEqual(s.skipped_invalid, 10)
            self.assertEqual(s.rays, 64 * 48 - 10)
            assert_same_grid(self, g, oracle_depth(policy, 0.05, depth, k, pose, max_range=2.0))

    def test_float64_depth_equals_float32_depth(self):
        k = iv.PinholeIntrinsics(32, 24, 30.0, 30.0, 15.5, 11.5)
        depth = np.full((24, 32), 1.7)
        a, b = iv.BayesGrid(0.05), iv.BayesGrid(0.05)
        a.insert_depth_image(depth, k, np.eye(4))
        b.insert_depth_image(depth.astype(np.float32), k, np.eye(4))
        assert_same_grid(self, a, b)


class ProjectiveDepthImage(unittest.TestCase):
    """Grid.insert_depth_image_projective and ProjectiveInserter against the C++ API and closed forms."""

    def frame(self, seed):
        k = iv.PinholeIntrinsics.from_fov(64, 48, math.radians(60), math.radians(45))
        rng = np.random.default_rng(seed)
        depth = rng.uniform(0.8, 3.0, size=(48, 64)).astype(np.float32)
        depth[0, :5] = np.inf   # no return: free up to max range
        depth[1, :5] = np.nan   # invalid
        return k, depth, camera_pose_looking_x(0.2, 0.1, 0.5)

    def test_projective_depth_image_equals_the_cpp_projective_insertion(self):
        k, depth, pose = self.frame(8)
        for policy, cls in (("bayes", iv.BayesGrid), ("interval", iv.IntervalGrid)):
            g = cls(0.05)
            s = g.insert_depth_image_projective(depth, k, pose, max_range=2.5)
            self.assertEqual(s.skipped_invalid, 5)
            self.assertEqual(s.rays, 64 * 48 - 5)
            self.assertGreater(s.misses, 1000)
            assert_same_grid(self, g, oracle_depth(policy, 0.05, depth, k, pose, max_range=2.5, mode="projective"))

    def test_a_projective_inserter_reused_on_any_thread_count_gives_the_same_map(self):
        ins1 = iv.ProjectiveInserter(max_range=2.5)
        ins2 = iv.ProjectiveInserter(max_range=2.5, threads=2)
        self.assertEqual(ins1.surface_band, 0.5)
        a, b, c = iv.BayesGrid(0.05), iv.BayesGrid(0.05), iv.BayesGrid(0.05)
        for seed in range(3):
            k, depth, pose = self.frame(20 + seed)
            ins1.insert_depth_image(a, depth, k, pose)
            ins2.insert_depth_image(b, depth, k, pose)
            c.insert_depth_image_projective(depth, k, pose, max_range=2.5)
        self.assertGreater(ins1.scratch_bytes(), 0)
        assert_same_grid(self, a, b)
        assert_same_grid(self, a, c)

    def test_a_wall_is_free_in_front_occupied_at_its_depth_and_unknown_behind(self):
        k = iv.PinholeIntrinsics.from_fov(40, 30, 0.9, 0.7)
        depth = np.full((30, 40), 1.02, dtype=np.float32)
        g = iv.BayesGrid(0.1)
        g.insert_depth_image_projective(depth, k, np.eye(4))  # optical z = world z
        p = g.probability(np.array([[0.01, 0.01, 0.55], [0.01, 0.01, 1.05], [0.01, 0.01, 1.25]]))
        self.assertLess(p[0], 0.5)
        self.assertGreater(p[1], 0.5)
        self.assertEqual(p[2], 0.5)

    def test_integer_depth_needs_a_scale_and_a_bad_band_is_refused(self):
        k, depth, pose = self.frame(9)
        g = iv.BayesGrid(0.05)
        with self.assertRaisesRegex(ValueError, "depth_scale"):
            g.insert_depth_image_projective(np.nan_to_num(depth * 1000, posinf=0).astype(np.uint16), k, pose)
        with self.assertRaises(ValueError):
            iv.ProjectiveInserter(surface_band=-1.0)
        mm = g.insert_depth_image_projective(np.nan_to_num((depth * 1000), posinf=0).astype(np.uint16), k, pose,
                                             depth_scale=0.001, max_range=2.5)
        self.assertGreater(mm.rays, 0)


class ClosedForms(unittest.TestCase):
    def test_one_ray_gives_misses_along_it_and_a_hit_at_its_end(self):
        g = iv.BayesGrid(0.1)
        s = g.insert_point_cloud(np.array([[1.05, 0.05, 0.05]]), (0.05, 0.05, 0.05))
        self.assertEqual((s.rays, s.hits, s.misses), (1, 1, 10))
        xs = np.array([[0.05 + 0.1 * i, 0.05, 0.05] for i in range(11)])
        p = g.probability(xs)
        np.testing.assert_allclose(p[:10], 0.25, rtol=1e-6)
        self.assertAlmostEqual(p[10], 0.75, places=6)
        # A second scan: log-odds add up (lq 3 * 3 = 9 -> 0.9; 1/9 -> 0.1).
        g.insert_point_cloud(np.array([[1.05, 0.05, 0.05]]), (0.05, 0.05, 0.05))
        p = g.probability(xs)
        np.testing.assert_allclose(p[:10], 0.1, rtol=1e-6)
        self.assertAlmostEqual(p[10], 0.9, places=6)

    def test_interval_bounds_follow_the_log_odds_sum(self):
        params = iv.IntervalParams()
        g = iv.IntervalGrid(0.1, params=params)
        for _ in range(3):
            g.insert_ray((0.05, 0.05, 0.05), (0.55, 0.05, 0.05))
        lo = sigmoid(logit(params.initial_lower) + 3 * logit(params.p_hit))
        hi = min(sigmoid(logit(params.initial_upper) + 3 * logit(params.p_hit)), params.clamp_max)
        np.testing.assert_allclose(g.interval(np.array([[0.55, 0.05, 0.05]]))[0], [lo, hi], rtol=1e-5)
        mlo = sigmoid(logit(params.initial_lower) + 3 * logit(params.p_miss))
        mlo = max(mlo, params.clamp_min)
        mhi = sigmoid(logit(params.initial_upper) + 3 * logit(params.p_miss))
        np.testing.assert_allclose(g.interval(np.array([[0.25, 0.05, 0.05]]))[0], [mlo, mhi], rtol=1e-5)

    def test_beams_without_return_are_free_up_to_max_range(self):
        g = iv.BayesGrid(0.1)
        s = g.insert_beams(np.array([[0.05, 0.05, 0.05]] * 2), np.array([[5.0, 0.05, 0.05], [0.05, 5.0, 0.05]]),
                           np.array([False, True]), max_range=1.0)
        self.assertEqual(s.truncated, 2)
        self.assertEqual(s.hits, 0)
        self.assertEqual(g.counts().occupied + g.counts().unknown + g.counts().free, g.observed_count())
        self.assertTrue(np.all(g.probability(np.array([[0.55, 0.05, 0.05], [0.05, 0.55, 0.05]])) < 0.5))

    def test_single_origin_broadcasts_over_beams(self):
        ends = random_cloud(8, n=200)
        a, b = iv.BayesGrid(0.1), iv.BayesGrid(0.1)
        a.insert_beams((0, 0, 0), ends)
        b.insert_point_cloud(ends, (0, 0, 0))
        assert_same_grid(self, a, b)


class Gil(unittest.TestCase):
    def test_another_python_thread_runs_while_cpp_inserts(self):
        pts = random_cloud(11, n=4000, spread=10.0)
        g = iv.BayesGrid(0.05)
        done = threading.Event()
        ticks = [0]

        def spin():
            while not done.is_set():
                ticks[0] += 1

        t = threading.Thread(target=spin)
        t.start()
        t0, before = time.perf_counter(), ticks[0]
        time.sleep(0.1)
        rate = (ticks[0] - before) / (time.perf_counter() - t0)  # the spinner's ticks per second alone
        before = ticks[0]
        g.insert_point_cloud(pts, (0, 0, 0))
        during = ticks[0] - before
        done.set()
        t.join()
        # Holding the GIL, the spinner could run at most about one switch interval (5 ms) of the call.
        self.assertGreater(during, 10 * rate * sys.getswitchinterval())


class BadInput(unittest.TestCase):
    def test_nan_points_and_origins_are_skipped_and_counted(self):
        pts = random_cloud(9, n=10)
        pts[3] = np.nan
        pts[5, 1] = np.inf
        g = iv.BayesGrid(0.1)
        s = g.insert_point_cloud(pts, (0, 0, 0))
        self.assertEqual((s.rays, s.skipped_invalid), (8, 2))
        s = g.insert_point_cloud(pts, (np.nan, 0, 0))
        self.assertEqual((s.rays, s.skipped_invalid), (0, 10))

    def test_wrong_shapes_and_dtypes_raise_value_error_with_the_message(self):
        g = iv.BayesGrid(0.1)
        with self.assertRaisesRegex(ValueError, r"shape \(N, 3\).*\(5, 2\)"):
            g.insert_point_cloud(np.zeros((5, 2)), (0, 0, 0))
        with self.assertRaises(ValueError):
            g.insert_point_cloud(np.array([["a", "b", "c"]]), (0, 0, 0))
        with self.assertRaisesRegex(ValueError, "min_range"):
            g.insert_point_cloud(np.zeros((1, 3)), (0, 0, 0), min_range=-1.0)
        with self.assertRaisesRegex(ValueError, "max_range is NaN"):
            g.insert_point_cloud(np.zeros((1, 3)), (0, 0, 0), max_range=float("nan"))
        k = iv.PinholeIntrinsics(4, 3, 2.0, 2.0, 1.5, 1.0)
        with self.assertRaisesRegex(ValueError, "intrinsics are 4x3"):
            g.insert_depth_image(np.ones((3, 5)), k, np.eye(4))
        with self.assertRaisesRegex(ValueError, r"\(4, 4\)"):
            g.insert_depth_image(np.ones((3, 4)), k, np.eye(3))
        bad = np.eye(4)
        bad[0, 0] = 2.0
        with self.assertRaisesRegex(ValueError, "not a rigid transform"):
            g.insert_depth_image(np.ones((3, 4)), k, bad)
        with self.assertRaisesRegex(ValueError, "differ in length"):
            g.insert_beams(np.zeros((2, 3)), np.ones((3, 3)))
        with self.assertRaisesRegex(ValueError, "focal"):
            iv.PinholeIntrinsics(4, 3, -1.0, 2.0, 1.5, 1.0)
        self.assertEqual(g.observed_count(), 0)

    def test_empty_cloud_is_fine(self):
        g = iv.BayesGrid(0.1)
        s = g.insert_point_cloud(np.zeros((0, 3)), (0, 0, 0))
        self.assertEqual(s, iv.InsertStats())


if __name__ == "__main__":
    unittest.main()
