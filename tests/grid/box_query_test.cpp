// VoxelGrid::for_each_observed_in: the observed voxels of a key or metric box, against a brute-force
// filter of every observed voxel, on every policy and storage.
#include "../common/grid_types.hpp"

#include <catch2/catch.hpp>
#include <intervox/grid/voxel_grid.hpp>

#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <random>
#include <vector>

namespace iv = intervox;

namespace {

// A grid with observed voxels scattered over [-3, 3]^3 m at 0.1 m (keys -30..29), clustered so that
// some blocks are full and many absent.
template <class G>
G scattered_grid(std::uint64_t seed) {
  G g = test::make_grid_for<G>(0.1, iv::Bounds{{-2.0, -2.5, -2.0}, {2.5, 2.0, 2.5}});
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> centre(-3.0, 3.0), near(-0.4, 0.4);
  for (int c = 0; c < 12; ++c) {
    const iv::Point3 m(centre(rng), centre(rng), centre(rng));
    for (int i = 0; i < 300; ++i)
      g.update(iv::Point3(m + iv::Point3(near(rng), near(rng), near(rng))),
               i % 3 ? iv::Observation::Miss : iv::Observation::Hit);
  }
  return g;
}

// The observed voxels of g in box, by a filter over every observed voxel.
template <class G>
std::map<iv::Key, typename G::Cell> brute_force_box(const G& g, const iv::KeyBox& box) {
  std::map<iv::Key, typename G::Cell> out;
  g.for_each_observed([&](const iv::Key& k, const typename G::Cell& c) {
    if (box.contains(k)) out.emplace(k, c);
  });
  return out;
}

template <class G>
std::map<iv::Key, typename G::Cell> box_query(const G& g, const iv::KeyBox& box) {
  std::map<iv::Key, typename G::Cell> out;
  g.for_each_observed_in(box, [&](const iv::Key& k, const typename G::Cell& c) {
    REQUIRE(out.emplace(k, c).second);  // each voxel once
  });
  return out;
}

template <class C>
bool same_cells(const std::map<iv::Key, C>& a, const std::map<iv::Key, C>& b) {
  if (a.size() != b.size()) return false;
  for (auto i = a.begin(), j = b.begin(); i != a.end(); ++i, ++j)
    if (i->first != j->first || std::memcmp(&i->second, &j->second, sizeof(C)) != 0) return false;
  return true;
}

}  // namespace

TEMPLATE_TEST_CASE("a box query visits exactly the observed voxels inside the box", "[grid][query][typed]",
                   INTERVOX_TEST_GRIDS) {
  const TestType g = scattered_grid<TestType>(3);
  REQUIRE(g.observed_count() > 1000);
  std::vector<iv::Key> observed;
  g.for_each_observed([&](const iv::Key& k, const auto&) { observed.push_back(k); });
  std::mt19937_64 rng(17);
  std::uniform_int_distribution<int> key(-40, 40), size(0, 30), shift(-15, 0);
  std::uniform_int_distribution<std::size_t> pick(0, observed.size() - 1);
  std::size_t nonempty = 0;
  for (int trial = 0; trial < 60; ++trial) {
    // The first boxes cover most of the grid, then random ones, then boxes around an observed voxel.
    iv::KeyBox box;
    const iv::Key anchor = observed[pick(rng)];
    for (int a = 0; a < 3; ++a) {
      box.min[a] = trial < 30 ? key(rng) : anchor[a] + shift(rng);
      box.max[a] = box.min[a] + (trial < 5 ? 60 : size(rng));
    }
    CAPTURE(trial);
    const auto want = brute_force_box(g, box);
    nonempty += !want.empty();
    REQUIRE(same_cells(box_query(g, box), want));
  }
  CHECK(nonempty > 20);
  // A single voxel, an empty box (max < min), a box beyond the key range.
  const iv::Key one = [&] {
    iv::Key k{};
    g.for_each_observed([&](const iv::Key& x, const auto&) { k = x; });
    return k;
  }();
  CHECK(box_query(g, iv::KeyBox{one, one}).size() == 1);
  CHECK(box_query(g, iv::KeyBox{{5, 5, 5}, {4, 9, 9}}).empty());
  const iv::KeyBox huge{{std::numeric_limits<std::int32_t>::min(), std::numeric_limits<std::int32_t>::min(),
                         std::numeric_limits<std::int32_t>::min()},
                        {std::numeric_limits<std::int32_t>::max(), std::numeric_limits<std::int32_t>::max(),
                         std::numeric_limits<std::int32_t>::max()}};
  CHECK(box_query(g, huge).size() == g.observed_count());
}

TEMPLATE_TEST_CASE("a metric box query visits the observed voxels that intersect the box", "[grid][query][typed]",
                   INTERVOX_TEST_GRIDS) {
  const TestType g = scattered_grid<TestType>(4);
  const iv::Bounds b{{-1.23, -0.5, 0.07}, {0.91, 1.8, 1.5}};
  std::map<iv::Key, typename TestType::Cell> got;
  g.for_each_observed_in(b, [&](const iv::Key& k, const auto& c) { got.emplace(k, c); });
  REQUIRE(same_cells(got, brute_force_box(g, g.geometry().key_box(b))));
  // Each visited voxel intersects the box; a voxel just outside it is not visited.
  for (const auto& [k, c] : got) {
    const iv::Point3 lo = g.geometry().corner(k), hi = lo + iv::Point3::Constant(0.1);
    REQUIRE(((hi.array() >= b.min.array()).all() && (lo.array() <= b.max.array()).all()));
  }
  CHECK(!got.empty());
  // A box reaching far beyond the key range is cut to it: every observed voxel.
  std::size_t all = 0;
  g.for_each_observed_in(iv::Bounds{iv::Point3::Constant(-1e300), iv::Point3::Constant(1e300)},
                         [&](const iv::Key&, const auto&) { ++all; });
  CHECK(all == g.observed_count());
  CHECK_THROWS_AS(g.for_each_observed_in(iv::Bounds{{0, 0, 0}, {-1, 1, 1}}, [](const iv::Key&, const auto&) {}),
                  iv::InvalidArgument);
  CHECK_THROWS_AS(
      g.for_each_observed_in(iv::Bounds{{0, 0, 0}, {std::nan(""), 1, 1}}, [](const iv::Key&, const auto&) {}),
      iv::InvalidArgument);
}
