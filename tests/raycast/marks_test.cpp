// The two per-scan mark structures (the bitmaps over the scan's key box and the block hash used
// when that box is too large) and the walks of the box bitmaps (AVX-512 and AVX2, sixteen and
// eight rays at once, where the processor has them; the portable table-driven walk; one ray at a
// time) give exactly the reference result.
#include "reference.hpp"

#include <intervox/raycast/vector_walks.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <vector>

namespace iv = intervox;

namespace {

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

TEMPLATE_TEST_CASE("the box bitmaps with either walk and the block hash give identical grids, in every direction",
                   "[raycast][insert][marks]", rt::BayesSparse, rt::BayesDense, rt::MeanDense, rt::UpperSparse,
                   rt::BayesBoundedSparse) {
  iv::use_vector_walks();  // the walks this processor runs, beside the portable ones
  constexpr double res = 0.25;
  std::mt19937_64 rng(2024);
  std::uniform_real_distribution<double> jitter(-0.6, 0.6);
  auto boxed = rt::make_grid<TestType>(res);
  auto portable = rt::make_grid<TestType>(res);
  auto avx2 = rt::make_grid<TestType>(res);
  auto hashed = rt::make_grid<TestType>(res);
  rt::ReferenceMap<TestType> ref;
  const iv::InsertOptions opt{.max_range = 2.0, .min_range = 0.0, .threads = 1};
  iv::ScanInserter a(opt), b(opt), c(opt), d(opt);
  iv::detail::ScanInserterAccess::force_hash(b, true);
  iv::detail::ScanInserterAccess::set_walk(c, iv::detail::WalkKind::Table);
  iv::detail::ScanInserterAccess::set_walk(d, iv::detail::WalkKind::Avx2);  // Table without AVX2
  for (int scan = 0; scan < 120; ++scan) {
    // Voxel-centred origins (exact edge crossings) alternate with random ones, around key 0
    // (negative keys: block floors below zero).
    const iv::Point3 origin =
        scan % 2 ? iv::Point3(0.125, 0.125 - res, 0.125) : iv::Point3(jitter(rng), jitter(rng), jitter(rng));
    // Fewer rays than the AVX2 walk's eight lanes, and many more (lanes refilled while others
    // walk; rays of one voxel, of none, cut at max range).
    const int n = scan % 3 == 0 ? 60 + scan % 7 : 1 + scan % 7;
    const auto pts = all_directions(rng, origin, n, 2.6, res);
    const auto sa = a.insert_point_cloud(boxed, origin, pts);
    const auto sb = b.insert_point_cloud(hashed, origin, pts);
    const auto sc = c.insert_point_cloud(portable, origin, pts);
    const auto sd = d.insert_point_cloud(avx2, origin, pts);
    REQUIRE(sa == sb);
    REQUIRE(sa == sc);
    REQUIRE(sa == sd);
    ref.insert(boxed, origin, pts, 2.0);
  }
  rt::require_equal(boxed, ref);
  for (const auto* other : {&hashed, &portable, &avx2}) {
    const auto ca = rt::cells_of(boxed), cb = rt::cells_of(*other);
    REQUIRE(ca.size() == cb.size());
    for (std::size_t i = 0; i < ca.size(); ++i) {  // same order: same block allocation order
      REQUIRE(ca[i].first == cb[i].first);
      REQUIRE(rt::same_cell(ca[i].second, cb[i].second));
    }
  }
}

TEST_CASE("very long rays and scans wider than the box bitmaps match the reference, for every walk",
          "[raycast][insert][marks]") {
  iv::use_vector_walks();  // the walks this processor runs, beside the portable ones
  constexpr double res = 0.1;
  using Grid = rt::BayesSparse;
  using W = iv::detail::WalkKind;
  const W kind = GENERATE(W::Fastest, W::Avx512, W::Avx2, W::Table, W::Single);
  Grid g(res);
  rt::ReferenceMap<Grid> ref;
  iv::ScanInserter ins;  // no max range
  iv::detail::ScanInserterAccess::set_walk(ins, kind);
  const iv::Point3 origin(0.05, -0.03, 0.02);
  // 1. One ray of about 70,000 voxels (longer than TableWalk's tables) with short ones: the key
  //    box is long but thin, so the box bitmaps are used.
  const std::vector<iv::Point3> long_scan{{7000.03, 1.2, -0.7}, {-3.3, 1.1, 0.4}, {0.5, -0.9, 2.2}};
  const auto s1 = ins.insert_point_cloud(g, origin, long_scan);
  CHECK(s1.voxel_steps > iv::detail::TableWalk::kMaxTableSteps);
  ref.insert(g, origin, long_scan, -1.0);
  rt::require_equal(g, ref);
  // 2. Rays far apart in y and z: the key box is far beyond BoxMarks::kMaxVoxels, so the block
  //    hash is used.
  const std::vector<iv::Point3> wide_scan{{-2.0, 1500.0, 0.3}, {0.7, 0.2, -1600.0}, {3.1, -0.4, 0.9}};
  const iv::Point3 o2(0.3, 0.4, 0.5);
  ins.insert_point_cloud(g, o2, wide_scan);
  ref.insert(g, o2, wide_scan, -1.0);
  rt::require_equal(g, ref);
  // 3. A small scan again reuses the box bitmaps, cleared.
  const std::vector<iv::Point3> small{{1.0, 1.0, 1.0}, {-1.0, 0.5, 0.25}};
  ins.insert_point_cloud(g, origin, small);
  ref.insert(g, origin, small, -1.0);
  rt::require_equal(g, ref);
}

TEST_CASE("the box bitmaps cover exactly the scan's key box and convert to the grid's blocks", "[raycast][marks]") {
  iv::detail::BoxMarks m;
  REQUIRE(m.reset(iv::Key{-9, 0, 5}, iv::Key{8, 7, 5}));
  CHECK(m.base() == iv::Key{-16, 0, 0});  // floored to whole blocks
  CHECK(m.stride(1) == 64);               // rows of whole words
  CHECK(m.stride(2) == 64 * 8);
  CHECK(m.block_layers() == 1);
  m.set_miss(m.id(iv::Key{-9, 3, 5}));
  m.set_miss(m.id(iv::Key{-10, 3, 5}));
  m.set_hit(m.id(iv::Key{8, 7, 5}));
  // The idle lanes' scratch bit lies outside the box: it never shows up as a mark.
  m.set_miss(m.scratch_id());
  std::vector<std::pair<iv::Key, iv::detail::BlockMarks>> blocks;
  auto collect = [&](const iv::detail::BoxMarks* ms, std::size_t n) {
    blocks.clear();
    iv::detail::BoxMarks::for_each_block(
        ms, n, 0, ms[0].block_layers(),
        [&](const iv::Key& k, const iv::detail::BlockMarks& b) { blocks.emplace_back(k, b); });
  };
  collect(&m, 1);
  REQUIRE(blocks.size() == 2);  // in block order: x = -16..-9 first, then 8..15
  CHECK(blocks[0].first == iv::Key{-16, 0, 0});
  CHECK(blocks[0].second.miss[5] == ((std::uint64_t{1} << (7 | (3 << 3))) | (std::uint64_t{1} << (6 | (3 << 3)))));
  CHECK(blocks[0].second.hit[5] == 0);
  CHECK(blocks[1].first == iv::Key{8, 0, 0});
  CHECK(blocks[1].second.hit[5] == std::uint64_t{1} << (0 | (7 << 3)));
  CHECK(blocks[1].second.miss[5] == 0);
  for (int w : {0, 1, 2, 3, 4, 6, 7}) CHECK((blocks[0].second.miss[w] | blocks[1].second.hit[w]) == 0);
  // Two threads' bitmaps over the same box are OR-ed.
  iv::detail::BoxMarks two[2];
  for (auto& t : two) REQUIRE(t.reset(iv::Key{-9, 0, 5}, iv::Key{8, 7, 5}));
  two[0].set_miss(two[0].id(iv::Key{0, 0, 5}));
  two[1].set_miss(two[1].id(iv::Key{1, 0, 5}));
  two[1].set_hit(two[1].id(iv::Key{0, 0, 5}));
  collect(two, 2);
  REQUIRE(blocks.size() == 1);
  CHECK(blocks[0].first == iv::Key{0, 0, 0});
  CHECK(blocks[0].second.miss[5] == 3);
  CHECK(blocks[0].second.hit[5] == 1);
  // Too large a box is refused, and a reset clears every mark of the previous scan.
  CHECK_FALSE(m.reset(iv::Key{0, 0, 0}, iv::Key{8 * 1024, 8 * 1024, 0}));
  CHECK_FALSE(m.reset(iv::Key{-(1 << 23), 0, 0}, iv::Key{(1 << 23) - 1, 0, 0}));
  REQUIRE(m.reset(iv::Key{-9, 0, 5}, iv::Key{8, 7, 5}));
  collect(&m, 1);
  CHECK(blocks.empty());
}

TEST_CASE("every marking walk marks the voxels traverse() visits", "[raycast][marks]") {
  iv::use_vector_walks();  // the walks this processor runs, beside the portable ones
  // Rays of every length from one voxel up, in all directions, some through exact voxel edges,
  // walked as one batch (lanes refilled as rays end) and one ray at a time.
  std::mt19937_64 rng(77);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> len(0.0, 30.0);
  const iv::GridGeometry g(1.0);
  std::vector<std::pair<iv::Point3, iv::Point3>> segs;
  for (int i = 0; i < 400; ++i) {
    const iv::Point3 a(gauss(rng) * 3, gauss(rng) * 3, gauss(rng) * 3);
    const iv::Point3 d(gauss(rng), gauss(rng), gauss(rng));
    segs.emplace_back(a, a + d.normalized() * (i % 10 == 0 ? 0.3 : len(rng)));
  }
  for (int i = -3; i <= 3; ++i) segs.emplace_back(iv::Point3(0.5, 0.5, 0.5), iv::Point3(0.5 + i, 0.5 + 2 * i, 0.5 - i));
  iv::Key lo{-64, -64, -64}, hi{63, 63, 63};
  std::vector<iv::detail::BoxRay> rays;
  iv::detail::BoxMarks expect, walked[5];
  REQUIRE(expect.reset(lo, hi));
  for (auto& m : walked) REQUIRE(m.reset(lo, hi));
  for (const auto& [a, b] : segs) {
    iv::Point3 v0, v1;
    iv::Key k0, k1;
    REQUIRE(iv::detail::voxel_of(g, a, v0, k0));
    REQUIRE(iv::detail::voxel_of(g, b, v1, k1));
    // traverse() visits the misses and then the end voxel; the walks mark the misses.
    std::vector<iv::Key> keys;
    iv::traverse(g, a, b, [&](const iv::Key& k) {
      keys.push_back(k);
      return true;
    });
    keys.pop_back();
    for (const auto& k : keys) expect.set_miss(expect.id(k));
    iv::detail::BoxRay r;
    REQUIRE(iv::detail::make_box_ray(expect, v0, v1, k0, k1, r) == !keys.empty());
    if (!keys.empty()) {
      CHECK(r.rem + 1 == static_cast<std::int64_t>(keys.size()));
      rays.push_back(r);
    }
  }
  std::size_t next = 0;
  auto source = [&](iv::detail::BoxRay& r) {
    if (next == rays.size()) return false;
    r = rays[next++];
    return true;
  };
  using W = iv::detail::WalkKind;
  // Walks the processor lacks run as Table (resolve_walk()).
  const W kinds[5] = {W::Fastest, W::Avx512, W::Avx2, W::Table, W::Single};
  const std::int64_t words = expect.scratch_id() / 64;
  for (int k = 0; k < 5; ++k) {
    INFO("walk " << int(kinds[k]) << " runs as " << iv::detail::walk_name(kinds[k]));
    next = 0;
    iv::detail::walk_rays(walked[k], kinds[k], source);
    CHECK(next == rays.size());
    for (std::int64_t w = 0; w < words; ++w) REQUIRE(walked[k].miss()[w] == expect.miss()[w]);
  }
}

TEST_CASE("the rays are split between threads in runs of equal walk length, each ray once, in order",
          "[raycast][marks][threads][threaded]") {
  // Lists as the key-box pass leaves them (one per thread), of very different costs.
  std::mt19937_64 rng(3);
  std::uniform_int_distribution<int> len(0, 400);
  for (unsigned n : {1u, 2u, 3u, 5u}) {
    std::vector<std::vector<iv::detail::PreparedRay>> lists(n + 1);  // one stale list past n
    std::vector<std::uint64_t> cost(n, 0);
    std::uint64_t total = 0, most = 0;
    for (unsigned t = 0; t < n; ++t) {
      const int rays = t == 0 ? 0 : int(50 + 400 * t);  // an empty list, then growing ones
      for (int i = 0; i < rays; ++i) {
        iv::detail::PreparedRay p{iv::Point3::Zero(), iv::Point3::Zero(), {}, {}, false};
        p.k1 = iv::Key{len(rng) * (t % 2 ? 3 : 1), -len(rng), 0};
        lists[t].push_back(p);
        cost[t] += p.cost();
        most = std::max(most, p.cost());
      }
      total += cost[t];
    }
    lists[n].resize(7);  // must never be handed out
    const auto bounds = iv::detail::balanced_runs(lists, cost, n);
    REQUIRE(bounds.size() == n + 1);
    std::vector<const iv::detail::PreparedRay*> seen;
    for (unsigned t = 0; t < n; ++t) {
      iv::detail::RayCursor c(lists, bounds[t], bounds[t + 1]);
      std::uint64_t run = 0;
      while (const auto* p = c.next()) {
        seen.push_back(p);
        run += p->cost();
      }
      CHECK(run <= total / n + most);  // balanced to within one ray
      CHECK(run + most * 2 >= total / n);
    }
    std::vector<const iv::detail::PreparedRay*> all;
    for (unsigned t = 0; t < n; ++t)
      for (const auto& p : lists[t]) all.push_back(&p);
    CHECK(seen == all);
  }
}

TEST_CASE("scans too large to keep their prepared rays give the same grid and statistics",
          "[raycast][insert][marks][threads][threaded]") {
  using Grid = rt::BayesSparse;
  std::mt19937_64 rng(11);
  const iv::Point3 origin(0.3, -0.2, 0.1);
  std::vector<iv::Point3> pts = all_directions(rng, origin, 5000, 3.0, 0.1);
  pts.emplace_back(std::nan(""), 0.0, 0.0);  // skipped and counted once, in either mode
  pts.push_back(origin);
  const test::ThreadCap cap(3);  // three threads even on a smaller machine
  for (unsigned threads : {1u, 2u, 3u}) {
    const iv::InsertOptions opt{.max_range = 2.5, .min_range = 0.0, .threads = threads};
    for (bool hash : {false, true}) {
      Grid kept(0.1), again(0.1);
      iv::ScanInserter a(opt), b(opt);
      // Every scan here is larger; its rays are prepared again 777 at a time.
      iv::detail::ScanInserterAccess::set_max_kept_rays(b, 100, 777);
      iv::detail::ScanInserterAccess::force_hash(a, hash);
      iv::detail::ScanInserterAccess::force_hash(b, hash);
      for (int scan = 0; scan < 3; ++scan) {
        const auto sa = a.insert_point_cloud(kept, origin, pts);
        const auto sb = b.insert_point_cloud(again, origin, pts);
        REQUIRE(sa == sb);
        CHECK(sa.skipped_invalid == 1);
        CHECK(sa.skipped_zero_length == 1);
      }
      const auto ca = rt::cells_of(kept), cb = rt::cells_of(again);
      REQUIRE(ca.size() == cb.size());
      for (std::size_t i = 0; i < ca.size(); ++i) {
        REQUIRE(ca[i].first == cb[i].first);
        REQUIRE(rt::same_cell(ca[i].second, cb[i].second));
      }
      CHECK(b.scratch_bytes() < a.scratch_bytes());  // no prepared rays kept
    }
  }
}

TEST_CASE("use_vector_walks switches insertion to the fastest walk the processor runs", "[raycast][marks]") {
  const std::string walk = iv::use_vector_walks();
  CHECK(walk == iv::insertion_walk());
#if INTERVOX_HAVE_X86_WALKS
  __builtin_cpu_init();
  const bool avx512 = __builtin_cpu_supports("avx512f"), avx2 = __builtin_cpu_supports("avx2");
  CHECK(walk == (avx512 ? "AVX-512" : avx2 ? "AVX2" : "table"));
#else
  CHECK(walk == "table");
#endif
  CHECK(std::string(iv::use_vector_walks()) == walk);  // calling again changes nothing
}
