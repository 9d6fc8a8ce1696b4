#include "reference.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <vector>

namespace iv = intervox;

namespace {

std::vector<iv::Key> walk(const iv::GridGeometry& g, const iv::Point3& a, const iv::Point3& b) {
  std::vector<iv::Key> keys;
  iv::traverse(g, a, b, [&](const iv::Key& k) {
    keys.push_back(k);
    return true;
  });
  return keys;
}

/// Length of the part of segment a-b inside voxel k (slab clipping).
double length_inside(const iv::GridGeometry& g, const iv::Point3& a, const iv::Point3& b, const iv::Key& k) {
  const iv::Point3 lo = g.corner(k);
  const iv::Point3 hi = lo + iv::Point3::Constant(g.resolution());
  return rt::length_in_box(a, b, lo, hi);
}

}  // namespace

TEST_CASE("the DDA visits exactly the voxels a fine sampling of the segment finds", "[raycast][traversal]") {
  const iv::GridGeometry g(0.1, iv::Point3(0.013, -0.021, 0.007));
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> coord(-1.5, 1.5);
  std::size_t extra_checked = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const iv::Point3 a(coord(rng), coord(rng), coord(rng));
    const iv::Point3 b(coord(rng), coord(rng), coord(rng));
    const auto keys = walk(g, a, b);
    REQUIRE_FALSE(keys.empty());
    // Starts and ends in the endpoint voxels, face-connected, no repeats.
    CHECK(keys.front() == g.key(a));
    CHECK(keys.back() == g.key(b));
    const std::set<iv::Key> unique(keys.begin(), keys.end());
    CHECK(unique.size() == keys.size());
    for (std::size_t i = 1; i < keys.size(); ++i) {
      const int manhattan = std::abs(keys[i].x - keys[i - 1].x) + std::abs(keys[i].y - keys[i - 1].y) +
                            std::abs(keys[i].z - keys[i - 1].z);
      REQUIRE(manhattan == 1);
    }
    // Brute force: 4000 samples per voxel length.
    const double len = (b - a).norm();
    const int n = std::max(2, int(len / g.resolution() * 4000));
    const double spacing = len / n;
    std::set<iv::Key> sampled;
    for (int i = 0; i <= n; ++i) sampled.insert(g.key(a + (b - a) * (double(i) / n)));
    for (const auto& k : sampled) CHECK(unique.count(k) == 1);
    // Voxels the sampling missed may only be clipped by less than a sample spacing.
    for (const auto& k : unique) {
      if (sampled.count(k)) continue;
      ++extra_checked;
      CHECK(length_inside(g, a, b, k) <= 2 * spacing);
    }
  }
  CHECK(extra_checked < 10);  // corner clips are rare for random segments
}

TEST_CASE("a segment through an exact voxel edge steps the higher axis first", "[raycast][traversal]") {
  const iv::GridGeometry g(1.0);
  const auto keys = walk(g, {0.5, 0.5, 0.5}, {2.5, 2.5, 0.5});
  const std::vector<iv::Key> expected{{0, 0, 0}, {0, 1, 0}, {1, 1, 0}, {1, 2, 0}, {2, 2, 0}};
  CHECK(keys == expected);
}

TEST_CASE("axis-aligned, backward and single-voxel segments", "[raycast][traversal]") {
  const iv::GridGeometry g(0.5);
  CHECK(walk(g, {0.1, 0.1, 0.1}, {0.2, 0.4, 0.3}) == std::vector<iv::Key>{{0, 0, 0}});
  CHECK(walk(g, {0.1, 0.1, 0.1}, {1.6, 0.1, 0.1}) == std::vector<iv::Key>{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}});
  CHECK(walk(g, {0.1, 0.1, 0.1}, {0.1, 0.1, -1.1}) ==
        std::vector<iv::Key>{{0, 0, 0}, {0, 0, -1}, {0, 0, -2}, {0, 0, -3}});
  // A point on a face belongs to the voxel on its positive side.
  CHECK(walk(g, {0.1, 0.1, 0.1}, {0.5, 0.1, 0.1}) == std::vector<iv::Key>{{0, 0, 0}, {1, 0, 0}});
}

TEST_CASE("a visitor returning false stops the traversal", "[raycast][traversal]") {
  const iv::GridGeometry g(0.1);
  int seen = 0;
  const auto r = iv::traverse(g, iv::Point3(0.05, 0.05, 0.05), std::array<double, 3>{5.0, 0.05, 0.05},
                              [&](const iv::Key&) { return ++seen < 7; });
  CHECK(r.status == iv::TraverseStatus::Stopped);
  CHECK(r.voxels == 7);
  CHECK(seen == 7);
}

TEST_CASE("a traversal with a non-finite or out-of-range endpoint visits nothing", "[raycast][traversal]") {
  const iv::GridGeometry g(0.1);
  int seen = 0;
  auto count = [&](const iv::Key&) { return ++seen, true; };
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  CHECK(iv::traverse(g, iv::Point3(0, 0, 0), iv::Point3(nan, 0, 0), count).status == iv::TraverseStatus::Invalid);
  CHECK(iv::traverse(g, iv::Point3(inf, 0, 0), iv::Point3(0, 0, 0), count).status == iv::TraverseStatus::Invalid);
  CHECK(iv::traverse(g, iv::Point3(0, 0, 0), iv::Point3(1e7, 0, 0), count).status == iv::TraverseStatus::Invalid);
  CHECK(seen == 0);
  // The longest valid ray is bounded by the key range, not by the distance.
  const auto r = iv::traverse(iv::GridGeometry(1.0), iv::Point3(0, 0, 0), iv::Point3(1e6, 0, 0),
                              [](const iv::Key&) { return true; });
  CHECK(r.status == iv::TraverseStatus::Completed);
  CHECK(r.voxels == 1000001);
}
