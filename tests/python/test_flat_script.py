"""scripts/explained_planning_flat.py's measures, against closed forms on the flat's own boxes:
the reachable floor of each room and the share of it a grid knows free."""

import math
import unittest

import numpy as np

import intervox as iv
from helpers import load_script


class FlatScript(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.flat = load_script("explained_planning_flat.py")
        cls.scene, cls.obstacles = cls.flat.flat(mirror=True)
        cls.floor = cls.flat.reachable_floor(cls.obstacles, 0.1)

    def test_the_reachable_floor_keeps_the_robot_radius_from_every_obstacle_and_reaches_both_rooms(self):
        f = self.flat
        self.assertGreater(len(self.floor), 100)
        for x, y in self.floor:
            self.assertIsNone(f.collision(x, y, self.obstacles))
        # Closed forms of the flat's boxes: the start's cell is reachable, both rooms hold reachable
        # cells, and the 0.9 m doorway leaves a 0.18 m strip for the 0.72 m disc: the cells at y 1.95.
        cells = {(round(x, 2), round(y, 2)) for x, y in self.floor}
        self.assertIn((0.85, 1.85), cells)
        room2 = [c for c in cells if c[0] > f.PARTITION_X]
        self.assertGreater(len(room2), 100)
        doorway = sorted(c[1] for c in cells if 5.0 < c[0] < 5.1)
        self.assertEqual(doorway, [1.95])
        # The wardrobe's front face (y 3.4) keeps every reachable centre below it beyond the radius.
        near = [c for c in cells if 1.0 <= c[0] <= 2.5]
        self.assertLessEqual(max(c[1] for c in near), 3.4 - f.ROBOT_RADIUS)

    def test_the_floor_known_is_the_share_of_cells_whose_band_the_grid_knows_free(self):
        f = self.flat
        grid = iv.BayesGrid(0.1)
        cells = self.floor[:40]
        self.assertEqual(f.floor_known(grid, cells, 0.1), 0.0)  # nothing observed
        # Beams without a return down each cell's column from 1.5 m to -0.5 m: three misses make a
        # Bayes voxel free. Cell 0's beams end at 0.5 m: the lower half of its band stays unknown.
        def down(column_cells, bottom):
            origins = np.array([(x, y, 1.5) for x, y in column_cells])
            ends = np.array([(x, y, bottom) for x, y in column_cells])
            for _ in range(3):
                grid.insert_beams(origins, ends, np.zeros(len(origins), dtype=bool), max_range=1.5 - bottom)

        down(cells[1:20], -0.5)
        down(cells[:1], 0.5)
        self.assertTrue(math.isclose(f.floor_known(grid, cells, 0.1), 19 / 40))
        down(cells[:1], -0.5)
        self.assertTrue(math.isclose(f.floor_known(grid, cells, 0.1), 20 / 40))
        self.assertEqual(f.floor_known(grid, np.zeros((0, 2)), 0.1), 1.0)

    def test_the_known_surfaces_lie_on_the_flats_walls_and_mirror_and_leave_the_doorway_open(self):
        f = self.flat
        walls = f.known_surfaces(["walls"])
        self.assertEqual(len(walls), 10)
        # Oracle: the flat's scene. Points on each patch (a 5 x 5 lattice pulled 1 cm inside its
        # edges), 5 cm along the normal to one side, lie inside a solid (the wall); on the other
        # side, inside the flat's rooms (where furniture may stand against the wall).
        for w in walls:
            u = np.asarray(w.axis_u)
            v = np.cross(np.asarray(w.normal), u)
            n = np.asarray(w.normal)
            for a in np.linspace(-1, 1, 5):
                for b in np.linspace(-1, 1, 5):
                    p = np.asarray(w.center) + u * (w.half_u - 0.01) * a + v * (w.half_v - 0.01) * b
                    (x0, y0), (x1, y1) = f.INTERIOR
                    in_rooms = [x0 < q[0] < x1 and y0 < q[1] < y1 and not 5.0 <= q[0] <= 5.1
                                for q in (p + 0.05 * n, p - 0.05 * n)]
                    in_wall = [bool(self.scene.inside(q)) for q in (p + 0.05 * n, p - 0.05 * n)]
                    self.assertEqual(sorted(in_rooms), [False, True], (tuple(w.center), tuple(p)))
                    self.assertTrue(in_wall[in_rooms.index(False)], (tuple(w.center), tuple(p)))
        doorway = (5.05, 1.95, 1.0)
        for w in walls:
            d = np.asarray(doorway) - np.asarray(w.center)
            inside_rect = (abs(d @ np.asarray(w.axis_u)) <= w.half_u and
                           abs(d @ np.cross(np.asarray(w.normal), np.asarray(w.axis_u))) <= w.half_v)
            self.assertFalse(inside_rect and abs(d @ np.asarray(w.normal)) <= 0.06)
        (front,) = f.known_surfaces(["wardrobe"])
        self.assertAlmostEqual(front.center[1], 3.399)
        self.assertAlmostEqual(front.half_u, 0.7)
        self.assertAlmostEqual(front.half_v, 0.95)
        self.assertEqual(len(f.known_surfaces(["walls", "wardrobe"])), 11)
        self.assertEqual(f.known_surfaces([]), [])


if __name__ == "__main__":
    unittest.main()
