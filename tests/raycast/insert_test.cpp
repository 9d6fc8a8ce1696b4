#include "reference.hpp"

#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <vector>
#include <intervox/grid/named_grids.hpp>

namespace iv = intervox;

namespace {

template <class Grid>
typename Grid::Cell after(const Grid& g, std::initializer_list<iv::Observation> obs) {
  auto c = g.update_policy().unobserved();
  for (auto o : obs) g.update_policy().update(c, o);
  return c;
}

}  // namespace

TEMPLATE_TEST_CASE("a single ray gives misses along the way and one hit at its end", "[raycast][insert]",
                   INTERVOX_TEST_GRIDS) {
  auto g = rt::make_grid<TestType>(0.1);
  const auto st = iv::insert_ray(g, iv::Point3(0.05, 0.05, 0.05), iv::Point3(0.55, 0.05, 0.05));
  CHECK(st.rays == 1);
  CHECK(st.hits == 1);
  CHECK(st.misses == 5);
  CHECK(st.voxel_steps == 6);
  for (int x = 0; x < 5; ++x) CHECK(rt::same_cell(g.cell({x, 0, 0}), after(g, {iv::Observation::Miss})));
  CHECK(rt::same_cell(g.cell({5, 0, 0}), after(g, {iv::Observation::Hit})));
  CHECK_FALSE(g.is_observed(iv::Key{6, 0, 0}));
  CHECK(g.observed_count() == 6);
}

TEMPLATE_TEST_CASE("per scan a voxel is updated once and a hit wins over a miss", "[raycast][insert]",
                   INTERVOX_TEST_GRIDS) {
  auto g = rt::make_grid<TestType>(0.1);
  // Three rays along x: two end in voxel 3, one passes through it to voxel 6.
  const std::vector<std::array<float, 3>> pts{{0.35f, 0.05f, 0.05f}, {0.37f, 0.06f, 0.05f}, {0.65f, 0.05f, 0.05f}};
  const auto st = iv::insert_point_cloud(g, std::array<double, 3>{0.05, 0.05, 0.05}, pts);
  CHECK(st.rays == 3);
  CHECK(st.hits == 2);
  CHECK(st.misses == 5);  // voxels 0,1,2,4,5
  for (int x : {0, 1, 2, 4, 5}) CHECK(rt::same_cell(g.cell({x, 0, 0}), after(g, {iv::Observation::Miss})));
  CHECK(rt::same_cell(g.cell({3, 0, 0}), after(g, {iv::Observation::Hit})));
  CHECK(rt::same_cell(g.cell({6, 0, 0}), after(g, {iv::Observation::Hit})));
}

TEMPLATE_TEST_CASE("hundreds of random scans match the set-based reference voxel by voxel", "[raycast][insert]",
                   INTERVOX_TEST_GRIDS) {
  auto g = rt::make_grid<TestType>(0.1);
  rt::ReferenceMap<TestType> ref;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  iv::ScanInserter inserter({.max_range = 1.2, .min_range = 0.0, .threads = 1});
  for (int scan = 0; scan < 300; ++scan) {
    // The sensor stays in a small region, so the same voxels are updated scan after scan
    // (a cycling per-scan stamp would start dropping updates here).
    const iv::Point3 origin(jitter(rng), jitter(rng), jitter(rng));
    const auto pts = rt::random_scan(rng, origin, 40, 1.8);
    const auto st = inserter.insert_point_cloud(g, origin, pts);
    REQUIRE(st.rays == pts.size());
    ref.insert(g, origin, pts, 1.2);
  }
  rt::require_equal(g, ref);
  // Some voxels near the sensor have been observed in (nearly) every scan.
  std::size_t busy = 0;
  for (int x = -1; x <= 0; ++x)
    for (int y = -1; y <= 0; ++y)
      for (int z = -1; z <= 0; ++z) busy += g.is_observed(iv::Key{x, y, z}) ? 1 : 0;
  CHECK(busy == 8);
}

TEST_CASE("a voxel hit in every one of 1000 scans keeps counting", "[raycast][insert]") {
  // Bayes without clamping effects: with p_hit = 0.501 the log-odds grows linearly for 1000 scans
  // (to 4.0, below the clamp at 0.999, log-odds 6.9).
  iv::BayesParams p;
  p.p_hit = 0.501;
  p.clamp_max = 0.999;
  p.occupied_threshold = 0.99;
  iv::BayesGrid g(0.1, iv::BayesLogOdds(p));
  iv::ScanInserter ins;
  for (int i = 0; i < 1000; ++i) ins.insert_ray(g, iv::Point3(0.05, 0.05, 0.05), iv::Point3(0.45, 0.05, 0.05));
  const float expected = 1000.0f * g.update_policy().hit_log_odds();
  CHECK(g.update_policy().log_odds(g.cell({4, 0, 0})) == Approx(expected).epsilon(1e-4));
}

TEMPLATE_TEST_CASE("results are identical for any thread count", "[raycast][insert][threads][threaded]",
                   INTERVOX_TEST_GRIDS) {
  std::mt19937_64 rng(11);
  const iv::Point3 origin(0.01, -0.02, 0.03);
  const test::ThreadCap cap(3);  // three threads even on a smaller machine
  auto g1 = rt::make_grid<TestType>(0.05);
  auto g2 = rt::make_grid<TestType>(0.05);
  auto g3 = rt::make_grid<TestType>(0.05);
  auto g0 = rt::make_grid<TestType>(0.05);
  iv::ScanInserter i1({.max_range = 2.0, .min_range = 0.0, .threads = 1});
  iv::ScanInserter i2({.max_range = 2.0, .min_range = 0.0, .threads = 2});
  iv::ScanInserter i3({.max_range = 2.0, .min_range = 0.0, .threads = 3});
  iv::ScanInserter i0({.max_range = 2.0, .min_range = 0.0, .threads = 0});
  for (int scan = 0; scan < 3; ++scan) {
    const auto pts = rt::random_scan(rng, origin, 20000, 2.6);
    const auto s1 = i1.insert_point_cloud(g1, origin, pts);
    const auto s2 = i2.insert_point_cloud(g2, origin, pts);
    const auto s3 = i3.insert_point_cloud(g3, origin, pts);
    const auto s0 = i0.insert_point_cloud(g0, origin, pts);
    CHECK(s1 == s2);
    CHECK(s1 == s3);
    CHECK(s1 == s0);
  }
  const auto c1 = rt::cells_of(g1);
  for (const auto* g : {&g2, &g3, &g0}) {
    const auto c = rt::cells_of(*g);
    REQUIRE(c1.size() == c.size());
    for (std::size_t i = 0; i < c1.size(); ++i) {  // same order: same block allocation order
      REQUIRE(c1[i].first == c[i].first);
      REQUIRE(rt::same_cell(c1[i].second, c[i].second));
    }
  }
}

TEMPLATE_TEST_CASE("a point beyond max range gives misses only, up to the voxel of the cut end", "[raycast][insert]",
                   INTERVOX_TEST_GRIDS) {
  auto g = rt::make_grid<TestType>(0.1);
  const auto st = iv::insert_ray(g, iv::Point3(0.05, 0.05, 0.05), iv::Point3(2.05, 0.05, 0.05),
                                 {.max_range = 0.5, .min_range = 0.0, .threads = 1});
  CHECK(st.truncated == 1);
  CHECK(st.hits == 0);
  CHECK(st.misses == 5);  // voxels 0..4; the cut end lies in voxel 5, which is not updated (OctoMap)
  CHECK_FALSE(g.is_observed(iv::Key{5, 0, 0}));
  CHECK(g.occupancy(iv::Key{4, 0, 0}) != iv::Occupancy::Occupied);
}

TEMPLATE_TEST_CASE("bad points are skipped and counted, never inserted", "[raycast][insert]", INTERVOX_TEST_GRIDS) {
  auto g = rt::make_grid<TestType>(0.1);
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  const iv::Point3 o(0.05, 0.05, 0.05);
  const std::vector<iv::Point3> pts{
      {nan, 0, 0},
      {inf, 0, 0},
      {0, -inf, 0},        // invalid
      o,                   // zero length
      {0.07, 0.05, 0.05},  // closer than min range
      {1e9, 0, 0},
      {0, 0, -1e300},         // outside the key range
      {1e300, 1e300, 1e300},  // length overflows
      {0.45, 0.05, 0.05},     // the one good point
  };
  const auto st = iv::insert_point_cloud(g, o, pts, {.max_range = -1, .min_range = 0.05, .threads = 1});
  CHECK(st.skipped_invalid == 3);
  CHECK(st.skipped_zero_length == 1);
  CHECK(st.skipped_min_range == 1);
  CHECK(st.skipped_key_range == 3);
  CHECK(st.skipped() == 8);
  CHECK(st.rays == 1);
  CHECK(g.observed_count() == 5);
  // A bad origin skips everything.
  const auto bad = iv::insert_point_cloud(g, iv::Point3(nan, 0, 0), pts);
  CHECK(bad.rays == 0);
  CHECK(bad.skipped() == pts.size());
  CHECK(g.observed_count() == 5);
}

TEST_CASE("invalid options are rejected with InvalidArgument", "[raycast][insert]") {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(iv::ScanInserter({.max_range = nan}), iv::InvalidArgument);
  CHECK_THROWS_AS(iv::ScanInserter({.max_range = 1.0, .min_range = -1.0}), iv::InvalidArgument);
  CHECK_THROWS_AS(iv::ScanInserter({.max_range = 1.0, .min_range = 2.0}), iv::InvalidArgument);
  CHECK_THROWS_AS(iv::ScanInserter({.max_range = 1.0, .min_range = nan}), iv::InvalidArgument);
  CHECK_NOTHROW(iv::ScanInserter({.max_range = std::numeric_limits<double>::infinity(), .min_range = 3.0}));
}

TEMPLATE_TEST_CASE("a depth image is the point cloud it back-projects, and +inf is free to max range",
                   "[raycast][insert][depth]", INTERVOX_TEST_GRIDS) {
  iv::PinholeIntrinsics k;
  k.width = 16;
  k.height = 12;
  k.fx = k.fy = 10.0;
  k.cx = 7.5;
  k.cy = 5.5;
  iv::DepthImage img(16, 12);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<float> depth(0.3f, 2.5f);
  for (auto& d : img.depth) d = depth(rng);
  img.at(0, 0) = std::numeric_limits<float>::infinity();
  img.at(1, 0) = std::numeric_limits<float>::quiet_NaN();
  img.at(2, 0) = 0.0f;
  img.at(3, 0) = -1.0f;
  iv::Pose pose = iv::Pose::Identity();
  pose.translate(iv::Point3(0.2, -0.1, 0.3));
  pose.rotate(Eigen::AngleAxisd(0.4, iv::Point3(0.2, 1.0, 0.1).normalized()));
  const iv::InsertOptions opt{.max_range = 2.0, .min_range = 0.0, .threads = 1};

  auto g = rt::make_grid<TestType>(0.05);
  const auto st = iv::insert_depth_image(g, img, k, pose, opt);
  CHECK(st.skipped_invalid == 3);
  CHECK(st.rays == 16 * 12 - 3);

  // The same as beams from the pose's origin.
  std::vector<iv::Beam> beams;
  for (int v = 0; v < 12; ++v)
    for (int u = 0; u < 16; ++u) {
      const float z = img.at(u, v);
      if (std::isinf(z))
        beams.push_back({pose.translation(), pose * k.ray(u, v), false});
      else if (z > 0)
        beams.push_back({pose.translation(), pose * (k.ray(u, v) * double(z)), true});
    }
  auto h = rt::make_grid<TestType>(0.05);
  const auto sb = iv::insert_beams(h, std::span<const iv::Beam>(beams), opt);
  CHECK(sb.rays == st.rays);
  CHECK(sb.truncated == st.truncated);
  CHECK(sb.hits == st.hits);
  CHECK(sb.misses == st.misses);
  std::size_t n = 0;
  g.for_each_observed([&](const iv::Key& key, const auto& c) {
    ++n;
    REQUIRE(rt::same_cell(c, h.cell(key)));
  });
  CHECK(n == h.observed_count());

  // Mismatched intrinsics are an error.
  k.width = 15;
  CHECK_THROWS_AS(iv::insert_depth_image(g, img, k, pose, opt), iv::InvalidArgument);
}

TEST_CASE("a beam without a return needs a max range", "[raycast][insert]") {
  iv::BayesGrid g(0.1);
  const std::vector<iv::Beam> beams{{iv::Point3(0.05, 0.05, 0.05), iv::Point3(1, 0.05, 0.05), false}};
  CHECK(iv::insert_beams(g, std::span<const iv::Beam>(beams)).skipped_no_max_range == 1);
  CHECK(g.observed_count() == 0);
  const auto st = iv::insert_beams(g, std::span<const iv::Beam>(beams), {.max_range = 0.3});
  CHECK(st.misses == 3);  // voxels 0, 1, 2; the cut end (0.35) lies in voxel 3, not updated
  CHECK(g.counts().free + g.counts().unknown == 3);
}

TEMPLATE_TEST_CASE(
    "a bounded grid holds bit for bit the in-box voxels of rays that run far past its box, walked only to it",
    "[raycast][insert]", rt::BayesDense, rt::MeanDense, rt::BayesBoundedSparse) {
  // Returns 30 to 100 m away (and some inside) from origins inside the 6 m box (kBounds) and 4 m
  // outside it, with and without a max range: the bounded grid must hold exactly what the reference
  // (every ray traversed whole, std::set per scan) leaves inside the box, while its walks, cut
  // where the rays leave the box, take about the box's voxels, not the rays' length.
  for (const double max_range : {-1.0, 25.0}) {
    CAPTURE(max_range);
    auto bounded = rt::make_grid<TestType>(0.1);
    rt::ReferenceMap<TestType> ref;
    iv::ScanInserter ins({.max_range = max_range, .threads = 2});
    std::mt19937_64 rng(19);
    std::normal_distribution<double> gauss(0.0, 1.0);
    std::uniform_real_distribution<double> far(30.0, 100.0), inside(-2.9, 2.9);
    std::uint64_t steps = 0, rays = 0;
    for (int scan = 0; scan < 4; ++scan) {
      const iv::Point3 origin =
          scan == 3 ? iv::Point3(-7.0, inside(rng), inside(rng)) : iv::Point3(inside(rng), inside(rng), inside(rng));
      std::vector<iv::Point3> pts;
      for (int i = 0; i < 500; ++i) {
        const iv::Point3 d = iv::Point3(gauss(rng), gauss(rng), gauss(rng)).normalized();
        pts.push_back(i % 5 == 0 ? iv::Point3(inside(rng), inside(rng), inside(rng))
                                 : iv::Point3(origin + d * far(rng)));
      }
      const iv::InsertStats st = ins.insert_point_cloud(bounded, origin, pts);
      ref.insert(bounded, origin, pts, max_range);
      steps += st.voxel_steps;
      rays += st.rays;
    }
    rt::require_equal(bounded, ref);
    CHECK(ref.cells.size() > 10000);
    // A walk within the box takes at most 3 x 60 voxels, one from outside it (10 m from the far
    // face) some 100 more before it enters, and a cut walk one voxel past the box on each axis;
    // the whole rays run to 1,000 voxels and more.
    CHECK(steps <= rays * 300);
  }
}

TEMPLATE_TEST_CASE("updates outside a bounded grid are dropped and counted", "[raycast][insert]", rt::BayesDense,
                   rt::MeanDense, rt::BayesBoundedSparse, rt::CompactBoundedSparse) {
  auto g = rt::make_grid<TestType>(0.1);  // bounds [-3, 3]
  const auto st = iv::insert_ray(g, iv::Point3(2.55, 0.05, 0.05), iv::Point3(3.55, 0.05, 0.05));
  CHECK(st.misses == 5);          // 25..29
  CHECK(st.outside_bounds == 6);  // 30..34 misses and the hit at 35
  CHECK(g.observed_count() == 5);
}
