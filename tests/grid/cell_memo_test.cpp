// CellMemo (grid/cell_memo.hpp) against the grid's own reads of occupancy and utility, on every
// update policy, with more distinct cell values than the memo has entries.
#include "../common/grid_types.hpp"

#include <catch2/catch.hpp>
#include <intervox/grid/cell_memo.hpp>
#include <intervox/grid/voxel_grid.hpp>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <random>
#include <vector>

namespace iv = intervox;

TEMPLATE_TEST_CASE("a cell memo answers exactly what the grid computes, for any value and after evictions",
                   "[grid][memo]", INTERVOX_TEST_GRIDS) {
  TestType g = test::make_grid_for<TestType>(0.1, iv::Bounds{{-2, -2, -2}, {2, 2, 2}});
  // Distinct cell values: voxels updated by random runs of hits and misses (the clamps and, for
  // the credal cells, the counts give many different values), plus the unobserved value.
  std::mt19937_64 rng(20261130);
  std::vector<typename TestType::Cell> cells{g.update_policy().unobserved()};
  for (int i = 0; i < 6000; ++i) {
    typename TestType::Cell c = g.update_policy().unobserved();
    const int n = static_cast<int>(rng() % 40);
    for (int k = 0; k < n; ++k)
      g.update_policy().update(c, rng() % 3 == 0 ? iv::Observation::Hit : iv::Observation::Miss);
    cells.push_back(c);
  }
  iv::CellMemo<TestType> memo(g);
  // Three passes in random order: the first fills the table, the later ones hit and evict.
  for (int pass = 0; pass < 3; ++pass) {
    std::shuffle(cells.begin(), cells.end(), rng);
    for (const auto& c : cells) {
      const iv::CellSummary& s = memo(c);
      const double u = g.utility_of(c);
      // Bit for bit: the memo hands out the value computed for these very bytes.
      REQUIRE(std::bit_cast<std::uint64_t>(s.utility) == std::bit_cast<std::uint64_t>(u));
      REQUIRE(s.occupancy == g.update_policy().occupancy(c));
    }
  }
}
