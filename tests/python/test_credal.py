"""Credal grids: imprecise Dirichlet counts and Dempster–Shafer belief, against their closed forms."""

import math
import unittest

import numpy as np

import intervox as iv

P = np.array([[0.05, 0.05, 0.05]])  # one voxel
HIT, MISS = iv.Observation.HIT, iv.Observation.MISS


def observe(g, hits, misses):
    for _ in range(hits):
        g.update(P, HIT)
    for _ in range(misses):
        g.update(P, MISS)


def h2(p):
    return 0.0 if p in (0.0, 1.0) else -(p * math.log2(p) + (1 - p) * math.log2(1 - p))


class Dirichlet(unittest.TestCase):
    def test_interval_is_h_over_n_plus_s_to_h_plus_s_over_n_plus_s(self):
        for s in (2.0, 0.5, 7.0):
            for h, m in ((0, 0), (1, 0), (0, 3), (5, 2), (40, 40)):
                for cls in (iv.DirichletGrid, iv.DenseDirichletGrid):
                    g = cls(0.1, bounds=((0, 0, 0), (1, 1, 1)), params=iv.DirichletParams(prior_strength=s))
                    observe(g, h, m)
                    n = h + m
                    np.testing.assert_allclose(g.interval(P)[0], [h / (n + s), (h + s) / (n + s)], rtol=1e-12)
                    np.testing.assert_array_equal(g.evidence(P)[0], [h, m])
                    # mean rule: the state is the midpoint (h + s/2) / (N + s)
                    self.assertAlmostEqual(g.probability(P)[0], (h + s / 2) / (n + s), places=12)

    def test_five_consistent_observations_decide_a_voxel_with_the_defaults(self):
        g = iv.DirichletGrid(0.1)
        observe(g, 4, 0)
        self.assertEqual(g.occupancy(P)[0], int(iv.Occupancy.UNKNOWN))  # 5/6 < 0.85
        observe(g, 1, 0)
        self.assertEqual(g.occupancy(P)[0], int(iv.Occupancy.OCCUPIED))  # 6/7
        f = iv.DirichletGrid(0.1)
        observe(f, 0, 5)
        self.assertEqual(f.occupancy(P)[0], int(iv.Occupancy.FREE))  # 1/7

    def test_a_full_counter_saturates_or_halves_both_counts(self):
        sat = iv.DirichletGrid(0.1, params=iv.DirichletParams(max_count=4))
        observe(sat, 7, 1)
        np.testing.assert_array_equal(sat.evidence(P)[0], [4, 1])
        halve = iv.DirichletGrid(0.1, params=iv.DirichletParams(max_count=4, forgetting=iv.DirichletForgetting.HALVE_AT_MAX))
        observe(halve, 5, 0)  # 4 hits, then halved to 2 and counted: 3
        np.testing.assert_array_equal(halve.evidence(P)[0], [3, 0])

    def test_total_uncertainty_is_max_entropy_plus_width(self):
        g = iv.DirichletGrid(0.1)
        self.assertEqual(iv.DirichletGrid.utility_name, "total-uncertainty")
        self.assertAlmostEqual(g.utility(P)[0], 2.0)  # vacuous [0, 1]
        observe(g, 1, 1)  # [0.25, 0.75]: contains 0.5
        self.assertAlmostEqual(g.utility(P)[0], 1.0 + 0.5)
        observe(g, 6, 0)  # h 7, m 1: [0.7, 0.9]
        self.assertAlmostEqual(g.utility(P)[0], h2(0.7) + 0.2)

    def test_parameters_are_checked_and_kept(self):
        with self.assertRaisesRegex(ValueError, "prior_strength"):
            iv.DirichletGrid(0.1, params=iv.DirichletParams(prior_strength=0.0))
        with self.assertRaisesRegex(ValueError, "max_count"):
            iv.DirichletParams(max_count=1).validate()
        with self.assertRaisesRegex(TypeError, "DirichletParams"):
            iv.DirichletGrid(0.1, params=iv.BeliefParams())
        p = iv.DirichletParams(prior_strength=3.0, forgetting=iv.DirichletForgetting.HALVE_AT_MAX, max_count=100)
        self.assertEqual(iv.DirichletGrid(0.1, params=p).params, p)
        self.assertIn("HALVE_AT_MAX", repr(p))
        self.assertFalse(hasattr(iv.DirichletGrid, "thesis"))


class Belief(unittest.TestCase):
    def test_a_hit_then_a_miss_combine_as_worked_by_hand(self):
        for rule in (iv.BeliefCombination.DEMPSTER, iv.BeliefCombination.CONJUNCTIVE):
            for cls in (iv.BeliefGrid, iv.DenseBeliefGrid):
                g = cls(0.1, bounds=((0, 0, 0), (1, 1, 1)), params=iv.BeliefParams(discount=0.0, combination=rule))
                np.testing.assert_allclose(g.masses(P)[0], [0, 0, 1])
                observe(g, 1, 0)  # m(occ) = 0.6, m(Θ) = 0.4
                np.testing.assert_allclose(g.masses(P)[0], [0.6, 0.0, 0.4], rtol=1e-6, atol=1e-7)
                observe(g, 0, 1)  # K = 0.6 * 0.4 = 0.24
                k = 0.24
                np.testing.assert_allclose(g.masses(P)[0], [0.36 / (1 - k), 0.16 / (1 - k), 0.24 / (1 - k)], rtol=1e-6)
                np.testing.assert_allclose(g.interval(P)[0], [0.36 / 0.76, 1 - 0.16 / 0.76], rtol=1e-6)
                conjunctive = rule == iv.BeliefCombination.CONJUNCTIVE
                self.assertAlmostEqual(g.conflict(P)[0], k if conjunctive else 0.0, places=6)

    def test_conflict_accumulates_as_one_minus_the_product_of_one_minus_k(self):
        g = iv.BeliefGrid(0.1, params=iv.BeliefParams(discount=0.0, combination=iv.BeliefCombination.CONJUNCTIVE))
        o = f = 0.0
        acc = 0.0
        for obs in (HIT, MISS, HIT, MISS, MISS):
            hit = obs == HIT
            o2, f2 = (0.6, 0.0) if hit else (0.0, 0.4)
            t, t2 = 1 - o - f, 1 - o2 - f2
            k = o * f2 + f * o2
            o, f = (o * o2 + o * t2 + t * o2) / (1 - k), (f * f2 + f * t2 + t * f2) / (1 - k)
            acc = acc + (1 - acc) * k
            g.update(P, obs)
        np.testing.assert_allclose(g.masses(P)[0], [o, f, 1 - o - f], rtol=1e-5)
        self.assertAlmostEqual(g.conflict(P)[0], acc, places=6)

    def test_discount_keeps_ignorance_of_at_least_alpha(self):
        g = iv.BeliefGrid(0.1, params=iv.BeliefParams(discount=0.01))
        observe(g, 200, 0)
        m = g.masses(P)[0]
        self.assertGreaterEqual(m[2], 0.01 - 1e-6)
        self.assertAlmostEqual(m.sum(), 1.0, places=6)
        self.assertEqual(g.occupancy(P)[0], int(iv.Occupancy.OCCUPIED))

    def test_parameters_are_checked_and_kept(self):
        with self.assertRaisesRegex(ValueError, "hit_support"):
            iv.BeliefGrid(0.1, params=iv.BeliefParams(hit_support=1.0))
        with self.assertRaisesRegex(ValueError, "discount"):
            iv.BeliefParams(discount=0.5).validate()
        p = iv.BeliefParams(hit_support=0.7, combination=iv.BeliefCombination.CONJUNCTIVE)
        self.assertEqual(iv.BeliefGrid(0.1, params=p).params, p)
        self.assertIn("CONJUNCTIVE", repr(p))


class Insertion(unittest.TestCase):
    def test_a_ray_counts_misses_along_it_and_a_hit_at_its_end(self):
        g = iv.DirichletGrid(0.1)
        g.insert_ray((0.05, 0.05, 0.05), (0.55, 0.05, 0.05))
        ev = g.evidence(np.array([[0.05 + 0.1 * i, 0.05, 0.05] for i in range(6)]))
        np.testing.assert_array_equal(ev, [[0, 1]] * 5 + [[1, 0]])
        b = iv.BeliefGrid(0.1, params=iv.BeliefParams(discount=0.0))
        b.insert_point_cloud(np.array([[0.55, 0.05, 0.05]]), (0.05, 0.05, 0.05))
        np.testing.assert_allclose(b.masses(np.array([[0.55, 0.05, 0.05], [0.25, 0.05, 0.05]])),
                                   [[0.6, 0, 0.4], [0, 0.4, 0.6]], rtol=1e-6, atol=1e-7)

    def test_nan_points_raise_value_error(self):
        with self.assertRaisesRegex(ValueError, "point 0 has a NaN"):
            iv.DirichletGrid(0.1).evidence(np.array([[np.nan, 0, 0]]))
        with self.assertRaisesRegex(ValueError, "point 0 has a NaN"):
            iv.BeliefGrid(0.1).conflict(np.array([[np.nan, 0, 0]]))


class Planning(unittest.TestCase):
    def test_episode_insertion_on_credal_grids_equals_direct_insertion(self):
        lab = iv.make_lab_room()
        rig = iv.SensorRig.mobile_base()
        body = np.eye(4)
        body[:3, 3] = lab.start
        params = iv.MobilePlannerParams()
        params.max_steps = 1
        params.threads = 1
        params.region = ((0, 0, 0.2), (8, 6, 0.8))
        for cls in (iv.DirichletGrid, iv.BeliefGrid):
            planner = iv.MobilePlanner(rig, params)
            g = cls(0.1)
            self.assertEqual(planner.plan(g, body).reason, iv.ViewReason.INITIAL)
            ep = iv.Episode(g, planner, iv.SimulatedRig(lab.scene, rig, seed=4), body)
            ep.sense(body[None])
            ref = cls(0.1)
            o, e, h = iv.SimulatedRig(lab.scene, rig, seed=4)(body)
            ref.insert_beams(o, e, h, max_range=planner.max_range)
            self.assertGreater(ref.observed_count(), 1000)
            self.assertEqual(g.to_bytes(), ref.to_bytes())


if __name__ == "__main__":
    unittest.main()
