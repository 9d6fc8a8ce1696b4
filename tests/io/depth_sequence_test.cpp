// Recorded depth sequences in the TUM RGB-D layout: the committed sequence tests/data/tum_lab
// (rendered by the simulator, see the hidden generator below) replays into the same map as the
// simulated frames inserted directly; malformed files name the file and line.
#include <catch2/catch.hpp>
#include <intervox/grid/named_grids.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/io/depth_sequence.hpp>
#include <intervox/raycast/insert.hpp>
#include <intervox/sim/scenes.hpp>
#include <intervox/sim/simulate.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace iv = intervox;

namespace {
const std::string kSequence = std::string(INTERVOX_TEST_DATA) + "/tum_lab";
constexpr int kFrames = 4;

// The recorded camera: 32 x 24 pixels, 60 x 45 degrees, 0.1-5 m, at 1 m height in the lab room.
iv::DepthCamera camera() { return iv::DepthCamera::make(32, 24, iv::deg(60), iv::deg(45), 0.1, 5.0); }
iv::Pose frame_pose(const iv::sim::LabRoom& lab, int i) {
  const iv::Point3 eye = lab.start + iv::Point3(0.1 * i, 0.0, 1.0);
  const double yaw = iv::deg(40.0 * i);
  return iv::look_at(eye, eye + iv::Point3(std::cos(yaw), std::sin(yaw), -0.1));
}
iv::sim::CameraMeasurement simulated(const iv::sim::LabRoom& lab, int i) {
  return iv::sim::simulate(camera(), lab.scene, frame_pose(lab, i), 100 + static_cast<std::uint64_t>(i));
}
// What the file keeps of a depth: 1/5000 m steps, no return and invalid both 0 (invalid).
iv::DepthImage as_stored(const iv::DepthImage& d) {
  iv::DepthImage q = d;
  for (float& v : q.depth) {
    const std::uint16_t s = iv::depth_png_value(v);
    v = s == 0 ? std::numeric_limits<float>::quiet_NaN() : static_cast<float>(s / 5000.0);
  }
  return q;
}
void write_text(const std::string& path, const std::string& text) { std::ofstream(path) << text; }
}  // namespace

TEST_CASE("generate the committed TUM sequence", "[.generate]") {
  const iv::sim::LabRoom lab = iv::sim::make_lab_room();
  std::vector<double> times;
  std::vector<iv::DepthImage> images;
  std::vector<iv::Pose> poses;
  for (int i = 0; i < kFrames; ++i) {
    times.push_back(1000.0 + 0.5 * i);
    images.push_back(simulated(lab, i).image);
    poses.push_back(frame_pose(lab, i));
  }
  std::filesystem::create_directories(kSequence + "/depth");
  iv::write_depth_sequence(kSequence, times, images, poses);
}

TEST_CASE("the replayed TUM sequence gives the map of the simulated frames inserted directly", "[io][sequence]") {
  const iv::sim::LabRoom lab = iv::sim::make_lab_room();
  const iv::DepthSequence seq = iv::DepthSequence::open(kSequence, camera().intrinsics);
  REQUIRE(seq.size() == kFrames);
  iv::InsertOptions io;
  io.max_range = 5.0;
  iv::BayesGrid replayed(0.05), direct(0.05);
  for (std::size_t i = 0; i < seq.size(); ++i) {
    iv::insert_depth_image(replayed, seq.frame(i), io);
    const iv::sim::CameraMeasurement m = simulated(lab, static_cast<int>(i));
    CHECK((seq.frames()[i].pose.matrix() - m.pose.matrix()).cwiseAbs().maxCoeff() < 1e-12);
    iv::insert_depth_image(direct, as_stored(m.image), m.intrinsics, m.pose, io);
  }
  REQUIRE(replayed.counts().observed() > 1000);
  CHECK(replayed.counts().free == direct.counts().free);
  CHECK(replayed.counts().occupied == direct.counts().occupied);
  CHECK(replayed.counts().unknown == direct.counts().unknown);
  std::size_t differ = 0;
  replayed.for_each_observed(
      [&](const iv::Key& k, const auto&) { differ += replayed.probability(k) != direct.probability(k); });
  CHECK(differ == 0);
}

TEST_CASE("a depth frame takes the nearest pose within the tolerance, or is skipped", "[io][sequence]") {
  const std::string dir = (std::filesystem::temp_directory_path() / "intervox_tum_assoc").string();
  std::filesystem::create_directories(dir + "/depth");
  iv::DepthImage img(2, 2);
  img.at(0, 0) = 1.0f;
  iv::write_depth_png(dir + "/depth/a.png", img);
  write_text(dir + "/depth.txt", "# comment\n10.00 depth/a.png\n10.50 depth/a.png\n20.00 depth/a.png\n");
  write_text(dir + "/groundtruth.txt", "9.99 1 0 0 0 0 0 1\n10.015 2 0 0 0 0 0 1\n10.49 3 0 0 0 0 0 1\n");
  const auto k = iv::PinholeIntrinsics::from_fov(2, 2, 1.0, 1.0);
  const iv::DepthSequence s = iv::DepthSequence::open(dir, k);
  CHECK(s.depth_frames() == 3);
  REQUIRE(s.size() == 2);                              // 20.00 has no pose within 0.02 s
  CHECK(s.frames()[0].pose.translation().x() == 1.0);  // 9.99 is nearer than 10.015
  CHECK(s.frames()[1].pose.translation().x() == 3.0);
  const iv::DepthImage d = s.depth(0);
  CHECK(d.at(0, 0) == 1.0f);
  CHECK(std::isnan(d.at(1, 1)));
  CHECK_THROWS_AS(s.depth(2), iv::OutOfRange);
  CHECK_THROWS_AS(iv::DepthSequence::open(dir, iv::PinholeIntrinsics::from_fov(4, 4, 1.0, 1.0)).depth(0), iv::IoError);
}

TEST_CASE("malformed or missing sequence files give an IoError naming the file and line", "[io][sequence]") {
  const std::string dir = (std::filesystem::temp_directory_path() / "intervox_tum_bad").string();
  std::filesystem::create_directories(dir + "/depth");
  const auto k = iv::PinholeIntrinsics::from_fov(2, 2, 1.0, 1.0);
  auto message = [&] {
    try {
      iv::DepthSequence::open(dir, k);
    } catch (const iv::IoError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  std::filesystem::remove(dir + "/groundtruth.txt");
  write_text(dir + "/depth.txt", "1.0 depth/a.png\n");
  CHECK_THAT(message(), Catch::Contains("groundtruth.txt") && Catch::Contains("cannot open"));
  write_text(dir + "/groundtruth.txt", "# header\n1.0 0 0 0 0 0 0 1\n1.1 0 0 zero 0 0 0 1\n");
  CHECK_THAT(message(), Catch::Contains("groundtruth.txt' line 3"));
  write_text(dir + "/groundtruth.txt", "1.0 0 0 0 0 0 0 2\n");
  CHECK_THAT(message(), Catch::Contains("line 1") && Catch::Contains("unit length"));
  write_text(dir + "/groundtruth.txt", "1.0 0 0 0 0 0 0 1\n");
  write_text(dir + "/depth.txt", "1.0\n");
  CHECK_THAT(message(), Catch::Contains("depth.txt' line 1"));
  write_text(dir + "/depth.txt", "1.0 depth/missing.png\n");
  const iv::DepthSequence s = iv::DepthSequence::open(dir, k);
  CHECK_THROWS_WITH(s.depth(0), Catch::Contains("missing.png"));
  write_text(dir + "/depth/text.png", "not a png");
  CHECK_THROWS_WITH(iv::read_depth_png(dir + "/depth/text.png"), Catch::Contains("text.png"));
}

TEST_CASE("a depth list that is a directory, empty, or holds a hexadecimal timestamp is refused", "[io][sequence]") {
  const std::string dir = (std::filesystem::temp_directory_path() / "intervox_tum_strict").string();
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir + "/depth");
  const auto k = iv::PinholeIntrinsics::from_fov(2, 2, 1.0, 1.0);
  auto message = [&] {
    try {
      iv::DepthSequence::open(dir, k);
    } catch (const iv::IoError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  write_text(dir + "/groundtruth.txt", "1.0 0 0 0 0 0 0 1\n");
  std::filesystem::create_directory(dir + "/depth.txt");
  CHECK_THAT(message(), Catch::Contains("depth.txt") && Catch::Contains("directory"));
  std::filesystem::remove(dir + "/depth.txt");
  write_text(dir + "/depth.txt", "# only comments\n\n");
  CHECK_THAT(message(), Catch::Contains("depth.txt") && Catch::Contains("no depth frames"));
  write_text(dir + "/depth.txt", "0x3e8 depth/a.png\n");
  CHECK_THAT(message(), Catch::Contains("depth.txt' line 1") && Catch::Contains("'0x3e8' is not a decimal number"));
  write_text(dir + "/depth.txt", "1.0s depth/a.png\n");
  CHECK_THAT(message(), Catch::Contains("'1.0s' is not a decimal number"));
  write_text(dir + "/groundtruth.txt", "1.0 0 0 0x1 0 0 0 1\n");
  write_text(dir + "/depth.txt", "1.0 depth/a.png\n");
  CHECK_THAT(message(), Catch::Contains("groundtruth.txt' line 1") && Catch::Contains("'0x1'"));
  write_text(dir + "/groundtruth.txt", "1.0 0 0 0 0 0 0 1\n");
  write_text(dir + "/depth.txt", "1.0 depth/\x1b]0;owned\x07.png\n");
  CHECK_THAT(message(), Catch::Contains("control bytes") && Catch::Contains("\\x1B]0;owned\\x07.png"));
  // Escape bytes of a file are quoted, never echoed to the terminal.
  write_text(dir + "/groundtruth.txt", "1.0 0 0 \x1b[2J 0 0 0 1\n");
  const std::string m = message();
  CHECK(m.find('\x1b') == std::string::npos);
  CHECK_THAT(m, Catch::Contains("\\x1B[2J"));
}

TEST_CASE("lists with CR-only or CR LF line endings read line by line", "[io][sequence]") {
  const std::string dir = (std::filesystem::temp_directory_path() / "intervox_tum_cr").string();
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir + "/depth");
  const auto k = iv::PinholeIntrinsics::from_fov(2, 2, 1.0, 1.0);
  write_text(dir + "/groundtruth.txt", "# truth\r1.0 1 0 0 0 0 0 1\r2.0 2 0 0 0 0 0 1\r");
  write_text(dir + "/depth.txt", "# depth\r\n1.0 depth/a.png\r\n2.0 depth/b.png\r\n");
  const iv::DepthSequence s = iv::DepthSequence::open(dir, k);
  CHECK(s.depth_frames() == 2);
  REQUIRE(s.size() == 2);
  CHECK(s.frames()[1].pose.translation().x() == 2.0);
  CHECK(s.frames()[1].depth_path == dir + "/depth/b.png");
  write_text(dir + "/depth.txt", "1.0 depth/a.png\r2.0 depth/b.png\rbad\r");
  CHECK_THROWS_WITH(iv::DepthSequence::open(dir, k), Catch::Contains("depth.txt' line 3"));
}
