"""intervox.ros_bag.replay_bag: a bag written with Debian's python3-rosbag (point clouds, depth images,
/tf and /tf_static) replays into the same grid as inserting the same data directly."""

import importlib
import importlib.util
import os
import tempfile
import unittest

import numpy as np

import intervox as iv

try:
    import rosbag
    import rospy
    from geometry_msgs.msg import TransformStamped
    from sensor_msgs.msg import CameraInfo, Image, PointCloud2, PointField
    from tf2_msgs.msg import TFMessage
    import tf2_py  # noqa: F401  (replay_bag's tf2 buffer)
    _SKIP = None
except ImportError as e:  # pragma: no cover - depends on the machine
    _SKIP = ("ROS 1 Python packages not importable (%s): install python3-rosbag, python3-sensor-msgs, "
             "python3-tf2-msgs, python3-geometry-msgs, python3-tf2 (scripts/setup.sh, INTERVOX_ROS_PACKAGES) "
             "and run with Debian's /usr/bin/python3" % e)


def _ros_bag_module():
    """intervox.ros_bag from the build folder, or from the source tree when the build folder was
    assembled before ros_bag.py existed (python/CMakeLists.txt copies it on the next build)."""
    try:
        return importlib.import_module("intervox.ros_bag")
    except ImportError:
        here = os.path.dirname(os.path.abspath(__file__))
        path = os.path.join(here, "..", "..", "python", "intervox", "ros_bag.py")
        spec = importlib.util.spec_from_file_location("intervox.ros_bag", path)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        return module


def _transform(parent, child, stamp, t, q):
    m = TransformStamped()
    m.header.frame_id = parent
    m.header.stamp = stamp
    m.child_frame_id = child
    m.transform.translation.x, m.transform.translation.y, m.transform.translation.z = t
    (m.transform.rotation.x, m.transform.rotation.y, m.transform.rotation.z,
     m.transform.rotation.w) = q
    return m


def _cloud(points, frame, stamp):
    c = PointCloud2()
    c.header.frame_id = frame
    c.header.stamp = stamp
    c.height, c.width = 1, len(points)
    c.fields = [PointField(name=n, offset=4 * i, datatype=PointField.FLOAT32, count=1) for i, n in enumerate("xyz")]
    c.is_bigendian = False
    c.point_step, c.row_step = 12, 12 * len(points)
    c.is_dense = False
    c.data = np.asarray(points, dtype="<f4").tobytes()
    return c


def _depth(mm, frame, stamp, encoding="16UC1"):
    img = Image()
    img.header.frame_id = frame
    img.header.stamp = stamp
    img.height, img.width = mm.shape
    img.encoding = encoding
    img.is_bigendian = False
    img.step = 2 * img.width
    img.data = mm.astype("<u2").tobytes()
    return img


def _pose(t, q):
    x, y, z, w = q
    m = np.eye(4)
    m[:3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                 [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                 [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    m[:3, 3] = t
    return m


@unittest.skipIf(_SKIP is not None, _SKIP or "")
class ReplayBag(unittest.TestCase):
    # Quarter-turn rotations and dyadic offsets: every pose product is exact, so the replay's
    # poses equal the ones composed here bit for bit.
    SENSOR = ((0.25, 0.0, 0.5), (0.0, 0.0, 1.0, 0.0))       # base_link -> sensor, yaw 180 deg
    CAMERA = ((0.125, 0.0, 0.75), (-0.5, 0.5, -0.5, 0.5))   # base_link -> camera (optical), along base x
    BASE = [(0.0, 0.0, 0.0), (0.5, 0.0, 0.0), (1.0, 0.25, 0.0)]    # map -> base_link at 1, 2, 3 s
    BASE_AT_2_5 = (0.75, 0.125, 0.0)
    STAMPS = [rospy.Time(1), rospy.Time(2), rospy.Time(3), rospy.Time(2, 500000000)] if _SKIP is None else []
    # map -> turntable at 1, 2, 3 s: yaw 0, 90 and 180 degrees (slerp between them).
    TURNTABLE = [(0.0, 0.0, 0.0, 1.0), (0.0, 0.0, np.sqrt(0.5), np.sqrt(0.5)), (0.0, 0.0, 1.0, 0.0)]

    @classmethod
    def setUpClass(cls):
        cls.ros_bag = _ros_bag_module()
        cls.tmp = tempfile.TemporaryDirectory()
        cls.path = os.path.join(cls.tmp.name, "test.bag")
        k = iv.PinholeIntrinsics.from_fov(32, 24, np.radians(60), np.radians(45))
        cls.intrinsics = k
        info = CameraInfo()
        info.header.frame_id = "camera"
        info.width, info.height = 32, 24
        info.K = [k.fx, 0.0, k.cx, 0.0, k.fy, k.cy, 0.0, 0.0, 1.0]
        cls.clouds, cls.images, cls.sensor_poses, cls.camera_poses = [], [], [], []
        with rosbag.Bag(cls.path, "w") as bag:
            tf_static = TFMessage(transforms=[
                _transform("base_link", "sensor", rospy.Time(1), *cls.SENSOR),
                _transform("base_link", "camera", rospy.Time(1), *cls.CAMERA)])
            bag.write("/tf_static", tf_static, rospy.Time(1))
            bag.write("/camera/depth/camera_info", info, rospy.Time(0, 500000000))
            for i, b in enumerate(cls.BASE):
                stamp = rospy.Time(1 + i)
                bag.write("/tf", TFMessage(transforms=[
                    _transform("map", "base_link", stamp, b, (0, 0, 0, 1)),
                    _transform("map", "turntable", stamp, (0, 0, 0), cls.TURNTABLE[i])]), stamp)
            # The scans at the /tf samples (1, 2, 3 s) and one between them (2.5 s: the base
            # interpolated half-way between its samples, exactly (0.75, 0.125, 0)).
            for i, (stamp, b) in enumerate(zip(cls.STAMPS, cls.BASE + [cls.BASE_AT_2_5])):
                base = _pose(b, (0, 0, 0, 1))
                sensor = base @ _pose(*cls.SENSOR)
                camera = base @ _pose(*cls.CAMERA)
                # A wall at x = -1.5 m of the map behind the sensor, and a NaN point.
                yy, zz = np.meshgrid(np.arange(-10, 11) * 0.1 + 0.013, np.arange(0, 16) * 0.1 + 0.027)
                wall = np.stack([np.full(yy.size, -1.5), yy.ravel(), zz.ravel(), np.ones(yy.size)])
                pts = (np.linalg.inv(sensor) @ wall)[:3].T
                pts = np.vstack([pts, [np.nan, 0.0, 0.0]]).astype(np.float32)
                cloud = _cloud(pts, "sensor", stamp)
                bag.write("/cloud", cloud, stamp)
                mm = np.full((24, 32), 2875 - int(1000 * b[0]), dtype=np.uint16)  # a wall at x = 3 m
                mm[4, 3] = 0  # no measurement
                bag.write("/camera/depth/image", _depth(mm, "camera", stamp), stamp)
                cls.clouds.append(pts.astype(np.float64))
                cls.images.append(mm)
                cls.sensor_poses.append(sensor)
                cls.camera_poses.append(camera)
            # A depth image in another encoding: refused and counted.
            bag.write("/camera/depth/image", _depth(np.zeros((24, 32)), "camera", rospy.Time(3), "rgb8"), rospy.Time(3))
            # A cloud after the last /tf sample: tf2 does not extrapolate, refused as missing_transform.
            late = rospy.Time(3, 500000000)
            bag.write("/cloud", _cloud(cls.clouds[0].astype(np.float32), "sensor", late), late)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_point_clouds_equal_direct_insertion(self):
        for grid_type in (iv.BayesGrid, iv.IntervalGrid):
            grid = grid_type(0.1)
            result = self.ros_bag.replay_bag(self.path, grid, "/cloud", max_range=5.0)
            self.assertEqual(result["messages"], 5)
            self.assertEqual(result["inserted"], 4)
            self.assertEqual(result["invalid_points"], 4)
            self.assertEqual(result["refused"]["missing_transform"], 1)  # the late cloud
            self.assertEqual(sum(result["refused"].values()), 1)
            direct = grid_type(0.1)
            for pts, pose in zip(self.clouds, self.sensor_poses):
                direct.insert_point_cloud(pts @ pose[:3, :3].T + pose[:3, 3], pose[:3, 3].copy(), max_range=5.0)
            self.assertGreater(direct.counts().occupied + direct.counts().unknown, 0)
            if grid_type is iv.BayesGrid:
                self.assertGreater(direct.counts().occupied, 0)  # three hits: occupied for Bayes
            self.assertEqual(grid.to_bytes(), direct.to_bytes())

    def test_depth_images_equal_direct_insertion(self):
        grid = iv.BayesGrid(0.1)
        result = self.ros_bag.replay_bag(self.path, grid, "/camera/depth/image", max_range=5.0)
        self.assertEqual(result["inserted"], 4)
        self.assertEqual(result["refused"]["bad_encoding"], 1)
        self.assertEqual(sum(result["refused"].values()), 1)
        self.assertEqual(result["invalid_points"], 4)
        direct = iv.BayesGrid(0.1)
        for mm, pose in zip(self.images, self.camera_poses):
            direct.insert_depth_image(mm, self.intrinsics, pose, max_range=5.0, depth_scale=0.001)
        self.assertGreater(direct.counts().occupied, 0)
        self.assertEqual(grid.to_bytes(), direct.to_bytes())

    def test_missing_transforms_are_counted(self):
        grid = iv.BayesGrid(0.1)
        result = self.ros_bag.replay_bag(self.path, grid, "/cloud", frame_id="elsewhere")
        self.assertEqual(result["inserted"], 0)
        self.assertEqual(result["refused"]["missing_transform"], 5)
        self.assertEqual(grid.observed_count(), 0)

    def test_tf2_lookup_interpolates_and_refuses(self):
        # The tf2 buffer replay_bag fills: slerp between samples of a turning frame, static frames
        # chained to moving ones, and tf2's refusals (extrapolation, unknown frames, leading '/'),
        # as intervox_bag's tf2::BufferCore.
        with rosbag.Bag(self.path) as bag:
            tf = self.ros_bag._transform_buffer(bag, ["/tf", "/tf_static"])
        for stamp, yaw in ((rospy.Time(1), 0.0), (rospy.Time(1, 500000000), 45.0), (rospy.Time(2), 90.0),
                           (rospy.Time(2, 500000000), 135.0), (rospy.Time(3), 180.0)):
            c, s = np.cos(np.radians(yaw)), np.sin(np.radians(yaw))
            expect = np.eye(4)
            expect[:2, :2] = [[c, -s], [s, c]]
            np.testing.assert_allclose(self.ros_bag._lookup_pose(tf, "map", "turntable", stamp), expect, atol=1e-12)
        np.testing.assert_array_equal(self.ros_bag._lookup_pose(tf, "map", "sensor", rospy.Time(2, 500000000)),
                                      _pose(self.BASE_AT_2_5, (0, 0, 0, 1)) @ _pose(*self.SENSOR))
        np.testing.assert_array_equal(self.ros_bag._lookup_pose(tf, "base_link", "camera", rospy.Time(100)),
                                      _pose(*self.CAMERA))  # static: at any time
        for target, source, stamp, message in (
                ("map", "sensor", rospy.Time(3, 500000000), "extrapolation"),
                ("map", "sensor", rospy.Time(0, 500000000), "extrapolation"),
                ("elsewhere", "sensor", rospy.Time(2), "does not exist"),
                ("map", "/sensor", rospy.Time(2), "cannot start with a '/'")):
            with self.assertRaisesRegex(self.ros_bag._Refused, message) as caught:
                self.ros_bag._lookup_pose(tf, target, source, stamp)
            self.assertEqual(caught.exception.kind, "missing_transform")

    def test_a_bag_spanning_more_than_2_31_seconds_raises_instead_of_aborting_the_interpreter(self):
        # tf2's buffer cannot hold such a span: its C++ constructor threw an error nothing caught,
        # and Python ended with exit 134.
        path = os.path.join(self.tmp.name, "span.bag")
        with rosbag.Bag(path, "w") as bag:
            first, last = rospy.Time(1), rospy.Time(3000000000)
            bag.write("/cloud", _cloud(self.clouds[0].astype(np.float32), "sensor", first), first)
            bag.write("/cloud", _cloud(self.clouds[0].astype(np.float32), "sensor", last), last)
        grid = iv.BayesGrid(0.1)
        with self.assertRaisesRegex(ValueError, r"span 2999999999 s .*out of dual 32-bit range"):
            self.ros_bag.replay_bag(path, grid, "/cloud")
        self.assertEqual(grid.observed_count(), 0)

    def test_a_corrupt_message_is_refused_and_counted_and_a_file_that_is_no_bag_is_named(self):
        import io
        path = os.path.join(self.tmp.name, "corrupt.bag")
        stamp = rospy.Time(2)
        good = _cloud(self.clouds[1].astype(np.float32), "sensor", stamp)
        buf = io.BytesIO()
        good.serialize(buf)
        with rosbag.Bag(path, "w") as bag:
            with rosbag.Bag(self.path) as source:
                for t, m, when in source.read_messages(topics=["/tf", "/tf_static"]):
                    bag.write(t, m, when)
            # The same cloud with its data cut short: its deserialization fails.
            bag.write("/cloud", ("sensor_msgs/PointCloud2", buf.getvalue()[:-100], PointCloud2._md5sum, PointCloud2),
                      stamp, raw=True)
            bag.write("/cloud", good, stamp)
        grid = iv.BayesGrid(0.1)
        result = self.ros_bag.replay_bag(path, grid, "/cloud", max_range=5.0)
        self.assertEqual(result["messages"], 2)
        self.assertEqual(result["inserted"], 1)
        self.assertEqual(result["refused"]["size_mismatch"], 1)
        self.assertGreater(grid.observed_count(), 0)
        # A file whose first line is not text (not a bag): a ValueError naming it, not the raw
        # UnicodeDecodeError of rosbag's version line.
        junk = os.path.join(self.tmp.name, "junk.bag")
        with open(junk, "wb") as f:
            f.write(b"\x89PNG\xff\xfe\n" + bytes(range(256)))
        with self.assertRaises(ValueError) as caught:
            self.ros_bag.replay_bag(junk, iv.BayesGrid(0.1), "/cloud")
        self.assertNotIsInstance(caught.exception, UnicodeDecodeError)
        self.assertIn(junk, str(caught.exception))
        self.assertIn("UTF-8", str(caught.exception))

    def test_missing_topic_raises(self):
        with self.assertRaisesRegex(ValueError, r"the topic '/nope' is not in the bag .*/cloud \(sensor_msgs/PointCloud2\)"):
            self.ros_bag.replay_bag(self.path, iv.BayesGrid(0.1), "/nope")
        with self.assertRaisesRegex(ValueError, r"holds tf2_msgs/TFMessage"):
            self.ros_bag.replay_bag(self.path, iv.BayesGrid(0.1), "/tf")


if __name__ == "__main__":
    unittest.main()
