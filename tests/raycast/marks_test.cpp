// The two per-scan mark structures (the dense bitmap over the scan's key box and the block
// hash used when that box is too large) and the two walks of the dense one (the table-driven
// merge and the plain SegmentDda walk for very long rays) give exactly the reference result.
#include "reference.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <vector>

namespace iv = intervox;

namespace {

/// Every observed voxel of both grids, in iteration (block allocation) order.
template <class Grid>
std::vector<std::pair<iv::Key, typename Grid::Cell>> cells_of(const Grid& g) {
  std::vector<std::pair<iv::Key, typename Grid::Cell>> c;
  g.for_each_observed([&](const iv::Key& k, const auto& v) { c.emplace_back(k, v); });
  return c;
}

/// Points in every direction (all eight octants, axis-dominant in x, y and z alike) around
/// \p origin, some of them on exact voxel edges and corners.
std::vector<iv::Point3> all_directions(std::mt19937_64& rng, const iv::Point3& origin, int n, double radius,
                                       double resolution) {
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> r(0.01, radius);
  std::vector<iv::Point3> pts;
  for (int i = 0; i < n; ++i) {
    const iv::Point3 d(gauss(rng), gauss(rng), gauss(rng));
    pts.push_back(origin + d.normalized() * r(rng));
  }
  // Diagonals through voxel edges and corners (exact in binary for resolution 0.25).
  for (int sx : {-1, 0, 1})
    for (int sy : {-1, 0, 1})
      for (int sz : {-1, 0, 1})
        for (int len : {1, 3, 6})
          if (sx || sy || sz) pts.push_back(origin + iv::Point3(sx, sy, sz) * (len * resolution));
  return pts;
}

}  // namespace

TEMPLATE_TEST_CASE("the dense marks and the block hash give identical grids, in every direction",
                   "[raycast][insert][marks]", rt::BayesSparse, rt::BayesDense, rt::MeanDense, rt::UpperSparse) {
  constexpr double res = 0.25;
  std::mt19937_64 rng(2024);
  std::uniform_real_distribution<double> jitter(-0.6, 0.6);
  auto dense = rt::make_grid<TestType>(res);
  auto hashed = rt::make_grid<TestType>(res);
  rt::ReferenceMap<TestType> ref;
  iv::ScanInserter a({.max_range = 2.0, .min_range = 0.0, .threads = 1});
  iv::ScanInserter b({.max_range = 2.0, .min_range = 0.0, .threads = 1});
  iv::detail::ScanInserterAccess::force_hash(b, true);
  for (int scan = 0; scan < 120; ++scan) {
    // Voxel-centred origins (exact edge crossings) alternate with random ones, around key 0
    // (negative keys: block floors below zero).
    const iv::Point3 origin = scan % 2 ? iv::Point3(0.125, 0.125 - res, 0.125)
                                       : iv::Point3(jitter(rng), jitter(rng), jitter(rng));
    const auto pts = all_directions(rng, origin, 1 + scan % 7, 2.6, res);  // odd and even ray counts
    const auto sa = a.insert_point_cloud(dense, origin, pts);
    const auto sb = b.insert_point_cloud(hashed, origin, pts);
    REQUIRE(sa == sb);
    ref.insert(dense, origin, pts, 2.0);
  }
  rt::require_equal(dense, ref);
  const auto ca = cells_of(dense), cb = cells_of(hashed);
  REQUIRE(ca.size() == cb.size());
  for (std::size_t i = 0; i < ca.size(); ++i) {  // same order: same block allocation order
    REQUIRE(ca[i].first == cb[i].first);
    REQUIRE(rt::same_cell(ca[i].second, cb[i].second));
  }
}

TEST_CASE("rays longer than the walk tables and scans wider than the dense box match the reference",
          "[raycast][insert][marks]") {
  constexpr double res = 0.1;
  using Grid = rt::BayesSparse;
  Grid g(res);
  rt::ReferenceMap<Grid> ref;
  iv::ScanInserter ins;  // no max range
  const iv::Point3 origin(0.05, -0.03, 0.02);
  // 1. One ray of about 70,000 voxels (beyond DenseRayMarker::kMaxTableSteps) with short ones:
  //    the dense box is long but thin, so the dense marks are used.
  const std::vector<iv::Point3> long_scan{{7000.03, 1.2, -0.7}, {-3.3, 1.1, 0.4}, {0.5, -0.9, 2.2}};
  const auto s1 = ins.insert_point_cloud(g, origin, long_scan);
  CHECK(s1.voxel_steps > iv::detail::DenseRayMarker::kMaxTableSteps);
  ref.insert(g, origin, long_scan, -1.0);
  rt::require_equal(g, ref);
  // 2. Rays far apart in y and z: the key box is far beyond DenseMarks::kMaxBlocks blocks, so
  //    the block hash is used.
  const std::vector<iv::Point3> wide_scan{{-2.0, 1500.0, 0.3}, {0.7, 0.2, -1600.0}, {3.1, -0.4, 0.9}};
  const iv::Point3 o2(0.3, 0.4, 0.5);
  ins.insert_point_cloud(g, o2, wide_scan);
  ref.insert(g, o2, wide_scan, -1.0);
  rt::require_equal(g, ref);
  // 3. A small scan again reuses the dense marks, cleared.
  const std::vector<iv::Point3> small{{1.0, 1.0, 1.0}, {-1.0, 0.5, 0.25}};
  ins.insert_point_cloud(g, origin, small);
  ref.insert(g, origin, small, -1.0);
  rt::require_equal(g, ref);
}

TEST_CASE("the dense marks cover exactly the scan's key box", "[raycast][marks]") {
  iv::detail::DenseMarks m;
  REQUIRE(m.reset(iv::Key{-9, 0, 5}, iv::Key{8, 7, 5}));
  CHECK(m.blocks() == 4);  // x blocks -16..-9, -8..-1, 0..7, 8..15
  CHECK(m.block_base(0) == iv::Key{-16, 0, 0});
  CHECK(m.block_base(3) == iv::Key{8, 0, 0});
  // Ids are distinct for distinct keys in the box and the miss/hit bits sit where BlockMarks says.
  m.set(m.id(iv::Key{-9, 3, 5}));
  m.set(m.id(iv::Key{8, 7, 5}) + iv::detail::DenseMarks::kHit);
  CHECK(m.marks(0).miss[5] == std::uint64_t{1} << (7 | (3 << 3)));
  CHECK(m.marks(3).hit[5] == std::uint64_t{1} << (0 | (7 << 3)));
  // Too large a box is refused, and a refused reset leaves nothing behind.
  CHECK_FALSE(m.reset(iv::Key{0, 0, 0}, iv::Key{8 * 1024, 8 * 1024, 0}));
  REQUIRE(m.reset(iv::Key{-9, 0, 5}, iv::Key{8, 7, 5}));
  for (std::size_t j = 0; j < m.blocks(); ++j)
    for (int w = 0; w < 8; ++w) CHECK((m.marks(j).miss[w] | m.marks(j).hit[w]) == 0);
}
