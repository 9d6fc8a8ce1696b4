"""Files: grid files, OctoMap .bt, PLY, slices and PNG."""

import os
import tempfile
import unittest

import numpy as np

import intervox as iv
from helpers import random_cloud


def filled(cls):
    g = cls(0.1, bounds=((-2, -2, -2), (2, 2, 2)))
    pts = random_cloud(1, n=400, spread=1.8)
    for _ in range(8):  # enough hits for the interval grids to call voxels occupied
        g.insert_point_cloud(pts, (0, 0, 0))
    return g


class GridFiles(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        self.addCleanup(self.dir.cleanup)

    def path(self, name):
        return os.path.join(self.dir.name, name)

    def test_save_and_load_round_trip_every_grid_type(self):
        for cls in iv.GRID_TYPES:
            g = filled(cls)
            for version in (1, 2):
                g.save(self.path("g.ivx"), version=version)
                h = cls.load(self.path("g.ivx"))
                a, b = g.observed_voxels(), h.observed_voxels()
                ia, ib = np.lexsort(a["keys"].T), np.lexsort(b["keys"].T)  # block order may differ
                np.testing.assert_array_equal(a["keys"][ia], b["keys"][ib])
                np.testing.assert_array_equal(a["interval"][ia], b["interval"][ib])
                self.assertEqual(h.params, g.params)
            info = iv.read_grid_file_info(self.path("g.ivx"))
            self.assertEqual((info["update_policy"], info["storage"]), (cls.policy, cls.storage))
            self.assertEqual(info["voxel_count"], g.observed_count())
            self.assertEqual(cls.from_bytes(g.to_bytes()).to_bytes(), g.to_bytes())

    def test_loading_errors_raise_io_error_an_os_error_with_the_message(self):
        self.assertTrue(issubclass(iv.IoError, OSError))
        with self.assertRaisesRegex(iv.IoError, "no_such_file"):
            iv.BayesGrid.load(self.path("no_such_file.ivx"))
        filled(iv.IntervalGrid).save(self.path("i.ivx"))
        with self.assertRaisesRegex(OSError, "policy 'interval-mean'.*'bayes'"):
            iv.BayesGrid.load(self.path("i.ivx"))
        data = bytearray(filled(iv.BayesGrid).to_bytes())
        data[len(data) // 2] ^= 0xFF
        with self.assertRaises(iv.IoError):
            iv.BayesGrid.from_bytes(bytes(data))
        with self.assertRaisesRegex(iv.IoError, "max_bytes|budget"):
            iv.BayesGrid.from_bytes(filled(iv.BayesGrid).to_bytes(), max_bytes=1000)


class Exports(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        self.addCleanup(self.dir.cleanup)

    def path(self, name):
        return os.path.join(self.dir.name, name)

    def test_bt_round_trip_keeps_the_occupied_and_free_voxels(self):
        g = filled(iv.BayesGrid)
        g.write_bt(self.path("m.bt"))
        for cls in (iv.BayesGrid, iv.DenseBayesGrid):
            h = cls.read_bt(self.path("m.bt"))
            v = g.observed_voxels()
            np.testing.assert_array_equal(h.is_observed(v["centers"]), True)
            np.testing.assert_array_equal(h.probability(v["centers"]) >= 0.5, v["probability"] >= 0.5)
        with self.assertRaises(iv.IoError):
            iv.BayesGrid.read_bt(self.path("missing.bt"))
        self.assertFalse(hasattr(iv.IntervalGrid, "read_bt"))

    def test_bt_export_of_a_map_beyond_octomaps_keys_leaves_those_voxels_out_and_counts_them(self):
        g = iv.BayesGrid(0.05)
        g.insert_point_cloud(np.array([[1.0, 0.0, 0.0], [2000.0, 0.0, 0.0]]), np.zeros(3))  # 2 km at 5 cm
        self.assertGreater(g.observed_count(), 32768)
        left_out = g.write_bt(self.path("far.bt"))
        self.assertGreater(left_out, 0)
        self.assertEqual(iv.BayesGrid.read_bt(self.path("far.bt")).observed_count(), g.observed_count() - left_out)
        self.assertEqual(filled(iv.BayesGrid).write_bt(self.path("near.bt")), 0)

    def test_the_html_view_page_holds_the_selected_voxels_and_refuses_bad_options(self):
        g = filled(iv.IntervalGrid)
        occupied = int((g.observed_voxels()["occupancy"] == 2).sum())
        s = g.write_html_view(self.path("map.html"), voxels="occupied", show=["occupied"], title="kitchen <1>",
                              trajectory=[np.eye(4), np.eye(4)], scans=[np.eye(4)])
        self.assertEqual(s["selected"], occupied)
        self.assertEqual(s["drawn"], occupied)
        self.assertEqual((s["level"], s["surface_only"]), (0, False))
        with open(self.path("map.html"), encoding="utf-8") as f:
            page = f.read()
        self.assertEqual(len(page.encode("utf-8")), s["bytes"])
        self.assertIn("kitchen &lt;1&gt;", page)  # the title, escaped
        small = g.write_html_view(self.path("small.html"), voxels="observed", max_voxels=50)
        self.assertLessEqual(small["drawn"], 50)
        self.assertGreater(small["level"] + small["surface_only"], 0)
        with self.assertRaisesRegex(iv.IoError, "three"):
            g.write_html_view(self.path("x.html"), three_dir=self.path("no_three_here"))
        for bad in ({"voxels": "walls"}, {"show": ["walls"]}, {"max_voxels": 0}):
            with self.assertRaises(ValueError):
                g.write_html_view(self.path("x.html"), **bad)
        self.assertFalse(os.path.exists(self.path("x.html")))

    def test_ply_export_has_one_vertex_per_occupied_voxel(self):
        g = filled(iv.IntervalGrid)
        occupied = int(g.counts().occupied)
        self.assertGreater(occupied, 0)
        g.write_ply(self.path("m.ply"), binary=False)
        with open(self.path("m.ply"), "rb") as f:
            header = f.read(400).decode("ascii", "replace")
        self.assertIn("element vertex %d\n" % occupied, header)
        g.write_ply(self.path("c.ply"), geometry="cubes", voxels="observed", color=iv.ColorBy.INTERVAL_WIDTH)
        with open(self.path("c.ply"), "rb") as f:
            header = f.read(400).decode("ascii", "replace")
        self.assertIn("element vertex %d\n" % (8 * g.observed_count()), header)
        with self.assertRaisesRegex(ValueError, "geometry"):
            g.write_ply(self.path("x.ply"), geometry="spheres")

    def test_slice_is_an_rgb_array_with_the_voxel_colours(self):
        g = iv.DenseBayesGrid(0.1, bounds=((0, 0, 0), (1, 0.5, 0.1)))
        g.update(np.array([[0.05, 0.05, 0.05]] * 10), iv.Observation.HIT)   # occupied: black
        g.update(np.array([[0.95, 0.45, 0.05]] * 10), iv.Observation.MISS)  # free: white
        img = g.render_slice(pixels_per_voxel=2)
        self.assertEqual((img.shape, img.dtype), ((10, 20, 3), np.uint8))
        self.assertTrue(np.all(img[8:, :2] <= 3))     # bottom-left voxel (x = 0, y = 0): state 0.99, black
        self.assertTrue(np.all(img[:2, 18:] >= 252))  # top-right voxel: state 0.01, white
        np.testing.assert_array_equal(img[0, 0], [0, 150, 150])  # unobserved teal
        with self.assertRaisesRegex(ValueError, "pixels_per_voxel"):
            g.render_slice(pixels_per_voxel=0)

    @unittest.skipUnless(iv.HAS_PNG, "built without libpng")
    def test_png_round_trip(self):
        img = filled(iv.IntervalGrid).render_slice(color=iv.ColorBy.INTERVAL_WIDTH, mode=iv.SliceMode.MAX_PROJECTION)
        iv.write_png(self.path("s.png"), img)
        np.testing.assert_array_equal(iv.read_png(self.path("s.png")), img)
        with self.assertRaisesRegex(ValueError, "uint8"):
            iv.write_png(self.path("t.png"), img.astype(np.float64))
        with self.assertRaises(OSError):
            iv.write_png(os.path.join(self.path("no_dir"), "x.png"), img)


if __name__ == "__main__":
    unittest.main()
