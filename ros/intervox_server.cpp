// intervox_server: a ROS 1 node that builds an Intervox map from point clouds and depth images
// and publishes what octomap_server users expect (occupied voxels as markers and as a cloud of
// centres, the projected 2D map), plus the exploration map and, on request, the mobile planner's
// next best view. Topics, parameters and services: docs/ros.md.
#include "ros_conversions.hpp"
#include "ros_map.hpp"

#include <intervox/raycast/vector_walks.hpp>

#include <ros/ros.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <exception>
#include <memory>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace iv = intervox;
namespace ir = intervox_ros;
namespace msg = intervox_ros::msg;

/// What the node was given and what it refused (docs/ros.md, "Bad messages").
struct Counters {
  std::uint64_t clouds = 0;          ///< point clouds inserted
  std::uint64_t images = 0;          ///< depth images inserted
  std::uint64_t rays = 0;            ///< rays traversed
  std::uint64_t invalid_points = 0;  ///< NaN / infinite points and invalid pixels skipped
  bool explained = false;            ///< the map keeps the explained evidence: count the beam classes
  std::uint64_t trusted = 0, suspect = 0, no_return = 0;   ///< beams per class (with ~explained)
  std::array<std::uint64_t, ir::kProblemKinds> refused{};  ///< messages refused, per ir::Problem
  std::uint64_t callback_errors = 0;  ///< callbacks ended by an unexpected exception (out of memory, ...)

  std::uint64_t refused_total() const {
    std::uint64_t n = 0;
    for (const auto v : refused) n += v;
    return n;
  }
  std::string text() const {
    std::ostringstream s;
    s << "clouds=" << clouds << " images=" << images << " rays=" << rays << " invalid_points=" << invalid_points;
    if (explained)
      s << " beams_trusted=" << trusted << " beams_suspect=" << suspect << " beams_no_return=" << no_return;
    for (std::size_t i = 0; i < refused.size(); ++i)
      s << ' ' << ir::problem_name(static_cast<ir::Problem>(i)) << '=' << refused[i];
    s << " callback_errors=" << callback_errors;
    return s.str();
  }
};

template <class T>
T param(const ros::NodeHandle& nh, const std::string& name, const T& fallback) {
  T v;
  nh.param<T>(name, v, fallback);
  return v;
}

class Server {
 public:
  Server() : pnh_("~") {
    frame_id_ = param<std::string>(pnh_, "frame_id", "map");
    base_frame_ = param<std::string>(pnh_, "base_frame", "base_link");
    const double resolution = param(pnh_, "resolution", 0.05);
    iv::InsertOptions io;
    io.min_range = param(pnh_, "min_range", 0.0);
    io.max_range = param(pnh_, "max_range", 5.0);
    io.threads = static_cast<unsigned>(std::max(0, param(pnh_, "threads", 1)));
    // The insertion budget in MiB (InsertOptions::max_grid_bytes; 0: none): what one message may
    // add to the map, and the explained channel's scratch for it.
    const int budget_mib = param(pnh_, "insert_budget_mib", static_cast<int>(iv::kDefaultInsertBudgetBytes >> 20));
    if (budget_mib < 0) throw iv::InvalidArgument("~insert_budget_mib must be >= 0 (0: no budget)");
    io.max_grid_bytes = budget_mib == 0 ? iv::kUnlimitedInsertBudget : static_cast<std::uint64_t>(budget_mib) << 20;
    const std::string update = param<std::string>(pnh_, "update", "interval-mean");
    const std::string utility = param<std::string>(pnh_, "utility", "max-entropy");
    const bool explained = param(pnh_, "explained", false);
    color_ = ir::colouring(param<std::string>(pnh_, "color", "state"));
    if (color_.explained && !explained)
      throw iv::InvalidArgument("~color 'explained' needs ~explained: true (the explained evidence channel)");
    projected_min_z_ = param(pnh_, "projected_min_z", 0.2);
    projected_max_z_ = param(pnh_, "projected_max_z", 2.0);
    if (!(projected_min_z_ <= projected_max_z_))
      throw iv::InvalidArgument("~projected_min_z must not exceed ~projected_max_z");
    tf_timeout_ = param(pnh_, "tf_timeout", 0.2);
    save_path_ = param<std::string>(pnh_, "save_path", "intervox_map");
    const double rate = param(pnh_, "publish_rate", 1.0);

    // Planner settings (MobilePlannerParams; the defaults are the library's, the start rule replay's).
    planner_.gain.max_range = param(pnh_, "planner/max_range", io.has_max_range() ? io.max_range : 4.0);
    planner_.map.robot_radius = param(pnh_, "planner/robot_radius", planner_.map.robot_radius);
    planner_.floor_clearance = param(pnh_, "planner/floor_clearance", planner_.floor_clearance);
    planner_.obstacle_height = param(pnh_, "planner/obstacle_height", planner_.obstacle_height);
    planner_.start_free_radius = param(pnh_, "planner/start_free_radius", 1.0);
    planner_.start_free_columns = param(pnh_, "planner/start_free_columns", true);
    planner_.gain_stride = param(pnh_, "planner/gain_stride", planner_.gain_stride);
    planner_.ring.inner_radius = param(pnh_, "planner/ring_inner_radius", planner_.ring.inner_radius);
    planner_.ring.outer_radius = param(pnh_, "planner/ring_outer_radius", planner_.ring.outer_radius);
    planner_.ring.positions = param(pnh_, "planner/ring_positions", planner_.ring.positions);
    planner_.max_steps = param(pnh_, "planner/max_steps", planner_.max_steps);
    planner_.face_along_path = param(pnh_, "planner/face_along_path", planner_.face_along_path);
    planner_.threads = static_cast<unsigned>(std::max(0, param(pnh_, "planner/threads", 0)));
    planner_.validate();
    camera_max_range_ = planner_.gain.max_range;

    map_ = ir::make_map(update, utility, resolution, io,
                        explained ? std::optional<iv::ExplainOptions>(iv::ExplainOptions{}) : std::nullopt);
    counters_.explained = explained;
    tf_ = ir::TfPoses::live();

    markers_pub_ = nh_.advertise<msg::MarkerArray>("occupied_cells_vis_array", 1, true);
    centers_pub_ = nh_.advertise<msg::PointCloud2>("octomap_point_cloud_centers", 1, true);
    projected_pub_ = nh_.advertise<msg::OccupancyGrid>("projected_map", 1, true);
    exploration_pub_ = nh_.advertise<msg::OccupancyGrid>("exploration_map", 1, true);
    path_pub_ = nh_.advertise<msg::Path>("next_view_path", 1, true);
    view_pub_ = nh_.advertise<msg::PoseStamped>("next_view", 1, true);
    cloud_sub_ = nh_.subscribe("cloud_in", 5, &Server::on_cloud, this);
    depth_sub_ = nh_.subscribe("depth/image", 5, &Server::on_depth, this);
    info_sub_ = nh_.subscribe("depth/camera_info", 5, &Server::on_camera_info, this);
    save_srv_ = pnh_.advertiseService("save_map", &Server::on_save, this);
    reset_srv_ = pnh_.advertiseService("reset", &Server::on_reset, this);
    plan_srv_ = pnh_.advertiseService("plan_next_view", &Server::on_plan, this);
    stats_srv_ = pnh_.advertiseService("stats", &Server::on_stats, this);
    publish_on_insert_ = !(rate > 0);
    if (!publish_on_insert_)
      publish_timer_ = nh_.createTimer(ros::Duration(1.0 / rate), &Server::on_publish_timer, this);
    const double stats_period = param(pnh_, "stats_period", 30.0);
    if (stats_period > 0) stats_timer_ = nh_.createTimer(ros::Duration(stats_period), &Server::on_stats_timer, this);
    ROS_INFO("intervox_server: %s map%s at %.3f m in frame '%s', max range %.2f m, %s (%s)",
             map_->summary().type.c_str(), explained ? " with explained evidence" : "", resolution, frame_id_.c_str(),
             io.max_range, publish_on_insert_ ? "publishing after every insertion" : "publishing on a timer",
             iv::insertion_walk());
  }

 private:
  /// Runs the work \p f of the callback \p callback. An exception that escapes it (out of memory on
  /// a large message, anything unexpected) is counted and logged, and the node goes on: roscpp
  /// would pass it to ros::spin() and end the node. A message whose insertion failed that way may
  /// have left part of itself in the map.
  template <class F>
  void guarded(const char* callback, F&& f) noexcept {
    try {
      f();
    } catch (const std::exception& e) {
      failed(callback, e.what());
    } catch (...) {
      failed(callback, "an exception that is not a std::exception");
    }
  }
  void failed(const char* callback, const char* what) noexcept {
    ++counters_.callback_errors;
    try {
      ROS_ERROR("intervox_server: %s failed: %s; the node goes on [%s]", callback, what, counters_.text().c_str());
    } catch (...) {  // (logging needs memory too)
    }
  }

  void refuse(ir::Problem p, const std::string& what) {
    ++counters_.refused[static_cast<std::size_t>(p)];
    ROS_WARN_THROTTLE(5.0, "intervox_server: refused a message (%s): %s [%s]", ir::problem_name(p), what.c_str(),
                      counters_.text().c_str());
  }

  /// The pose of \p frame in the map frame at \p stamp.
  iv::Pose pose_of(const std::string& frame, const ros::Time& stamp) {
    iv::Pose pose;
    std::string error;
    if (!tf_->lookup(frame_id_, frame, stamp, tf_timeout_, pose, error))
      throw ir::BadMessage(ir::Problem::Transform, "no transform '" + frame_id_ + "' <- '" + frame + "': " + error);
    if (!ir::pose_is_finite(pose))
      throw ir::BadMessage(ir::Problem::Transform, "transform of '" + frame + "' is not finite");
    return pose;
  }

  void inserted(const iv::InsertStats& st) {
    counters_.rays += st.rays;
    counters_.invalid_points += st.skipped_invalid;
    counters_.trusted += st.beams_trusted;
    counters_.suspect += st.beams_suspect;
    counters_.no_return += st.beams_no_return;
    if (st.skipped_invalid > 0)
      ROS_WARN_THROTTLE(5.0, "intervox_server: %llu invalid (NaN / infinite) points or pixels skipped [%s]",
                        static_cast<unsigned long long>(st.skipped_invalid), counters_.text().c_str());
    dirty_ = true;
    if (publish_on_insert_) publish();
  }

  void on_cloud(const boost::shared_ptr<const msg::PointCloud2>& cloud) {
    guarded("cloud_in", [&] { insert_cloud(*cloud); });
  }
  void insert_cloud(const msg::PointCloud2& cloud) {
    try {
      const std::vector<iv::Point3> points = ir::cloud_points(cloud);
      const iv::Pose sensor = pose_of(cloud.header.frame_id, cloud.header.stamp);
      iv::InsertStats st;
      try {
        st = map_->insert_points(sensor, points);
      } catch (const iv::Error& e) {
        throw ir::BadMessage(ir::Problem::Insert, e.what());
      }
      ++counters_.clouds;
      inserted(st);
    } catch (const ir::BadMessage& e) {
      refuse(e.kind(), e.what());
    }
  }

  void on_camera_info(const boost::shared_ptr<const msg::CameraInfo>& info) {
    guarded("depth/camera_info", [&] { camera_info_ = info; });
  }

  void on_depth(const boost::shared_ptr<const msg::Image>& image) {
    guarded("depth/image", [&] { insert_depth(image); });
  }
  void insert_depth(const boost::shared_ptr<const msg::Image>& image) {
    try {
      if (!camera_info_)
        throw ir::BadMessage(ir::Problem::NoCameraInfo, "depth image before any message on depth/camera_info");
      // Encoding and size first: a wrong image is refused whatever tf says.
      (void)ir::depth_image(*image);
      const iv::Pose camera = pose_of(image->header.frame_id, image->header.stamp);
      const iv::DepthFrame frame = ir::depth_frame(*image, *camera_info_, camera);
      iv::InsertStats st;
      try {
        st = map_->insert_depth(frame);
      } catch (const iv::Error& e) {
        throw ir::BadMessage(ir::Problem::Insert, e.what());
      }
      ++counters_.images;
      camera_frame_ = image->header.frame_id;
      inserted(st);
    } catch (const ir::BadMessage& e) {
      refuse(e.kind(), e.what());
    }
  }

  void publish() {
    dirty_ = false;
    const ros::Time now = ros::Time::now();
    map_->occupied(color_, centres_, colours_);
    markers_pub_.publish(ir::occupied_markers(centres_, colours_, map_->geometry().resolution(), frame_id_, now));
    centers_pub_.publish(ir::make_cloud(centres_, frame_id_, now));
    try {
      if (const auto cols = map_->projected(projected_min_z_, projected_max_z_))
        projected_pub_.publish(ir::to_occupancy_grid(*cols, map_->geometry(), projected_min_z_, frame_id_, now));
    } catch (const iv::Error& e) {
      ROS_WARN_THROTTLE(30.0, "intervox_server: no projected map: %s", e.what());
    }
    iv::Pose base;
    std::string error;
    if (!tf_->lookup(frame_id_, base_frame_, ros::Time(0), 0.0, base, error) || !ir::pose_is_finite(base)) {
      ROS_DEBUG_THROTTLE(30.0, "intervox_server: no exploration map (no pose of '%s': %s)", base_frame_.c_str(),
                         error.c_str());
      return;
    }
    try {
      if (const auto em = map_->exploration(base, planner_))
        exploration_pub_.publish(ir::to_occupancy_grid(
            *em, map_->geometry(), base.translation().z() + planner_.floor_clearance, frame_id_, now));
    } catch (const iv::Error& e) {
      ROS_WARN_THROTTLE(30.0, "intervox_server: no exploration map: %s", e.what());
    }
  }

  void on_publish_timer(const ros::TimerEvent&) {
    guarded("publishing", [&] {
      if (dirty_) publish();
    });
  }
  void on_stats_timer(const ros::TimerEvent&) {
    guarded("the stats timer", [&] {
      const std::string text = counters_.text();
      if (text != last_stats_) ROS_INFO("intervox_server: %s", text.c_str());
      last_stats_ = text;
    });
  }

  /// A service's work \p f, guarded: an exception that escapes it is counted and logged, and the
  /// response \p res (of a std_srvs/Trigger service; nullptr for others) says the call failed.
  template <class F>
  bool service(const char* name, msg::TriggerResponse* res, F&& f) noexcept {
    bool ok = false;
    guarded(name, [&] {
      f();
      ok = true;
    });
    if (!ok && res) {
      res->success = false;
      try {
        res->message = std::string(name) + " failed (see the node's log)";
      } catch (...) {
      }
    }
    return true;
  }

  std::string map_text() const {
    const ir::MapSummary s = map_->summary();
    return "occupied=" + std::to_string(s.counts.occupied) + " free=" + std::to_string(s.counts.free) +
           " unknown=" + std::to_string(s.counts.unknown);
  }

  bool on_stats(msg::TriggerRequest&, msg::TriggerResponse& res) {
    return service("~stats", &res, [&] {
      res.success = true;
      res.message = counters_.text() + " " + map_text();
    });
  }

  bool on_save(msg::TriggerRequest&, msg::TriggerResponse& res) {
    return service("~save_map", &res, [&] { save(res); });
  }
  void save(msg::TriggerResponse& res) {
    const std::string ivx = save_path_ + ".ivx", bt = save_path_ + ".bt", ivxe = save_path_ + ".ivxe";
    // Every file made and checked before the first is written; a failure while writing says
    // which were written (ros_map.hpp, AnyMap::save()).
    const ir::SaveReport report = map_->save(ivx, bt, map_->explained() ? ivxe : std::string());
    res.success = report.ok();
    res.message = report.text() + " (" + map_text() + "; " + counters_.text() + ")";
    if (res.success)
      ROS_INFO("intervox_server: %s", res.message.c_str());
    else
      ROS_ERROR("intervox_server: %s", res.message.c_str());
  }

  bool on_reset(msg::EmptyRequest&, msg::EmptyResponse&) {
    return service("~reset", nullptr, [&] {
      map_->clear();
      ROS_INFO("intervox_server: map reset");
      publish();
    });
  }

  bool on_plan(msg::TriggerRequest&, msg::TriggerResponse& res) {
    return service("~plan_next_view", &res, [&] { plan(res); });
  }
  void plan(msg::TriggerResponse& res) {
    res.success = false;
    try {
      if (!camera_info_ || camera_frame_.empty()) {
        res.message = "no depth image with camera info inserted yet: the planner's rig is the received camera";
        return;
      }
      iv::Pose base, mount;
      std::string error;
      if (!tf_->lookup(frame_id_, base_frame_, ros::Time(0), tf_timeout_, base, error)) {
        res.message = "no pose of the base '" + base_frame_ + "' in '" + frame_id_ + "': " + error;
        return;
      }
      if (!tf_->lookup(base_frame_, camera_frame_, ros::Time(0), tf_timeout_, mount, error)) {
        res.message = "no mount of the camera '" + camera_frame_ + "' on '" + base_frame_ + "': " + error;
        return;
      }
      iv::SensorRig rig;
      iv::DepthCamera cam;
      cam.intrinsics = ir::intrinsics(*camera_info_);
      cam.min_range = 0.0;
      cam.max_range = camera_max_range_;
      rig.add(cam, mount, camera_frame_);
      const iv::MobilePlan plan = map_->plan_next_view(rig, planner_, base);
      if (plan.termination != iv::Termination::Running) {
        res.message = "no next view: " + std::string(iv::to_string(plan.termination));
        return;
      }
      const ros::Time now = ros::Time::now();
      msg::Path path;
      path.header.frame_id = frame_id_;
      path.header.stamp = now;
      for (const iv::Pose& p : plan.path.empty() ? std::vector<iv::Pose>{base, plan.view} : plan.path) {
        msg::PoseStamped ps;
        ps.header = path.header;
        ps.pose = ir::to_pose_msg(p);
        path.poses.push_back(ps);
      }
      msg::PoseStamped view;
      view.header = path.header;
      view.pose = ir::to_pose_msg(plan.view);
      path_pub_.publish(path);
      view_pub_.publish(view);
      std::ostringstream s;
      s.precision(3);
      s << "next view (" << plan.view.translation().x() << ", " << plan.view.translation().y() << ") heading "
        << std::atan2(plan.view.linear()(1, 0), plan.view.linear()(0, 0)) * 180.0 / std::numbers::pi << " deg, gain "
        << plan.gain << " (" << 100.0 * plan.relative_gain << " % of an unknown world), path " << plan.path_length
        << " m over " << plan.path.size() << " waypoints, " << plan.considered << " candidates";
      res.success = true;
      res.message = s.str();
    } catch (const std::exception& e) {
      res.message = std::string("planning failed: ") + e.what();
    }
    ROS_INFO("intervox_server: plan_next_view: %s", res.message.c_str());
  }

  ros::NodeHandle nh_, pnh_;
  std::string frame_id_, base_frame_, save_path_, camera_frame_, last_stats_;
  ir::Colouring color_;
  double projected_min_z_ = 0.2, projected_max_z_ = 2.0, tf_timeout_ = 0.2, camera_max_range_ = 4.0;
  bool publish_on_insert_ = false, dirty_ = false;
  iv::MobilePlannerParams planner_;
  std::unique_ptr<ir::AnyMap> map_;
  std::unique_ptr<ir::TfPoses> tf_;
  boost::shared_ptr<const msg::CameraInfo> camera_info_;
  Counters counters_;
  std::vector<iv::Point3> centres_;
  std::vector<iv::Rgb> colours_;
  ros::Publisher markers_pub_, centers_pub_, projected_pub_, exploration_pub_, path_pub_, view_pub_;
  ros::Subscriber cloud_sub_, depth_sub_, info_sub_;
  ros::ServiceServer save_srv_, reset_srv_, plan_srv_, stats_srv_;
  ros::Timer publish_timer_, stats_timer_;
};

}  // namespace

int main(int argc, char** argv) {
  intervox::use_vector_walks();  // the AVX-512 / AVX2 walks where the processor has them
  ros::init(argc, argv, "intervox_server");
  // A bad parameter ends the node at start; after that every callback is guarded (Server::guarded).
  try {
    Server server;
    ros::spin();
  } catch (const std::exception& e) {
    ROS_FATAL("intervox_server: %s", e.what());
    return 1;
  } catch (...) {
    ROS_FATAL("intervox_server: an exception that is not a std::exception");
    return 1;
  }
  return 0;
}
