// The bag tool test (CTest ros.bag): writes a bag with rosbag_storage (point clouds on /cloud,
// 16UC1 depth images with their CameraInfo on /camera/depth/*, a moving base on /tf and the
// sensor mounts on /tf_static), runs intervox_bag on each topic and checks that the saved map
// equals the same input inserted directly into the same grid type, and that the .bt loads; a map
// reaching beyond OctoMap's key range saves every file (the .bt without the voxels beyond); a save
// refused for one file writes none; corrupt bags (an lz4 chunk, a message record claiming 1.29 GB)
// are refused with a message under a 2 GB memory limit, never with an abort.
//   bag_test <intervox_bag> <work folder>
// The bag stays in the work folder for the command-line checks (ros.bag.* in CMakeLists.txt).
#include "bag_check.hpp"
#include "depth_image.hpp"
#include "ros_conversions.hpp"

#include <intervox/core/sensors.hpp>
#include <intervox/explain/explained_space.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/io/explained_file.hpp>
#include <intervox/io/grid_file.hpp>
#include <intervox/io/octomap.hpp>
#include <intervox/raycast/insert.hpp>
#include <intervox/update/bayes_log_odds.hpp>
#include <intervox/utility/utility_policies.hpp>

#include <rosbag/bag.h>
#include <roslz4/lz4s.h>

#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <tuple>
#include <utility>
#include <vector>

namespace {

namespace iv = intervox;
namespace ir = intervox_ros;
namespace msg = intervox_ros::msg;
using Grid = iv::VoxelGrid<iv::BayesLogOdds, iv::Entropy>;

int failures = 0;
void check(bool ok, const std::string& what) {
  std::printf("%s: %s\n", ok ? "ok" : "FAILED", what.c_str());
  if (!ok) ++failures;
}

/// Runs a shell command; returns its exit status (a signal: 128 + its number) and its output.
std::pair<int, std::string> run(const std::string& cmd) {
  FILE* p = popen((cmd + " 2>&1").c_str(), "r");
  if (!p) return {-1, {}};
  std::string out;
  char buf[512];
  while (std::fgets(buf, sizeof buf, p)) out += buf;
  const int status = pclose(p);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status), out};
}

/// Replaces the 8-byte field \p name of the record header that starts at \p at (its header length
/// first) by f(old value).
template <class F>
void patch_u64_field(std::string& bytes, std::size_t at, const std::string& name, F&& f) {
  namespace bd = intervox_ros::bag_detail;
  const std::uint32_t hlen = bd::u32(std::string_view(bytes).substr(at, 4));
  const std::size_t v = bytes.find(name + "=", at + 4);
  if (v == std::string::npos || v >= at + 4 + hlen) return;
  const std::uint64_t now = f(bd::u64(std::string_view(bytes).substr(v + name.size() + 1, 8)));
  for (int i = 0; i < 8; ++i)
    bytes[v + name.size() + 1 + static_cast<std::size_t>(i)] = static_cast<char>((now >> (8 * i)) & 0xFF);
}

/// The offset just past the record at \p at.
std::size_t record_end(const std::string& bytes, std::size_t at) {
  namespace bd = intervox_ros::bag_detail;
  const std::uint32_t hlen = bd::u32(std::string_view(bytes).substr(at, 4));
  return at + 8 + hlen + bd::u32(std::string_view(bytes).substr(at + 4 + hlen, 4));
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}
void write_file(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

/// The file offset of the first record of op \p op at or after \p from in the records that start
/// at \p at (a bag's top level, or a chunk's uncompressed data), and its header; npos if none.
std::size_t find_record(const std::string& bytes, std::size_t at, std::size_t end, std::uint8_t op,
                        intervox_ros::bag_detail::Fields& fields) {
  namespace bd = intervox_ros::bag_detail;
  const bd::Failer fail("test");
  while (at + 8 <= end) {
    const std::uint32_t hlen = bd::u32(std::string_view(bytes).substr(at, 4));
    fields = bd::parse_header(std::string_view(bytes).substr(at + 4, hlen), at, fail);
    const std::uint32_t dlen = bd::u32(std::string_view(bytes).substr(at + 4 + hlen, 4));
    if (static_cast<std::uint8_t>(fields["op"][0]) == op) return at;
    at += 8 + hlen + dlen;
  }
  return std::string::npos;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: bag_test <intervox_bag> <work folder>\n");
    return 2;
  }
  ros::Time::init();
  const std::string tool = argv[1], work = argv[2];
  std::filesystem::create_directories(work);
  const std::string bag_path = work + "/test.bag";

  // Poses with dyadic values and rotations of quarter turns: tf2 chains them exactly, so the
  // tool's poses equal the ones composed here bit for bit.
  iv::Pose sensor_mount = iv::Pose::Identity();
  sensor_mount.linear() = Eigen::Quaterniond(0.0, 0.0, 0.0, 1.0).toRotationMatrix();  // yaw 180 deg
  sensor_mount.translation() = iv::Point3(0.25, 0.0, 0.5);
  iv::Pose camera_mount = iv::Pose::Identity();
  camera_mount.linear() = Eigen::Quaterniond(0.5, -0.5, 0.5, -0.5).toRotationMatrix();  // optical, along base x
  camera_mount.translation() = iv::Point3(0.125, 0.0, 0.75);
  const iv::Point3 base_at[3] = {{0.0, 0.0, 0.0}, {0.5, 0.0, 0.0}, {1.0, 0.25, 0.0}};

  const iv::PinholeIntrinsics k = iv::PinholeIntrinsics::from_fov(32, 24, iv::deg(60), iv::deg(45));
  msg::CameraInfo info;
  info.header.frame_id = "camera";
  info.width = 32;
  info.height = 24;
  info.K = {k.fx, 0.0, k.cx, 0.0, k.fy, k.cy, 0.0, 0.0, 1.0};

  Grid cloud_map(0.1), depth_map(0.1);
  // The same scans with the explained evidence channel (intervox_bag --explained): its grid must
  // equal the plain one, and its evidence the channel's own.
  Grid explained_grid(0.1);
  iv::ExplainedSpace explained(explained_grid.geometry());
  std::vector<msg::PointCloud2> clouds;
  std::vector<msg::Image> images;
  iv::InsertOptions io;
  io.max_range = 5.0;
  {
    rosbag::Bag bag(bag_path, rosbag::bagmode::Write);
    msg::TFMessage statics;
    statics.transforms.push_back(ir::to_transform_msg(sensor_mount, "base_link", "sensor", ros::Time(1.0)));
    statics.transforms.push_back(ir::to_transform_msg(camera_mount, "base_link", "camera", ros::Time(1.0)));
    bag.write("/tf_static", ros::Time(1.0), statics);
    bag.write("/camera/depth/camera_info", ros::Time(0.5), info);
    for (int i = 0; i < 3; ++i) {
      const ros::Time t(1.0 + i);
      iv::Pose base = iv::Pose::Identity();
      base.translation() = base_at[i];
      msg::TFMessage dynamic;
      dynamic.transforms.push_back(ir::to_transform_msg(base, "map", "base_link", t));
      bag.write("/tf", t, dynamic);

      // A wall at x = -1.5 m of the map, behind the sensor (which looks along -x of the base), the
      // same in every scan, and a NaN point.
      const iv::Pose to_sensor = (base * sensor_mount).inverse();
      std::vector<iv::Point3> pts;
      for (int j = -10; j <= 10; ++j)
        for (int m = 0; m <= 15; ++m) pts.push_back(to_sensor * iv::Point3(-1.5, 0.1 * j + 0.013, 0.1 * m + 0.027));
      pts.emplace_back(std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0);
      const msg::PointCloud2 cloud = ir::make_cloud(pts, "sensor", t);
      bag.write("/cloud", t, cloud);

      // A plane at x = 3 m of the map, facing the camera (z-depth 3 m - the camera's x).
      msg::Image image = ir::test::depth_image_mm("camera", 32, 24,
                                                  [&](int, int) { return static_cast<std::uint16_t>(2875 - 500 * i); });
      image.header.stamp = t;
      bag.write("/camera/depth/image", t, image);

      clouds.push_back(cloud);
      images.push_back(image);
    }
    bag.close();
  }
  // The same, inserted directly, with the poses tf2 gives from the bag's transforms (as the tool
  // looks them up; tf2's chaining may differ from an Eigen product in the last bit).
  const std::unique_ptr<ir::TfPoses> tf = ir::TfPoses::from_bag(bag_path);
  for (std::size_t i = 0; i < clouds.size(); ++i) {
    iv::Pose sensor, camera;
    std::string error;
    if (!tf->lookup("map", "sensor", clouds[i].header.stamp, 0.0, sensor, error) ||
        !tf->lookup("map", "camera", images[i].header.stamp, 0.0, camera, error)) {
      check(false, "tf poses from the bag: " + error);
      return 1;
    }
    iv::Pose base = iv::Pose::Identity();
    base.translation() = base_at[i];
    check((sensor.matrix() - (base * sensor_mount).matrix()).cwiseAbs().maxCoeff() < 1e-12, "tf gives the sensor pose");
    std::vector<iv::Point3> world;
    for (const auto& p : ir::cloud_points(clouds[i])) world.push_back(sensor * p);
    iv::insert_point_cloud(cloud_map, iv::Point3(sensor.translation()), world, io);
    iv::ScanInserter inserter(io);
    explained.insert_point_cloud(inserter, explained_grid, iv::Point3(sensor.translation()), world);
    iv::insert_depth_image(depth_map, ir::depth_frame(images[i], info, camera), io);
  }
  check(cloud_map.counts().occupied > 0 && depth_map.counts().occupied > 0, "the direct maps have occupied voxels");

  check(iv::save_grid_to_memory(explained_grid) == iv::save_grid_to_memory(cloud_map) &&
            explained.counts(iv::BeamClass::Trusted).observed_count() > 0,
        "the explained channel leaves the grid as it is and holds trusted evidence");
  const auto replay = [&](const std::string& topic, const std::string& out, const Grid& expected,
                          const iv::ExplainedSpace* expected_explained = nullptr) {
    const std::string cmd = "'" + tool + "' '" + bag_path + "' --topic " + topic +
                            " --update bayes --utility entropy --resolution 0.1 --max-range 5 --no-progress --out '" +
                            work + "/" + out + "'" + (expected_explained ? " --explained" : "");
    const int status = std::system(cmd.c_str());
    check(status == 0, "intervox_bag --topic " + topic + " exits with 0");
    try {
      const Grid loaded = iv::load_grid<Grid>(work + "/" + out + ".ivx");
      check(
          iv::save_grid_to_memory(loaded) == iv::save_grid_to_memory(expected),
          "the map of " + topic + " equals direct insertion (" + std::to_string(loaded.observed_count()) + " voxels)");
      std::ifstream in(work + "/" + out + ".bt", std::ios::binary);
      const std::string bt((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      check(bt == iv::write_bt_to_memory(expected), "the .bt of " + topic + " equals the direct map's");
      if (expected_explained) {
        const iv::ExplainedSpace loaded_explained = iv::load_explained(work + "/" + out + ".ivxe");
        check(iv::save_explained_to_memory(loaded_explained) == iv::save_explained_to_memory(*expected_explained),
              "the explained evidence of " + topic + " (--explained) equals the channel's own");
      } else {
        check(!std::filesystem::exists(work + "/" + out + ".ivxe"), "no .ivxe without --explained");
      }
    } catch (const std::exception& e) {
      check(false, std::string("loading the maps of ") + topic + ": " + e.what());
    }
  };
  replay("/cloud", "cloud_map", cloud_map);
  replay("/cloud", "cloud_map_explained", cloud_map, &explained);
  replay("/camera/depth/image", "depth_map", depth_map);

  // A map beyond OctoMap's key range (+-1.6 km at 5 cm): a return 2 km away, no max range. Every
  // file is saved, the .bt without the voxels beyond the range, and the tool says how many.
  {
    const std::string far_bag = work + "/far.bag";
    std::vector<iv::Point3> pts{{-1.5, 0.013, 0.527}, {-2000.0, 0.013, 0.527}};  // in the map frame
    const iv::Pose sensor_at_1 = sensor_mount;                                   // the base at the origin at 1 s
    {
      rosbag::Bag bag(far_bag, rosbag::bagmode::Write);
      msg::TFMessage statics, dynamic;
      statics.transforms.push_back(ir::to_transform_msg(sensor_mount, "base_link", "sensor", ros::Time(1.0)));
      dynamic.transforms.push_back(ir::to_transform_msg(iv::Pose::Identity(), "map", "base_link", ros::Time(1.0)));
      bag.write("/tf_static", ros::Time(1.0), statics);
      bag.write("/tf", ros::Time(1.0), dynamic);
      std::vector<iv::Point3> local;
      for (const iv::Point3& p : pts) local.push_back(sensor_at_1.inverse() * p);
      bag.write("/cloud", ros::Time(1.0), ir::make_cloud(local, "sensor", ros::Time(1.0)));
    }
    const auto [code, out] = run("'" + tool + "' '" + far_bag +
                                 "' --topic /cloud --update bayes --utility entropy "
                                 "--resolution 0.05 --max-range -1 --explained --no-progress --out '" +
                                 work + "/far'");
    check(code == 0, "a map reaching 2 km at 5 cm is saved (exit " + std::to_string(code) + "): " + out);
    check(out.find("saved " + work + "/far.ivx, " + work + "/far.bt and " + work + "/far.ivxe") != std::string::npos &&
              out.find("voxels beyond OctoMap's 16-bit key range") != std::string::npos,
          "the tool names the three files and the voxels the .bt leaves out");
    try {
      const Grid map = iv::load_grid<Grid>(work + "/far.ivx");
      iv::OctomapExportSummary bt;
      const std::string expected_bt = iv::write_bt_to_memory(map, {}, &bt);
      check(bt.out_of_range > 0 && read_file(work + "/far.bt") == expected_bt,
            "the .bt holds the map without its " + std::to_string(bt.out_of_range) + " voxels beyond the key range");
      check(iv::load_explained(work + "/far.ivxe").size() > 0, "the .ivxe is written too");
    } catch (const std::exception& e) {
      check(false, std::string("loading the far map: ") + e.what());
    }
  }

  // A save that cannot write one of its files writes none: <out>.ivxe is a directory.
  {
    std::filesystem::create_directories(work + "/blocked.ivxe");
    const auto [code, out] =
        run("'" + tool + "' '" + bag_path + "' --topic /cloud --explained --no-progress --out '" + work + "/blocked'");
    check(code == 1 && out.find("nothing was written") != std::string::npos &&
              out.find("a directory, not a regular file") != std::string::npos,
          "a save refused for the .ivxe fails before writing: " + out);
    check(!std::filesystem::exists(work + "/blocked.ivx") && !std::filesystem::exists(work + "/blocked.bt"),
          "neither the .ivx nor the .bt was written");
  }

  // Corrupt bags, read under a 2 GB address-space limit: refused with a message (exit 1), never an
  // abort of rosbag_storage (exit 134).
  {
    namespace bd = intervox_ros::bag_detail;
    bd::Fields f;
    // The first record inside the first lz4 chunk of \p bytes made to claim \p claim bytes of data:
    // the chunk decompressed, patched, compressed again, and the offsets after it (the bag header's
    // index position, the chunk infos' chunk positions) moved by its new length.
    const auto corrupt_lz4_record = [&](std::string bytes, std::uint32_t claim) {
      const std::size_t chunk = find_record(bytes, 13, bytes.size(), 5, f);
      const std::uint32_t usize = bd::u32(f["size"]);
      const std::uint32_t hlen = bd::u32(std::string_view(bytes).substr(chunk, 4));
      const std::uint32_t dlen = bd::u32(std::string_view(bytes).substr(chunk + 4 + hlen, 4));
      std::string plain(usize, '\0');
      unsigned int got = usize;
      roslz4_buffToBuffDecompress(&bytes[chunk + 8 + hlen], dlen, plain.data(), &got);
      bd::Fields g;
      const std::size_t rec = find_record(plain, 0, plain.size(), 2, g);
      const std::uint32_t rh = bd::u32(std::string_view(plain).substr(rec, 4));
      std::memcpy(&plain[rec + 4 + rh], &claim, 4);
      std::string packed(plain.size() + plain.size() / 8 + 1024, '\0');
      unsigned int packed_size = static_cast<unsigned>(packed.size());
      roslz4_buffToBuffCompress(plain.data(), usize, packed.data(), &packed_size, 6);
      packed.resize(packed_size);
      const std::int64_t delta = std::int64_t{packed_size} - std::int64_t{dlen};
      std::string out = bytes.substr(0, chunk + 4 + hlen);
      for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((packed_size >> (8 * i)) & 0xFF));
      out += packed + bytes.substr(chunk + 8 + hlen + dlen);
      const auto moved = [&](std::uint64_t v) {
        return v > chunk ? static_cast<std::uint64_t>(std::int64_t(v) + delta) : v;
      };
      patch_u64_field(out, 13, "index_pos", moved);
      for (std::size_t at = find_record(out, 13, out.size(), 6, f); at != std::string::npos;
           at = find_record(out, record_end(out, at), out.size(), 6, f))
        patch_u64_field(out, at, "chunk_pos", moved);
      return out;
    };
    const std::string lz4_bag = work + "/lz4.bag", plain_bag = work + "/plain.bag";
    for (const bool lz4 : {true, false}) {
      rosbag::Bag bag(lz4 ? lz4_bag : plain_bag, rosbag::bagmode::Write);
      if (lz4) bag.setCompression(rosbag::compression::LZ4);
      msg::TFMessage statics;
      statics.transforms.push_back(ir::to_transform_msg(sensor_mount, "base_link", "sensor", ros::Time(1.0)));
      bag.write("/tf_static", ros::Time(1.0), statics);
      for (std::size_t i = 0; i < clouds.size(); ++i) {
        iv::Pose base = iv::Pose::Identity();
        base.translation() = base_at[i];
        msg::TFMessage dynamic;
        dynamic.transforms.push_back(ir::to_transform_msg(base, "map", "base_link", clouds[i].header.stamp));
        bag.write("/tf", clouds[i].header.stamp, dynamic);
        bag.write("/cloud", clouds[i].header.stamp, clouds[i]);
      }
    }
    const auto replay_limited = [&](const std::string& bag) {
      return run("ulimit -v 2000000; '" + tool + "' '" + bag + "' --topic /cloud --no-progress --out '" + work +
                 "/corrupt'");
    };
    check(replay_limited(lz4_bag).first == 0 && replay_limited(plain_bag).first == 0,
          "the intact lz4 and plain bags replay");
    // The lz4 bag's first message record claims 1.29 GB (inside its compressed chunk).
    const std::string lz4_record_bag = work + "/lz4_record.bag";
    write_file(lz4_record_bag, corrupt_lz4_record(read_file(lz4_bag), 1290000000u));
    {
      const auto [code, out] = replay_limited(lz4_record_bag);
      check(code == 1 && out.find("claims 1290000000 bytes of data") != std::string::npos,
            "an lz4 bag whose message record claims 1.29 GB is refused with a message (exit " + std::to_string(code) +
                "): " + out);
    }
    // Top-level records of the lz4 bag that claim 1.29 GB: the first chunk's header, and the data of
    // the first connection record of the index (rosbag_storage: "Buffer::ensureCapacity: Assertion
    // `buffer_' failed", exit 134, before the check).
    const std::uint32_t huge = 1290000000u;
    for (const auto& [op, part, expect] : {std::tuple{std::uint8_t{5}, 0, "claims a header of 1290000000 bytes"},
                                           std::tuple{std::uint8_t{7}, 1, "claims 1290000000 bytes of data"}}) {
      std::string bytes = read_file(lz4_bag);
      const std::size_t at = find_record(bytes, 13, bytes.size(), op, f);
      if (at == std::string::npos) {
        check(false, "the lz4 bag has a record of op " + std::to_string(op));
        continue;
      }
      const std::size_t field_at = part == 0 ? at : at + 4 + bd::u32(std::string_view(bytes).substr(at, 4));
      std::memcpy(&bytes[field_at], &huge, 4);
      const std::string corrupt = work + "/top_" + std::to_string(op) + ".bag";
      write_file(corrupt, bytes);
      const auto [code, out] = replay_limited(corrupt);
      check(code == 1 && out.find(expect) != std::string::npos, "a record of op " + std::to_string(op) + " that " +
                                                                    expect + " is refused with a message (exit " +
                                                                    std::to_string(code) + "): " + out);
    }
    // The lz4 bag's first chunk claims 1.29 GB uncompressed.
    std::string bytes = read_file(lz4_bag);
    const std::size_t chunk = find_record(bytes, 13, bytes.size(), 5, f);
    const std::size_t size_at = bytes.find(std::string("size=") + f["size"], chunk);
    check(chunk != std::string::npos && f["compression"] == "lz4" && size_at != std::string::npos,
          "the lz4 bag has an lz4 chunk");
    if (size_at != std::string::npos) {
      const std::uint32_t claim = 1290000000u;
      std::memcpy(&bytes[size_at + 5], &claim, 4);
      write_file(lz4_bag, bytes);
      const auto [code, out] = replay_limited(lz4_bag);
      check(code == 1 && out.find("claims 1290000000 bytes uncompressed") != std::string::npos,
            "an lz4 chunk claiming 1.29 GB is refused with a message (exit " + std::to_string(code) + "): " + out);
    }
    // The plain bag's first message record (inside its first chunk) claims 1.29 GB of data.
    bytes = read_file(plain_bag);
    const std::size_t plain_chunk = find_record(bytes, 13, bytes.size(), 5, f);
    const std::uint32_t chunk_header = bd::u32(std::string_view(bytes).substr(plain_chunk, 4));
    const std::size_t data_at = plain_chunk + 8 + chunk_header;
    const std::size_t data_end = data_at + bd::u32(std::string_view(bytes).substr(data_at - 4, 4));
    const std::size_t message = find_record(bytes, data_at, data_end, 2, f);
    check(message != std::string::npos, "the plain bag has a message record in its first chunk");
    if (message != std::string::npos) {
      const std::uint32_t hlen = bd::u32(std::string_view(bytes).substr(message, 4));
      const std::uint32_t claim = 1290000000u;
      std::memcpy(&bytes[message + 4 + hlen], &claim, 4);
      write_file(plain_bag, bytes);
      const auto [code, out] = replay_limited(plain_bag);
      check(code == 1 && out.find("claims 1290000000 bytes of data") != std::string::npos,
            "a message record claiming 1.29 GB is refused with a message (exit " + std::to_string(code) + "): " + out);
    }
  }

  std::printf(failures == 0 ? "bag test passed\n" : "bag test FAILED (%d checks)\n", failures);
  return failures == 0 ? 0 : 1;
}
