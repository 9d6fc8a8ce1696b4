"""A path with a NUL byte names another file to the operating system ('a\\0b.ivx' is 'a'): every
binding that takes a path refuses it with ValueError, and no file is written."""

import os
import tempfile
import unittest

import numpy as np

import intervox as iv

BAD = "a\x00b.ivx"


class NulInPathsIsRefused(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        self.cwd = os.getcwd()
        os.chdir(self.dir.name)
        self.g = iv.BayesGrid(0.1)
        self.g.insert_point_cloud(np.array([[0.5, 0.2, 0.1]]), (0, 0, 0))
        self.g.save("a")  # the file a NUL path would name
        self.before = open("a", "rb").read()

    def tearDown(self):
        os.chdir(self.cwd)
        self.dir.cleanup()

    def refused(self, call):
        with self.assertRaises(ValueError) as ctx:
            call()
        self.assertIn("NUL", str(ctx.exception))
        self.assertIn("a\\0b.ivx", str(ctx.exception))  # the path, with the NUL shown as \0

    def test_every_path_binding_refuses_a_nul_byte(self):
        img = np.zeros((2, 2, 3), dtype=np.uint8)
        calls = [
            lambda: self.g.save(BAD),
            lambda: self.g.write_bt(BAD),
            lambda: self.g.write_ply(BAD),
            lambda: iv.IntervalGrid(0.1).save(BAD),
            lambda: iv.BayesGrid.load(BAD),
            lambda: iv.DenseBayesGrid.load(BAD),
            lambda: iv.BayesGrid.read_bt(BAD),
            lambda: iv.read_grid_file_info(BAD),
            lambda: iv.read_point_cloud(BAD),
        ]
        if iv.HAS_PNG:
            calls += [lambda: iv.write_png(BAD, img), lambda: iv.read_png(BAD)]
        for call in calls:
            self.refused(call)
        self.assertEqual(sorted(os.listdir(".")), ["a"])
        self.assertEqual(open("a", "rb").read(), self.before)


if __name__ == "__main__":
    unittest.main()
