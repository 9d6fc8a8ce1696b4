// The tf2 side of ros/tf_poses.hpp, compiled as C++17 (see ros/CMakeLists.txt).
#include "tf_poses.hpp"

#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <tf2/buffer_core.h>
#include <tf2/exceptions.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <stdexcept>
#include <vector>

namespace intervox_ros {
namespace {

class LiveTf final : public TfPoses {
 public:
  explicit LiveTf(double cache) : buffer_(ros::Duration(cache)), listener_(buffer_) {}
  bool lookup(const std::string& target, const std::string& source, const ros::Time& stamp, double timeout,
              Eigen::Isometry3d& pose, std::string& error) const override {
    try {
      const geometry_msgs::TransformStamped t = buffer_.lookupTransform(target, source, stamp, ros::Duration(timeout));
      pose = transform_to_pose(t.transform);
      return true;
    } catch (const tf2::TransformException& e) {
      error = e.what();
      return false;
    }
  }

 private:
  tf2_ros::Buffer buffer_;
  tf2_ros::TransformListener listener_;
};

class BagTf final : public TfPoses {
 public:
  explicit BagTf(const std::string& path) {
    rosbag::Bag bag;
    bag.open(path, rosbag::bagmode::Read);
    // The cache must hold the whole bag: its duration and a margin.
    rosbag::View all(bag);
    const double span = all.size() > 0 ? (all.getEndTime() - all.getBeginTime()).toSec() : 0.0;
    buffer_ = std::make_unique<tf2::BufferCore>(ros::Duration(span + 10.0));
    const std::vector<std::string> topics{"/tf", "/tf_static", "tf", "tf_static"};
    rosbag::View view(bag, rosbag::TopicQuery(topics));
    for (const rosbag::MessageInstance& m : view) {
      const tf2_msgs::TFMessage::ConstPtr msg = m.instantiate<tf2_msgs::TFMessage>();
      if (!msg) continue;
      const bool is_static = m.getTopic().find("tf_static") != std::string::npos;
      for (const geometry_msgs::TransformStamped& t : msg->transforms) {
        if (buffer_->setTransform(t, "bag", is_static)) ++read_;
      }
    }
    bag.close();
  }
  bool lookup(const std::string& target, const std::string& source, const ros::Time& stamp, double,
              Eigen::Isometry3d& pose, std::string& error) const override {
    try {
      pose = transform_to_pose(buffer_->lookupTransform(target, source, stamp).transform);
      return true;
    } catch (const tf2::TransformException& e) {
      error = e.what();
      return false;
    }
  }
  std::size_t transforms_read() const noexcept override { return read_; }

 private:
  std::unique_ptr<tf2::BufferCore> buffer_;
  std::size_t read_ = 0;
};

}  // namespace

std::unique_ptr<TfPoses> TfPoses::live(double cache_seconds) { return std::make_unique<LiveTf>(cache_seconds); }

std::unique_ptr<TfPoses> TfPoses::from_bag(const std::string& path) {
  try {
    return std::make_unique<BagTf>(path);
  } catch (const rosbag::BagException& e) {
    throw std::runtime_error("cannot read the transforms of '" + path + "': " + e.what());
  }
}

}  // namespace intervox_ros
