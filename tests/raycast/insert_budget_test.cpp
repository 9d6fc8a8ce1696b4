// The insertion budget (InsertOptions::max_grid_bytes): a scan that may add more than it to a
// sparse map is refused before anything is allocated, with a message naming the likely cause;
// the bound it uses is never below what a scan really adds.
#include <catch2/catch.hpp>
#include <intervox/grid/named_grids.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/raycast/insert.hpp>
#include <intervox/raycast/projective.hpp>

#include <cstdint>
#include <random>
#include <set>
#include <string>
#include <tuple>
#include <vector>

namespace iv = intervox;

namespace {
// A 64 x 48 camera looking along +z from (0, 0, 1), every pixel at z-depth `depth`.
iv::DepthFrame flat_frame(float depth) {
  iv::DepthFrame f;
  f.intrinsics = iv::PinholeIntrinsics::from_fov(64, 48, 1.0, 0.8);
  f.image = iv::DepthImage(64, 48);
  for (auto& d : f.image.depth) d = depth;
  f.pose = iv::Pose::Identity();
  f.pose.translate(iv::Point3(0.0, 0.0, 1.0));
  return f;
}

// The distinct 8^3 blocks of a grid's observed voxels (a fresh grid allocates only those).
template <class G>
std::size_t observed_blocks(const G& g) {
  std::set<std::tuple<int, int, int>> blocks;
  g.for_each_observed([&](const iv::Key& k, const auto&) { blocks.emplace(k.x >> 3, k.y >> 3, k.z >> 3); });
  return blocks.size();
}
}  // namespace

TEST_CASE("a depth image in millimetres without a max range is refused before the map grows",
          "[raycast][insert][budget]") {
  const iv::DepthFrame f = flat_frame(1500.0f);  // 1.5 m written in millimetres
  iv::BayesGrid g(0.05);
  const std::size_t before = g.memory_bytes();
  iv::ScanInserter ins;  // default budget, no max range
  try {
    ins.insert_depth_image(g, f.image, f.intrinsics, f.pose);
    FAIL("the scan was not refused");
  } catch (const iv::InvalidArgument& e) {
    const std::string msg = e.what();
    CHECK(msg.find("insertion budget") != std::string::npos);
    CHECK(msg.find("max_grid_bytes") != std::string::npos);
    CHECK(msg.find("millimetres") != std::string::npos);
    CHECK(msg.find("max_range") != std::string::npos);
  }
  CHECK(g.observed_count() == 0);
  CHECK(g.memory_bytes() == before);
  // The same image in metres, and the millimetres with a max range, are within the budget.
  CHECK(ins.insert_depth_image(g, flat_frame(1.5f).image, f.intrinsics, f.pose).rays == 64 * 48);
  iv::ScanInserter capped({.max_range = 4.0});
  CHECK(capped.insert_depth_image(g, f.image, f.intrinsics, f.pose).truncated == 64 * 48);
}

TEST_CASE("a depth image whose tiny focal length fans its rays out is refused naming the intrinsics, not millimetres",
          "[raycast][insert][budget]") {
  iv::DepthFrame f = flat_frame(1.5f);       // metres, as it should be
  f.intrinsics.fx = f.intrinsics.fy = 0.01;  // a focal length of 10 mm given in metres, not pixels
  REQUIRE(f.intrinsics.fov_x() > 3.1);
  iv::BayesGrid g(0.05);
  const auto refused = [&](auto&& insert) {
    try {
      insert();
      FAIL("the frame was not refused");
    } catch (const iv::InvalidArgument& e) {
      const std::string msg = e.what();
      INFO(msg);
      CHECK(msg.find("max_grid_bytes") != std::string::npos);
      CHECK(msg.find("fx = 0.01") != std::string::npos);
      CHECK(msg.find("field of view") != std::string::npos);
      CHECK(msg.find("millimetres") == std::string::npos);
    }
  };
  iv::ScanInserter exact;
  refused([&] { exact.insert_depth_image(g, f.image, f.intrinsics, f.pose); });
  iv::ProjectiveInserter projective;
  refused([&] { projective.insert_depth_image(g, f.image, f.intrinsics, f.pose); });
  CHECK(g.observed_count() == 0);
  // Ordinary intrinsics keep the usual causes.
  CHECK(iv::detail::wide_intrinsics_cause(flat_frame(1.5f).intrinsics).empty());
  CHECK(iv::PinholeIntrinsics::from_fov(64, 48, 1.0, 0.8).fov_x() == Approx(1.0));
}

TEST_CASE("the insertion budget is what the options say, and bounded grids clip it", "[raycast][insert][budget]") {
  const iv::DepthFrame f = flat_frame(3.0f);
  iv::InsertOptions small;
  small.max_grid_bytes = 64 * 1024;  // 30 blocks of a Bayes grid
  iv::BayesGrid g(0.02);
  CHECK_THROWS_AS(iv::insert_depth_image(g, f.image, f.intrinsics, f.pose, small), iv::InvalidArgument);
  CHECK(g.observed_count() == 0);
  iv::InsertOptions off = small;
  off.max_grid_bytes = iv::kUnlimitedInsertBudget;
  CHECK(iv::insert_depth_image(g, f.image, f.intrinsics, f.pose, off).rays == 64 * 48);
  // A sparse grid with small bounds drops what lies outside: the bound is clipped to them.
  iv::BayesGrid bounded(0.02, iv::Bounds{iv::Point3(-0.1, -0.1, 0.9), iv::Point3(0.1, 0.1, 1.1)});
  CHECK(iv::insert_depth_image(bounded, flat_frame(30.0f).image, f.intrinsics, f.pose, small).rays == 64 * 48);
  // A dense grid never grows: never refused.
  iv::DenseBayesGrid dense(0.05, iv::Bounds{iv::Point3(-1, -1, 0), iv::Point3(1, 1, 2)});
  CHECK(iv::insert_depth_image(dense, flat_frame(300.0f).image, f.intrinsics, f.pose, small).rays == 64 * 48);
  CHECK(iv::InsertOptions{}.max_grid_bytes == iv::kDefaultInsertBudgetBytes);
}

TEST_CASE("the block bound of a scan is never below the blocks it allocates", "[raycast][insert][budget]") {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  for (int trial = 0; trial < 20; ++trial) {
    const double res = trial % 2 ? 0.05 : 0.013;
    const iv::Point3 origin(u(rng) * 0.1, u(rng) * 0.1, u(rng) * 0.1);
    std::vector<iv::Point3> pts;
    for (int i = 0; i < 200; ++i) pts.emplace_back(u(rng), u(rng), u(rng) * (trial % 3 + 1));
    iv::BayesGrid g(res);
    iv::InsertStats counted;
    std::uint64_t cost = 0;
    iv::Key lo{}, hi{};
    bool any = false;
    for (const auto& p : pts) {
      const auto r = iv::detail::prepare_ray(g.geometry(), iv::InsertOptions{}, iv::Beam{origin, p, true}, counted);
      REQUIRE(r);
      cost += r->cost();
      for (int a = 0; a < 3; ++a) {
        const int l = std::min(r->k0[a], r->k1[a]), h = std::max(r->k0[a], r->k1[a]);
        lo[a] = any ? std::min(lo[a], l) : l;
        hi[a] = any ? std::max(hi[a], h) : h;
      }
      any = true;
    }
    const std::uint64_t bound = iv::detail::scan_block_bound(lo, hi, cost, counted.rays, std::nullopt);
    iv::insert_point_cloud(g, origin, pts);
    INFO("trial " << trial << ": bound " << bound << ", blocks " << observed_blocks(g));
    CHECK(bound >= observed_blocks(g));
    // One ray alone: its own bound holds too (the rays' part of the bound, not the box's).
    iv::BayesGrid one(res);
    iv::InsertStats c1;
    const auto r = iv::detail::prepare_ray(one.geometry(), iv::InsertOptions{}, iv::Beam{origin, pts[0], true}, c1);
    iv::insert_ray(one, origin, pts[0]);
    CHECK(r->cost() / 8 + 4 >= observed_blocks(one));
  }
}
