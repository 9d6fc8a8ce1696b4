"""The insertion budget and the depth scale: a depth image in millimetres read as metres is refused
with a clear error before the map grows, and integer depth is never read as metres."""

import math
import resource
import subprocess
import sys
import textwrap
import unittest

import numpy as np

import intervox as iv
from helpers import camera_pose_looking_x

K = iv.PinholeIntrinsics.from_fov(64, 48, math.radians(60), math.radians(45))


def depth_metres(seed=0):
    rng = np.random.default_rng(seed)
    return rng.uniform(0.5, 2.5, size=(48, 64)).astype(np.float32)


def limited_to(byte_limit):
    def set_limit():
        resource.setrlimit(resource.RLIMIT_AS, (byte_limit, byte_limit))
    return set_limit


class MillimetreDepthIsRefused(unittest.TestCase):
    def test_a_millimetre_depth_image_without_max_range_raises_within_4_gb(self):
        # The issue: 24 GB and the kernel's OOM killer (MemoryError under a 4 GB limit). Now a
        # ValueError naming the cause, quickly, under `ulimit -v 4000000`.
        script = textwrap.dedent("""
            import math, numpy as np, intervox as iv
            k = iv.PinholeIntrinsics.from_fov(640, 480, math.radians(60), math.radians(45))
            depth = np.random.default_rng(1).uniform(500.0, 3000.0, size=(480, 640)).astype(np.float32)
            pose = np.eye(4)
            g = iv.BayesGrid(0.05)
            try:
                g.insert_depth_image(depth, k, pose)
            except ValueError as e:
                print("refused:", e)
            else:
                print("inserted")
            print("observed", g.observed_count())
        """)
        r = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120,
                           preexec_fn=limited_to(4_000_000 * 1024))
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("refused:", r.stdout)
        self.assertIn("millimetres", r.stdout)
        self.assertIn("max_range", r.stdout)
        self.assertIn("max_grid_bytes", r.stdout)
        self.assertIn("observed 0", r.stdout)

    def test_a_finite_max_range_beyond_the_largest_float_frees_what_any_range_beyond_the_map_frees(self):
        # max_range=1e39 is finite as a double and infinite as a float: the projective frustum
        # collapsed (a dense box got a fraction of its misses) and a sparse grid skipped its budget.
        depth = np.full((48, 64), np.inf, dtype=np.float32)
        pose = camera_pose_looking_x(0.52, 0.48, 0.51)
        near, huge = (iv.DenseBayesGrid(0.1, bounds=((0, 0, 0), (4, 4, 4))) for _ in range(2))
        a = near.insert_depth_image_projective(depth, K, pose, max_range=100.0)
        b = huge.insert_depth_image_projective(depth, K, pose, max_range=1e39)
        self.assertGreater(a.misses, 1000)
        self.assertEqual(b.misses, a.misses)
        self.assertEqual(near.to_bytes(), huge.to_bytes())
        with self.assertRaisesRegex(ValueError, "max_grid_bytes"):
            iv.BayesGrid(0.1).insert_depth_image_projective(depth, K, pose, max_range=1e39)

    def test_the_budget_is_a_keyword_and_an_inserter_option(self):
        pose = camera_pose_looking_x(0, 0, 0)
        mm = depth_metres() * 1000.0
        g = iv.BayesGrid(0.05)
        with self.assertRaisesRegex(ValueError, "insertion budget"):
            g.insert_depth_image(mm, K, pose)
        with self.assertRaisesRegex(ValueError, "insertion budget"):
            g.insert_depth_image(depth_metres(), K, pose, max_grid_bytes=10_000)
        self.assertEqual(g.observed_count(), 0)
        ins = iv.ScanInserter(max_grid_bytes=10_000)
        self.assertEqual(ins.max_grid_bytes, 10_000)
        self.assertEqual(iv.ScanInserter().max_grid_bytes, 1 << 32)
        with self.assertRaisesRegex(ValueError, "insertion budget"):
            ins.insert_depth_image(g, depth_metres(), K, pose)
        with self.assertRaisesRegex(ValueError, "insertion budget"):
            g.insert_point_cloud(np.array([[3000.0, 0, 0], [0, 4000.0, 0]]), (0, 0, 0), max_grid_bytes=10_000)
        # Within the budget (metres, or millimetres cut at a max range) it inserts.
        self.assertEqual(g.insert_depth_image(depth_metres(), K, pose).rays, 64 * 48)
        self.assertEqual(g.insert_depth_image(mm, K, pose, max_range=3.0).truncated, 64 * 48)


class IntegerDepthNeedsAScale(unittest.TestCase):
    def test_uint16_depth_without_depth_scale_is_refused(self):
        g = iv.BayesGrid(0.05)
        mm = (depth_metres() * 1000).astype(np.uint16)
        with self.assertRaisesRegex(ValueError, "depth_scale"):
            g.insert_depth_image(mm, K, camera_pose_looking_x(0, 0, 0))
        with self.assertRaisesRegex(ValueError, "depth_scale"):
            iv.ScanInserter().insert_depth_image(g, mm.astype(np.int32), K, camera_pose_looking_x(0, 0, 0))
        self.assertEqual(g.observed_count(), 0)

    def test_uint16_millimetres_with_a_scale_equal_the_same_depth_in_metres(self):
        pose = camera_pose_looking_x(0.1, 0.2, 0.3)
        mm = (depth_metres() * 1000).astype(np.uint16)
        mm[3, 4] = 0  # no measurement: invalid, skipped
        a = iv.BayesGrid(0.05)
        sa = a.insert_depth_image(mm, K, pose, depth_scale=0.001)
        b = iv.BayesGrid(0.05)
        sb = b.insert_depth_image((mm.astype(np.float64) * 0.001).astype(np.float32), K, pose)
        self.assertEqual(sa, sb)
        self.assertEqual(sa.skipped_invalid, 1)
        self.assertEqual(a.to_bytes(), b.to_bytes())
        c = iv.BayesGrid(0.05)
        c.insert_depth_image(mm.astype(np.float32), K, pose, depth_scale=0.001)
        self.assertEqual(a.to_bytes(), c.to_bytes())

    def test_a_bad_depth_scale_or_dtype_is_refused(self):
        g = iv.BayesGrid(0.05)
        pose = camera_pose_looking_x(0, 0, 0)
        for bad in (0.0, -1.0, float("nan"), float("inf")):
            with self.assertRaisesRegex(ValueError, "depth_scale"):
                g.insert_depth_image(depth_metres(), K, pose, depth_scale=bad)
        with self.assertRaisesRegex(ValueError, "dtype"):
            g.insert_depth_image(np.ones((48, 64), dtype=bool), K, pose)


if __name__ == "__main__":
    unittest.main()
