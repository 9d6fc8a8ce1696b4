"""The simulator: scenes, materials, depth images as numpy, determinism."""

import math
import unittest

import numpy as np

import intervox as iv


def wall_scene(material=None):
    s = iv.Scene()
    s.add_box(((2.0, -5.0, -5.0), (2.5, 5.0, 5.0)), material or iv.Material.diffuse(0.0), "wall")
    return s


class Simulate(unittest.TestCase):
    def test_noise_free_depth_of_a_wall_is_its_distance(self):
        cam = iv.DepthCamera.make(32, 24, math.radians(40), math.radians(30), 0.1, 4.0)
        pose = iv.look_at((0, 0, 0), (1, 0, 0))
        m = iv.simulate(cam, wall_scene(), pose, seed=1)
        self.assertEqual((m.depth.shape, m.depth.dtype), ((24, 32), np.float32))
        np.testing.assert_allclose(m.depth, 2.0, rtol=1e-6)  # z-depth of a plane facing the camera
        np.testing.assert_allclose(m.pose, pose)
        o, e, h = m.beams()
        self.assertEqual(e.shape, (24 * 32, 3))
        np.testing.assert_allclose(e[:, 0], 2.0, rtol=1e-6)
        self.assertTrue(h.all())

    def test_a_mirror_shows_the_wall_beside_it_at_the_folded_range(self):
        # A 45-degree mirror (the plane x - y = 2) reflects the camera's beams onto a wall at y = 3:
        # every pixel reports the folded path along its own direction (closed form per beam).
        s = iv.Scene()
        s.add_quad((1.5, -0.5, -1.0), (1.0, 1.0, 0.0), (0.0, 0.0, 2.0), iv.Material.mirror(), "mirror")
        s.add_box(((-5.0, 3.0, -5.0), (10.0, 3.2, 5.0)), iv.Material.diffuse(0.0), "wall")
        cam = iv.DepthCamera.make(33, 25, math.radians(10), math.radians(10), 0.1, 8.0)
        m = iv.simulate(cam, s, iv.look_at((0, 0, 0), (1, 0, 0)), seed=1)
        o, e, h = m.beams()
        self.assertTrue(h.all())
        ranges = np.linalg.norm(e - o, axis=1)
        d = (e - o) / ranges[:, None]
        n = np.array([1.0, -1.0, 0.0]) / math.sqrt(2.0)
        t1 = 2.0 / (d[:, 0] - d[:, 1])
        p = t1[:, None] * d
        r = d - 2.0 * (d @ n)[:, None] * n
        t2 = (3.0 - p[:, 1]) / r[:, 1]
        np.testing.assert_allclose(ranges, t1 + t2, rtol=1e-5)  # float32 depth image
        self.assertTrue(np.all(e[:, 0] > 2.0))  # the phantom wall lies behind the mirror
        metal = iv.Material.named("polished-metal")
        self.assertEqual((metal.surface, metal.p_direct, metal.lobe_exponent), (iv.Surface.SPECULAR, 0.8, 40.0))
        self.assertEqual(iv.Material.specular_random_range().specular_model, iv.SpecularModel.RANDOM_RANGE)
        self.assertFalse(iv.Material.transparent_without_fresnel().fresnel)
        with self.assertRaises(ValueError):
            iv.Material.named("chrome")

    def test_same_seed_same_image_for_any_thread_count(self):
        lab = iv.make_lab_room(closet_material=iv.Material.absorbing())
        cam = iv.DepthCamera.o3d100()
        pose = iv.look_at(lab.start + [0, 0, 0.5], (0.3, 4.0, 0.8))
        a = iv.simulate(cam, lab.scene, pose, seed=9).depth
        b = iv.simulate(cam, lab.scene, pose, seed=9, threads=3).depth
        c = iv.simulate(cam, lab.scene, pose, seed=10).depth
        np.testing.assert_array_equal(a, b)
        self.assertFalse(np.array_equal(a, c, equal_nan=True))

    def test_rig_scan_and_simulated_rig_give_world_beams(self):
        lab = iv.make_lab_room()
        rig = iv.SensorRig.mobile_base()
        body = np.eye(4)
        body[:3, 3] = lab.start
        o, e, h = iv.simulate_rig(rig, lab.scene, body, seed=2)
        self.assertEqual(len(o), rig.beam_count())
        ends = e[h]
        self.assertTrue(np.all((ends[:, 0] > -0.2) & (ends[:, 0] < 8.2) & (ends[:, 1] > -0.2) & (ends[:, 1] < 6.2)))
        src = iv.SimulatedRig(lab.scene, rig, seed=2)
        first = src(body)
        again = iv.SimulatedRig(lab.scene, rig, seed=2)(body)
        for x, y in zip(first, again):
            np.testing.assert_array_equal(x, y)
        self.assertEqual(src.scans, 1)
        imgs = iv.simulate_images(rig, lab.scene, body, seed=2)
        self.assertEqual(len(imgs), 8)
        self.assertEqual(imgs[0].depth.shape, (48, 64))

    def test_workcell_and_ground_truth(self):
        w = iv.make_workcell()
        self.assertEqual(w.scene.name(w.part), "part")
        region = w.object_region("box", 0.02)
        keys = w.scene.ground_truth(0.01, region)
        self.assertEqual(keys.shape[1], 3)
        self.assertGreater(len(keys), 0)
        centers = (keys + 0.5) * 0.01
        self.assertTrue(w.scene.inside(centers).mean() > 0.5)
        with self.assertRaisesRegex(ValueError, "unknown object"):
            w.object_region("cup", 0.0)

    def test_lab_room_options_open_an_annex_and_a_window_and_mirror_the_closet_front(self):
        plain = iv.make_lab_room()
        self.assertIsNone(plain.annex_interior)
        self.assertIsNone(plain.window)
        self.assertEqual(plain.closet, plain.closet_body)
        lab = iv.make_lab_room(annex=True, window=True, closet_front_only=True,
                               closet_material=iv.Material.mirror())
        # Through the doorway to the annex's east wall, through the window to the crate outside.
        t, obj = lab.scene.intersect(np.array([7.0, 5.3, 1.0]), np.array([1.0, 0.0, 0.0]))
        self.assertEqual(lab.scene.name(obj), "annex_wall_east")
        self.assertAlmostEqual(t, 4.1)
        t, obj = lab.scene.intersect(np.array([5.7, 1.0, 0.5]), np.array([0.0, -1.0, 0.0]))
        self.assertEqual(lab.scene.name(obj), "crate_outside")
        self.assertAlmostEqual(t, 2.2)
        self.assertIsNotNone(lab.annex_interior)
        self.assertIsNotNone(lab.window)
        t, obj = lab.scene.intersect(np.array([2.0, 4.0, 1.0]), np.array([-1.0, 0.0, 0.0]))
        self.assertEqual(obj, lab.closet)
        self.assertNotEqual(lab.closet, lab.closet_body)

    def test_symmetric_rooms_are_mirror_images_joined_by_an_open_doorway(self):
        plain = iv.make_symmetric_rooms()
        self.assertIsNone(plain.mirror)
        self.assertIsNone(plain.mirror_object)
        self.assertAlmostEqual(plain.symmetry_x, 4.1)
        west, east = plain.rooms
        np.testing.assert_allclose(plain.reflect(np.array([1.0, 2.0, 0.5])), [7.2, 2.0, 0.5])
        # Through the doorway to the east room's east wall at x = 8.2; the same range mirrored.
        t, obj = plain.scene.intersect(np.array([3.5, 1.1, 1.0]), np.array([1.0, 0.0, 0.0]))
        self.assertEqual(plain.scene.name(obj), "east_wall")
        self.assertAlmostEqual(t, 4.7)
        t, obj = plain.scene.intersect(np.array([4.7, 1.1, 1.0]), np.array([-1.0, 0.0, 0.0]))
        self.assertEqual(plain.scene.name(obj), "west_wall")
        self.assertAlmostEqual(t, 4.7)
        self.assertAlmostEqual(east.min[0], 4.2)
        rooms = iv.make_symmetric_rooms(mirror=True)
        t, obj = rooms.scene.intersect(np.array([3.0, 2.7, 1.0]), np.array([1.0, 0.0, 0.0]))
        self.assertEqual(obj, rooms.mirror_object)
        self.assertAlmostEqual(t, 1.1)
        self.assertAlmostEqual(rooms.mirror.min[0], 4.1)

    def test_glint_and_robot_body_are_off_by_default_and_change_mirror_scans(self):
        rooms = iv.make_symmetric_rooms(mirror=True)
        rig = iv.SensorRig.mobile_base()
        body = np.eye(4)
        body[:3, 3] = (3.4, 2.7, 0.0)  # the front camera 0.4 m before the mirror, facing it
        plain = iv.simulate_rig(rig, rooms.scene, body, seed=4)
        off = iv.simulate_rig(rig, rooms.scene, body, seed=4, glint=False, robot_body=None)
        for x, y in zip(plain, off):
            np.testing.assert_array_equal(x, y)
        glint = iv.simulate_rig(rig, rooms.scene, body, seed=4, glint=True, glint_angle=np.radians(3.0))
        robot = iv.simulate_rig(rig, rooms.scene, body, seed=4, robot_body=iv.RobotBody.mobile_base())
        self.assertFalse(np.array_equal(plain[1], glint[1]))
        self.assertFalse(np.array_equal(plain[1], robot[1]))
        src = iv.SimulatedRig(rooms.scene, rig, seed=4, glint=True, robot_body=iv.RobotBody.mobile_base(height=0.7))
        self.assertEqual(len(src(body)[0]), rig.beam_count())
        imgs = iv.simulate_images(rig, rooms.scene, body, seed=4, robot_body=iv.RobotBody(((-0.3, -0.2, 0.0), (0.3, 0.2, 0.6))))
        self.assertEqual(len(imgs), 8)
        with self.assertRaisesRegex(ValueError, "glint_angle"):
            iv.simulate_rig(rig, rooms.scene, body, seed=4, glint=True, glint_angle=-1.0)
        with self.assertRaisesRegex(ValueError, "height"):
            iv.RobotBody.mobile_base(height=0.0)

    def test_bad_input_raises_value_error(self):
        with self.assertRaisesRegex(ValueError, "fov_x"):
            iv.DepthCamera.make(32, 24, 0.0, 1.0, 0.1, 4.0)
        with self.assertRaisesRegex(ValueError, "p_return"):
            iv.Material.absorbing(p_return=2.0)
        bad = np.eye(4)
        bad[:3, :3] *= 2
        with self.assertRaisesRegex(ValueError, "rigid"):
            iv.simulate(iv.DepthCamera.o3d100(), wall_scene(), bad, seed=1)
        with self.assertRaisesRegex(ValueError, "radius"):
            iv.Scene().add_sphere((0, 0, 0), -1.0)


if __name__ == "__main__":
    unittest.main()
