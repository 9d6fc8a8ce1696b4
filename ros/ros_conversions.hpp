#pragma once
// Conversions between ROS 1 messages (Debian's ROS packages) and Intervox's own types: a
// sensor_msgs/PointCloud2 to points (core/point.hpp Point3), a sensor_msgs/Image with its
// CameraInfo to a DepthFrame (core/sensor_data.hpp: DepthImage in metres, PinholeIntrinsics), a
// geometry_msgs/Transform to a Pose, and the maps back to messages (centres as PointCloud2,
// occupied voxels as a MarkerArray, ColumnMap and ExplorationMap as nav_msgs/OccupancyGrid).
//
// C++20 and ROS 1 messages: the generated message headers name
// `ContainerAllocator::template rebind<T>::other`, which C++20 removed from std::allocator, so
// the messages with std::allocator<void> (sensor_msgs::PointCloud2 etc.) do not compile in a
// C++20 translation unit. ROS messages take their allocator as a template parameter; this header
// instantiates them with MsgAlloc (std::allocator plus the rebind member), which serialises to the
// same bytes with the same MD5 sums and type names, so nodes, bags and tools see ordinary
// messages. tf2's own API (which returns std::allocator messages) lives in the C++17 translation
// unit behind tf_poses.hpp.
#include "tf_poses.hpp"

#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/point.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/io/color.hpp>
#include <intervox/plan/exploration_map.hpp>

#include <ros/message_traits.h>
#include <ros/service_traits.h>

#include <geometry_msgs/Pose.h>
#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/OccupancyGrid.h>
#include <nav_msgs/Path.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/PointField.h>
#include <std_srvs/EmptyRequest.h>
#include <std_srvs/EmptyResponse.h>
#include <std_srvs/TriggerRequest.h>
#include <std_srvs/TriggerResponse.h>
#include <tf2_msgs/TFMessage.h>
#include <visualization_msgs/Marker.h>
#include <visualization_msgs/MarkerArray.h>

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace intervox_ros {

/// The allocator parameter of the messages: std::allocator with the rebind member the ROS 1
/// message headers (and ros/serialization.h's vector serialiser) need in C++20 (see above). It
/// rebinds char to std::allocator, so a message's strings are std::string; its arrays are
/// std::vector<T, MsgAlloc<T>>, which the serialiser requires.
template <class T>
struct MsgAlloc : std::allocator<T> {
  using value_type = T;
  MsgAlloc() noexcept = default;
  template <class U>
  MsgAlloc(const MsgAlloc<U>&) noexcept {}  // NOLINT: implicit, as std::allocator's
  template <class U>
  struct rebind {
    using other = std::conditional_t<std::is_same_v<U, char>, std::allocator<char>, MsgAlloc<U>>;
  };
};
template <class T, class U>
constexpr bool operator==(const MsgAlloc<T>&, const MsgAlloc<U>&) noexcept {
  return true;
}

namespace msg {
using A = MsgAlloc<void>;
using PointCloud2 = sensor_msgs::PointCloud2_<A>;
using PointField = sensor_msgs::PointField_<A>;
using Image = sensor_msgs::Image_<A>;
using CameraInfo = sensor_msgs::CameraInfo_<A>;
using Marker = visualization_msgs::Marker_<A>;
using MarkerArray = visualization_msgs::MarkerArray_<A>;
using OccupancyGrid = nav_msgs::OccupancyGrid_<A>;
using Path = nav_msgs::Path_<A>;
using PoseStamped = geometry_msgs::PoseStamped_<A>;
using PoseMsg = geometry_msgs::Pose_<A>;
using TransformStamped = geometry_msgs::TransformStamped_<A>;
using TFMessage = tf2_msgs::TFMessage_<A>;
using TriggerRequest = std_srvs::TriggerRequest_<A>;
using TriggerResponse = std_srvs::TriggerResponse_<A>;
using EmptyRequest = std_srvs::EmptyRequest_<A>;
using EmptyResponse = std_srvs::EmptyResponse_<A>;
}  // namespace msg

}  // namespace intervox_ros

// The service traits of std_srvs/Trigger and std_srvs/Empty for MsgAlloc requests and responses
// (the generated std_srvs/Trigger.h, which holds them for std::allocator, does not compile in
// C++20). The sums are those of the .srv files; a mismatch would make every call fail, which the
// node test (a C++17 client with the stock headers) would catch.
namespace ros::service_traits {
#define INTERVOX_ROS_SERVICE_TRAITS(Msg, md5, type)          \
  template <>                                                \
  struct MD5Sum<Msg> {                                       \
    static const char* value() { return md5; }               \
    static const char* value(const Msg&) { return value(); } \
  };                                                         \
  template <>                                                \
  struct DataType<Msg> {                                     \
    static const char* value() { return type; }              \
    static const char* value(const Msg&) { return value(); } \
  };
INTERVOX_ROS_SERVICE_TRAITS(intervox_ros::msg::TriggerRequest, "937c9679a518e3a18d831e57125ea522", "std_srvs/Trigger")
INTERVOX_ROS_SERVICE_TRAITS(intervox_ros::msg::TriggerResponse, "937c9679a518e3a18d831e57125ea522", "std_srvs/Trigger")
INTERVOX_ROS_SERVICE_TRAITS(intervox_ros::msg::EmptyRequest, "d41d8cd98f00b204e9800998ecf8427e", "std_srvs/Empty")
INTERVOX_ROS_SERVICE_TRAITS(intervox_ros::msg::EmptyResponse, "d41d8cd98f00b204e9800998ecf8427e", "std_srvs/Empty")
#undef INTERVOX_ROS_SERVICE_TRAITS
}  // namespace ros::service_traits

namespace intervox_ros {

namespace iv = intervox;

/// Why a message was refused (the node and the bag tool count them per kind).
enum class Problem : std::uint8_t {
  Encoding,      ///< an image encoding other than 16UC1 / 32FC1, a cloud without float x, y, z, wrong endianness
  Size,          ///< data shorter than the header says, image and camera info of different sizes, bad intrinsics
  Transform,     ///< no transform to the map frame at the message's stamp, or a transform that is not finite
  NoCameraInfo,  ///< a depth image before any CameraInfo of its camera
  Insert,        ///< the insertion refused the scan (e.g. over the insertion budget)
};
inline constexpr std::size_t kProblemKinds = 5;
inline const char* problem_name(Problem p) noexcept {
  switch (p) {
    case Problem::Encoding:
      return "bad_encoding";
    case Problem::Size:
      return "size_mismatch";
    case Problem::Transform:
      return "missing_transform";
    case Problem::NoCameraInfo:
      return "no_camera_info";
    case Problem::Insert:
      return "insert_failed";
  }
  return "?";
}

/// A message that cannot be used, with the kind of problem.
class BadMessage : public std::runtime_error {
 public:
  BadMessage(Problem kind, const std::string& what) : std::runtime_error(what), kind_(kind) {}
  Problem kind() const noexcept { return kind_; }

 private:
  Problem kind_;
};

namespace detail {
inline bool host_is_big_endian() noexcept { return std::endian::native == std::endian::big; }
template <class T>
T read_unaligned(const std::uint8_t* p) noexcept {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return v;
}
}  // namespace detail

/// The points of a PointCloud2 in its own frame (header.frame_id), in row-major order: the
/// FLOAT32 or FLOAT64 fields x, y and z of every point (organised clouds: width x height points).
/// NaN and infinite points are kept (insertion skips and counts them; count_invalid() counts them).
/// \throws BadMessage (Encoding) without float fields x, y, z or with the other byte order;
///         (Size) if point_step, row_step or the data are too short for width x height points.
template <class A>
std::vector<iv::Point3> cloud_points(const sensor_msgs::PointCloud2_<A>& cloud) {
  if (static_cast<bool>(cloud.is_bigendian) != detail::host_is_big_endian())
    throw BadMessage(Problem::Encoding, "point cloud in the other byte order");
  int offset[3] = {-1, -1, -1};
  std::uint8_t type[3] = {0, 0, 0};
  for (const auto& f : cloud.fields) {
    const int axis = f.name == "x" ? 0 : f.name == "y" ? 1 : f.name == "z" ? 2 : -1;
    if (axis < 0) continue;
    if (f.datatype != msg::PointField::FLOAT32 && f.datatype != msg::PointField::FLOAT64)
      throw BadMessage(Problem::Encoding, "point cloud field '" + f.name + "' is not FLOAT32 or FLOAT64");
    if (f.count != 1)
      throw BadMessage(Problem::Encoding, "point cloud field '" + f.name + "' has a count other than 1");
    offset[axis] = static_cast<int>(f.offset);
    type[axis] = f.datatype;
  }
  if (offset[0] < 0 || offset[1] < 0 || offset[2] < 0)
    throw BadMessage(Problem::Encoding, "point cloud without the fields x, y and z");
  const std::uint64_t w = cloud.width, h = cloud.height, step = cloud.point_step, row = cloud.row_step;
  for (int a = 0; a < 3; ++a) {
    const std::uint64_t size = type[a] == msg::PointField::FLOAT32 ? 4 : 8;
    if (static_cast<std::uint64_t>(offset[a]) + size > step)
      throw BadMessage(Problem::Size, "point cloud field beyond point_step " + std::to_string(step));
  }
  if (w > 0 && h > 0 && (row < w * step || cloud.data.size() < (h - 1) * row + w * step))
    throw BadMessage(Problem::Size, "point cloud of " + std::to_string(w) + " x " + std::to_string(h) + " points at " +
                                        std::to_string(step) + " bytes each (rows of " + std::to_string(row) +
                                        ") needs more than its " + std::to_string(cloud.data.size()) + " bytes");
  std::vector<iv::Point3> points;
  points.reserve(static_cast<std::size_t>(w * h));
  for (std::uint64_t v = 0; v < h; ++v) {
    for (std::uint64_t u = 0; u < w; ++u) {
      const std::uint8_t* p = cloud.data.data() + v * row + u * step;
      iv::Point3 q;
      for (int a = 0; a < 3; ++a)
        q[a] = type[a] == msg::PointField::FLOAT32 ? double(detail::read_unaligned<float>(p + offset[a]))
                                                   : detail::read_unaligned<double>(p + offset[a]);
      points.push_back(q);
    }
  }
  return points;
}

/// Number of points with a NaN or infinite coordinate.
inline std::size_t count_invalid(std::span<const iv::Point3> points) noexcept {
  std::size_t n = 0;
  for (const auto& p : points) n += p.allFinite() ? 0 : 1;
  return n;
}

/// A PointCloud2 of \p points (FLOAT32 fields x, y, z, 12 bytes per point, one row), e.g. the
/// centres of the occupied voxels.
inline msg::PointCloud2 make_cloud(std::span<const iv::Point3> points, const std::string& frame,
                                   const ros::Time& stamp) {
  msg::PointCloud2 c;
  c.header.frame_id = frame;
  c.header.stamp = stamp;
  c.height = 1;
  c.width = static_cast<std::uint32_t>(points.size());
  const char* names[3] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    msg::PointField f;
    f.name = names[a];
    f.offset = static_cast<std::uint32_t>(4 * a);
    f.datatype = msg::PointField::FLOAT32;
    f.count = 1;
    c.fields.push_back(f);
  }
  c.is_bigendian = detail::host_is_big_endian();
  c.point_step = 12;
  c.row_step = 12 * c.width;
  c.is_dense = count_invalid(points) == 0;
  c.data.resize(points.size() * 12);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const float xyz[3] = {float(points[i].x()), float(points[i].y()), float(points[i].z())};
    std::memcpy(c.data.data() + 12 * i, xyz, 12);
  }
  return c;
}

/// A depth image in metres (DepthImage value rules) from a sensor_msgs/Image:
///  - 16UC1 (also "mono16"): millimetres, as OpenNI and RealSense drivers publish; 0 is no
///    measurement (NaN, invalid);
///  - 32FC1: metres; NaN invalid, +inf no return (free up to the max range; REP 117), 0,
///    negative and -inf invalid.
/// \throws BadMessage (Encoding) for any other encoding or the other byte order; (Size) if step
///         or data are too short for width x height pixels.
template <class A>
iv::DepthImage depth_image(const sensor_msgs::Image_<A>& img) {
  const bool mm = img.encoding == "16UC1" || img.encoding == "mono16";
  const bool m = img.encoding == "32FC1";
  if (!mm && !m)
    throw BadMessage(Problem::Encoding,
                     "depth image encoding '" + img.encoding + "' (expected 16UC1 in mm or 32FC1 in m)");
  const std::size_t bytes = mm ? 2 : 4;
  if (img.width > 0 && static_cast<bool>(img.is_bigendian) != detail::host_is_big_endian())
    throw BadMessage(Problem::Encoding, "depth image in the other byte order");
  const std::uint64_t w = img.width, h = img.height;
  if (w > (1u << 16) || h > (1u << 16)) throw BadMessage(Problem::Size, "depth image larger than 65536 pixels a side");
  if (w > 0 && h > 0 && (img.step < w * bytes || img.data.size() < (h - 1) * img.step + w * bytes))
    throw BadMessage(Problem::Size, "depth image of " + std::to_string(w) + " x " + std::to_string(h) +
                                        " pixels (step " + std::to_string(img.step) + ") needs more than its " +
                                        std::to_string(img.data.size()) + " bytes");
  iv::DepthImage out(static_cast<int>(w), static_cast<int>(h));
  for (std::uint64_t v = 0; v < h; ++v) {
    const std::uint8_t* row = img.data.data() + v * img.step;
    for (std::uint64_t u = 0; u < w; ++u) {
      float z;
      if (mm) {
        const std::uint16_t raw = detail::read_unaligned<std::uint16_t>(row + 2 * u);
        z = raw == 0 ? std::numeric_limits<float>::quiet_NaN() : float(raw) * 0.001f;
      } else {
        z = detail::read_unaligned<float>(row + 4 * u);
      }
      out.at(static_cast<int>(u), static_cast<int>(v)) = z;
    }
  }
  return out;
}

/// Pinhole intrinsics from a CameraInfo: the size and K (fx = K[0], cx = K[2], fy = K[4],
/// cy = K[5]). Distortion is ignored (rectified depth images have none); binning and a region
/// of interest are refused.
/// \throws BadMessage (Size) for binning, a region of interest, or invalid intrinsics.
template <class A>
iv::PinholeIntrinsics intrinsics(const sensor_msgs::CameraInfo_<A>& info) {
  if (info.binning_x > 1 || info.binning_y > 1 || info.roi.width != 0 || info.roi.height != 0)
    throw BadMessage(Problem::Size, "camera info with binning or a region of interest (not supported)");
  iv::PinholeIntrinsics k;
  k.width = static_cast<int>(info.width);
  k.height = static_cast<int>(info.height);
  k.fx = info.K[0];
  k.cx = info.K[2];
  k.fy = info.K[4];
  k.cy = info.K[5];
  try {
    k.validate();
  } catch (const iv::InvalidArgument& e) {
    throw BadMessage(Problem::Size, std::string("camera info: ") + e.what());
  }
  return k;
}

/// The depth frame of \p img with the camera \p info seen from \p camera_pose (camera optical
/// frame to map), its max range unknown (+inf: the insertion's max range applies).
/// \throws BadMessage as depth_image() and intrinsics(), (Size) if image and camera info differ in
///         size, (Transform) for a pose that is not finite and rigid.
template <class A>
iv::DepthFrame depth_frame(const sensor_msgs::Image_<A>& img, const sensor_msgs::CameraInfo_<A>& info,
                           const iv::Pose& camera_pose) {
  iv::DepthFrame f;
  f.image = depth_image(img);
  f.intrinsics = intrinsics(info);
  if (f.image.width != f.intrinsics.width || f.image.height != f.intrinsics.height)
    throw BadMessage(Problem::Size, "depth image is " + std::to_string(f.image.width) + "x" +
                                        std::to_string(f.image.height) + " but its camera info " +
                                        std::to_string(f.intrinsics.width) + "x" + std::to_string(f.intrinsics.height));
  f.pose = camera_pose;
  try {
    f.validate();
  } catch (const iv::InvalidArgument& e) {
    throw BadMessage(Problem::Transform, e.what());
  }
  return f;
}

/// The Pose of a geometry_msgs/Transform (transform_to_pose() of tf_poses.hpp).
template <class A>
iv::Pose to_pose(const geometry_msgs::Transform_<A>& t) {
  return transform_to_pose(t);
}

/// A geometry_msgs/Pose of \p pose.
inline msg::PoseMsg to_pose_msg(const iv::Pose& pose) {
  msg::PoseMsg p;
  p.position.x = pose.translation().x();
  p.position.y = pose.translation().y();
  p.position.z = pose.translation().z();
  const Eigen::Quaterniond q(pose.linear());
  p.orientation.x = q.x();
  p.orientation.y = q.y();
  p.orientation.z = q.z();
  p.orientation.w = q.w();
  return p;
}

/// A TransformStamped parent -> child of \p pose (child to parent), e.g. for test publishers.
inline msg::TransformStamped to_transform_msg(const iv::Pose& pose, const std::string& parent, const std::string& child,
                                              const ros::Time& stamp) {
  msg::TransformStamped t;
  t.header.frame_id = parent;
  t.header.stamp = stamp;
  t.child_frame_id = child;
  const msg::PoseMsg p = to_pose_msg(pose);
  t.transform.translation.x = p.position.x;
  t.transform.translation.y = p.position.y;
  t.transform.translation.z = p.position.z;
  t.transform.rotation = p.orientation;
  return t;
}

/// The OccupancyGrid values of a column map (projected_map): occupied 100, free 0, unknown -1.
/// Cell (i, j) is data[j * width + i]; the origin is the corner of the map's first column at
/// height \p z.
inline msg::OccupancyGrid to_occupancy_grid(const iv::ColumnMap& map, const iv::GridGeometry& g, double z,
                                            const std::string& frame, const ros::Time& stamp) {
  msg::OccupancyGrid o;
  o.header.frame_id = frame;
  o.header.stamp = stamp;
  o.info.map_load_time = stamp;
  o.info.resolution = static_cast<float>(map.resolution());
  o.info.width = static_cast<std::uint32_t>(map.width());
  o.info.height = static_cast<std::uint32_t>(map.height());
  const iv::Point3 corner = g.corner(map.key_origin());
  o.info.origin.position.x = corner.x();
  o.info.origin.position.y = corner.y();
  o.info.origin.position.z = z;
  o.info.origin.orientation.w = 1.0;
  o.data.resize(map.size());
  for (std::size_t i = 0; i < map.size(); ++i) {
    const iv::Occupancy c = map.at(map.cell_of(i));
    o.data[i] = c == iv::Occupancy::Occupied ? 100 : c == iv::Occupancy::Free ? 0 : -1;
  }
  return o;
}

/// The OccupancyGrid value of an exploration-map label (docs/ros.md): unknown -1, occupied 100,
/// collision space 90, unknown in collision space 80, maybe-collision 70, unresolvable 60,
/// unreachable free 40, border (frontier) 10, reachable free 0.
inline std::int8_t exploration_value(iv::MapLabel l) noexcept {
  switch (l) {
    case iv::MapLabel::Unknown:
      return -1;
    case iv::MapLabel::Occupied:
      return 100;
    case iv::MapLabel::CollisionSpace:
      return 90;
    case iv::MapLabel::UnknownInCollision:
      return 80;
    case iv::MapLabel::MaybeCollision:
      return 70;
    case iv::MapLabel::Unresolvable:
      return 60;
    case iv::MapLabel::Unreachable:
      return 40;
    case iv::MapLabel::Border:
      return 10;
    case iv::MapLabel::ReachableFree:
      return 0;
  }
  return -1;
}

/// The exploration map as an OccupancyGrid (exploration_value() per cell).
inline msg::OccupancyGrid to_occupancy_grid(const iv::ExplorationMap& map, const iv::GridGeometry& g, double z,
                                            const std::string& frame, const ros::Time& stamp) {
  msg::OccupancyGrid o = to_occupancy_grid(map.columns(), g, z, frame, stamp);
  for (std::size_t i = 0; i < o.data.size(); ++i) o.data[i] = exploration_value(map.label(map.columns().cell_of(i)));
  return o;
}

/// The marker colours of the explained states, indexed by intervox::ExplainedState (unknown,
/// free, occupied, unexplained); chosen to stand out on RViz's dark background.
inline constexpr std::array<iv::Rgb, 4> kExplainedMarkerColours{{
    {200, 200, 200},  // unknown: light gray
    {255, 255, 255},  // explained free: white
    {40, 110, 230},   // explained occupied: blue
    {240, 130, 0},    // unexplained: orange
}};

/// The occupied voxels as one CUBE_LIST marker (namespace "occupied", id 0) of cubes of edge
/// \p resolution at \p centres with \p colours (one per centre), as octomap_server's
/// occupied_cells_vis_array; an empty list gives a DELETE marker.
inline msg::MarkerArray occupied_markers(std::span<const iv::Point3> centres, std::span<const iv::Rgb> colours,
                                         double resolution, const std::string& frame, const ros::Time& stamp) {
  msg::Marker m;
  m.header.frame_id = frame;
  m.header.stamp = stamp;
  m.ns = "occupied";
  m.id = 0;
  m.type = msg::Marker::CUBE_LIST;
  m.action = centres.empty() ? msg::Marker::DELETE : msg::Marker::ADD;
  m.pose.orientation.w = 1.0;
  m.scale.x = m.scale.y = m.scale.z = resolution;
  m.color.a = 1.0f;
  m.points.resize(centres.size());
  m.colors.resize(centres.size());
  for (std::size_t i = 0; i < centres.size(); ++i) {
    m.points[i].x = centres[i].x();
    m.points[i].y = centres[i].y();
    m.points[i].z = centres[i].z();
    m.colors[i].r = colours[i].r / 255.0f;
    m.colors[i].g = colours[i].g / 255.0f;
    m.colors[i].b = colours[i].b / 255.0f;
    m.colors[i].a = 1.0f;
  }
  msg::MarkerArray a;
  a.markers.push_back(std::move(m));
  return a;
}

}  // namespace intervox_ros
