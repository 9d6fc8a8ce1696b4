// GridAccessor (grid/accessor.hpp) against the grid's own reads, on every storage.
#include "../common/grid_types.hpp"

#include <catch2/catch.hpp>
#include <intervox/grid/accessor.hpp>
#include <intervox/grid/named_grids.hpp>
#include <intervox/grid/voxel_grid.hpp>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

namespace iv = intervox;

namespace {
// Bounds of the bounded grids: keys -39..38 at 0.05 m, a key box that starts and ends inside an
// 8^3 block, so that blocks straddle the box boundary.
const iv::Bounds kBounds{iv::Point3(-1.93, -1.93, -1.93), iv::Point3(1.93, 1.93, 1.93)};

// True if two cells hold the same bits (the interval cells mark unobserved with a NaN).
template <class C>
bool same(const C& a, const C& b) {
  return std::memcmp(&a, &b, sizeof(C)) == 0;
}
}  // namespace

TEMPLATE_TEST_CASE("an accessor reads what the grid reads, across blocks, bounds and the key range", "[grid][accessor]",
                   iv::BayesGrid, test::BoundedSparse<iv::BayesGrid>, iv::DenseBayesGrid, iv::IntervalGrid,
                   test::BoundedSparse<iv::IntervalGrid>, iv::DenseIntervalGrid) {
  TestType grid = test::make_grid_for<TestType>(0.05, kBounds);
  std::mt19937_64 rng(5);
  std::uniform_int_distribution<std::int32_t> near(-48, 47);  // beyond the bounds on every side
  const auto random_key = [&] { return iv::Key{near(rng), near(rng), near(rng)}; };
  // Observe a few thousand voxels, some several times, hits and misses.
  std::vector<iv::Key> updated;
  for (int i = 0; i < 4000; ++i) {
    const iv::Key k = random_key();
    updated.push_back(k);
    grid.update(k, (i % 3 == 0) ? iv::Observation::Hit : iv::Observation::Miss);
    if (i % 5 == 0) grid.update(k, iv::Observation::Hit);
  }
  REQUIRE(grid.observed_count() > 1000);

  iv::GridAccessor<TestType> access(grid);
  // Random keys (the cache jumps between blocks), near and beyond the bounds, every other one a
  // key that was updated (observed unless outside the bounds).
  std::uint64_t observed = 0;
  for (std::size_t i = 0; i < 20000; ++i) {
    const iv::Key k = i % 2 == 0 ? random_key() : updated[i / 2 % updated.size()];
    REQUIRE(same(access.cell(k), grid.cell(k)));
    REQUIRE(access.occupancy(k) == grid.occupancy(k));
    REQUIRE(access.is_observed(k) == grid.is_observed(k));
    REQUIRE(access.utility(k) == grid.utility(k));
    observed += grid.is_observed(k) ? 1 : 0;
  }
  CHECK(observed > 2000);  // the reads do meet observed cells
  // Straight runs along each axis through block boundaries (the cache hits, then moves on).
  for (int axis = 0; axis < 3; ++axis)
    for (std::int32_t a = -50; a < 50; ++a) {
      iv::Key k{3, -5, 7};
      (axis == 0 ? k.x : axis == 1 ? k.y : k.z) = a;
      grid.update(k, iv::Observation::Hit);
    }
  iv::GridAccessor<TestType> fresh(grid);  // writes invalidate accessors: a new one
  for (int axis = 0; axis < 3; ++axis)
    for (std::int32_t a = -50; a < 50; ++a) {
      iv::Key k{3, -5, 7};
      (axis == 0 ? k.x : axis == 1 ? k.y : k.z) = a;
      REQUIRE(same(fresh.cell(k), grid.cell(k)));
      REQUIRE(fresh.is_observed(k) == grid.is_observed(k));
    }
  // Outside the key range: the unobserved cell, as the grid reads it.
  for (const iv::Key k : {iv::Key{iv::kKeyLimit, 0, 0}, iv::Key{0, -iv::kKeyLimit - 1, 0},
                          iv::Key{0, 0, std::numeric_limits<std::int32_t>::max()}}) {
    REQUIRE(same(fresh.cell(k), grid.cell(k)));
    REQUIRE(same(fresh.cell(k), grid.update_policy().unobserved()));
    REQUIRE_FALSE(fresh.is_observed(k));
  }
  CHECK(&fresh.grid() == &grid);
}
