// The scratch of ray insertion is bounded by design (issue: one stray ray used to cost hundreds
// of MB), threads are capped at the hardware, and bounded sparse grids are safe on threads.
#include "reference.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <thread>
#include <vector>

namespace iv = intervox;

namespace {

template <class Grid>
std::vector<std::pair<iv::Key, typename Grid::Cell>> sorted_cells(const Grid& g) {
  auto c = rt::cells_of(g);
  std::sort(c.begin(), c.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  return c;
}

template <class A, class B>
void require_same_cells(const A& a, const B& b) {
  REQUIRE(a.size() == b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    REQUIRE(a[i].first == b[i].first);
    REQUIRE(rt::same_cell(a[i].second, b[i].second));
  }
}

}  // namespace

TEMPLATE_TEST_CASE("a scan whose block-hash marks outgrow the budget is applied region by region with the same result",
                   "[raycast][insert][scratch][threads][threaded]", rt::BayesSparse, rt::MeanBoundedSparse,
                   rt::UpperDense) {
  const test::ThreadCap cap(3);
  std::mt19937_64 rng(5);
  const iv::Point3 origin(0.02, -0.03, 0.01);
  std::vector<std::vector<iv::Point3>> scans;
  for (int s = 0; s < 3; ++s) scans.push_back(rt::random_scan(rng, origin, 3000, 2.9, 0.4));
  auto reference = rt::make_grid<TestType>(0.05);
  rt::ReferenceMap<TestType> ref;
  for (const auto& pts : scans) ref.insert(reference, origin, pts, 2.5);

  for (std::size_t budget : {std::size_t{128} << 20, std::size_t{16} << 10, std::size_t{4096}}) {
    std::vector<std::pair<iv::Key, typename TestType::Cell>> first_order;
    std::vector<iv::InsertStats> first_stats;
    for (unsigned threads : {1u, 2u, 3u}) {
      CAPTURE(budget, threads);
      auto g = rt::make_grid<TestType>(0.05);
      iv::ScanInserter ins({.max_range = 2.5, .min_range = 0.0, .threads = threads, .max_mark_bytes = budget});
      iv::detail::ScanInserterAccess::force_hash(ins, true);
      std::vector<iv::InsertStats> stats;
      for (const auto& pts : scans) stats.push_back(ins.insert_point_cloud(g, origin, pts));
      rt::require_equal(g, ref);
      // The marks stay within the budget per thread (the first thread's also holding the union);
      // besides them: the prepared rays, the sorted list of one part's blocks, and each hash
      // table's initial 256 slots.
      const std::size_t blocks = std::max<std::size_t>(1, budget / iv::detail::ScanMarks::kBytesPerBlock);
      CHECK(ins.scratch_bytes() <=
            threads * (budget + 8192) + 64 * blocks + 2 * 3000 * sizeof(iv::detail::PreparedRay));
      if (threads == 1) {
        first_order = rt::cells_of(g);
        first_stats = stats;
      } else {
        CHECK(stats == first_stats);
        require_same_cells(first_order, rt::cells_of(g));  // same block allocation order too
      }
    }
  }
}

TEST_CASE("one stray point kilometres away leaves the scratch within its budget", "[raycast][insert][scratch]") {
  const iv::Bounds bounds{{-3, -3, -3}, {3, 3, 3}};
  std::mt19937_64 rng(8);
  const iv::Point3 origin(0.1, 0.2, 0.3);
  std::vector<iv::Point3> pts = rt::random_scan(rng, origin, 2000, 2.5, 0.4);
  pts.emplace_back(1000.0, 700.0, -300.0);  // a stray return 1.26 km away: 80 k voxels at 2 cm
  constexpr std::size_t budget = 64 << 10;
  for (unsigned threads : {1u, 2u}) {
    CAPTURE(threads);
    // An unbounded grid walks the stray ray whole, in the block hash within its budget.
    rt::BayesSparse small(0.02), large(0.02);
    iv::ScanInserter bounded({.threads = threads, .max_mark_bytes = budget});
    iv::ScanInserter generous({.threads = threads});
    const auto a = bounded.insert_point_cloud(small, origin, pts);
    const auto b = generous.insert_point_cloud(large, origin, pts);
    CHECK(a == b);
    require_same_cells(sorted_cells(small), sorted_cells(large));
    // Before the budget the marks of the stray ray alone took about 2 MB.
    CHECK(bounded.scratch_bytes() < 16 * budget + pts.size() * sizeof(iv::detail::PreparedRay) * 2);
    CHECK(generous.scratch_bytes() > bounded.scratch_bytes());
    // A bounded grid cuts the stray ray where it leaves its box (before issue 71 it walked the
    // 1.26 km through the hash): the same cells in the box, the voxels beyond it counted as dropped.
    test::BoundedSparse<rt::BayesSparse> boxed(0.02, bounds);
    iv::ScanInserter cut({.threads = threads, .max_mark_bytes = budget});
    const auto c = cut.insert_point_cloud(boxed, origin, pts);
    CHECK(c.outside_bounds > 50000);  // the stray ray's voxels beyond the grid, dropped
    CHECK(c.voxel_steps < a.voxel_steps - 50000);
    std::vector<std::pair<iv::Key, rt::BayesSparse::Cell>> in_box;
    for (const auto& kc : sorted_cells(small))
      if (boxed.key_box()->contains(kc.first)) in_box.push_back(kc);
    require_same_cells(sorted_cells(boxed), in_box);
  }
}

TEST_CASE("release_scratch frees the scratch and the inserter keeps inserting exactly", "[raycast][insert][scratch]") {
  std::mt19937_64 rng(3);
  const iv::Point3 origin(0, 0, 0);
  const auto pts = rt::random_scan(rng, origin, 5000, 2.0, 0.4);
  rt::BayesSparse a(0.05), b(0.05);
  iv::ScanInserter reused({.max_range = 1.5, .min_range = 0.0, .threads = 2});
  iv::ScanInserter fresh({.max_range = 1.5, .min_range = 0.0, .threads = 2});
  reused.insert_point_cloud(a, origin, pts);
  fresh.insert_point_cloud(b, origin, pts);
  REQUIRE(reused.scratch_bytes() > 0);
  reused.release_scratch();
  CHECK(reused.scratch_bytes() == 0);
  CHECK(reused.insert_point_cloud(a, origin, pts) == fresh.insert_point_cloud(b, origin, pts));
  require_same_cells(rt::cells_of(a), rt::cells_of(b));
}

TEST_CASE("a thread count above the hardware's is capped at it", "[raycast][insert][threads][threaded]") {
  std::mt19937_64 rng(4);
  const iv::Point3 origin(0, 0, 0);
  const auto pts = rt::random_scan(rng, origin, 150000, 2.0, 0.4);  // enough rays for 64 threads before the cap
  rt::BayesSparse a(0.05), b(0.05);
  iv::ScanInserter many({.max_range = 1.5, .min_range = 0.0, .threads = 1000});
  iv::ScanInserter all({.max_range = 1.5, .min_range = 0.0, .threads = 0});
  CHECK(many.insert_point_cloud(a, origin, pts) == all.insert_point_cloud(b, origin, pts));
  CHECK(many.scratch_bytes() == all.scratch_bytes());  // the same number of per-thread buffers
  CHECK(iv::resolve_threads(1000) == std::max(1u, std::thread::hardware_concurrency()));
}

TEST_CASE("a mark budget below 4 KiB is rejected", "[raycast][insert][errors]") {
  CHECK_THROWS_AS(iv::ScanInserter({.max_mark_bytes = 100}), iv::InvalidArgument);
  CHECK_NOTHROW(iv::ScanInserter({.max_mark_bytes = iv::InsertOptions::kMinMarkBytes}));
}
