"""Grid classes: construction, presets, parameters, geometry, updates, copies."""

import copy
import os
import tempfile
import unittest

import numpy as np

import intervox as iv

BOUNDS = ((0.0, 0.0, 0.0), (1.0, 1.0, 1.0))


def make(cls, **kw):
    return cls(0.1, bounds=BOUNDS, **kw) if cls.storage == "dense" else cls(0.1, **kw)


class Construction(unittest.TestCase):
    def test_every_named_configuration_has_its_policy_and_storage(self):
        expected = {
            iv.BayesGrid: ("bayes", "sparse"), iv.DenseBayesGrid: ("bayes", "dense"),
            iv.IntervalGrid: ("interval-mean", "sparse"), iv.IntervalLowerGrid: ("interval-lower", "sparse"),
            iv.IntervalUpperGrid: ("interval-upper", "sparse"), iv.DenseIntervalGrid: ("interval-mean", "dense"),
            iv.CompactIntervalGrid: ("compact-interval-mean", "sparse"),
            iv.DenseIntervalLowerGrid: ("interval-lower", "dense"), iv.DenseIntervalUpperGrid: ("interval-upper", "dense"),
            iv.DenseCompactIntervalGrid: ("compact-interval-mean", "dense"),
            iv.DirichletGrid: ("dirichlet-mean", "sparse"), iv.DenseDirichletGrid: ("dirichlet-mean", "dense"),
            iv.BeliefGrid: ("belief-mean", "sparse"), iv.DenseBeliefGrid: ("belief-mean", "dense"),
        }
        self.assertEqual(set(expected), set(iv.GRID_TYPES))
        for cls, (policy, storage) in expected.items():
            g = make(cls)
            self.assertEqual((g.policy, g.storage), (policy, storage))
            self.assertEqual(g.resolution, 0.1)
            self.assertEqual(g.observed_count(), 0)

    def test_presets_carry_their_parameters(self):
        self.assertEqual(iv.BayesGrid.octomap(0.05).params, iv.BayesParams.octomap())
        self.assertEqual(iv.BayesParams.octomap().p_hit, 0.7)
        self.assertTrue(iv.BayesGrid.thesis(0.05).params.latch)
        self.assertEqual(iv.IntervalGrid.thesis(0.05).params, iv.IntervalParams.thesis())
        self.assertAlmostEqual(iv.IntervalParams.thesis().clamp_min, 1 / 510)
        self.assertEqual(iv.DenseBayesGrid.octomap(0.1, BOUNDS).params, iv.BayesParams.octomap())
        self.assertFalse(hasattr(iv.IntervalGrid, "octomap"))

    def test_the_thesis_classification_of_unobserved_space_is_a_parameter_kept_in_files(self):
        p = iv.IntervalParams()
        self.assertFalse(p.classify_unobserved)
        p.classify_unobserved = True
        self.assertIn("classify_unobserved=True", repr(p))
        self.assertNotEqual(p, iv.IntervalParams())
        g = iv.IntervalGrid(0.1, params=p)
        # The mean rule on the initial interval [0.05, 0.95] is 0.5: still unknown.
        self.assertEqual(g.occupancy(np.array([[0.05, 0.05, 0.05]]))[0], int(iv.Occupancy.UNKNOWN))
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "g.ivx")
            g.save(path)
            self.assertTrue(iv.IntervalGrid.load(path).params.classify_unobserved)

    def test_invalid_parameters_raise_value_error_naming_the_rule(self):
        p = iv.BayesParams()
        p.p_hit = 0.4
        with self.assertRaisesRegex(ValueError, r"p_hit must lie in \(0.5, 1\)"):
            iv.BayesGrid(0.1, params=p)
        with self.assertRaisesRegex(ValueError, "p_hit"):
            p.validate()
        q = iv.IntervalParams()
        q.initial_lower = 0.99
        q.initial_upper = 0.5
        with self.assertRaisesRegex(ValueError, "initial interval"):
            iv.IntervalGrid(0.1, params=q)
        with self.assertRaisesRegex(ValueError, "resolution"):
            iv.BayesGrid(0.0)
        with self.assertRaisesRegex(ValueError, "needs bounds"):
            iv.DenseIntervalGrid(0.1)
        with self.assertRaisesRegex(ValueError, "min <= max"):
            iv.DenseBayesGrid(0.1, bounds=((1, 1, 1), (0, 0, 0)))
        with self.assertRaises(TypeError):
            iv.BayesGrid(0.1, params=iv.IntervalParams())

    def test_bounded_grid_has_the_key_box_of_its_bounds(self):
        g = iv.DenseBayesGrid(0.1, bounds=iv.Bounds((0, 0, 0), (1, 1, 0.5)))
        np.testing.assert_array_equal(g.key_box, [[0, 0, 0], [9, 9, 4]])
        self.assertIsNone(iv.BayesGrid(0.1).key_box)
        self.assertEqual(iv.BayesGrid(0.1, origin=(0.5, 0, 0)).origin.tolist(), [0.5, 0, 0])


class Updates(unittest.TestCase):
    def test_update_applies_one_observation_per_point_and_reports_outside_points(self):
        g = iv.DenseBayesGrid(0.1, bounds=BOUNDS)
        done = g.update(np.array([[0.05, 0.05, 0.05], [0.05, 0.05, 0.05], [5.0, 5.0, 5.0]]), iv.Observation.HIT)
        np.testing.assert_array_equal(done, [True, True, False])
        self.assertAlmostEqual(g.probability(np.array([[0.05, 0.05, 0.05]]))[0], 0.9, places=6)
        self.assertEqual(g.observed_count(), 1)
        with self.assertRaisesRegex(ValueError, "NaN"):
            g.update(np.array([[0.5, 0.5, 0.5], [np.nan, 0, 0]]), iv.Observation.MISS)
        self.assertEqual(g.observed_count(), 1)  # nothing applied

    def test_counts_classify_by_the_thresholds(self):
        g = iv.BayesGrid(0.1)
        for _ in range(4):
            g.update(np.array([[0.05, 0.05, 0.05]]), iv.Observation.HIT)
            g.update(np.array([[0.15, 0.05, 0.05]]), iv.Observation.MISS)
        g.update(np.array([[0.25, 0.05, 0.05]]), iv.Observation.HIT)
        c = g.counts()
        self.assertEqual((c.occupied, c.free, c.unknown, c.observed), (1, 1, 1, 3))

    def test_copy_is_independent(self):
        g = iv.IntervalGrid(0.1)
        g.insert_ray((0, 0, 0), (1, 0, 0))
        for h in (g.copy(), copy.copy(g), copy.deepcopy(g)):
            self.assertEqual(h.to_bytes(), g.to_bytes())
            h.clear()
            self.assertEqual(h.observed_count(), 0)
        self.assertGreater(g.observed_count(), 0)

    def test_keys_and_centers_round_trip(self):
        g = iv.BayesGrid(0.2, origin=(0.1, 0, 0))
        pts = np.array([[0.15, 0.0, -0.01], [1.0, 2.0, 3.0]])
        keys = g.keys(pts)
        self.assertEqual(keys.dtype, np.int32)
        np.testing.assert_array_equal(keys, [[0, 0, -1], [4, 10, 15]])
        np.testing.assert_allclose(g.centers(keys), [[0.2, 0.1, -0.1], [1.0, 2.1, 3.1]])
        with self.assertRaisesRegex(IndexError, "key range"):
            g.keys(np.array([[1e12, 0, 0]]))
        with self.assertRaises(ValueError):
            g.keys(np.array([[np.nan, 0, 0]]))


if __name__ == "__main__":
    unittest.main()
