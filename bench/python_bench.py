"""Python binding overhead: one 640 x 480 depth frame inserted from Python against the same insertion
in C++ (exact, and projective with a reused ProjectiveInserter: frames per second of a stream), and
10^6 vectorised probability queries against a C++ loop.

    PYTHONPATH=build/python python3 bench/python_bench.py build/python/intervox_python_oracle

The two sides alternate in rounds so that load from other processes affects both alike. Prints the median seconds of each side and their ratio (docs/performance.md records a run).
"""

import math
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

import intervox as iv


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: python_bench.py <path of intervox_python_oracle>")
    oracle = sys.argv[1]
    rounds = 7
    lab = iv.make_lab_room()
    cam = iv.DepthCamera.make(640, 480, math.radians(58), math.radians(45), 0.1, 4.0)
    pose = iv.look_at(lab.start + [0, 0, 0.6], (1.0, 4.0, 0.8))
    frame = iv.simulate(cam, lab.scene, pose, seed=1, threads=0)
    depth, k = frame.depth, frame.intrinsics

    with tempfile.TemporaryDirectory() as d:
        raw = os.path.join(d, "depth.f32")
        np.ascontiguousarray(depth, dtype="<f4").tofile(raw)
        args = [oracle, "time-depth", "bayes", "0.02", raw, str(k.width), str(k.height), repr(k.fx), repr(k.fy),
                repr(k.cx), repr(k.cy)] + [repr(float(v)) for v in frame.pose.ravel()]
        args += [repr(frame.max_range), "3"]
        # Rounds alternate the two sides so that load from other processes hits both alike; each side
        # inserts 3 times into fresh grids per round (median; the process's heap is warm after the first).
        py_times, cpp_times = [], []
        for _ in range(rounds):
            t = []
            for _ in range(3):
                g = iv.BayesGrid(0.02)
                t0 = time.perf_counter()
                g.insert_depth_image(depth, k, frame.pose, max_range=frame.max_range)
                t.append(time.perf_counter() - t0)
            py_times.append(statistics.median(t))
            cpp_times.append(float(subprocess.run(args, check=True, capture_output=True, text=True).stdout.split()[0]))
        py_insert, cpp_insert = statistics.median(py_times), statistics.median(cpp_times)

        # The same frame by projection, as a depth stream would insert it: one ProjectiveInserter kept
        # across frames (its scratch warm), a fresh grid each time.
        pargs = list(args)
        pargs[1] = "time-projective"
        ins = iv.ProjectiveInserter(max_range=frame.max_range)
        pj_py, pj_cpp = [], []
        for _ in range(rounds):
            t = []
            for _ in range(3):
                g = iv.BayesGrid(0.02)
                t0 = time.perf_counter()
                ins.insert_depth_image(g, depth, k, frame.pose)
                t.append(time.perf_counter() - t0)
            pj_py.append(statistics.median(t))
            pj_cpp.append(float(subprocess.run(pargs, check=True, capture_output=True, text=True).stdout.split()[0]))
        py_proj, cpp_proj = statistics.median(pj_py), statistics.median(pj_cpp)

        g = iv.BayesGrid(0.02)
        g.insert_depth_image(depth, k, frame.pose, max_range=frame.max_range)
        grid_path = os.path.join(d, "grid.ivx")
        g.save(grid_path)
        rng = np.random.default_rng(1)
        pts = rng.uniform((0, 0, 0), (8, 6, 3), size=(1_000_000, 3))
        pts_path = os.path.join(d, "points.f64")
        pts.astype("<f8").tofile(pts_path)
        qt, ct = [], []
        for _ in range(5):
            t0 = time.perf_counter()
            p = g.probability(pts)
            qt.append(time.perf_counter() - t0)
            out = subprocess.run([oracle, "time-query", "bayes", grid_path, pts_path], check=True, capture_output=True,
                                 text=True).stdout.split()
            ct.append(float(out[0]))
            if abs(float(out[1]) - float(p.sum())) > 1e-3 * len(p):
                sys.exit("query results differ between Python and C++")
        py_query, cpp_query = statistics.median(qt), statistics.median(ct)

    print("insert one 640x480 depth frame (BayesGrid 2 cm, max range 4 m), median of %d rounds:" % rounds)
    print("  python %.2f ms   c++ %.2f ms   ratio %.3f" % (1e3 * py_insert, 1e3 * cpp_insert, py_insert / cpp_insert))
    print("the same frame by projection (ProjectiveInserter reused), median of %d rounds:" % rounds)
    print("  python %.2f ms (%.0f frames/s)   c++ %.2f ms   ratio %.3f   exact/projective from python %.1f"
          % (1e3 * py_proj, 1.0 / py_proj, 1e3 * cpp_proj, py_proj / cpp_proj, py_insert / py_proj))
    print("probability of 10^6 points, median of 5:")
    print("  python %.1f ms   c++ loop %.1f ms   ratio %.3f" % (1e3 * py_query, 1e3 * cpp_query, py_query / cpp_query))


if __name__ == "__main__":
    main()
