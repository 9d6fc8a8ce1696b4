"""Surfaces that lie, from Python: a planted mirror panel (closed-form phantoms, a numpy ray tracer of
boxes and one mirror rectangle, no simulator) is found in its plane; told to the channel, its
phantoms become suspect, its face explained occupied; the mirrors survive a save; a mirror a user
knows can be told directly; bad input is refused."""

import os
import tempfile
import unittest

import numpy as np

import intervox as iv

# A room 4.5 x 5 x 2.5 m with two boxes, and a free-standing panel in the plane x = 1
# (y in [1.8, 3.2], z in [0, 1.6]), a perfect mirror on its east face (as tests/analysis/
# lying_surfaces_test.cpp).
BOXES = np.array([
    [[-0.1, -0.1, -0.1], [4.6, 5.1, 0.0]],  # floor
    [[-0.1, -0.1, 2.5], [4.6, 5.1, 2.6]],   # ceiling
    [[-0.1, -0.1, 0.0], [0.0, 5.1, 2.5]],   # west wall
    [[4.5, -0.1, 0.0], [4.6, 5.1, 2.5]],    # east wall
    [[-0.1, -0.1, 0.0], [4.6, 0.0, 2.5]],   # south wall
    [[-0.1, 5.0, 0.0], [4.6, 5.1, 2.5]],    # north wall
    [[3.0, 0.5, 0.0], [3.4, 1.5, 1.2]],     # shelf
    [[2.5, 3.5, 0.0], [2.9, 4.5, 0.9]],     # crate
])
PANEL_X, Y0, Y1, Z1 = 1.0, 1.8, 3.2, 1.6
RES, RANGE = 0.05, 6.0
ORIGINS = [(3.5, 2.5, 0.5), (4.0, 1.5, 0.5), (4.0, 3.8, 0.5), (2.2, 2.5, 0.5),
           (4.2, 2.5, 0.8), (2.0, 1.0, 0.5), (2.0, 4.2, 0.5), (1.6, 0.6, 0.5)]


def first_box(o, d):
    """Distance to the first box face along o + t d (rows), inf where none."""
    best = np.full(len(d), np.inf)
    with np.errstate(divide="ignore", invalid="ignore"):
        for lo, hi in BOXES:
            ta, tb = (lo - o) / d, (hi - o) / d
            t0 = np.max(np.minimum(ta, tb), axis=1)
            t1 = np.min(np.maximum(ta, tb), axis=1)
            ok = (t0 <= t1) & (t0 > 1e-9)
            best = np.where(ok & (t0 < best), t0, best)
    return best


def scans():
    """One scan per origin (azimuth every degree, elevation -30..30 every degree): origins, ends,
    hits and which beams are the mirror's phantoms (reported at the folded range along the beam)."""
    az, el = np.meshgrid(np.radians(np.arange(360)), np.radians(np.arange(-30, 31)), indexing="ij")
    d = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], axis=-1).reshape(-1, 3)
    d = np.where(np.abs(d) < 1e-12, 0.0, d)
    out = []
    for origin in ORIGINS:
        o = np.broadcast_to(np.asarray(origin, float), d.shape)
        t = first_box(o, d)
        with np.errstate(divide="ignore", invalid="ignore"):
            tm = (PANEL_X - o[:, 0]) / d[:, 0]
            p = o + tm[:, None] * d
        at_mirror = (d[:, 0] < -1e-12) & (tm > 1e-9) & (tm < t) & (p[:, 1] >= Y0) & (p[:, 1] <= Y1) & \
            (p[:, 2] >= 0.0) & (p[:, 2] <= Z1)
        r = d * np.array([-1.0, 1.0, 1.0])
        t = np.where(at_mirror, tm + first_box(np.where(at_mirror[:, None], p, o), r), t)
        hits = t <= RANGE
        ends = o + d * np.where(hits, t, RANGE)[:, None]
        out.append((np.asarray(origin, float), ends, hits, at_mirror & hits))
    return out


class LyingSurfacesFromPython(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.scans = scans()

    def survey(self):
        grid = iv.BayesGrid(RES)
        space = iv.ExplainedSpace(RES)
        classes = []
        for o, ends, hits, _ in self.scans:
            classes.append(space.insert_beams(grid, o, ends, hits, max_range=RANGE)[1])
        space.revise()
        return grid, space

    def phantoms_suspect(self, space, behind=0.0):
        """The share of the phantoms classed suspect now (classify: the channel as it stands), of those
        that end more than `behind` metres along the beam behind the panel's plane."""
        n = suspect = 0
        for o, ends, hits, phantom in self.scans:
            e = ends[phantom]
            past = (PANEL_X - e[:, 0]) / np.abs((e - o)[:, 0]) * np.linalg.norm(e - o, axis=1)
            c = space.classify(o, e[past > behind], max_range=RANGE)
            n += c.size
            suspect += int(np.count_nonzero(c == int(iv.BeamClass.SUSPECT)))
        return suspect / n

    def test_a_planted_mirror_is_found_in_its_plane_and_its_phantoms_become_suspect(self):
        grid, space = self.survey()
        found = iv.find_lying_surfaces(space)
        self.assertTrue(all(s.voxels >= 27 for s in found))
        mirrors = [s for s in found if s.kind == iv.LyingKind.MIRROR]
        self.assertGreaterEqual(len(mirrors), 1, found)
        for s in mirrors:
            p = s.surface
            self.assertIsNotNone(p)
            self.assertGreaterEqual(p.normal[0], np.cos(np.radians(3.0)))
            self.assertLessEqual(abs(p.center[0] - PANEL_X), RES)
            self.assertTrue(Y0 - RES <= p.center[1] <= Y1 + RES)
            self.assertGreaterEqual(s.mirror_votes, 60)
            # Opaque where its votes cross it: at most 1 in 5 reflected ends in free space.
            self.assertGreater(s.consistent_ends, 0)
            self.assertLessEqual(s.inconsistent_ends, 0.2 * (s.consistent_ends + s.inconsistent_ends))
            self.assertEqual(np.asarray(s.extent).shape, (2, 3))
        self.assertEqual(space.mirrors, [])
        before = self.phantoms_suspect(space)
        self.assertEqual(iv.resolve_mirrors(space, found), len(mirrors))
        self.assertEqual(len(space.mirrors), 1)  # the panel's pieces in one plane: one mirror
        after = self.phantoms_suspect(space)
        self.assertGreaterEqual(after, before + 0.2, (before, after))
        face = np.array([[PANEL_X, 2.5, 0.5]])
        self.assertTrue(space.on_mirror(face)[0])
        self.assertEqual(space.state(face)[0], int(iv.ExplainedState.OCCUPIED))
        self.assertFalse(space.on_mirror(np.array([[3.0, 2.5, 0.5]]))[0])
        # The mirrors are saved with the evidence.
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "room.ivxe")
            space.save(path)
            back = iv.ExplainedSpace.load(path)
        self.assertEqual(len(back.mirrors), 1)
        np.testing.assert_array_equal(back.mirrors[0].center, space.mirrors[0].center)
        self.assertEqual(back.state(face)[0], int(iv.ExplainedState.OCCUPIED))
        o, ends, hits, phantom = self.scans[0]
        np.testing.assert_array_equal(back.classify(o, ends, hits, max_range=RANGE),
                                      space.classify(o, ends, hits, max_range=RANGE))

    def test_a_mirror_the_user_knows_is_told_directly(self):
        grid, space = self.survey()
        before = self.phantoms_suspect(space)
        panel = iv.PlanePatch((PANEL_X, 2.5, 0.8), (1.0, 0.0, 0.0), 0.75, 0.85)  # the panel and 5 cm around
        np.testing.assert_allclose(panel.axis_u, (0.0, -1.0, 0.0))  # horizontal: normal x z
        np.testing.assert_allclose(panel.axis_v, (0.0, 0.0, -1.0))  # normal x axis_u
        space.add_mirror(panel)
        # The whole panel: every phantom that crosses it more than crossing_tolerance (0.15 m) before
        # its end is suspect; those that end on the floor right behind it are not.
        self.assertEqual(self.phantoms_suspect(space, behind=0.15 + RES), 1.0)
        self.assertGreaterEqual(self.phantoms_suspect(space), 0.9)
        self.assertLess(before, 0.6)
        self.assertIn("PlanePatch(center=(1.000, 2.500, 0.800)", repr(space.mirrors[0]))

    def test_bad_input_is_refused_with_a_reason(self):
        with self.assertRaisesRegex(ValueError, "unit vector"):
            iv.PlanePatch((0, 0, 0), (2.0, 0, 0), 0.5, 0.5)
        with self.assertRaisesRegex(ValueError, "orthogonal"):
            iv.PlanePatch((0, 0, 0), (1.0, 0, 0), 0.5, 0.5, axis_u=(1.0, 0, 0))
        with self.assertRaisesRegex(ValueError, "half_u"):
            iv.PlanePatch((0, 0, 0), (1.0, 0, 0), -0.5, 0.5)
        with self.assertRaisesRegex(ValueError, "finite"):
            iv.PlanePatch((np.nan, 0, 0), (1.0, 0, 0), 0.5, 0.5)
        space = iv.ExplainedSpace(RES)
        with self.assertRaisesRegex(ValueError, "normal_step_deg"):
            iv.find_lying_surfaces(space, normal_step_deg=0.0)
        with self.assertRaisesRegex(ValueError, "min_region_voxels"):
            iv.find_lying_surfaces(space, min_region_voxels=0)
        with self.assertRaisesRegex(ValueError, "max_inconsistent_share"):
            iv.find_lying_surfaces(space, max_inconsistent_share=1.5)
        self.assertEqual(iv.find_lying_surfaces(space), [])  # nothing inserted: no region
        self.assertEqual(iv.resolve_mirrors(space, []), 0)
        with self.assertRaisesRegex(ValueError, "NaN"):
            space.on_mirror(np.array([[np.nan, 0, 0]]))


if __name__ == "__main__":
    unittest.main()
