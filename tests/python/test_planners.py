"""Planners with numpy poses and the episode runner with a Python sensor callback."""

import unittest

import numpy as np

import intervox as iv


def start_pose(p):
    body = np.eye(4)
    body[:3, 3] = p
    return body


def small_mobile_params(steps):
    p = iv.MobilePlannerParams()
    p.max_steps = steps
    p.threads = 1
    p.region = ((0, 0, 0.2), (8, 6, 0.8))
    return p


class Mobile(unittest.TestCase):
    def test_first_plan_is_the_look_around_at_the_current_pose(self):
        lab = iv.make_lab_room()
        planner = iv.MobilePlanner(params=small_mobile_params(3))
        body = start_pose(lab.start)
        plan = planner.plan(iv.BayesGrid(0.1), body)
        self.assertEqual(plan.termination, iv.Termination.RUNNING)
        self.assertEqual(plan.reason, iv.ViewReason.INITIAL)
        self.assertEqual(plan.scans.shape, (4, 4, 4))
        np.testing.assert_allclose(plan.scans[:, :3, 3], np.tile(lab.start, (4, 1)))
        with self.assertRaisesRegex(ValueError, "pose"):
            planner.plan(iv.BayesGrid(0.1), np.full((4, 4), np.nan))

    def test_a_plan_says_why_it_refused_each_frontier(self):
        # A round room of 2.5 m seen from its centre, with a 60 degree opening without returns
        # (free to 4 m): the opening's far end is a frontier; no view can gain more than an unknown
        # world's, so with min_relative_gain 2 every frontier tried is refused as "low gain".
        centre = np.array([4.55, 2.05, 0.0])
        angles = np.radians(np.arange(-180, 180))
        origins, ends, hits = [], [], []
        for z in 0.25 + 0.1 * np.arange(6):
            o = centre + (0, 0, z)
            opening = np.abs(np.degrees(angles)) < 30
            r = np.where(opening, 4.0, 2.5)
            e = np.stack([o[0] + r * np.cos(angles), o[1] + r * np.sin(angles), np.full(angles.size, z)], axis=1)
            origins.append(np.tile(o, (angles.size, 1)))
            ends.append(e)
            hits.append(~opening)
        g = iv.BayesGrid(0.1)
        for _ in range(4):
            g.insert_beams(np.concatenate(origins), np.concatenate(ends), np.concatenate(hits), max_range=4.0)
        p = small_mobile_params(5)
        p.region = ((0, -2.5, 0.2), (9, 6.5, 0.8))
        p.min_relative_gain = 2.0
        planner = iv.MobilePlanner(params=p)
        body = start_pose(centre)
        planner.plan(g, body)
        plan = planner.plan(g, body)
        self.assertEqual(plan.termination, iv.Termination.EXPLORED)
        self.assertGreater(len(plan.refused), 0)
        for r in plan.refused:
            self.assertEqual(r["reason"], "low gain")
            self.assertTrue(0.0 <= r["relative_gain"] <= 1.0)
            self.assertEqual(len(r["frontier"]), 2)
            self.assertNotIn("reachable free", r["ring_refused"])
            self.assertTrue(all(v > 0 for v in r["ring_refused"].values()))
        self.assertGreater(plan.skipped, 0)

    def test_episode_with_a_python_callback_equals_the_simulated_rig_source(self):
        lab = iv.make_lab_room()
        rig = iv.SensorRig.mobile_base()
        calls = []
        returned = []

        def source(body):
            calls.append(body.copy())
            o, e, h = iv.simulate_rig(rig, lab.scene, body, seed=100 + len(calls))
            returned.append(len(o))
            return o, e, h

        grids = []
        for _ in range(2):
            calls.clear()
            returned.clear()
            g = iv.BayesGrid(0.1)
            ep = iv.Episode(g, iv.MobilePlanner(rig, small_mobile_params(2)), source, start_pose(lab.start))
            self.assertEqual(ep.run(), iv.Termination.BUDGET)
            steps = ep.steps
            self.assertEqual(steps[0].plan.reason, iv.ViewReason.INITIAL)
            self.assertEqual(sum(s.beams for s in steps), sum(returned))  # every returned beam inserted
            scans = sum(len(s.plan.scans) for s in steps)
            self.assertEqual(len(calls), scans)  # sensed exactly at the plan's scan poses
            np.testing.assert_allclose(np.array(calls), np.concatenate([s.plan.scans for s in steps if len(s.plan.scans)]))
            self.assertGreater(g.observed_count(), 1000)
            grids.append(g)
        self.assertEqual(grids[0].to_bytes(), grids[1].to_bytes())  # seeds fix the episode

    def test_explained_planning_runs_an_episode_and_reads_a_map_not_a_grid_alone(self):
        lab = iv.make_lab_room()
        rig = iv.SensorRig.mobile_base()
        params = small_mobile_params(2)
        self.assertFalse(params.explained)
        params.explained = True
        self.assertTrue(params.explained)
        self.assertFalse(params.unexplained_hazards)  # opt-in
        params.unexplained_hazards = True
        self.assertTrue(params.unexplained_hazards)
        self.assertEqual(params.unexplained_margin, 0.0)
        params.unexplained_margin = -0.1
        with self.assertRaisesRegex(ValueError, "unexplained_margin"):
            params.validate()
        params.unexplained_margin = 0.05
        self.assertFalse(params.open_group_hazards)  # opt-in
        params.open_group_hazards = True
        self.assertTrue(params.open_group_hazards)
        self.assertFalse(params.close_wall_gaps)  # opt-in
        params.close_wall_gaps = True
        self.assertTrue(params.close_wall_gaps)
        params.close_wall_gaps = False  # the episode below measures the hazards alone
        g = iv.BayesGrid(0.1)
        source = lambda body: iv.simulate_rig(rig, lab.scene, body, seed=7)
        ep = iv.Episode(g, iv.MobilePlanner(rig, params), source, start_pose(lab.start))
        self.assertIn(ep.run(), (iv.Termination.BUDGET, iv.Termination.EXPLORED))
        self.assertGreaterEqual(len(ep.steps), 2)
        for step in ep.steps:  # the lying regions of each plan: only unexplained groups (conflict-aware is off)
            for r in step.plan.regions:
                self.assertTrue(r["unexplained"])
                self.assertLessEqual(r["directions"], r["views"])
                self.assertTrue(r["unresolvable"] or r["directions"] < 3)
            if step.plan.reason == iv.ViewReason.CONFLICT:
                self.assertTrue(step.plan.regions[step.plan.conflict_region]["unexplained"])
        # Planned directly on a grid, without the episode's map and its evidence, the plan is refused.
        planner = iv.MobilePlanner(rig, params)
        with self.assertRaisesRegex(ValueError, "ExplainedMap"):
            planner.plan(g, start_pose(lab.start))

    def test_the_episode_shows_a_snapshot_of_its_maps_explained_space_equal_to_a_replay_of_its_scans(self):
        lab = iv.make_lab_room(closet_material=iv.Material.mirror())
        rig = iv.SensorRig.mobile_base()
        plain = iv.Episode(iv.BayesGrid(0.1), iv.MobilePlanner(rig, small_mobile_params(2)), iv.SimulatedRig(lab.scene, rig, seed=5),
                           start_pose(lab.start))
        plain.step()
        self.assertIsNone(plain.explained_space)  # no explained planning: the map is the grid alone
        params = small_mobile_params(4)
        params.explained = True
        planner = iv.MobilePlanner(rig, params)
        scans = []
        sim = iv.SimulatedRig(lab.scene, rig, seed=5)

        def source(body):
            scans.append(sim(body))
            return scans[-1]

        ep = iv.Episode(iv.BayesGrid(0.1), planner, source, start_pose(lab.start))
        self.assertEqual(ep.explained_space.size(), 0)  # no scan yet
        ep.step()
        ep.step()
        snapshot = ep.explained_space
        self.assertIsInstance(snapshot, iv.ExplainedSpace)
        # The oracle: the same scans replayed into a channel of its own, each classed against the
        # evidence before it (what the episode's map does).
        replay = iv.ExplainedSpace(0.1)
        for o, e, h in scans:
            replay.add(o, e, h, replay.classify(o, e, h, max_range=planner.max_range), max_range=planner.max_range)
        self.assertEqual(snapshot.size(), replay.size())
        self.assertGreater(snapshot.size(), 1000)
        ends = np.concatenate([e for _, e, _ in scans])
        origins = np.concatenate([o for o, _, _ in scans])
        points = np.concatenate([ends, 0.5 * (origins + ends)])
        np.testing.assert_array_equal(snapshot.evidence(points), replay.evidence(points))
        np.testing.assert_array_equal(snapshot.state(points), replay.state(points))
        self.assertGreater(int(np.sum(snapshot.evidence(points)[:, 3])), 0)  # the mirror made suspect misses
        # A snapshot: the episode's next scans do not change it.
        before = snapshot.evidence(points)
        ep.step()
        self.assertGreater(ep.explained_space.size(), snapshot.size())
        np.testing.assert_array_equal(snapshot.evidence(points), before)

    def test_the_planner_lists_the_positions_it_was_given_and_the_mean_sensor_origin_of_every_scan(self):
        lab = iv.make_lab_room()
        rig = iv.SensorRig.mobile_base()
        planner = iv.MobilePlanner(rig, small_mobile_params(3))
        self.assertEqual(planner.visited.shape, (0, 3))
        self.assertEqual(planner.scan_origins.shape, (0, 3))
        ep = iv.Episode(iv.BayesGrid(0.1), planner, iv.SimulatedRig(lab.scene, rig, seed=3), start_pose(lab.start))
        given = [start_pose(lab.start)[:3, 3]]
        scans = []
        for _ in range(3):
            step = ep.step()
            scans += list(step.plan.scans)
            if len(step.plan.scans):
                given.append(step.plan.scans[-1][:3, 3])  # the episode plans next from the last scan pose
        # The oracle: the rig's mounts at each scan pose, averaged.
        expected = [np.mean([rig.sensor_pose(i, q)[:3, 3] for i in range(len(rig))], axis=0) for q in scans]
        self.assertGreaterEqual(len(scans), 4)  # the look-around's headings and at least one view
        np.testing.assert_allclose(planner.scan_origins, np.array(expected), atol=1e-9)
        np.testing.assert_allclose(planner.visited, np.array(given[:len(planner.visited)]), atol=1e-9)
        self.assertEqual(len(planner.visited), planner.steps)
        # Copies: changing them changes nothing in the planner.
        o = planner.scan_origins
        o[:] = 0
        self.assertFalse(np.allclose(planner.scan_origins, 0))

    def test_known_surfaces_are_told_to_the_channel_of_the_planners_map_as_given(self):
        lab = iv.make_lab_room(closet_material=iv.Material.mirror())
        rig = iv.SensorRig.mobile_base()
        params = small_mobile_params(3)
        self.assertEqual(params.known_surfaces, [])  # the planner knows only what its beams tell
        # The closet's mirrored front (x 0.601 m, y 3.4-4.6 m, z 0-2 m) and, in its plane, a second
        # rectangle beyond a gap: kept apart, not grown across the gap.
        front = iv.PlanePatch((0.601, 4.0, 1.0), (1.0, 0.0, 0.0), 0.6, 1.0)
        beyond = iv.PlanePatch((0.601, 5.5, 1.0), (1.0, 0.0, 0.0), 0.2, 1.0)
        params.known_surfaces = [front, beyond]
        params.explained = True
        planner = iv.MobilePlanner(rig, params)
        scans = []
        sim = iv.SimulatedRig(lab.scene, rig, seed=4)

        def source(body):
            scans.append(sim(body))
            return scans[-1]

        ep = iv.Episode(iv.BayesGrid(0.1), planner, source, start_pose((2.0, 4.0, 0.0)))  # 1.4 m before the closet
        ep.step()
        known = ep.explained_space
        self.assertEqual(len(known.mirrors), 2)
        np.testing.assert_allclose(known.mirrors[1].center, (0.601, 5.5, 1.0))
        # The oracle: the scans replayed into a channel told the same surfaces first.
        replay = iv.ExplainedSpace(0.1)
        for m in (front, beyond):
            replay.add_mirror(m, merge=False)
        for o, e, h in scans:
            replay.add(o, e, h, replay.classify(o, e, h, max_range=planner.max_range), max_range=planner.max_range)
        ends = np.concatenate([e for _, e, _ in scans])
        np.testing.assert_array_equal(known.evidence(ends), replay.evidence(ends))
        face, gap = np.array([[0.62, 4.0, 0.5]]), np.array([[0.62, 5.0, 0.5]])
        self.assertEqual(known.state(face)[0], int(iv.ExplainedState.OCCUPIED))
        self.assertFalse(known.on_mirror(gap)[0])
        # merge=True (the default) grows one mirror across the gap instead.
        grown = iv.ExplainedSpace(0.1)
        grown.add_mirror(front)
        grown.add_mirror(beyond)
        self.assertEqual(len(grown.mirrors), 1)
        self.assertTrue(grown.on_mirror(gap)[0])
        # Without them the same scans leave less suspect evidence: the beams through the front count.
        plain = iv.ExplainedSpace(0.1)
        for o, e, h in scans:
            plain.add(o, e, h, plain.classify(o, e, h, max_range=planner.max_range), max_range=planner.max_range)
        suspect = lambda space: int(np.sum(space.evidence(ends)[:, 2:4]))
        self.assertGreater(suspect(known), suspect(plain), (suspect(known), suspect(plain)))

    def test_find_mirrors_and_min_lying_misses_are_options_of_explained_planning(self):
        params = small_mobile_params(3)
        self.assertFalse(params.find_mirrors)  # opt-in
        self.assertEqual(params.min_lying_misses, 1)
        params.min_lying_misses = 0
        with self.assertRaisesRegex(ValueError, "min_lying_misses"):
            params.validate()
        params.min_lying_misses = 2
        self.assertEqual(params.max_inconsistent_share, 1.0)  # the opacity test, off
        params.max_inconsistent_share = 1.5
        with self.assertRaisesRegex(ValueError, "max_inconsistent_share"):
            params.validate()
        params.max_inconsistent_share = 1.0
        params.explained = True
        params.find_mirrors = True
        self.assertTrue(params.find_mirrors)
        lab = iv.make_lab_room(closet_material=iv.Material.mirror())
        rig = iv.SensorRig.mobile_base()
        g = iv.BayesGrid(0.1)
        planner = iv.MobilePlanner(rig, params)
        source = lambda body: iv.simulate_rig(rig, lab.scene, body, seed=3)
        ep = iv.Episode(g, planner, source, start_pose(lab.start))
        self.assertIn(ep.run(), (iv.Termination.BUDGET, iv.Termination.EXPLORED))
        self.assertGreaterEqual(len(ep.steps), 2)

    def test_one_camera_rig_looks_all_round_and_drives_forward_only(self):
        rig = iv.SensorRig()
        mount = np.eye(4)  # optical frame (z forward, x right, y down) to the body: forward, 0.5 m up
        mount[:3, :3] = [[0, 0, 1], [-1, 0, 0], [0, -1, 0]]
        mount[:3, 3] = (0.3, 0.0, 0.5)
        rig.add(iv.DepthCamera.o3d100(), mount, "front")
        params = iv.MobilePlannerParams()
        self.assertIsNone(params.start_free_radius)
        self.assertIsNone(params.look_around_span)
        self.assertFalse(params.start_free_columns)
        self.assertFalse(params.exact_blind_zone)
        params.exact_blind_zone = True                           # what one camera needs at 5 cm
        params.face_along_path = True
        params.max_steps = 2
        params.threads = 1
        planner = iv.MobilePlanner(rig, params)
        yaws = np.array(planner.look_around_yaws)
        self.assertGreater(len(yaws), 10)                        # one 40° camera turns the circle
        self.assertGreater(yaws[-1] + np.radians(20), np.radians(340))
        self.assertTrue(1.0 < planner.start_free_radius < 2.0)   # the rig's blind zone
        lab = iv.make_lab_room()
        ep = iv.Episode(iv.BayesGrid(0.1), planner, iv.SimulatedRig(lab.scene, rig, seed=3), start_pose(lab.start))
        ep.run()
        self.assertEqual(len(ep.steps[0].plan.scans), len(yaws))
        for step in ep.steps[1:]:
            path = step.plan.path
            for a, b in zip(path[:-1], path[1:]):
                move = b[:3, 3] - a[:3, 3]
                if np.linalg.norm(move) > 1e-9:  # driving: forward along the heading, no turning
                    np.testing.assert_allclose(a[:3, :3], b[:3, :3], atol=1e-9)
                    self.assertAlmostEqual(float(a[:3, 0] @ move) / np.linalg.norm(move), 1.0, places=9)
        params.look_around_span = -1.0
        with self.assertRaisesRegex(ValueError, "look_around_span"):
            iv.MobilePlanner(rig, params)

    def test_passage_views_lead_through_the_annex_doorway_the_plain_planner_ends_before(self):
        # The lab room with the annex, seed 10 (docs/planning.md, "Doors and passages"): without
        # passage views the episode ends with the doorway closed and the robot never beyond it.
        lab = iv.make_lab_room(annex=True)
        rig = iv.SensorRig.mobile_base()
        far = []
        for passages in (False, True):
            params = small_mobile_params(30)
            params.region = ((0, 0, 0.2), (11.1, 6.5, 0.8))
            params.seed = 10
            self.assertFalse(iv.MobilePlannerParams().passage_views)
            params.passage_views = passages
            ep = iv.Episode(iv.IntervalGrid(0.05), iv.MobilePlanner(rig, params), iv.SimulatedRig(lab.scene, rig, seed=10),
                            start_pose(lab.start))
            ep.run()
            far.append(float(ep.trajectory[:, 0, 3].max()))
            reasons = {step.plan.reason for step in ep.steps}
            self.assertEqual(iv.ViewReason.PASSAGE in reasons, passages)
        self.assertLess(far[0], 8.0)     # never through the doorway (x 8.0-8.1)
        self.assertGreater(far[1], 8.6)  # into the annex
        params = iv.MobilePlannerParams()
        params.passage_frames = 0
        with self.assertRaisesRegex(ValueError, "frames"):
            iv.MobilePlanner(rig, params)

    def test_the_way_back_keeps_a_retired_region_from_shutting_the_robot_in(self):
        # The lab room with the annex, seed 10, explained planning with hazards and passage views
        # (docs/planning.md, "The way back"): at step 6 a retired unexplained group's zone cuts
        # the room, the robot stands in a pocket and, without the way back, the episode ends
        # "explored" at step 7; with it the path it came along stays passable and it goes on.
        lab = iv.make_lab_room(annex=True)
        rig = iv.SensorRig.mobile_base()
        ends = []
        for driven in (False, True):
            params = small_mobile_params(8)
            params.region = ((0, 0, 0.2), (11.1, 6.5, 0.8))
            params.seed = 10
            params.explained = True
            params.unexplained_hazards = True
            params.passage_views = True
            self.assertFalse(iv.MobilePlannerParams().driven_paths)  # opt-in
            params.driven_paths = driven
            ep = iv.Episode(iv.IntervalGrid(0.05), iv.MobilePlanner(rig, params), iv.SimulatedRig(lab.scene, rig, seed=10),
                            start_pose(lab.start))
            ends.append((ep.run(), len(ep.steps)))
        self.assertEqual(ends[0][0], iv.Termination.EXPLORED)
        self.assertLessEqual(ends[0][1], 8)
        self.assertEqual(ends[1][0], iv.Termination.BUDGET)
        self.assertGreater(ends[1][1], ends[0][1])

    def test_callback_errors_propagate_and_bad_returns_raise(self):
        lab = iv.make_lab_room()

        def broken(body):
            raise RuntimeError("sensor unplugged")

        ep = iv.Episode(iv.BayesGrid(0.1), iv.MobilePlanner(params=small_mobile_params(1)), broken,
                        start_pose(lab.start))
        with self.assertRaisesRegex(RuntimeError, "sensor unplugged"):
            ep.step()
        ep = iv.Episode(iv.BayesGrid(0.1), iv.MobilePlanner(params=small_mobile_params(1)), lambda b: 42,
                        start_pose(lab.start))
        with self.assertRaisesRegex(ValueError, "must return"):
            ep.step()
        with self.assertRaisesRegex(ValueError, "callable"):
            iv.Episode(iv.BayesGrid(0.1), iv.MobilePlanner(), 5, start_pose(lab.start))

    def test_insertion_through_the_episode_equals_direct_insertion(self):
        lab = iv.make_lab_room()
        rig = iv.SensorRig.mobile_base()
        planner = iv.MobilePlanner(rig, small_mobile_params(1))
        g = iv.IntervalGrid(0.1)
        src = iv.SimulatedRig(lab.scene, rig, seed=4)
        ep = iv.Episode(g, planner, src, start_pose(lab.start))
        ep.sense(start_pose(lab.start)[None])
        ref = iv.IntervalGrid(0.1)
        o, e, h = iv.SimulatedRig(lab.scene, rig, seed=4)(start_pose(lab.start))
        ref.insert_beams(o, e, h, max_range=planner.max_range)
        self.assertEqual(g.to_bytes(), ref.to_bytes())


class Arm(unittest.TestCase):
    def test_arm_episode_in_the_workcell_with_a_simulated_rig(self):
        w = iv.make_workcell()
        rig = iv.SensorRig.arm()
        params = iv.ArmPlannerParams()
        params.max_views = 2
        params.candidates = 4
        params.threads = 1
        planner = iv.ArmPlanner(rig, params)
        g = iv.IntervalGrid(0.01, bounds=((0.3, 0.3, 0.7), (1.2, 1.2, 1.2)))
        first = planner.copy().plan(g)
        self.assertEqual(first.reason, iv.ViewReason.INITIAL)
        self.assertEqual(first.scans.shape, (params.profiles, 4, 4))
        ep = iv.Episode(g, planner, iv.SimulatedRig(w.scene, rig, seed=3), np.eye(4))
        self.assertEqual(ep.run(), iv.Termination.BUDGET)
        self.assertGreater(g.counts().occupied, 0)

    def test_explained_arm_episode_counts_its_refused_sweeps(self):
        w = iv.make_workcell()  # the polished ring part: folded returns leave unexplained space
        rig = iv.SensorRig.arm()
        params = iv.ArmPlannerParams()
        params.max_views = 4
        params.threads = 1
        params.explained = True
        self.assertTrue(params.explained)
        planner = iv.ArmPlanner(rig, params)
        g = iv.IntervalGrid(0.01, bounds=((0.0, 0.0, 0.0), (1.5, 1.5, 1.5)))
        ep = iv.Episode(g, planner, iv.SimulatedRig(w.scene, rig, seed=1), np.eye(4))
        self.assertEqual(ep.run(), iv.Termination.BUDGET)
        for step in ep.steps[1:]:
            plan = step.plan
            refused = plan.refused
            self.assertEqual(set(refused), {"table", "occupied", "unexplained", "conflict margin"})
            self.assertEqual(plan.sampled, len(plan.candidates) + sum(refused.values()))
        self.assertGreater(sum(s.plan.refused["unexplained"] for s in ep.steps[1:]), 0)
        kept = ep.explained_space  # what the planner planned on: the evidence of the episode's map
        self.assertIsInstance(kept, iv.ExplainedSpace)
        self.assertGreater(kept.size(), 0)
        self.assertEqual(kept.resolution, 0.01)
        alone = iv.ArmPlanner(rig, params)
        with self.assertRaisesRegex(ValueError, "ExplainedMap"):
            alone.plan(g)  # a grid alone holds no evidence: an Episode's map does

    def test_arm_seeking_normals_scores_every_candidate_by_its_glint(self):
        w = iv.make_workcell()  # the polished ring part
        rig = iv.SensorRig.arm()
        params = iv.ArmPlannerParams()
        params.max_views = 5
        params.threads = 1
        params.seek_normals = True
        params.normals_weight = 2.0
        self.assertTrue(params.seek_normals)
        self.assertEqual(params.normals_weight, 2.0)
        planner = iv.ArmPlanner(rig, params)
        g = iv.IntervalGrid(0.01, bounds=((0.0, 0.0, 0.0), (1.5, 1.5, 1.5)))
        ep = iv.Episode(g, planner, iv.SimulatedRig(w.scene, rig, seed=2), np.eye(4))
        self.assertEqual(ep.run(), iv.Termination.BUDGET)
        self.assertEqual(ep.steps[0].plan.glint, [])
        for step in ep.steps[1:-1]:
            plan = step.plan
            self.assertEqual(len(plan.glint), len(plan.candidates))
            self.assertTrue(all(x >= 0 for x in plan.glint))
            self.assertIn(plan.reason, (iv.ViewReason.GAIN, iv.ViewReason.NORMALS))
        self.assertGreater(max(s.plan.glint_targets for s in ep.steps[1:-1]), 0)
        params.normals_weight = -1.0
        with self.assertRaises(ValueError):
            params.validate()


if __name__ == "__main__":
    unittest.main()
