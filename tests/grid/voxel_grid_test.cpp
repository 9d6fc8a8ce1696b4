#include <catch2/catch.hpp>

#include "../common/grid_types.hpp"

#include <intervox/core/sensor_data.hpp>
#include <intervox/grid/named_grids.hpp>

#include <array>
#include <cmath>
#include <limits>
#include <map>

namespace iv = intervox;

namespace {
/// A 2 m cube from (-1,-1,-1): 20^3 voxels at 0.1 m, the bounds of the dense and bounded sparse grids.
const iv::Bounds kTestBounds{{-1.0, -1.0, -1.0}, {1.0, 1.0, 1.0}};

/// A grid of type Grid at \p resolution, over kTestBounds if it is constructed with bounds.
template <class Grid>
Grid make_grid(double resolution = 0.1) {
  return test::make_grid_for<Grid>(resolution, kTestBounds);
}

struct XyzPoint {
  float x, y, z;
};
}  // namespace

TEMPLATE_TEST_CASE("an unobserved voxel reports the policy's prior and is unknown", "[core][grid]",
                   INTERVOX_TEST_GRIDS) {
  const auto g = make_grid<TestType>();
  const Eigen::Vector3d p(0.05, 0.05, 0.05);
  const auto& u = g.update_policy();
  CHECK_FALSE(g.is_observed(p));
  CHECK(g.probability(p) == u.state(u.unobserved()));
  CHECK(g.interval(p) == u.interval(u.unobserved()));
  CHECK(g.occupancy(p) == iv::Occupancy::Unknown);
  CHECK(g.observed_count() == 0);
  CHECK(g.counts().observed() == 0);
}

TEMPLATE_TEST_CASE("a voxel hit often enough becomes occupied and one passed often enough becomes free", "[core][grid]",
                   INTERVOX_TEST_GRIDS) {
  auto g = make_grid<TestType>();
  const Eigen::Vector3d wall(0.55, -0.25, 0.35), air(-0.45, 0.15, 0.05);
  for (int i = 0; i < 10; ++i) {
    CHECK(g.update(wall, iv::Observation::Hit));
    CHECK(g.update(air, iv::Observation::Miss));
  }
  CHECK(g.occupancy(wall) == iv::Occupancy::Occupied);
  CHECK(g.occupancy(air) == iv::Occupancy::Free);
  const auto& params = g.update_policy().params();
  CHECK(g.probability(wall) >= params.occupied_threshold);
  CHECK(g.probability(air) <= params.free_threshold);
  // Known voxels carry less utility than one never seen (for the count and belief policies the
  // interval still has some width after ten observations, so no absolute bound holds for all).
  const Eigen::Vector3d unseen(0.05, 0.05, 0.05);
  CHECK(g.utility(wall) < g.utility(unseen));
  CHECK(g.utility(air) < g.utility(unseen));
  CHECK(g.observed_count() == 2);
  const auto counts = g.counts();
  CHECK(counts.occupied == 1);
  CHECK(counts.free == 1);
  CHECK(counts.unknown == 0);
}

TEMPLATE_TEST_CASE("points of any shape address the same voxel as its key", "[core][grid]", INTERVOX_TEST_GRIDS) {
  auto g = make_grid<TestType>();
  const std::array<double, 3> a{0.33, 0.44, -0.55};
  const XyzPoint s{0.33f, 0.44f, -0.55f};
  const Eigen::Vector3f f(0.33f, 0.44f, -0.55f);
  g.update(a, iv::Observation::Hit);
  g.update(s, iv::Observation::Hit);
  g.update(f, iv::Observation::Hit);
  const iv::Key k = g.key(a);
  CHECK(k == iv::Key{3, 4, -6});
  CHECK(g.observed_count() == 1);
  TestType ref = make_grid<TestType>();
  for (int i = 0; i < 3; ++i) ref.update(k, iv::Observation::Hit);
  CHECK(g.probability(k) == ref.probability(k));
  CHECK(g.center(k).isApprox(Eigen::Vector3d(0.35, 0.45, -0.55)));
}

TEMPLATE_TEST_CASE("updates outside the bounds change nothing and report false", "[core][grid][errors]",
                   INTERVOX_TEST_GRIDS) {
  auto g = make_grid<TestType>();
  if constexpr (!test::kConstructBounded<TestType>) {
    // An unbounded grid takes every key in the key range, and nothing beyond it.
    CHECK(g.update(Eigen::Vector3d(1.5, 0, 0), iv::Observation::Hit));
    CHECK_FALSE(g.update(Eigen::Vector3d(0, 0, 1e12), iv::Observation::Hit));
    CHECK(g.observed_count() == 1);
    CHECK(g.occupancy(Eigen::Vector3d(0, 0, 1e12)) == iv::Occupancy::Unknown);
    return;
  }
  CHECK_FALSE(g.update(Eigen::Vector3d(1.5, 0, 0), iv::Observation::Hit));
  CHECK_FALSE(g.update(iv::Key{100, 0, 0}, iv::Observation::Hit));
  CHECK_FALSE(g.update(Eigen::Vector3d(0, 0, 1e12), iv::Observation::Hit));  // beyond the key range
  CHECK(g.observed_count() == 0);
  CHECK(g.occupancy(Eigen::Vector3d(1.5, 0, 0)) == iv::Occupancy::Unknown);
  CHECK(g.occupancy(Eigen::Vector3d(0, 0, 1e12)) == iv::Occupancy::Unknown);
  // The upper face of the bounds belongs to the next voxel, which is outside.
  CHECK_FALSE(g.update(Eigen::Vector3d(1.0, 0, 0), iv::Observation::Hit));
  CHECK(g.update(Eigen::Vector3d(0.999, 0, 0), iv::Observation::Hit));
}

TEMPLATE_TEST_CASE("non-finite points are rejected with InvalidArgument", "[core][grid][errors]", INTERVOX_TEST_GRIDS) {
  auto g = make_grid<TestType>();
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  CHECK_THROWS_AS(g.update(Eigen::Vector3d(nan, 0, 0), iv::Observation::Hit), iv::InvalidArgument);
  CHECK_THROWS_AS(g.update(Eigen::Vector3d(0, inf, 0), iv::Observation::Miss), iv::InvalidArgument);
  CHECK_THROWS_AS(g.probability(Eigen::Vector3d(0, 0, -inf)), iv::InvalidArgument);
  CHECK_THROWS_AS(g.key(Eigen::Vector3d(nan, nan, nan)), iv::InvalidArgument);
  CHECK_FALSE(g.try_key(Eigen::Vector3d(nan, 0, 0)).has_value());
  CHECK(g.observed_count() == 0);
}

TEMPLATE_TEST_CASE("iteration visits every observed voxel once with its cell", "[core][grid]", INTERVOX_TEST_GRIDS) {
  auto g = make_grid<TestType>();
  std::map<iv::Key, int> expected;
  for (int i = 0; i < 200; ++i) {
    const iv::Key k{(i * 7) % 20 - 10, (i * 13) % 20 - 10, (i * 3) % 20 - 10};
    g.update(k, (i % 3) ? iv::Observation::Miss : iv::Observation::Hit);
    ++expected[k];
  }
  std::map<iv::Key, int> seen;
  g.for_each_observed([&](const iv::Key& k, const typename TestType::Cell& c) {
    ++seen[k];
    CHECK(g.update_policy().state(c) == g.probability(k));
  });
  CHECK(seen.size() == expected.size());
  for (const auto& [k, n] : seen) {
    CHECK(n == 1);
    CHECK(expected.count(k) == 1);
  }
  CHECK(g.observed_count() == expected.size());
  CHECK(g.memory_bytes() > expected.size() * sizeof(typename TestType::Cell));
}

TEMPLATE_TEST_CASE("clearing forgets every observation, copies are independent", "[core][grid]", INTERVOX_TEST_GRIDS) {
  auto g = make_grid<TestType>();
  const iv::Key k{1, 2, 3};
  g.update(k, iv::Observation::Hit);
  TestType copy = g;
  g.update(k, iv::Observation::Hit);
  CHECK(copy.interval(k).lower < g.interval(k).lower);  // a second hit raises the lower bound
  g.clear();
  CHECK_FALSE(g.is_observed(k));
  CHECK(g.observed_count() == 0);
  CHECK(copy.is_observed(k));
}

TEMPLATE_TEST_CASE("max-entropy never falls below the entropy of the state", "[core][grid][utility]",
                   INTERVOX_TEST_GRIDS) {
  auto g = make_grid<TestType>();
  const iv::Key k{0, 0, 0};
  for (int i = 0; i < 20; ++i) {
    g.update(k, (i % 4 == 0) ? iv::Observation::Miss : iv::Observation::Hit);
    const auto c = g.cell(k);
    const auto& u = g.update_policy();
    const double h = iv::Entropy{}.value(u.state(c), u.interval(c));
    const double hmax = iv::MaxEntropy{}.value(u.state(c), u.interval(c));
    CHECK(hmax >= h - 1e-12);
    CHECK(hmax <= 1.0);
  }
}

TEST_CASE("a sparse grid is unbounded up to the key range, in every octant", "[core][grid][sparse]") {
  iv::BayesGrid g(0.05);
  const double far = (iv::kKeyLimit - 1) * 0.05;
  const std::vector<Eigen::Vector3d> pts{{far, far, far}, {-far, -far, -far}, {-0.01, 0.01, -0.01}, {1000, -2000, 3}};
  for (const auto& p : pts) CHECK(g.update(p, iv::Observation::Hit));
  for (const auto& p : pts) CHECK(g.is_observed(p));
  CHECK(g.observed_count() == pts.size());
  CHECK(g.storage().block_count() == pts.size());
  CHECK_FALSE(g.update(Eigen::Vector3d(iv::kKeyLimit * 0.05 + 1, 0, 0), iv::Observation::Hit));
}

TEST_CASE("a sparse grid grows its hash table without losing blocks", "[core][grid][sparse]") {
  iv::IntervalGrid g(0.1);
  for (int x = -40; x < 40; x += 2)
    for (int y = -40; y < 40; y += 3)
      for (int z = -16; z < 16; z += 5) g.update(iv::Key{x * 4, y * 4, z * 4}, iv::Observation::Hit);
  std::size_t n = 0;
  for (int x = -40; x < 40; x += 2)
    for (int y = -40; y < 40; y += 3)
      for (int z = -16; z < 16; z += 5) n += g.is_observed(iv::Key{x * 4, y * 4, z * 4});
  CHECK(n == g.observed_count());
  CHECK(n == 40u * 27u * 7u);
}

TEST_CASE("dense storage needs valid, not absurdly large bounds", "[core][grid][dense][errors]") {
  using G = iv::DenseBayesGrid;
  CHECK_THROWS_AS(G(0.1, iv::Bounds{{0, 0, 0}, {-1, 1, 1}}), iv::InvalidArgument);
  CHECK_THROWS_AS(G(0.1, iv::Bounds{{0, 0, NAN}, {1, 1, 1}}), iv::InvalidArgument);
  CHECK_THROWS_AS(G(0.001, iv::Bounds{{0, 0, 0}, {100, 100, 100}}), iv::InvalidArgument);
  CHECK_THROWS_AS(G(0.0, iv::Bounds{{0, 0, 0}, {1, 1, 1}}), iv::InvalidArgument);
  CHECK_THROWS_AS(G(-0.1, iv::Bounds{{0, 0, 0}, {1, 1, 1}}), iv::InvalidArgument);
  const G g(0.1, iv::Bounds{{0, 0, 0}, {1, 0.5, 0.3}});
  CHECK(g.key_box()->volume() == 10 * 5 * 3);
  CHECK(g.memory_bytes() >= 150 * sizeof(float));
}

TEST_CASE("geometry maps points to keys by floor, with an origin", "[core][key]") {
  const iv::GridGeometry geo(0.1, Eigen::Vector3d(1.0, 0.0, -0.5));
  CHECK(geo.key(Eigen::Vector3d(1.0, 0.0, -0.5)) == iv::Key{0, 0, 0});
  CHECK(geo.key(Eigen::Vector3d(0.99, -0.01, -0.51)) == iv::Key{-1, -1, -1});
  CHECK(geo.key(Eigen::Vector3d(1.25, 0.35, 0.0)) == iv::Key{2, 3, 5});
  CHECK(geo.center(iv::Key{2, 3, 5}).isApprox(Eigen::Vector3d(1.25, 0.35, 0.05)));
  CHECK_THROWS_AS(geo.key(Eigen::Vector3d(1e9, 0, 0)), iv::OutOfRange);
  CHECK_THROWS_AS(iv::GridGeometry(NAN), iv::InvalidArgument);
  CHECK_THROWS_AS(iv::GridGeometry(0.1, Eigen::Vector3d(INFINITY, 0, 0)), iv::InvalidArgument);
  const auto box = geo.key_box(iv::Bounds{{1.0, 0.0, -0.5}, {2.0, 1.0, 0.5}});
  CHECK(box.min == iv::Key{0, 0, 0});
  CHECK(box.max == iv::Key{9, 9, 9});
}

TEMPLATE_TEST_CASE("moved and copied grids keep writing to their own voxels", "[core][grid]", INTERVOX_TEST_GRIDS) {
  auto g = make_grid<TestType>();
  const iv::Key k{2, 2, 2}, near{3, 2, 2};
  g.update(k, iv::Observation::Hit);  // primes any write cache with k's block
  TestType copy = g;
  copy.update(near, iv::Observation::Hit);
  CHECK_FALSE(g.is_observed(near));
  TestType moved = std::move(g);
  moved.update(near, iv::Observation::Hit);
  CHECK(moved.is_observed(k));
  CHECK(moved.is_observed(near));
  g = make_grid<TestType>();  // a moved-from grid can be assigned and used again
  g.update(near, iv::Observation::Miss);
  CHECK(g.observed_count() == 1);
  CHECK(moved.observed_count() == 2);
  CHECK(moved.interval(near).lower > moved.update_policy().interval(moved.update_policy().unobserved()).lower);
}

TEST_CASE("returns at or below a height are removed whole and misses are kept", "[core][beams]") {
  std::vector<iv::Beam> beams{{{0, 0, 0.3}, {1, 0, 0.0}, true},    // the floor
                              {{0, 0, 0.3}, {1, 0, 0.05}, true},   // on the cut
                              {{0, 0, 0.3}, {1, 0, 0.06}, true},   // above it
                              {{0, 0, 0.3}, {1, 0, -1.0}, false},  // no return, pointing down
                              {{0, 0, 0.3}, {2, 0, 1.0}, true}};
  CHECK(iv::remove_returns_below(beams, 0.05) == 2);
  REQUIRE(beams.size() == 3);
  CHECK(beams[0].end.z() == 0.06);
  CHECK_FALSE(beams[1].hit);
  CHECK(beams[2].end.z() == 1.0);
  CHECK_THROWS_AS(iv::remove_returns_below(beams, std::nan("")), iv::InvalidArgument);
}

TEST_CASE("a dense grid whose bounds hold more voxels than 64 bits can count is refused",
          "[core][grid][dense][errors]") {
  // 4096 m at 1/1024 m: 2^22 voxels per axis, 2^66 in all, which a 64-bit product wraps to 0 (an
  // empty array that every update then writes past).
  using DenseBayes = iv::VoxelGrid<iv::BayesLogOdds, iv::Entropy, iv::DenseStorage>;
  const iv::Bounds huge{{0.0, 0.0, 0.0}, {4096.0, 4096.0, 4096.0}};
  CHECK_THROWS_AS(DenseBayes(iv::GridGeometry(1.0 / 1024), huge, iv::BayesLogOdds{}, iv::Entropy{}),
                  iv::InvalidArgument);
  CHECK_THROWS_WITH(DenseBayes(iv::GridGeometry(1.0 / 1024), huge, iv::BayesLogOdds{}, iv::Entropy{}),
                    Catch::Contains("more than 2^64") && Catch::Contains("SparseStorage"));
  // Just above the dense limit of 2^32 cells, exactly countable: refused with the count.
  const iv::Bounds big{{0.0, 0.0, 0.0}, {2048.0, 2048.0, 1025.0}};
  CHECK_THROWS_WITH(DenseBayes(iv::GridGeometry(1.0), big, iv::BayesLogOdds{}, iv::Entropy{}),
                    Catch::Contains("4299161600 voxels") && Catch::Contains("limit of 2^32"));
}
