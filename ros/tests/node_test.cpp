// The node test's driver (run by run_node_test.sh, which starts a real rosmaster and
// intervox_server): publishes a static tf, two point clouds and a depth image, waits for the
// node's MarkerArray, PointCloud2 and OccupancyGrids and checks them against the same input
// inserted directly into the same grid type; then sends bad messages (wrong encoding, NaN points,
// a short cloud, an unknown frame, an image of the wrong size) and checks that the node survives
// and counts them; sends a cloud whose explained scratch exceeds the node's insertion budget
// (refused, insert_failed) and, with the node's memory limit lowered for it, a cloud the node
// cannot allocate (counted in callback_errors and logged; the node goes on); calls ~save_map and
// compares the saved file with the direct map, calls ~plan_next_view and ~reset.
//   node_test <call_service program> <work folder>
// The node runs with ~resolution 0.1, ~max_range 5, ~publish_rate 0, ~update interval-mean,
// ~utility max-entropy, ~save_path <work>/map, ~explained, ~insert_budget_mib 64; its process id is
// in <work>/server.pid.
#include "depth_image.hpp"
#include "ros_conversions.hpp"

#include <intervox/core/sensors.hpp>
#include <intervox/explain/explained_space.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/io/explained_file.hpp>
#include <intervox/io/grid_file.hpp>
#include <intervox/io/octomap.hpp>
#include <intervox/plan/exploration_map.hpp>
#include <intervox/raycast/insert.hpp>
#include <intervox/update/interval_update.hpp>
#include <intervox/utility/utility_policies.hpp>

#include <ros/ros.h>

#include <sys/resource.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace {

namespace iv = intervox;
namespace ir = intervox_ros;
namespace msg = intervox_ros::msg;
using Grid = iv::VoxelGrid<iv::IntervalUpdate<iv::MeanState>, iv::MaxEntropy>;

int failures = 0;
void check(bool ok, const std::string& what) {
  std::printf("%s: %s\n", ok ? "ok" : "FAILED", what.c_str());
  std::fflush(stdout);
  if (!ok) ++failures;
}

/// Spins until \p done() or \p seconds pass; returns done().
bool wait_for(const std::function<bool()>& done, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (ros::ok() && !done() && std::chrono::steady_clock::now() < end) {
    ros::spinOnce();
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return done();
}

/// Runs the call_service program; returns its output ("" if the call did not go through).
std::string call(const std::string& caller, const std::string& kind, const std::string& service) {
  const std::string cmd = "'" + caller + "' " + kind + " " + service;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return {};
  std::string out;
  char buf[512];
  while (std::fgets(buf, sizeof buf, p)) out += buf;
  const int status = pclose(p);
  return status == 0 ? out : std::string();
}

/// The value of "key=<number>" in a stats line (the key after a space or '='), or -1.
long long stat(const std::string& text, const std::string& key) {
  for (std::size_t at = text.find(key + "="); at != std::string::npos; at = text.find(key + "=", at + 1))
    if (at == 0 || text[at - 1] == ' ' || text[at - 1] == '=') return std::atoll(text.c_str() + at + key.size() + 1);
  return -1;
}

msg::PointCloud2 cloud_of(const std::vector<iv::Point3>& pts, const std::string& frame) {
  return ir::make_cloud(pts, frame, ros::Time::now());
}

/// The virtual memory size of process \p pid in bytes (VmSize of /proc/<pid>/status), or 0.
std::uint64_t vm_size(long pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("VmSize:", 0) == 0) return std::strtoull(line.c_str() + 7, nullptr, 10) * 1024;
  return 0;
}

/// Sets the soft address-space limit of process \p pid (the hard one stays); false on failure.
bool set_memory_limit(long pid, rlim_t soft) {
  rlimit old{};
  if (prlimit(static_cast<pid_t>(pid), RLIMIT_AS, nullptr, &old) != 0) return false;
  const rlimit now{soft, old.rlim_max};
  return prlimit(static_cast<pid_t>(pid), RLIMIT_AS, &now, nullptr) == 0;
}

std::vector<std::array<float, 3>> sorted_points(const std::vector<iv::Point3>& pts) {
  std::vector<std::array<float, 3>> v;
  for (const auto& p : pts) v.push_back({float(p.x()), float(p.y()), float(p.z())});
  std::sort(v.begin(), v.end());
  return v;
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "intervox_node_test", ros::init_options::NoRosout);
  if (argc != 3) {
    std::fprintf(stderr, "usage: node_test <call_service> <work folder>\n");
    return 2;
  }
  const std::string caller = argv[1], work = argv[2];
  if (!wait_for([] { return ros::master::check(); }, 20.0)) {
    std::fprintf(stderr, "node_test: no ROS master\n");
    return 1;
  }
  ros::NodeHandle nh;

  // Frames: map -> base_link (identity), base_link -> sensor (yaw 180 deg), base_link -> camera
  // (optical frame looking along the base's x axis). Dyadic values: tf2's chaining is exact here,
  // so the node's poses equal the ones composed below bit for bit.
  iv::Pose base = iv::Pose::Identity();
  iv::Pose sensor_mount = iv::Pose::Identity();
  sensor_mount.linear() = Eigen::Quaterniond(0.0, 0.0, 0.0, 1.0).toRotationMatrix();
  sensor_mount.translation() = iv::Point3(0.25, 0.0, 0.5);
  iv::Pose camera_mount = iv::Pose::Identity();
  camera_mount.linear() = Eigen::Quaterniond(0.5, -0.5, 0.5, -0.5).toRotationMatrix();
  camera_mount.translation() = iv::Point3(0.125, 0.0, 0.75);
  msg::TFMessage statics;
  statics.transforms.push_back(ir::to_transform_msg(base, "map", "base_link", ros::Time::now()));
  statics.transforms.push_back(ir::to_transform_msg(sensor_mount, "base_link", "sensor", ros::Time::now()));
  statics.transforms.push_back(ir::to_transform_msg(camera_mount, "base_link", "camera", ros::Time::now()));
  ros::Publisher tf_pub = nh.advertise<msg::TFMessage>("/tf_static", 1, true);
  tf_pub.publish(statics);
  // The poses the node gets: looked up with tf2 as the node does (tf2's chaining may differ from
  // an Eigen product in the last bit, which moves points that lie on voxel faces).
  const std::unique_ptr<ir::TfPoses> tf = ir::TfPoses::live();
  iv::Pose sensor, camera;
  std::string tf_error;
  const bool poses = tf->lookup("map", "sensor", ros::Time(0), 10.0, sensor, tf_error) &&
                     tf->lookup("map", "camera", ros::Time(0), 10.0, camera, tf_error);
  check(poses, "tf gives the sensor and camera poses " + tf_error);
  if (!poses) return 1;
  check((sensor.matrix() - (base * sensor_mount).matrix()).cwiseAbs().maxCoeff() < 1e-12 &&
            (camera.matrix() - (base * camera_mount).matrix()).cwiseAbs().maxCoeff() < 1e-12,
        "the tf poses are the published ones");

  ros::Publisher cloud_pub = nh.advertise<msg::PointCloud2>("cloud_in", 10);
  ros::Publisher image_pub = nh.advertise<msg::Image>("depth/image", 10);
  ros::Publisher info_pub = nh.advertise<msg::CameraInfo>("depth/camera_info", 10, true);

  boost::shared_ptr<const msg::MarkerArray> markers;
  boost::shared_ptr<const msg::PointCloud2> centres;
  boost::shared_ptr<const msg::OccupancyGrid> projected, exploration;
  boost::shared_ptr<const msg::PoseStamped> next_view;
  ros::Subscriber s1 =
      nh.subscribe<msg::MarkerArray>("occupied_cells_vis_array", 5, [&](const auto& m) { markers = m; });
  ros::Subscriber s2 =
      nh.subscribe<msg::PointCloud2>("octomap_point_cloud_centers", 5, [&](const auto& m) { centres = m; });
  ros::Subscriber s3 = nh.subscribe<msg::OccupancyGrid>("projected_map", 5, [&](const auto& m) { projected = m; });
  ros::Subscriber s4 = nh.subscribe<msg::OccupancyGrid>("exploration_map", 5, [&](const auto& m) { exploration = m; });
  ros::Subscriber s5 = nh.subscribe<msg::PoseStamped>("next_view", 5, [&](const auto& m) { next_view = m; });

  const std::string stats_srv = "/intervox_server/stats";
  std::string stats;
  const bool up = wait_for([&] { return ros::service::exists(stats_srv, false); }, 20.0) &&
                  wait_for(
                      [&] {
                        return cloud_pub.getNumSubscribers() > 0 && image_pub.getNumSubscribers() > 0 &&
                               info_pub.getNumSubscribers() > 0;
                      },
                      20.0);
  check(up, "intervox_server is up and subscribed");
  if (!up) return 1;

  // Input: a wall 2 m behind the sensor (its -x; the sensor looks back along -x of the base),
  // a second cloud with a box, a 32 x 24 depth image in millimetres of a plane 1.5 m ahead.
  std::vector<iv::Point3> wall, box;
  for (int j = -10; j <= 10; ++j)
    for (int k = -5; k <= 10; ++k) wall.emplace_back(-2.0, 0.1 * j + 0.013, 0.1 * k + 0.027);
  for (int j = 0; j < 6; ++j)
    for (int k = 0; k < 6; ++k) box.emplace_back(-1.2 + 0.05 * j, 0.6 + 0.04 * k, -0.3 + 0.02 * (j + k));
  msg::CameraInfo info;
  info.header.frame_id = "camera";
  info.width = 32;
  info.height = 24;
  const iv::PinholeIntrinsics k = iv::PinholeIntrinsics::from_fov(32, 24, iv::deg(60), iv::deg(45));
  info.K = {k.fx, 0.0, k.cx, 0.0, k.fy, k.cy, 0.0, 0.0, 1.0};
  msg::Image image = ir::test::depth_image_mm("camera", 32, 24, [](int u, int v) {
    return (u == 3 && v == 4) ? std::uint16_t{0} : static_cast<std::uint16_t>(1500 + 10 * u);
  });

  info_pub.publish(info);
  ros::ServiceClient stats_client = nh.serviceClient<msg::TriggerRequest, msg::TriggerResponse>(stats_srv);
  const auto node_stats = [&] {
    msg::TriggerRequest req;
    msg::TriggerResponse res;
    return stats_client.call(req, res) ? res.message : std::string();
  };
  // Five rounds of wall, box and image (interval-mean needs several hits for an occupied voxel),
  // each message inserted before the next is sent, so that the order is known.
  constexpr int kRounds = 5;
  bool inserted = true;
  for (int round = 0; round < kRounds && inserted; ++round) {
    cloud_pub.publish(cloud_of(wall, "sensor"));
    inserted = inserted && wait_for([&] { return stat(stats = node_stats(), "clouds") == 2 * round + 1; }, 10.0);
    cloud_pub.publish(cloud_of(box, "sensor"));
    inserted = inserted && wait_for([&] { return stat(stats = node_stats(), "clouds") == 2 * round + 2; }, 10.0);
    image.header.stamp = ros::Time::now();
    image_pub.publish(image);
    inserted = inserted && wait_for([&] { return stat(stats = node_stats(), "images") == round + 1; }, 10.0);
  }
  check(inserted, "the node inserted 10 clouds and 5 depth images: " + stats);

  // The same input, inserted directly in the same order, through the explained evidence channel
  // as the node runs it (~explained: true, run_node_test.sh); the grid is the same as without it.
  Grid expected(0.1);
  iv::InsertOptions io;
  io.max_range = 5.0;
  iv::ScanInserter inserter(io);
  iv::ExplainedSpace explained(expected.geometry());
  std::uint64_t trusted = 0, suspect = 0, no_return = 0;
  const auto count = [&](const iv::InsertStats& st) {
    trusted += st.beams_trusted;
    suspect += st.beams_suspect;
    no_return += st.beams_no_return;
  };
  const auto insert_cloud = [&](const std::vector<iv::Point3>& pts) {
    std::vector<iv::Point3> world;  // the points as the message carries them (float32)
    for (const auto& p : ir::cloud_points(cloud_of(pts, "sensor"))) world.push_back(sensor * p);
    count(explained.insert_point_cloud(inserter, expected, iv::Point3(sensor.translation()), world));
  };
  for (int round = 0; round < kRounds; ++round) {
    insert_cloud(wall);
    insert_cloud(box);
    count(explained.insert_depth_image(inserter, expected, ir::depth_frame(image, info, camera)));
  }
  check(stat(stats, "beams_trusted") == static_cast<long long>(trusted) &&
            stat(stats, "beams_suspect") == static_cast<long long>(suspect) &&
            stat(stats, "beams_no_return") == static_cast<long long>(no_return) && trusted > 0,
        "the node's beam classes equal the channel's own (" + std::to_string(trusted) + " trusted, " +
            std::to_string(suspect) + " suspect, " + std::to_string(no_return) + " without a return): " + stats);
  std::vector<iv::Point3> expected_centres;
  expected.for_each_observed([&](const iv::Key& key, const auto& c) {
    if (expected.update_policy().occupancy(c) == iv::Occupancy::Occupied)
      expected_centres.push_back(expected.center(key));
  });
  check(!expected_centres.empty(),
        "the direct map has " + std::to_string(expected_centres.size()) + " occupied voxels");
  const auto want = sorted_points(expected_centres);

  const bool got_centres = wait_for([&] { return centres && sorted_points(ir::cloud_points(*centres)) == want; }, 15.0);
  if (!got_centres && centres) {  // name a few differences
    const auto got = sorted_points(ir::cloud_points(*centres));
    std::vector<std::array<float, 3>> only_node, only_direct;
    std::set_difference(got.begin(), got.end(), want.begin(), want.end(), std::back_inserter(only_node));
    std::set_difference(want.begin(), want.end(), got.begin(), got.end(), std::back_inserter(only_direct));
    for (std::size_t i = 0; i < std::min<std::size_t>(only_node.size(), 5); ++i)
      std::printf("  occupied in the node's map only: (%g, %g, %g)\n", only_node[i][0], only_node[i][1],
                  only_node[i][2]);
    for (std::size_t i = 0; i < std::min<std::size_t>(only_direct.size(), 5); ++i)
      std::printf("  occupied in the direct map only: (%g, %g, %g)\n", only_direct[i][0], only_direct[i][1],
                  only_direct[i][2]);
  }
  check(got_centres, "octomap_point_cloud_centers equals the direct map's occupied centres (" +
                         std::to_string(centres ? centres->width : 0) + " points)");
  const bool got_markers = wait_for(
      [&] {
        if (!markers || markers->markers.size() != 1) return false;
        std::vector<iv::Point3> pts;
        for (const auto& p : markers->markers[0].points) pts.emplace_back(p.x, p.y, p.z);
        return markers->markers[0].header.frame_id == "map" && markers->markers[0].scale.x == 0.1 &&
               sorted_points(pts) == want;
      },
      15.0);
  check(got_markers, "occupied_cells_vis_array holds one cube list of the occupied centres");
  // ~color: explained: each cube has the colour of its voxel's explained state in the direct channel.
  if (got_markers) {
    const msg::Marker& m = markers->markers[0];
    std::size_t right = 0, occupied_blue = 0;
    for (std::size_t i = 0; i < m.points.size() && i < m.colors.size(); ++i) {
      const iv::ExplainedState st =
          explained.state(expected.geometry().key(iv::Point3(m.points[i].x, m.points[i].y, m.points[i].z)));
      const iv::Rgb c = ir::kExplainedMarkerColours[static_cast<std::size_t>(st)];
      right +=
          (m.colors[i].r == c.r / 255.0f && m.colors[i].g == c.g / 255.0f && m.colors[i].b == c.b / 255.0f) ? 1 : 0;
      occupied_blue += st == iv::ExplainedState::Occupied ? 1 : 0;
    }
    check(m.colors.size() == m.points.size() && right == m.points.size() && occupied_blue > 0,
          "the markers are coloured by the explained state (" + std::to_string(right) + " of " +
              std::to_string(m.points.size()) + " right, " + std::to_string(occupied_blue) + " explained occupied)");
  }

  // The projected map: project_columns over the observed extent, band [0.2, 2.0] (the defaults).
  iv::Bounds extent{iv::Point3::Constant(1e9), iv::Point3::Constant(-1e9)};
  expected.for_each_observed([&](const iv::Key& key, const auto&) {
    extent.min = extent.min.cwiseMin(expected.center(key));
    extent.max = extent.max.cwiseMax(expected.center(key));
  });
  extent.min.z() = 0.2;
  extent.max.z() = 2.0;
  const msg::OccupancyGrid want_projected =
      ir::to_occupancy_grid(iv::project_columns(expected, extent), expected.geometry(), 0.2, "map", ros::Time());
  const bool got_projected = wait_for(
      [&] {
        return projected && projected->info.width == want_projected.info.width &&
               projected->info.height == want_projected.info.height && projected->data == want_projected.data &&
               projected->info.origin.position.x == want_projected.info.origin.position.x &&
               projected->info.origin.position.y == want_projected.info.origin.position.y;
      },
      15.0);
  check(got_projected, "projected_map equals project_columns of the direct map (" +
                           std::to_string(want_projected.info.width) + " x " +
                           std::to_string(want_projected.info.height) + ")");
  const bool got_exploration = wait_for(
      [&] {
        if (!exploration || exploration->data.empty()) return false;
        for (const auto v : exploration->data)
          if (v != -1 && v != 0 && v != 10 && v != 40 && v != 60 && v != 70 && v != 80 && v != 90 && v != 100)
            return false;
        return true;
      },
      15.0);
  check(got_exploration, "exploration_map received with documented labels only");

  // Bad messages: the node must survive and count them.
  const long long invalid_before = stat(stats, "invalid_points");
  msg::Image rgb = image;
  rgb.encoding = "rgb8";
  image_pub.publish(rgb);
  msg::Image wrong_size = image;
  wrong_size.encoding = "32FC1";
  wrong_size.width = 16;
  wrong_size.step = 64;
  image_pub.publish(wrong_size);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  cloud_pub.publish(cloud_of(std::vector<iv::Point3>(7, iv::Point3(nan, 0.0, 1.0)), "sensor"));
  msg::PointCloud2 short_cloud = cloud_of(wall, "sensor");
  short_cloud.data.resize(short_cloud.data.size() / 2);
  cloud_pub.publish(short_cloud);
  cloud_pub.publish(cloud_of(wall, "nowhere"));
  const bool counted = wait_for(
      [&] {
        stats = call(caller, "trigger", stats_srv);  // the stock client, too
        return stat(stats, "bad_encoding") == 1 && stat(stats, "size_mismatch") == 2 &&
               stat(stats, "missing_transform") == 1 && stat(stats, "invalid_points") == invalid_before + 7 &&
               stat(stats, "clouds") == 2 * kRounds + 1;
      },
      20.0);
  check(counted, "bad messages counted (1 encoding, 2 sizes, 1 transform, 7 NaN points): " + stats);

  // A cloud whose explained scratch (ExplainedSpace::kScratchBytesPerBeam per beam) exceeds the
  // node's insertion budget (~insert_budget_mib 64): refused before anything is allocated. NaN
  // points, so that the map would not change if it were inserted.
  {
    const long long failed_before = stat(stats, "insert_failed");
    const std::size_t n = (std::size_t{64} << 20) / iv::ExplainedSpace::kScratchBytesPerBeam + 1000;
    cloud_pub.publish(cloud_of(std::vector<iv::Point3>(n, iv::Point3(nan, 0.0, 1.0)), "sensor"));
    const bool refused =
        wait_for([&] { return stat(stats = node_stats(), "insert_failed") == failed_before + 1; }, 20.0);
    check(refused,
          "a cloud of " + std::to_string(n) + " points over the explained channel's budget is refused: " + stats);
  }

  // A cloud the node cannot allocate: its memory limit lowered to what it holds now and 150 MB,
  // enough to receive a 48 MB message, not to convert its 4 million points (96 MB) and class them.
  // The bad_alloc is counted and logged, and the node goes on.
  {
    long pid = 0;
    std::ifstream(work + "/server.pid") >> pid;
    const std::uint64_t vm = pid > 0 ? vm_size(pid) : 0;
    const bool limited = vm > 0 && set_memory_limit(pid, static_cast<rlim_t>(vm + (std::uint64_t{150} << 20)));
    check(limited, "the node's memory limit is lowered (pid " + std::to_string(pid) + ", VmSize " +
                       std::to_string(vm >> 20) + " MiB)");
    if (limited) {
      cloud_pub.publish(cloud_of(std::vector<iv::Point3>(std::size_t{4} << 20, iv::Point3(nan, 0.0, 1.0)), "sensor"));
      const bool caught = wait_for([&] { return stat(stats = node_stats(), "callback_errors") == 1; }, 20.0);
      check(set_memory_limit(pid, RLIM_INFINITY), "the node's memory limit is restored");
      check(caught, "a cloud the node cannot allocate is counted in callback_errors: " + stats);
      std::ifstream log(work + "/server.log");
      const std::string text((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
      check(text.find("cloud_in failed: std::bad_alloc") != std::string::npos, "the failure is logged");
      check(!node_stats().empty(), "the node still answers");
    }
  }

  // ~save_map, with the stock std_srvs client; the file equals the direct map.
  const std::string saved = call(caller, "trigger", "/intervox_server/save_map");
  check(saved.rfind("success=1", 0) == 0, "~save_map: " + saved);
  try {
    const Grid loaded = iv::load_grid<Grid>(work + "/map.ivx");
    check(iv::save_grid_to_memory(loaded) == iv::save_grid_to_memory(expected), "the saved map equals the direct map");
    std::ifstream in(work + "/map.bt", std::ios::binary);
    const std::string bt((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    check(bt == iv::write_bt_to_memory(expected),
          "the saved .bt equals the direct map's (" + std::to_string(bt.size()) + " bytes)");
    check(
        iv::save_explained_to_memory(iv::load_explained(work + "/map.ivxe")) == iv::save_explained_to_memory(explained),
        "the saved explained evidence (.ivxe) equals the channel's own");
  } catch (const std::exception& e) {
    check(false, std::string("loading the saved maps: ") + e.what());
  }

  // ~plan_next_view: a view (next_view published) or a termination, never a failure to plan.
  const std::string planned = call(caller, "trigger", "/intervox_server/plan_next_view");
  check(
      planned.rfind("success=1 message=next view", 0) == 0 || planned.rfind("success=0 message=no next view:", 0) == 0,
      "~plan_next_view: " + planned);
  if (planned.rfind("success=1", 0) == 0) check(wait_for([&] { return bool(next_view); }, 10.0), "next_view published");

  // ~reset empties the map.
  check(!call(caller, "empty", "/intervox_server/reset").empty(), "~reset called");
  stats = node_stats();
  check(stat(stats, "occupied") == 0 && stat(stats, "free") == 0, "the map is empty after ~reset: " + stats);

  std::printf(failures == 0 ? "node test passed\n" : "node test FAILED (%d checks)\n", failures);
  return failures == 0 ? 0 : 1;
}
