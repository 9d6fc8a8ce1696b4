"""Grids, inserters, planners and episodes shared between Python threads: a call that finds the
object in use by another thread raises RuntimeError; the interpreter never crashes. Queries may
run together. Each scenario runs in a subprocess, so that a crash fails the test cleanly."""

import json
import subprocess
import sys
import textwrap
import unittest

PRELUDE = textwrap.dedent("""
    import json, math, sys, threading, time
    import numpy as np
    import intervox as iv

    def busy(e):
        return isinstance(e, RuntimeError) and "in use by another thread" in str(e)

    def hammer(calls, rounds):
        # Runs each call `rounds` times on its own thread; counts results and RuntimeErrors.
        counts = {"ok": 0, "busy": 0}
        errors = []
        lock = threading.Lock()
        def run(call):
            for _ in range(rounds):
                try:
                    call()
                    key = "ok"
                except Exception as e:
                    if not busy(e):
                        errors.append(repr(e))
                        return
                    key = "busy"
                with lock:
                    counts[key] += 1
        threads = [threading.Thread(target=run, args=(c,)) for c in calls]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        counts["errors"] = errors
        return counts
""")


def run_script(body, timeout=300):
    r = subprocess.run([sys.executable, "-c", PRELUDE + textwrap.dedent(body)], capture_output=True, text=True,
                       timeout=timeout)
    return r


class SharedObjectsNeverCrash(unittest.TestCase):
    def check(self, body):
        r = run_script(body)
        self.assertEqual(r.returncode, 0, "the interpreter crashed or failed:\n" + r.stderr[-3000:])
        counts = json.loads(r.stdout.strip().splitlines()[-1])
        self.assertEqual(counts["errors"], [])
        return counts

    def test_insert_probability_and_clear_from_three_threads_give_results_or_runtime_errors(self):
        counts = self.check("""
            g = iv.BayesGrid(0.02)
            pts = np.random.default_rng(0).uniform(-2, 2, size=(20000, 3))
            calls = [lambda: g.insert_point_cloud(pts, (0, 0, 0), max_range=3.0),
                     lambda: g.probability(pts),
                     lambda: g.clear(),
                     lambda: g.observed_voxels(),
                     lambda: g.to_bytes(compression_level=0)]
            print(json.dumps(hammer(calls, 40)))
        """)
        self.assertGreater(counts["ok"], 0)
        self.assertGreater(counts["busy"], 0)  # the threads did meet

    def test_one_scan_inserter_on_two_threads_gives_results_or_runtime_errors(self):
        counts = self.check("""
            ins = iv.ScanInserter(max_range=3.0)
            grids = [iv.BayesGrid(0.02), iv.IntervalGrid(0.02)]
            pts = np.random.default_rng(1).uniform(-2, 2, size=(20000, 3))
            calls = [lambda g=g: ins.insert_point_cloud(g, pts, (0, 0, 0)) for g in grids]
            calls.append(lambda: ins.scratch_bytes())
            calls.append(lambda: ins.release_scratch())
            print(json.dumps(hammer(calls, 40)))
        """)
        self.assertGreater(counts["ok"], 0)
        self.assertGreater(counts["busy"], 0)

    def test_one_projective_inserter_on_two_threads_gives_results_or_runtime_errors(self):
        counts = self.check("""
            ins = iv.ProjectiveInserter(max_range=3.0)
            grids = [iv.BayesGrid(0.02), iv.IntervalGrid(0.02)]
            k = iv.PinholeIntrinsics.from_fov(320, 240, 1.0, 0.8)
            depth = np.random.default_rng(3).uniform(0.5, 2.5, size=(240, 320)).astype(np.float32)
            calls = [lambda g=g: ins.insert_depth_image(g, depth, k, np.eye(4)) for g in grids]
            calls.append(lambda: ins.scratch_bytes())
            calls.append(lambda: ins.release_scratch())
            print(json.dumps(hammer(calls, 40)))
        """)
        self.assertGreater(counts["ok"], 0)
        self.assertGreater(counts["busy"], 0)

    def test_queries_from_many_threads_run_together(self):
        counts = self.check("""
            g = iv.BayesGrid(0.05)
            pts = np.random.default_rng(2).uniform(-2, 2, size=(50000, 3))
            g.insert_point_cloud(pts, (0, 0, 0))
            calls = [lambda: g.probability(pts), lambda: g.interval(pts), lambda: g.occupancy(pts),
                     lambda: g.observed_count(), lambda: g.copy()]
            print(json.dumps(hammer(calls, 20)))
        """)
        self.assertEqual(counts["busy"], 0)
        self.assertEqual(counts["ok"], 100)

    def test_every_method_of_a_grid_refuses_while_another_thread_inserts(self):
        # While a long insertion holds the grid, each of its methods (and each call that takes the
        # grid) raises RuntimeError at once. The table must name every method of the class.
        counts = self.check("""
            import os, tempfile
            g = iv.BayesGrid(0.01)
            tmp = tempfile.mkdtemp()
            p = np.array([[0.1, 0.2, 0.3]])
            k = iv.PinholeIntrinsics(4, 3, 2.0, 2.0, 1.5, 1.0)
            depth = np.ones((3, 4), dtype=np.float32)
            calls = {
                "observed_count": lambda: g.observed_count(), "counts": lambda: g.counts(),
                "memory_bytes": lambda: g.memory_bytes(), "clear": lambda: g.clear(), "copy": lambda: g.copy(),
                "__copy__": lambda: g.__copy__(), "__deepcopy__": lambda: g.__deepcopy__({}),
                "__repr__": lambda: repr(g), "keys": lambda: g.keys(p), "centers": lambda: g.centers([[0, 0, 0]]),
                "update": lambda: g.update(p, iv.Observation.HIT), "probability": lambda: g.probability(p),
                "interval": lambda: g.interval(p), "occupancy": lambda: g.occupancy(p),
                "utility": lambda: g.utility(p), "is_observed": lambda: g.is_observed(p),
                "observed_voxels": lambda: g.observed_voxels(),
                "cast_ray": lambda: g.cast_ray((0, 0, 0), (1, 0, 0), max_range=1.0),
                "cast_rays": lambda: g.cast_rays((0, 0, 0), [[1, 0, 0]], max_range=1.0),
                "insert_point_cloud": lambda: g.insert_point_cloud(p, (0, 0, 0)),
                "insert_depth_image": lambda: g.insert_depth_image(depth, k, np.eye(4)),
                "insert_depth_image_projective": lambda: g.insert_depth_image_projective(depth, k, np.eye(4)),
                "insert_beams": lambda: g.insert_beams((0, 0, 0), p), "insert_ray": lambda: g.insert_ray((0, 0, 0), p[0]),
                "save": lambda: g.save(os.path.join(tmp, "g.ivx")), "to_bytes": lambda: g.to_bytes(),
                "write_bt": lambda: g.write_bt(os.path.join(tmp, "g.bt")),
                "write_ply": lambda: g.write_ply(os.path.join(tmp, "g.ply")),
                "write_html_view": lambda: g.write_html_view(os.path.join(tmp, "g.html")),
                "render_slice": lambda: g.render_slice(window=[[0, 0, 0], [3, 3, 0]]),
                "resolution": lambda: g.resolution, "origin": lambda: g.origin, "params": lambda: g.params,
                "key_box": lambda: g.key_box,
                "enable_change_detection": lambda: g.enable_change_detection(False),
                "change_detection_enabled": lambda: g.change_detection_enabled,
                "changed_keys": lambda: g.changed_keys(), "changed_count": lambda: g.changed_count(),
                "reset_change_detection": lambda: g.reset_change_detection(),
                "coarse_query": lambda: g.coarse_query(p, 3), "coarse_cubes": lambda: g.coarse_cubes(3),
            }
            others = {
                "ScanInserter.insert_point_cloud": lambda: iv.ScanInserter().insert_point_cloud(g, p, (0, 0, 0)),
                "ProjectiveInserter.insert_depth_image":
                    lambda: iv.ProjectiveInserter().insert_depth_image(g, depth, k, np.eye(4)),
                "MobilePlanner.plan": lambda: iv.MobilePlanner().plan(g, np.eye(4)),
                "Episode": lambda: iv.Episode(g, iv.MobilePlanner(), lambda b: (p[0], p), np.eye(4)),
            }
            static = {"load", "from_bytes", "read_bt", "octomap", "thesis", "policy", "utility_name", "storage"}
            public = {n for n in dir(iv.BayesGrid) if not n.startswith("_") or n in ("__copy__", "__deepcopy__", "__repr__")}
            missing = sorted(public - static - set(calls))
            pts = np.random.default_rng(3).uniform(-5, 5, size=(400000, 3))
            result = {"errors": [], "ok": 0, "busy": 0, "missing": missing}
            for attempt in range(4):
                t = threading.Thread(target=lambda: g.insert_point_cloud(pts, (0, 0, 0), max_range=6.0))
                t.start()
                while t.is_alive():  # wait until the insertion holds the grid
                    try:
                        g.resolution
                    except RuntimeError:
                        break
                not_refused = []
                for name, call in list(calls.items()) + list(others.items()):
                    try:
                        call()
                        not_refused.append(name)
                    except Exception as e:
                        if not busy(e):
                            not_refused.append(name + ": " + repr(e))
                finished_early = not t.is_alive()
                t.join()
                if not finished_early:
                    break
                pts = np.concatenate([pts, pts])
            result["ok"] = len(calls) + len(others) - len(not_refused)
            result["errors"] = not_refused if not finished_early else ["the insertion finished too early"]
            print(json.dumps(result))
        """)
        self.assertEqual(counts["missing"], [], "methods not in the table")

    def test_an_episode_holds_its_grid_while_it_senses(self):
        self.check("""
            g = iv.BayesGrid(0.1)
            p = np.array([[1.0, 0.2, 0.3], [0.5, -0.4, 0.2]])
            inside = []
            def busy_call(f):
                try:
                    f()
                    return "ran"
                except Exception as e:
                    return "busy" if busy(e) else repr(e)
            def source(body):
                # The episode's callback may query the episode's grid (same thread), but another
                # thread may not use it meanwhile.
                inside.append(("same thread", busy_call(lambda: g.observed_count())))
                out = []
                th = threading.Thread(target=lambda: out.append(busy_call(lambda: g.clear())))
                th.start()
                th.join()
                inside.append(("other thread", out[0]))
                return (np.zeros(3), p)
            ep = iv.Episode(g, iv.MobilePlanner(), source, np.eye(4))
            ep.sense(np.eye(4)[None])
            ok = inside == [("same thread", "ran"), ("other thread", "busy")] and g.observed_count() > 0
            print(json.dumps({"errors": [] if ok else [repr(inside)], "ok": 1, "busy": 0}))
        """)


if __name__ == "__main__":
    unittest.main()
