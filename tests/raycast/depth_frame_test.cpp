// Inserting a DepthFrame (image, intrinsics, pose, the camera's range) against inserting its
// parts by hand.
#include <catch2/catch.hpp>
#include <intervox/grid/named_grids.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/raycast/insert.hpp>

#include <Eigen/Geometry>
#include <cstddef>
#include <limits>
#include <random>

namespace iv = intervox;

namespace {
// A 24 x 18 camera at a tilted pose; random depths in [0.3, 3] m, some no-return and invalid pixels.
iv::DepthFrame some_frame(double max_range) {
  iv::DepthFrame f;
  f.intrinsics = iv::PinholeIntrinsics::from_fov(24, 18, 1.0, 0.8);
  f.image = iv::DepthImage(24, 18);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<float> depth(0.3f, 3.0f);
  for (auto& d : f.image.depth) d = depth(rng);
  for (int u = 0; u < 24; u += 3) f.image.at(u, 4) = std::numeric_limits<float>::infinity();
  f.image.at(5, 5) = std::numeric_limits<float>::quiet_NaN();
  f.pose = iv::Pose::Identity();
  f.pose.translate(iv::Point3(0.3, -0.2, 1.0));
  f.pose.rotate(Eigen::AngleAxisd(0.5, iv::Point3(0.1, 1.0, 0.3).normalized()));
  f.max_range = max_range;
  return f;
}

// Every observed cell of a is in b with the same value, and they observe as many cells.
void require_same_map(const iv::BayesGrid& a, const iv::BayesGrid& b) {
  REQUIRE(a.observed_count() == b.observed_count());
  a.for_each_observed([&](const iv::Key& k, const auto& c) { REQUIRE(c == b.cell(k)); });
}
}  // namespace

TEST_CASE("a depth frame inserts as its image with the smaller of its range and the options' range",
          "[raycast][insert][frame]") {
  struct Case {
    double frame_range;   // the frame's max range
    double option_range;  // InsertOptions::max_range (-1: unset)
    double by_hand;       // the max range the same image needs by hand
  };
  for (const Case c : {Case{2.0, -1.0, 2.0}, Case{2.0, 1.5, 1.5}, Case{2.0, 2.5, 2.0},
                       Case{std::numeric_limits<double>::infinity(), 1.2, 1.2},
                       Case{std::numeric_limits<double>::infinity(), -1.0, -1.0}}) {
    CAPTURE(c.frame_range, c.option_range);
    const iv::DepthFrame f = some_frame(c.frame_range);
    iv::InsertOptions opt;
    opt.max_range = c.option_range;
    iv::BayesGrid framed(0.05), manual(0.05);
    const iv::InsertStats a = iv::insert_depth_image(framed, f, opt);
    iv::InsertOptions hand = opt;
    hand.max_range = c.by_hand;
    const iv::InsertStats b = iv::insert_depth_image(manual, f.image, f.intrinsics, f.pose, hand);
    CHECK(a.rays == b.rays);
    CHECK(a.hits == b.hits);
    CHECK(a.misses == b.misses);
    CHECK(a.truncated == b.truncated);
    CHECK(a.skipped_no_max_range == b.skipped_no_max_range);
    require_same_map(framed, manual);
    REQUIRE(framed.observed_count() > 100);
    // A reused inserter keeps its own options after a frame.
    iv::ScanInserter inserter(opt);
    iv::BayesGrid g(0.05);
    inserter.insert_depth_image(g, f);
    CHECK(inserter.options().max_range == c.option_range);
  }
  // The frame's range is used: with one beyond every depth (3 m), its no-return pixels add free
  // space; without one they are skipped.
  iv::BayesGrid with(0.05), without(0.05);
  const auto sw = iv::insert_depth_image(with, some_frame(10.0));
  const auto st = iv::insert_depth_image(without, some_frame(std::numeric_limits<double>::infinity()));
  CHECK(sw.skipped_no_max_range == 0);
  CHECK(st.skipped_no_max_range == 8);
  CHECK(sw.hits == st.hits);
  CHECK(with.observed_count() > without.observed_count());
}

TEST_CASE("a bad depth frame is an InvalidArgument and leaves the grid untouched", "[raycast][insert][frame]") {
  iv::BayesGrid g(0.05);
  const auto throws = [&](const iv::DepthFrame& f, const iv::InsertOptions& o = {}) {
    CHECK_THROWS_AS(iv::insert_depth_image(g, f, o), iv::InvalidArgument);
    CHECK(g.observed_count() == 0);
  };
  iv::DepthFrame f = some_frame(2.0);
  f.image.depth.pop_back();  // buffer does not match width x height
  throws(f);
  f = some_frame(2.0);
  f.intrinsics.fx = 0;  // invalid intrinsics
  throws(f);
  f = some_frame(2.0);
  f.intrinsics.width = 23;  // image and intrinsics disagree
  f.intrinsics.cx = 11;
  throws(f);
  f = some_frame(2.0);
  f.pose.translation().x() = std::numeric_limits<double>::quiet_NaN();
  throws(f);
  f = some_frame(2.0);
  f.pose.linear()(0, 0) = std::numeric_limits<double>::infinity();
  throws(f);
  f = some_frame(2.0);
  f.pose.linear() *= 2.0;  // not rigid
  throws(f);
  for (double r : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN()}) throws(some_frame(r));
  // A min range beyond the camera's range leaves no valid window.
  throws(some_frame(2.0), iv::InsertOptions{.max_range = -1.0, .min_range = 3.0});
  CHECK_NOTHROW(iv::insert_depth_image(g, some_frame(2.0)));
}
