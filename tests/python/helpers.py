"""Shared pieces of the Python tests: the C++ oracle, closed forms and loading the scripts."""

import importlib.util
import math
import os
import pathlib
import subprocess
import tempfile
import unittest

import numpy as np

import intervox as iv


def logit(p):
    return math.log(p / (1.0 - p))


def sigmoid(x):
    return 1.0 / (1.0 + math.exp(-x))


def load_script(file_name):
    """The module of scripts/<file_name> (the scripts are no package)."""
    path = pathlib.Path(__file__).resolve().parents[2] / "scripts" / file_name
    spec = importlib.util.spec_from_file_location(path.stem, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def oracle_path():
    path = os.environ.get("INTERVOX_ORACLE")
    if not path:
        raise unittest.SkipTest("INTERVOX_ORACLE is not set (run the tests through CTest)")
    return path


def oracle_cloud(policy, resolution, points, origin, max_range=-1.0, threads=1):
    """The grid the C++ API builds from the same points (loaded back through the binding)."""
    with tempfile.TemporaryDirectory() as d:
        raw = os.path.join(d, "points.f64")
        out = os.path.join(d, "grid.ivx")
        np.ascontiguousarray(points, dtype="<f8").tofile(raw)
        subprocess.run([oracle_path(), "cloud", policy, repr(resolution), raw, *map(repr, map(float, origin)),
                        repr(float(max_range)), str(threads), out], check=True)
        cls = iv.BayesGrid if policy == "bayes" else iv.IntervalGrid
        return cls.load(out)


def oracle_depth(policy, resolution, depth, k, pose, max_range=-1.0, mode="depth"):
    with tempfile.TemporaryDirectory() as d:
        raw = os.path.join(d, "depth.f32")
        out = os.path.join(d, "grid.ivx")
        np.ascontiguousarray(depth, dtype="<f4").tofile(raw)
        args = [oracle_path(), mode, policy, repr(resolution), raw, str(k.width), str(k.height),
                repr(k.fx), repr(k.fy), repr(k.cx), repr(k.cy)]
        args += [repr(float(v)) for v in np.asarray(pose, dtype=float).ravel()]
        args += [repr(float(max_range)), out]
        subprocess.run(args, check=True)
        cls = iv.BayesGrid if policy == "bayes" else iv.IntervalGrid
        return cls.load(out)


def assert_same_grid(test, a, b):
    """Same observed voxels, same order, bit-identical values (compared through the grid file)."""
    va, vb = a.observed_voxels(), b.observed_voxels()
    test.assertGreater(len(va["keys"]), 0)
    np.testing.assert_array_equal(va["keys"], vb["keys"])
    np.testing.assert_array_equal(va["probability"], vb["probability"])
    np.testing.assert_array_equal(va["interval"], vb["interval"])
    test.assertEqual(a.to_bytes(), b.to_bytes())


def random_cloud(seed, n=2000, spread=3.0):
    rng = np.random.default_rng(seed)
    return rng.uniform(-spread, spread, size=(n, 3))


def yaw_pose(x, y, z, yaw):
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([[c, -s, 0, x], [s, c, 0, y], [0, 0, 1, z], [0, 0, 0, 1]], dtype=float)


def camera_pose_looking_x(x, y, z):
    """Optical frame (z forward, x right, y down) looking along world +x from (x, y, z)."""
    return np.array([[0, 0, 1, x], [-1, 0, 0, y], [0, -1, 0, z], [0, 0, 0, 1]], dtype=float)
