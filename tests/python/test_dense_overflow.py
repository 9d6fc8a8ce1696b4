"""A dense grid whose bounds make a box too large to count (its volume overflows 64 bits) raises
a Python exception instead of crashing the interpreter (issue 30, item 1)."""

import resource
import subprocess
import sys
import textwrap
import unittest


class HugeDenseGrid(unittest.TestCase):
    def test_a_dense_grid_whose_volume_overflows_raises_instead_of_crashing(self):
        # 2^22 voxels per axis: 2^66 cells, which used to wrap to a small size (then writes past
        # the array). Needs the checked volume of core/key.hpp (branch rel-io).
        script = textwrap.dedent("""
            import intervox as iv
            try:
                iv.DenseBayesGrid(1 / 1024, bounds=((0, 0, 0), (4096, 4096, 4096)))
            except Exception as e:
                print("raised", type(e).__name__, e)
            else:
                print("constructed")
        """)

        def limit():
            resource.setrlimit(resource.RLIMIT_AS, (4_000_000 * 1024, 4_000_000 * 1024))

        r = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=60,
                           preexec_fn=limit)
        self.assertEqual(r.returncode, 0, "crashed: " + r.stderr[-2000:])
        self.assertIn("raised", r.stdout)



if __name__ == "__main__":
    unittest.main()
