"""Replay of ROS 1 bags into Intervox grids, in Python (Debian's python3-rosbag and python3-tf2; no
ROS master).

``replay_bag(path, grid, topic)`` inserts the ``sensor_msgs/PointCloud2`` or ``sensor_msgs/Image``
messages of one topic into any Intervox grid, each seen from the pose of its frame in the map frame
at its stamp, from a tf2 buffer (``tf2_py.BufferCore``) filled with the bag's ``/tf`` and
``/tf_static``. It follows the rules of the C++ tool ``intervox_bag`` (docs/ros.md): depth images in
``16UC1`` are millimetres (0 = no measurement), ``32FC1`` metres (+inf = no return); other
encodings, short data, missing transforms and depth images before any ``CameraInfo`` are refused
and counted, never raised. The sensor messages' classes come from the bag itself (rosbag builds
them from the stored definitions); the transforms go through Debian's tf2_msgs and geometry_msgs.
"""

import time

import numpy as np

__all__ = ["replay_bag"]

_PROBLEMS = ("bad_encoding", "size_mismatch", "missing_transform", "no_camera_info", "insert_failed")

# tf2 keeps its cache length as a ros::Duration, whose seconds are a signed 32-bit integer: beyond
# that, tf2_py.BufferCore's C++ constructor throws an exception that nothing catches, and the
# interpreter aborts (exit 134).
_MAX_TF_CACHE_S = 2 ** 31 - 1


class _Refused(Exception):
    def __init__(self, kind, what):
        super().__init__(what)
        self.kind = kind


def _transform_buffer(bag, topics):
    """A tf2 buffer (``tf2_py.BufferCore``, Debian's python3-tf2) filled from the ``tf2_msgs/TFMessage``
    messages of ``topics`` of ``bag``, as ``intervox_bag`` fills its ``tf2::BufferCore``: a cache
    that holds the whole bag (its duration and 10 s), static transforms from topics named
    ``tf_static``, messages of another definition (MD5 sum) skipped."""
    import genpy
    import rosbag
    import rospy  # python3-rospy: tf2_py imports it itself, for rospy.Time and rospy.Duration
    import tf2_py
    from tf2_msgs.msg import TFMessage

    try:
        start, end = bag.get_start_time(), bag.get_end_time()
    except rosbag.ROSBagException:  # a bag without messages has no start and end
        start = end = 0.0
    span = end - start
    if not span + 10.0 < _MAX_TF_CACHE_S:
        raise ValueError(
            "the bag's messages span %.0f s (from %.3f s to %.3f s), more than a tf2 buffer can hold (2^31 - 1 s: "
            "Duration is out of dual 32-bit range); its message times are corrupt or come from different clocks"
            % (span, start, end))
    buffer = tf2_py.BufferCore(rospy.Duration.from_sec(span + 10.0))
    if topics:
        # The raw bytes into Debian's own TFMessage class: tf2_py wants real geometry_msgs classes,
        # not the ones rosbag generates from the bag's stored definitions.
        for t, (_, data, md5sum, _, _), _ in bag.read_messages(topics=topics, raw=True):
            if md5sum != TFMessage._md5sum:
                continue
            is_static = "tf_static" in t
            try:
                transforms = TFMessage().deserialize(data).transforms
            except genpy.DeserializationError:
                continue  # a corrupt message: its transforms are unknown, as those of a missing one
            for transform in transforms:
                if is_static:
                    buffer.set_transform_static(transform, "bag")
                else:
                    buffer.set_transform(transform, "bag")
    return buffer


def _lookup_pose(buffer, target, source, stamp):
    """The 4 x 4 pose of frame ``source`` in frame ``target`` at ``stamp`` (a rospy / genpy Time),
    from tf2 (interpolated between samples, no extrapolation). Raises _Refused
    ("missing_transform") with tf2's message when tf2 cannot give it or it is not finite."""
    import tf2_py
    from scipy.spatial.transform import Rotation

    try:
        t = buffer.lookup_transform_core(target, source, stamp).transform
    except tf2_py.TransformException as e:
        raise _Refused("missing_transform", "no transform '%s' <- '%s': %s" % (target, source, e))
    q, v = t.rotation, t.translation
    pose = np.eye(4)
    pose[:3, 3] = (v.x, v.y, v.z)
    quat = np.array([q.x, q.y, q.z, q.w])
    if not (np.all(np.isfinite(quat)) and np.all(np.isfinite(pose)) and np.any(quat != 0)):
        raise _Refused("missing_transform", "transform of '%s' is not finite" % source)
    pose[:3, :3] = Rotation.from_quat(quat).as_matrix()
    return pose


_FLOAT_TYPES = {7: "f4", 8: "f8"}  # sensor_msgs/PointField FLOAT32, FLOAT64


def cloud_points(cloud):
    """The (N, 3) float64 points of a sensor_msgs/PointCloud2 (width x height, row-major; NaN kept)."""
    fields = {f.name: f for f in cloud.fields}
    if not all(a in fields for a in "xyz"):
        raise _Refused("bad_encoding", "point cloud without the fields x, y and z")
    order = ">" if cloud.is_bigendian else "<"
    names, formats, offsets = [], [], []
    for a in "xyz":
        f = fields[a]
        if f.datatype not in _FLOAT_TYPES or f.count != 1:
            raise _Refused("bad_encoding", "point cloud field '%s' is not one FLOAT32 or FLOAT64" % a)
        size = 4 if f.datatype == 7 else 8
        if f.offset + size > cloud.point_step:
            raise _Refused("size_mismatch", "point cloud field '%s' beyond point_step" % a)
        names.append(a)
        formats.append(order + _FLOAT_TYPES[f.datatype])
        offsets.append(f.offset)
    w, h, step, row = cloud.width, cloud.height, cloud.point_step, cloud.row_step
    data = cloud.data if isinstance(cloud.data, (bytes, bytearray)) else bytes(cloud.data)
    if w * h == 0:
        return np.zeros((0, 3))
    if row < w * step or len(data) < (h - 1) * row + w * step:
        raise _Refused("size_mismatch", "point cloud of %d x %d points needs more than its %d bytes" % (w, h, len(data)))
    dtype = np.dtype({"names": names, "formats": formats, "offsets": offsets, "itemsize": step})
    rows = [np.frombuffer(data, dtype=dtype, count=w, offset=v * row) for v in range(h)]
    pts = np.concatenate(rows) if h > 1 else rows[0]
    return np.stack([pts["x"], pts["y"], pts["z"]], axis=1).astype(np.float64)


def depth_array(image):
    """The (H, W) depth of a sensor_msgs/Image and its scale (metres per unit): 16UC1 / mono16 in
    millimetres (uint16, scale 0.001), 32FC1 in metres (float32, scale None)."""
    if image.encoding in ("16UC1", "mono16"):
        dt, size, scale = "u2", 2, 0.001
    elif image.encoding == "32FC1":
        dt, size, scale = "f4", 4, None
    else:
        raise _Refused("bad_encoding", "depth image encoding '%s' (expected 16UC1 in mm or 32FC1 in m)" % image.encoding)
    w, h, step = image.width, image.height, image.step
    data = image.data if isinstance(image.data, (bytes, bytearray)) else bytes(image.data)
    if step < w * size or len(data) < (h - 1) * step + w * size:
        raise _Refused("size_mismatch", "depth image of %d x %d pixels needs more than its %d bytes" % (w, h, len(data)))
    dtype = np.dtype((">" if image.is_bigendian else "<") + dt)
    rows = [np.frombuffer(data, dtype=dtype, count=w, offset=v * step) for v in range(h)]
    return np.ascontiguousarray(np.stack(rows).astype(dtype.newbyteorder("="))), scale


def replay_bag(path, grid, topic, *, frame_id="map", camera_info_topic=None, max_range=5.0, min_range=0.0,
               threads=1, progress=False):
    """Inserts the point clouds or depth images of ``topic`` of the ROS 1 bag at ``path`` into ``grid``
    (any Intervox grid), each from the pose of its frame in ``frame_id`` at its header stamp (the bag
    time when the stamp is zero), from the bag's /tf and /tf_static.

    camera_info_topic: the CameraInfo topic of a depth image topic (default: its namespace +
    "/camera_info"); the latest CameraInfo before each image gives the intrinsics (K; distortion is
    ignored). max_range, min_range and threads as ``grid.insert_point_cloud``. progress: print a
    progress line with the time left to stderr.

    Returns a dict: ``inserted`` (messages), ``messages`` (of the topic), ``rays``, ``invalid_points``
    (NaN points and invalid pixels skipped), ``refused`` (counts per kind: bad_encoding,
    size_mismatch, missing_transform, no_camera_info, insert_failed; each message refused is
    counted, never raised; one whose data cannot be deserialized counts as size_mismatch). Raises
    ValueError if the topic is not in the bag or holds another type, if the bag's messages span more
    than a tf2 buffer holds (2^31 - 1 s: corrupt or mixed clocks; tf2 would abort the interpreter),
    or if the file is no bag or a corrupt one whose headers are not UTF-8 (naming the file; other
    corruption raises rosbag's ROSBagException), ImportError if rosbag or tf2_py (Debian:
    python3-rosbag, python3-tf2, python3-tf2-msgs) is missing.
    """
    # Debian's python3-rosbag and python3-tf2, imported here so that `import intervox` never needs them.
    import rosbag
    import tf2_py  # noqa: F401  (missing: ImportError before the bag is read)
    from intervox import PinholeIntrinsics

    try:
        return _replay(rosbag, PinholeIntrinsics, path, grid, topic, frame_id, camera_info_topic, max_range,
                       min_range, threads, progress)
    except UnicodeDecodeError as e:
        # rosbag decodes the version line and every record header's field names and topics as
        # UTF-8: bytes that are not are a file that is no bag, or a corrupt one.
        raise ValueError("'%s' is not a ROS bag, or a corrupt one: a header holds bytes that are not UTF-8 (%s)"
                         % (path, e)) from e


def _replay(rosbag, PinholeIntrinsics, path, grid, topic, frame_id, camera_info_topic, max_range, min_range, threads,
            progress):
    """replay_bag's work (its arguments, and the modules it imported)."""
    import genpy
    import sys

    with rosbag.Bag(path, "r") as bag:
        info = bag.get_type_and_topic_info()
        topics = info.topics
        if topic not in topics:
            raise ValueError("the topic '%s' is not in the bag '%s'; its topics: %s" % (
                topic, path, ", ".join("%s (%s)" % (t, v.msg_type) for t, v in sorted(topics.items())) or "none"))
        kind = topics[topic].msg_type
        if kind not in ("sensor_msgs/PointCloud2", "sensor_msgs/Image"):
            raise ValueError("the topic '%s' holds %s (expected sensor_msgs/PointCloud2 or sensor_msgs/Image)" % (topic, kind))
        is_cloud = kind == "sensor_msgs/PointCloud2"
        if not is_cloud and camera_info_topic is None:
            camera_info_topic = topic.rsplit("/", 1)[0] + "/camera_info"

        tf = _transform_buffer(bag, [t for t in ("/tf", "/tf_static", "tf", "tf_static") if t in topics])

        result = {"inserted": 0, "messages": topics[topic].message_count, "rays": 0, "invalid_points": 0,
                  "refused": {k: 0 for k in _PROBLEMS}}
        camera = None
        start = time.monotonic()
        done = 0
        read = [topic] + ([camera_info_topic] if camera_info_topic else [])
        # Raw, and each message deserialized here: a corrupt one (data shorter than its fields) is
        # refused and counted, and the replay goes on. (Strings that are not UTF-8 are read with
        # replacement characters, genpy's rule.)
        for t, (_, data, _, _, pytype), bag_time in bag.read_messages(topics=read, raw=True):
            try:
                msg = pytype().deserialize(data)
            except genpy.DeserializationError:
                if t == topic:
                    done += 1
                    result["refused"]["size_mismatch"] += 1
                continue
            if t != topic:
                camera = msg
                continue
            done += 1
            stamp = msg.header.stamp if not msg.header.stamp.is_zero() else bag_time
            try:
                if not is_cloud:
                    depth, scale = depth_array(msg)  # encoding and size first
                    if camera is None:
                        raise _Refused("no_camera_info", "depth image before any message on " + camera_info_topic)
                    if (camera.width, camera.height) != (msg.width, msg.height):
                        raise _Refused("size_mismatch", "depth image and camera info differ in size")
                pose = _lookup_pose(tf, frame_id, msg.header.frame_id, stamp)
                try:
                    if is_cloud:
                        pts = cloud_points(msg)
                        world = pts @ pose[:3, :3].T + pose[:3, 3]
                        st = grid.insert_point_cloud(world, pose[:3, 3].copy(), max_range=max_range,
                                                     min_range=min_range, threads=threads)
                    else:
                        k = camera.K
                        intr = PinholeIntrinsics(camera.width, camera.height, k[0], k[4], k[2], k[5])
                        kwargs = {"depth_scale": scale} if scale is not None else {}
                        st = grid.insert_depth_image(depth, intr, pose, max_range=max_range, min_range=min_range,
                                                     threads=threads, **kwargs)
                except ValueError as e:
                    raise _Refused("insert_failed", str(e))
                result["inserted"] += 1
                result["rays"] += st.rays
                result["invalid_points"] += st.skipped_invalid
            except _Refused as e:
                result["refused"][e.kind] += 1
            if progress:
                s = time.monotonic() - start
                n = max(1, result["messages"])
                left = s * (n - done) / done
                sys.stderr.write("\r%3.0f %% %d/%d messages, %.1f s, about %.1f s left " % (100.0 * done / n, done, n, s, left))
                if done == n:
                    sys.stderr.write("\n")
        return result
