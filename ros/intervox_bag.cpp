// intervox_bag: replays a ROS 1 bag into an Intervox map without a ROS master: the point clouds
// or depth images of one topic, each seen from the pose tf gives its frame at its stamp (a tf2
// buffer filled from the bag's /tf and /tf_static), saved at the end in the own format (.ivx) and
// as OctoMap .bt. docs/ros.md has the options; try
//   intervox_bag recording.bag --topic /camera/depth/points --out map
// The bag's structure is checked first (bag_check.hpp), and the replay runs in a child process, so
// that a library that aborts on a corrupt bag cannot end the tool without a message.
#include "bag_check.hpp"
#include "ros_conversions.hpp"
#include "ros_map.hpp"

#include <intervox/raycast/vector_walks.hpp>

#include <rosbag/bag.h>
#include <rosbag/view.h>

#include "common/cli.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace {

namespace iv = intervox;
namespace ir = intervox_ros;
namespace msg = intervox_ros::msg;

struct Options {
  std::string bag;
  std::string topic;
  std::string camera_info_topic;  ///< empty: the image topic's namespace + "/camera_info"
  std::string frame_id = "map";
  std::string update = "interval-mean";
  std::string utility = "max-entropy";
  double resolution = 0.05;
  double min_range = 0.0;
  double max_range = 5.0;
  unsigned threads = 1;
  std::string out = "intervox_map";
  bool progress = true;
  bool explained = false;  ///< keep the explained evidence channel and save it as <out>.ivxe
  std::uint64_t max_chunk_mib = ir::BagCheckOptions{}.max_chunk_bytes >> 20;  ///< largest uncompressed chunk
};

/// A progress bar on stderr: "[=====>    ]  45 % 123/456 messages, 2.1 s, about 2.6 s left".
class Progress {
 public:
  Progress(std::size_t total, bool on) : total_(total), on_(on), start_(std::chrono::steady_clock::now()) {}
  void update(std::size_t done) {
    if (!on_ || total_ == 0) return;
    const auto now = std::chrono::steady_clock::now();
    if (done < total_ && now - last_ < std::chrono::milliseconds(200)) return;
    last_ = now;
    const double s = std::chrono::duration<double>(now - start_).count();
    const double f = double(done) / double(total_);
    constexpr int kWidth = 30;
    const int bar = static_cast<int>(f * kWidth);
    std::string b(kWidth, ' ');
    for (int i = 0; i < bar; ++i) b[static_cast<std::size_t>(i)] = '=';
    if (bar < kWidth) b[static_cast<std::size_t>(bar)] = '>';
    const double left = done > 0 ? s * (1.0 - f) / f : 0.0;
    std::fprintf(stderr, "\r[%s] %3.0f %% %zu/%zu messages, %.1f s, about %.1f s left   ", b.c_str(), 100.0 * f, done,
                 total_, s, left);
    if (done == total_) std::fprintf(stderr, "\n");
    std::fflush(stderr);
  }

 private:
  std::size_t total_;
  bool on_;
  std::chrono::steady_clock::time_point start_, last_{};
};

std::string default_camera_info_topic(const std::string& image_topic) {
  const auto slash = image_topic.rfind('/');
  return (slash == std::string::npos ? std::string() : image_topic.substr(0, slash)) + "/camera_info";
}

int run(const Options& o) {
  // The bag's records within the file and the chunk budget before rosbag_storage trusts them.
  ir::BagCheckOptions check;
  check.max_chunk_bytes = o.max_chunk_mib << 20;
  (void)ir::check_bag(o.bag, check);
  rosbag::Bag bag;
  try {
    bag.open(o.bag, rosbag::bagmode::Read);
  } catch (const rosbag::BagException& e) {
    throw iv::IoError("cannot open the bag '" + o.bag + "': " + e.what());
  }
  // The topic and its type.
  std::string type;
  std::set<std::string> topics;
  {
    rosbag::View all(bag);
    for (const rosbag::ConnectionInfo* c : all.getConnections()) {
      topics.insert(c->topic + " (" + c->datatype + ")");
      if (c->topic == o.topic) type = c->datatype;
    }
  }
  if (type.empty()) {
    std::string list;
    for (const auto& t : topics) list += "\n  " + t;
    throw iv::InvalidArgument("the topic '" + o.topic + "' is not in the bag '" + o.bag +
                              "'; its topics:" + (list.empty() ? std::string(" none") : list));
  }
  const bool cloud = type == "sensor_msgs/PointCloud2";
  if (!cloud && type != "sensor_msgs/Image")
    throw iv::InvalidArgument("the topic '" + o.topic + "' holds " + type +
                              " (expected sensor_msgs/PointCloud2 or sensor_msgs/Image)");
  const std::string info_topic =
      cloud ? std::string() : (o.camera_info_topic.empty() ? default_camera_info_topic(o.topic) : o.camera_info_topic);

  const std::unique_ptr<ir::TfPoses> tf = ir::TfPoses::from_bag(o.bag);
  iv::InsertOptions io;
  io.min_range = o.min_range;
  io.max_range = o.max_range;
  io.threads = o.threads;
  const std::unique_ptr<ir::AnyMap> map =
      ir::make_map(o.update, o.utility, o.resolution, io,
                   o.explained ? std::optional<iv::ExplainOptions>(iv::ExplainOptions{}) : std::nullopt);

  std::vector<std::string> query{o.topic};
  if (!cloud) query.push_back(info_topic);
  rosbag::View view(bag, rosbag::TopicQuery(query));
  std::size_t total = 0;
  for (const rosbag::MessageInstance& m : view) total += m.getTopic() == o.topic ? 1 : 0;
  std::fprintf(stderr, "intervox_bag: %s: %zu messages of %s (%s)%s, %zu transforms, %s map at %.3f m\n", o.bag.c_str(),
               total, o.topic.c_str(), type.c_str(), cloud ? "" : (" with " + info_topic).c_str(),
               tf->transforms_read(), map->summary().type.c_str(), o.resolution);

  std::array<std::uint64_t, ir::kProblemKinds> refused{};
  std::uint64_t inserted = 0, rays = 0, invalid = 0;
  std::array<std::uint64_t, 3> classes{};  // beams trusted, suspect, without a return (--explained)
  boost::shared_ptr<const msg::CameraInfo> info;
  Progress progress(total, o.progress);
  std::size_t done = 0;
  const auto refuse = [&](const ir::BadMessage& e, const ros::Time& stamp) {
    const auto k = static_cast<std::size_t>(e.kind());
    if (refused[k]++ < 3) {
      std::fprintf(stderr, "%sintervox_bag: warning: message at %.3f refused (%s): %s\n", o.progress ? "\n" : "",
                   stamp.toSec(), ir::problem_name(e.kind()), e.what());
    }
  };
  const auto pose_of = [&](const std::string& frame, const ros::Time& stamp) {
    iv::Pose pose;
    std::string error;
    if (!tf->lookup(o.frame_id, frame, stamp, 0.0, pose, error))
      throw ir::BadMessage(ir::Problem::Transform, "no transform '" + o.frame_id + "' <- '" + frame + "': " + error);
    if (!ir::pose_is_finite(pose))
      throw ir::BadMessage(ir::Problem::Transform, "transform of '" + frame + "' is not finite");
    return pose;
  };
  for (const rosbag::MessageInstance& m : view) {
    if (m.getTopic() != o.topic) {
      if (auto i = m.instantiate<msg::CameraInfo>()) info = i;
      continue;
    }
    ros::Time stamp = m.getTime();
    try {
      iv::InsertStats st;
      if (cloud) {
        const auto c = m.instantiate<msg::PointCloud2>();
        if (!c) continue;
        if (!c->header.stamp.isZero()) stamp = c->header.stamp;
        const std::vector<iv::Point3> points = ir::cloud_points(*c);
        const iv::Pose sensor = pose_of(c->header.frame_id, stamp);
        try {
          st = map->insert_points(sensor, points);
        } catch (const iv::Error& e) {
          throw ir::BadMessage(ir::Problem::Insert, e.what());
        }
      } else {
        const auto img = m.instantiate<msg::Image>();
        if (!img) continue;
        if (!img->header.stamp.isZero()) stamp = img->header.stamp;
        if (!info) throw ir::BadMessage(ir::Problem::NoCameraInfo, "depth image before any message on " + info_topic);
        (void)ir::depth_image(*img);  // encoding and size first
        const iv::DepthFrame frame = ir::depth_frame(*img, *info, pose_of(img->header.frame_id, stamp));
        try {
          st = map->insert_depth(frame);
        } catch (const iv::Error& e) {
          throw ir::BadMessage(ir::Problem::Insert, e.what());
        }
      }
      ++inserted;
      rays += st.rays;
      invalid += st.skipped_invalid;
      classes[0] += st.beams_trusted;
      classes[1] += st.beams_suspect;
      classes[2] += st.beams_no_return;
    } catch (const ir::BadMessage& e) {
      refuse(e, stamp);
    }
    progress.update(++done);
  }
  bag.close();

  std::string refused_text;
  std::uint64_t refused_total = 0;
  for (std::size_t k = 0; k < refused.size(); ++k) {
    refused_total += refused[k];
    if (refused[k] > 0)
      refused_text +=
          std::string(" ") + ir::problem_name(static_cast<ir::Problem>(k)) + "=" + std::to_string(refused[k]);
  }
  if (inserted == 0)
    throw iv::InvalidArgument(
        "none of the " + std::to_string(total) + " messages of '" + o.topic +
        "' could be inserted (refused:" + (refused_text.empty() ? std::string(" none") : refused_text) + ")");
  const std::filesystem::path out(o.out);
  if (out.has_parent_path()) std::filesystem::create_directories(out.parent_path());
  // Every file made and checked before the first is written; a failure while writing says which
  // were written (ros_map.hpp, AnyMap::save()).
  const ir::SaveReport saved = map->save(o.out + ".ivx", o.out + ".bt", o.explained ? o.out + ".ivxe" : std::string());
  if (!saved.ok()) throw iv::IoError(saved.text());
  const ir::MapSummary s = map->summary();
  std::printf("intervox_bag: inserted %llu of %zu messages (%llu rays, %llu invalid points skipped), refused %llu%s\n",
              static_cast<unsigned long long>(inserted), total, static_cast<unsigned long long>(rays),
              static_cast<unsigned long long>(invalid), static_cast<unsigned long long>(refused_total),
              refused_text.empty() ? "" : (" (" + refused_text.substr(1) + ")").c_str());
  if (o.explained)
    std::printf("intervox_bag: beams trusted %llu, suspect %llu, without a return %llu\n",
                static_cast<unsigned long long>(classes[0]), static_cast<unsigned long long>(classes[1]),
                static_cast<unsigned long long>(classes[2]));
  std::printf("intervox_bag: map %s: %zu occupied, %zu free, %zu unknown voxels; %s\n", s.type.c_str(),
              s.counts.occupied, s.counts.free, s.counts.unknown, saved.text().c_str());
  return 0;
}

/// Runs run(o) in a child process and returns its exit code: a library that aborts inside (an
/// assertion of rosbag_storage on a record beyond what check_bag() checks, an allocation it cannot
/// make) ends the child, and this process says so as an error (exit code 1) instead of ending with
/// it. Without fork() the replay runs here.
int run_in_child(const Options& o) {
  std::fflush(stdout);
  std::fflush(stderr);
  const pid_t pid = ::fork();
  if (pid < 0) return run(o);
  if (pid == 0) {
    const int code = examples::guarded_main("intervox_bag", [&] { return run(o); });
    std::fflush(stdout);
    std::fflush(stderr);
    ::_exit(code);
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) throw iv::IoError(std::string("cannot wait for the replay: ") + std::strerror(errno));
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  const int sig = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
  throw iv::IoError("the replay of the bag '" + o.bag + "' ended with signal " + std::to_string(sig) + " (" +
                    ::strsignal(sig) +
                    ") inside a library: the bag is corrupt beyond what intervox_bag checks, or its "
                    "reading needs more memory than the process may use; nothing was saved");
}

}  // namespace

int main(int argc, char** argv) {
  intervox::use_vector_walks();  // the AVX-512 / AVX2 walks where the processor has them
  ros::Time::init();             // rosbag_storage and tf2 use ros::Time; no master is needed
  Options o;
  CLI::App app{"Intervox: replay the point clouds or depth images of one topic of a ROS 1 bag into a map (poses from\n"
               "the bag's /tf and /tf_static), and save it as <out>.ivx and OctoMap <out>.bt. No ROS master needed."};
  app.add_option("bag", o.bag, "the bag file")->required()->check(CLI::ExistingFile);
  app.add_option("--topic", o.topic, "topic of sensor_msgs/PointCloud2 or sensor_msgs/Image (16UC1 mm, 32FC1 m)")
      ->required();
  app.add_option("--camera-info-topic", o.camera_info_topic,
                 "CameraInfo topic of a depth image topic (default: its namespace + /camera_info)");
  app.add_option("--frame-id", o.frame_id, "map frame of tf")->capture_default_str();
  app.add_option("--update", o.update, "update policy")
      ->check(examples::one_of(examples::offered_updates<ir::RosOffer>()))
      ->capture_default_str();
  app.add_option("--utility", o.utility, "utility policy")
      ->check(examples::one_of(examples::offered_utilities<ir::RosOffer>()))
      ->capture_default_str();
  app.add_option("--resolution", o.resolution, "voxel edge length in metres")
      ->check(examples::number_in(0.001, 10.0))
      ->capture_default_str();
  app.add_option("--min-range", o.min_range, "points closer than this are skipped (m)")
      ->check(examples::number_in(0.0, 1e6))
      ->capture_default_str();
  app.add_option("--max-range", o.max_range, "rays are cut at this range in metres (negative: none)")
      ->check(examples::number_in(-1.0, 1e6))
      ->capture_default_str();
  app.add_option("--threads", o.threads, "insertion threads (0: all cores)")
      ->check(examples::integer_in<unsigned>(0, 1024))
      ->capture_default_str();
  app.add_option("--out", o.out, "output path without extension: <out>.ivx and <out>.bt")->capture_default_str();
  app.add_flag("!--no-progress", o.progress, "no progress bar on stderr");
  app.add_flag("--explained", o.explained,
               "class every beam (trusted, suspect, no return) and save the explained evidence as <out>.ivxe");
  app.add_option("--max-chunk-mib", o.max_chunk_mib,
                 "largest uncompressed chunk of the bag in MiB: a chunk claiming more is refused before it is read")
      ->check(examples::integer_in<std::uint64_t>(1, std::uint64_t{1} << 20))
      ->capture_default_str();
  app.callback([&] {
    if (const std::string e = examples::offer_error<ir::RosOffer>(o.update, o.utility); !e.empty())
      throw CLI::ValidationError("--utility", e);
    if (o.max_range >= 0 && o.min_range > o.max_range) throw CLI::ValidationError("--min-range", "exceeds --max-range");
  });
  // Bad options: "intervox_bag: error: ..." and exit code 2; failures while running (a missing
  // topic, an unreadable bag, an unwritable output): the same line and exit code 1.
  return examples::cli_main("intervox_bag", app, argc, argv, [&] { return run_in_child(o); });
}
