"""The committed type stubs match the module, and help() documents it."""

import os
import pydoc
import subprocess
import sys
import tempfile
import unittest

import intervox as iv

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


class Stubs(unittest.TestCase):
    def test_committed_stubs_equal_the_ones_generated_from_the_module(self):
        with tempfile.TemporaryDirectory() as d:
            out = os.path.join(d, "stubs.pyi")
            subprocess.run([sys.executable, os.path.join(ROOT, "python", "gen_stubs.py"), out], check=True)
            with open(out) as f:
                generated = f.read()
        with open(os.path.join(ROOT, "python", "intervox", "_intervox.pyi")) as f:
            committed = f.read()
        self.assertEqual(committed, generated,
                         "python/intervox/_intervox.pyi is stale: run python/gen_stubs.py (see its docstring)")

    def test_help_shows_signatures_and_documentation(self):
        text = pydoc.render_doc(iv.IntervalGrid, renderer=pydoc.plaintext)
        self.assertIn("insert_depth_image(self: intervox._intervox.IntervalGrid, depth: object", text)
        self.assertIn("GIL is released", text)
        for name in dir(iv):
            obj = getattr(iv, name)
            if not name.startswith("_") and callable(obj):
                self.assertTrue(obj.__doc__, name + " has no docstring")


if __name__ == "__main__":
    unittest.main()
