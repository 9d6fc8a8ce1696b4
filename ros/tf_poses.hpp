#pragma once
// Sensor poses from tf2, behind an interface that uses only Eigen and the standard library, so
// that it compiles both as C++17 and as C++20 (ros/CMakeLists.txt says why the tf2 side is a
// C++17 translation unit of its own: tf2's API returns geometry_msgs with std::allocator<void>,
// whose rebind C++20 removed). Eigen::Isometry3d is intervox::Pose (core/sensor_data.hpp).
#include <ros/time.h>

#include <Eigen/Geometry>

#include <cmath>
#include <memory>
#include <string>

namespace intervox_ros {

/// The pose (child to parent) of a geometry_msgs/Transform of any allocator: the one conversion
/// from a ROS transform to the library's Pose. The quaternion is normalised; a transform with a
/// NaN or infinite entry or a zero quaternion gives a pose that is not finite (callers check
/// pose_is_finite()).
template <class Transform>
Eigen::Isometry3d transform_to_pose(const Transform& t) {
  Eigen::Quaterniond q(t.rotation.w, t.rotation.x, t.rotation.y, t.rotation.z);
  const double n = q.norm();
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  if (!(std::isfinite(n) && n > 0)) {
    pose.matrix().setConstant(std::nan(""));
    return pose;
  }
  if (n != 1.0) q.coeffs() /= n;
  pose.linear() = q.toRotationMatrix();
  pose.translation() = Eigen::Vector3d(t.translation.x, t.translation.y, t.translation.z);
  return pose;
}

/// True if every entry of \p pose is finite.
inline bool pose_is_finite(const Eigen::Isometry3d& pose) { return pose.matrix().allFinite(); }

/// A tf2 buffer: either listening to /tf and /tf_static of a running ROS graph (live()), or
/// filled from the /tf and /tf_static messages of a bag (from_bag()).
class TfPoses {
 public:
  /// A buffer with a tf2_ros::TransformListener (needs ros::init and a node handle first).
  static std::unique_ptr<TfPoses> live(double cache_seconds = 10.0);
  /// A buffer holding every transform of the topics /tf and /tf_static of the bag at \p path
  /// (rosbag_storage), for lookups at any time within the bag.
  /// \throws std::runtime_error if the bag cannot be read.
  static std::unique_ptr<TfPoses> from_bag(const std::string& path);
  virtual ~TfPoses() = default;

  /// The pose of frame \p source in frame \p target at \p stamp (ros::Time(0): the latest),
  /// waiting up to \p timeout seconds for it (live buffers only). Returns false and sets \p error
  /// when there is none (unknown frame, extrapolation, ...).
  virtual bool lookup(const std::string& target, const std::string& source, const ros::Time& stamp, double timeout,
                      Eigen::Isometry3d& pose, std::string& error) const = 0;
  /// Number of transforms read from the bag (from_bag()); 0 for a live buffer.
  virtual std::size_t transforms_read() const noexcept { return 0; }
};

}  // namespace intervox_ros
