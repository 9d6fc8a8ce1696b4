// CoarseSummary: what a cube of 2^level voxels holds, against a brute-force pass over every observed
// voxel, on every policy and storage; kept current by refresh() with the changed keys.
#include "../common/grid_types.hpp"

#include <catch2/catch.hpp>
#include <intervox/grid/coarse_summary.hpp>
#include <intervox/grid/voxel_grid.hpp>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace iv = intervox;

namespace {

// Observed voxels in clusters over [-3, 3]^3 m at 0.1 m (keys -30..29: cubes on both sides of 0).
template <class G>
G clustered_grid(std::uint64_t seed) {
  G g = test::make_grid_for<G>(0.1, iv::Bounds{{-2.0, -2.5, -2.0}, {2.5, 2.0, 2.5}});
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> centre(-3.0, 3.0), near(-0.4, 0.4);
  for (int c = 0; c < 10; ++c) {
    const iv::Point3 m(centre(rng), centre(rng), centre(rng));
    for (int i = 0; i < 250; ++i)
      g.update(iv::Point3(m + iv::Point3(near(rng), near(rng), near(rng))),
               i % 4 ? iv::Observation::Miss : iv::Observation::Hit);
  }
  return g;
}

// The summary of the cube of key k at level, by a pass over every observed voxel of the grid.
template <class G>
iv::CubeSummary brute_force_cube(const G& g, const iv::Key& k, int level) {
  const auto& u = g.update_policy();
  iv::CubeSummary s{0, 0, -std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  g.for_each_observed([&](const iv::Key& v, const typename G::Cell& c) {
    for (int a = 0; a < 3; ++a)
      if ((v[a] >> level) != (k[a] >> level)) return;
    ++s.observed;
    s.occupied += u.occupancy(c) == iv::Occupancy::Occupied;
    s.max_probability = std::max(s.max_probability, u.state(c));
    s.max_upper = std::max(s.max_upper, u.interval(c).upper);
  });
  if (!s.observed) {
    s.max_probability = u.state(u.unobserved());
    s.max_upper = u.interval(u.unobserved()).upper;
  }
  return s;
}

// Every level at keys near observed voxels, at random keys and at keys of the grid's corners.
template <class G>
void check_against_brute_force(const G& g, const iv::CoarseSummary<G>& cs, std::uint64_t seed) {
  std::vector<iv::Key> observed;
  g.for_each_observed([&](const iv::Key& k, const auto&) { observed.push_back(k); });
  REQUIRE(!observed.empty());
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<std::size_t> pick(0, observed.size() - 1);
  std::uniform_int_distribution<int> any(-70, 70), jitter(-9, 9);
  for (int level = 0; level <= iv::CoarseSummary<G>::kMaxLevel; ++level) {
    for (int trial = 0; trial < 12; ++trial) {
      iv::Key k = trial < 6 ? observed[pick(rng)] : iv::Key{any(rng), any(rng), any(rng)};
      if (trial % 3 == 1)
        for (int a = 0; a < 3; ++a) k[a] += jitter(rng);
      CAPTURE(level, k.x, k.y, k.z);
      const iv::CubeSummary want = brute_force_cube(g, k, level);
      REQUIRE(cs.summary(k, level) == want);
      REQUIRE(cs.any_occupied(k, level) == (want.occupied > 0));
      REQUIRE(cs.max_probability(k, level) == want.max_probability);
    }
  }
}

}  // namespace

TEMPLATE_TEST_CASE("a coarse summary answers every level like a pass over the cube's voxels", "[grid][query][typed]",
                   INTERVOX_TEST_GRIDS) {
  const TestType g = clustered_grid<TestType>(5);
  const iv::CoarseSummary<TestType> cs(g);
  check_against_brute_force(g, cs, 11);
  // The coarsest cubes hold every observed voxel; a level-3 cube is a block.
  std::uint64_t total = 0;
  cs.for_each_cube(3, [&](const iv::KeyBox& box, const iv::CubeSummary& s) {
    REQUIRE(box.extent(0) == 8);
    REQUIRE(s.observed > 0);
    total += s.observed;
  });
  CHECK(total == g.observed_count());
  total = 0;
  cs.for_each_cube(iv::CoarseSummary<TestType>::kMaxLevel,
                   [&](const iv::KeyBox&, const iv::CubeSummary& s) { total += s.observed; });
  CHECK(total == g.observed_count());
  CHECK(cs.cube_count(23) <= 8);  // the cubes on either side of 0
  CHECK(cs.cube_count(3) >= cs.cube_count(4));
  CHECK(cs.memory_bytes() > 0);
}

TEMPLATE_TEST_CASE("a coarse summary refreshed with the changed keys stays exact for the occupied counts",
                   "[grid][query][typed]", INTERVOX_TEST_GRIDS) {
  TestType g = clustered_grid<TestType>(6);
  iv::CoarseSummary<TestType> cs(g);
  g.enable_change_detection();
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> at(-2.0, 2.0);
  std::vector<iv::Key> updated;
  for (int i = 0; i < 400; ++i) {
    const iv::Point3 p(at(rng), at(rng), at(rng));
    for (int j = 0; j < 4; ++j) g.update(p, i % 2 ? iv::Observation::Hit : iv::Observation::Miss);
    if (const auto k = g.try_key(p)) updated.push_back(*k);
  }
  REQUIRE(g.changed_count() > 0);
  const std::vector<iv::Key> changed = g.changed_keys();
  cs.refresh(changed);
  // Observed and occupied counts are exact after refreshing with the changed keys alone.
  const iv::CoarseSummary<TestType> fresh(g);
  for (int level = 3; level <= 12; ++level)
    for (const iv::Key& k : updated) {
      const iv::CubeSummary a = cs.summary(k, level), b = fresh.summary(k, level);
      REQUIRE(a.observed == b.observed);
      REQUIRE(a.occupied == b.occupied);
    }
  // Refreshing with every updated key makes the maxima exact too: the same as a rebuild.
  cs.refresh(updated);
  check_against_brute_force(g, cs, 12);
  for (int level = 3; level <= iv::CoarseSummary<TestType>::kMaxLevel; ++level)
    CHECK(cs.cube_count(level) == fresh.cube_count(level));
  // Clearing the grid and refreshing the keys that were observed empties the summaries.
  std::vector<iv::Key> all;
  g.for_each_observed([&](const iv::Key& k, const auto&) { all.push_back(k); });
  g.clear();
  cs.refresh(all);
  for (int level = 3; level <= iv::CoarseSummary<TestType>::kMaxLevel; ++level) CHECK(cs.cube_count(level) == 0);
  CHECK(!cs.summary(all.front(), 5).any_observed());
}

TEMPLATE_TEST_CASE("a coarse summary answers points, bad levels and keys beyond the key range by its rules",
                   "[grid][query][typed]", INTERVOX_TEST_GRIDS) {
  const TestType g = clustered_grid<TestType>(7);
  const iv::CoarseSummary<TestType> cs(g);
  iv::Key some{};
  g.for_each_observed([&](const iv::Key& k, const auto&) { some = k; });
  // A point answers for the cube of its voxel.
  for (int level : {0, 2, 3, 5, 9}) CHECK(cs.summary(g.center(some), level) == cs.summary(some, level));
  CHECK(cs.summary(some, 0).observed == 1);
  CHECK_THROWS_AS(cs.summary(some, -1), iv::InvalidArgument);
  CHECK_THROWS_AS(cs.summary(some, 24), iv::InvalidArgument);
  CHECK_THROWS_AS(cs.summary(iv::Point3(std::nan(""), 0, 0), 3), iv::InvalidArgument);
  CHECK_THROWS_AS(cs.for_each_cube(2, [](const iv::KeyBox&, const iv::CubeSummary&) {}), iv::InvalidArgument);
  CHECK(cs.cube_count(2) == 0);
  // Beyond the key range: nothing observed, the prior as both maxima.
  const auto& u = g.update_policy();
  const iv::CubeSummary far = cs.summary(iv::Key{iv::kKeyLimit, 0, 0}, 4);
  CHECK(!far.any_observed());
  CHECK(far.max_probability == u.state(u.unobserved()));
  CHECK(far.max_upper == u.interval(u.unobserved()).upper);
  CHECK(!cs.summary(iv::Point3(1e30, 0, 0), 6).any_observed());
  // Cubes are aligned key boxes of 2^level keys per axis, negative keys included, at the int32 edge too.
  CHECK(iv::CoarseSummary<TestType>::cube(iv::Key{-1, 0, 7}, 3) == iv::KeyBox{{-8, 0, 0}, {-1, 7, 7}});
  const iv::KeyBox top = iv::CoarseSummary<TestType>::cube(iv::Key{std::numeric_limits<std::int32_t>::max(), 0, 0}, 23);
  CHECK(top.max.x == std::numeric_limits<std::int32_t>::max());
  CHECK(top.extent(0) == (std::int64_t{1} << 23));
}
