"""Misuse that used to be silent, slow or a crash: each is refused with a clear error."""

import signal
import subprocess
import sys
import textwrap
import time
import unittest

import numpy as np

import intervox as iv


class CastRaysNeedARange(unittest.TestCase):
    def test_cast_rays_on_an_unbounded_grid_without_max_range_is_refused(self):
        g = iv.BayesGrid(0.05)
        t = time.monotonic()
        with self.assertRaisesRegex(ValueError, "max_range"):
            g.cast_rays((0, 0, 0), np.tile([1.0, 0.3, 0.2], (1000, 1)))
        with self.assertRaisesRegex(ValueError, "max_range"):
            g.cast_ray((0, 0, 0), (1, 0, 0))
        with self.assertRaisesRegex(ValueError, "max_range"):
            g.cast_ray((0, 0, 0), (1, 0, 0), max_range=float("inf"))
        self.assertLess(time.monotonic() - t, 1.0)
        # With a range it casts; a bounded grid ends the cast at its bounds, so it needs none.
        self.assertEqual(g.cast_ray((0, 0, 0), (1, 0, 0), max_range=2.0).status, iv.CastStatus.MAX_RANGE)
        d = iv.DenseBayesGrid(0.1, bounds=((-1, -1, -1), (1, 1, 1)))
        self.assertEqual(d.cast_ray((0, 0, 0), (1, 0, 0)).status, iv.CastStatus.LEFT_GRID)

    def test_ctrl_c_interrupts_a_long_cast_rays(self):
        # 1000 rays that each walk to the key limit (about 0.1 s each): Ctrl-C must stop the call.
        script = textwrap.dedent("""
            import sys, numpy as np, intervox as iv
            g = iv.BayesGrid(0.01)
            print("start", flush=True)
            try:
                g.cast_rays((0, 0, 0), np.tile([1.0, 0.3, 0.2], (1000, 1)), max_range=1e6)
            except KeyboardInterrupt:
                print("interrupted", flush=True)
                sys.exit(3)
            print("finished", flush=True)
        """)
        p = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        try:
            self.assertEqual(p.stdout.readline().strip(), "start")
            time.sleep(1.0)
            sent = time.monotonic()
            p.send_signal(signal.SIGINT)
            out, err = p.communicate(timeout=20)
            self.assertLess(time.monotonic() - sent, 5.0)
        finally:
            if p.poll() is None:
                p.kill()
                p.wait()
        self.assertEqual(p.returncode, 3, out + err)
        self.assertIn("interrupted", out)


class KeysAndHitsAreChecked(unittest.TestCase):
    def test_centers_refuses_keys_outside_the_key_range_instead_of_wrapping(self):
        g = iv.BayesGrid(0.1)
        np.testing.assert_allclose(g.centers([[0, 1, -1]]), [[0.05, 0.15, -0.05]])
        for key in ([2 ** 40, 0, 0], [0, -(2 ** 23) - 1, 0], [0, 0, 2 ** 23]):
            with self.assertRaisesRegex(IndexError, "key range"):
                g.centers(np.array([key], dtype=np.int64))
        g.centers([[-(2 ** 23), 2 ** 23 - 1, 0]])  # the ends of the range are keys

    def test_insert_beams_refuses_float_hits(self):
        g = iv.BayesGrid(0.1)
        ends = np.array([[1.0, 0, 0], [0, 1.0, 0]])
        with self.assertRaisesRegex(ValueError, "hits"):
            g.insert_beams((0, 0, 0), ends, np.array([0.4, 1.0]), max_range=3.0)
        self.assertEqual(g.observed_count(), 0)
        a = g.insert_beams((0, 0, 0), ends, np.array([1, 0], dtype=np.int8), max_range=3.0)
        b = iv.BayesGrid(0.1).insert_beams((0, 0, 0), ends, np.array([True, False]), max_range=3.0)
        self.assertEqual(a, b)


class EpisodeAndBoundsArguments(unittest.TestCase):
    def test_episode_refuses_a_nan_or_negative_max_range(self):
        src = lambda body: (np.zeros(3), np.ones((1, 3)))
        for bad in (float("nan"), -1.0, 0.0, -float("inf")):
            with self.assertRaisesRegex(ValueError, "max_range"):
                iv.Episode(iv.BayesGrid(0.1), iv.MobilePlanner(), src, np.eye(4), max_range=bad)
        iv.Episode(iv.BayesGrid(0.1), iv.MobilePlanner(), src, np.eye(4))  # None: the planner's range
        iv.Episode(iv.BayesGrid(0.1), iv.MobilePlanner(), src, np.eye(4), max_range=2.5)

    def test_bad_bounds_name_the_expected_shape(self):
        for bad in ((1, 2), ((0, 0), (1, 1)), "ab", 5, ((0, 0, 0), (1, 1, 1), (2, 2, 2))):
            with self.assertRaisesRegex(ValueError, r"\(\(xmin, ymin, zmin\), \(xmax, ymax, zmax\)\)"):
                iv.DenseBayesGrid(0.1, bounds=bad)
        with self.assertRaisesRegex(ValueError, r"\(\(xmin, ymin, zmin\), \(xmax, ymax, zmax\)\)"):
            iv.Bounds(1, 2)
        self.assertIsNotNone(iv.DenseBayesGrid(0.1, bounds=((0, 0, 0), (1, 1, 1))).key_box)


if __name__ == "__main__":
    unittest.main()
