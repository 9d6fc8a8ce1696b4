// Soak: ten thousand scans into one grid lose no update and keep the inserter's memory bounded.
#include "reference.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdint>
#include <random>
#include <string_view>
#include <vector>

namespace iv = intervox;

namespace {

/// An update policy that counts: hits in the high 16 bits, misses in the low 16 bits. Any lost,
/// doubled or misplaced update shows in the counts.
struct CountingUpdate {
  using Cell = std::uint32_t;
  static constexpr std::string_view kName = "counting";
  static constexpr Cell kUnobserved = 0xFFFFFFFFu;
  Cell unobserved() const noexcept { return kUnobserved; }
  bool is_observed(const Cell& c) const noexcept { return c != kUnobserved; }
  void update(Cell& c, iv::Observation o) const noexcept {
    if (c == kUnobserved) c = 0;
    c += o == iv::Observation::Hit ? 0x10000u : 1u;
  }
  double state(const Cell&) const noexcept { return 0.5; }
  iv::Interval interval(const Cell&) const noexcept { return {0.0, 1.0}; }
  iv::Occupancy occupancy(const Cell&) const noexcept { return iv::Occupancy::Unknown; }
};
static_assert(iv::UpdatePolicy<CountingUpdate>);

using CountingGrid = iv::VoxelGrid<CountingUpdate, iv::Entropy, iv::SparseStorage>;

}  // namespace

TEST_CASE("ten thousand scans into one grid lose no update and keep the inserter's memory bounded",
          "[raycast][insert][soak][threads][threaded]") {
  const test::ThreadCap cap(2);
  constexpr double res = 0.1;
  constexpr int n = 32;  // the grid's box: keys [-16, 16)^3, 3.2 m
  const iv::Bounds bounds{{-1.6, -1.6, -1.6}, {1.6 - 1e-9, 1.6 - 1e-9, 1.6 - 1e-9}};
  CountingGrid plain(res, bounds), regions(res, bounds);
  iv::ScanInserter a({.max_range = 2.0, .min_range = 0.0, .threads = 2});
  iv::ScanInserter b({.max_range = 2.0, .min_range = 0.0, .threads = 2, .max_mark_bytes = 4096});
  iv::detail::ScanInserterAccess::force_hash(b, true);  // the block hash, split into regions

  // The reference: per voxel the expected hit and miss counts, one update per voxel and scan.
  std::vector<std::uint32_t> hits(n * n * n, 0), misses(n * n * n, 0);
  std::vector<int> hit_stamp(n * n * n, -1), miss_stamp(n * n * n, -1);
  auto index = [&](const iv::Key& k) {
    return static_cast<std::size_t>((k.x + 16) + n * ((k.y + 16) + n * (k.z + 16)));
  };

  std::mt19937_64 rng(77);
  std::uniform_real_distribution<double> coord(-1.9, 1.9);  // some ends outside the box
  std::uint64_t total_hits = 0, total_misses = 0, outside = 0;
  std::size_t warm_scratch_a = 0, warm_scratch_b = 0, max_scratch_a = 0, max_scratch_b = 0;
  constexpr int kScans = 10000;
  for (int scan = 0; scan < kScans; ++scan) {
    const iv::Point3 origin(coord(rng) * 0.5, coord(rng) * 0.5, coord(rng) * 0.5);
    const int rays = scan % 100 == 99 ? 5000 : 24;  // every hundredth scan large enough for two threads
    std::vector<iv::Point3> pts(rays);
    for (auto& p : pts) p = iv::Point3(coord(rng), coord(rng), coord(rng));
    // Reference per scan: hit keys, and miss keys that are not hit keys.
    std::vector<iv::Key> scan_hits;
    for (const auto& p : pts) {
      iv::Point3 end = p;
      bool is_hit = true;
      const double len = (p - origin).norm();
      if (len > 2.0) end = origin + (p - origin) * (2.0 / len), is_hit = false;
      const iv::Key ke = plain.geometry().key(end);
      iv::traverse(plain.geometry(), origin, end, [&](const iv::Key& k) {
        if (k != ke && plain.contains(k) && miss_stamp[index(k)] != scan) miss_stamp[index(k)] = scan;
        return true;
      });
      if (is_hit && plain.contains(ke)) hit_stamp[index(ke)] = scan;
    }
    const auto sa = a.insert_point_cloud(plain, origin, pts);
    const auto sb = b.insert_point_cloud(regions, origin, pts);
    REQUIRE(sa == sb);
    total_hits += sa.hits;
    total_misses += sa.misses;
    outside += sa.outside_bounds;
    max_scratch_a = std::max(max_scratch_a, a.scratch_bytes());
    max_scratch_b = std::max(max_scratch_b, b.scratch_bytes());
    if (scan == 999) warm_scratch_a = max_scratch_a, warm_scratch_b = max_scratch_b;
    // Fold this scan's stamps into the counts (a hit wins over a miss).
    for (std::size_t v = 0; v < hits.size(); ++v) {
      if (hit_stamp[v] == scan)
        ++hits[v];
      else if (miss_stamp[v] == scan)
        ++misses[v];
    }
  }
  std::uint64_t expected_hits = 0, expected_misses = 0;
  for (std::size_t v = 0; v < hits.size(); ++v) expected_hits += hits[v], expected_misses += misses[v];
  CHECK(total_hits == expected_hits);
  CHECK(total_misses == expected_misses);
  CHECK(outside > 0);

  for (const CountingGrid* g : {&plain, &regions}) {
    std::size_t observed = 0;
    g->for_each_observed([&](const iv::Key& k, const std::uint32_t& c) {
      ++observed;
      INFO("key " << k.x << " " << k.y << " " << k.z);
      REQUIRE(c >> 16 == hits[index(k)]);
      REQUIRE((c & 0xFFFFu) == misses[index(k)]);
    });
    const auto expected_observed = static_cast<std::size_t>(std::count_if(
        hits.begin(), hits.end(), [&](const std::uint32_t& h) { return h != 0 || misses[&h - hits.data()] != 0; }));
    CHECK(observed == expected_observed);
  }
  // Memory: after a thousand scans (ten of them large) the scratch grows by at most the odd
  // larger scan shape (a leak per scan would multiply it over the nine thousand scans left).
  CHECK(max_scratch_a <= warm_scratch_a + warm_scratch_a / 20);
  CHECK(max_scratch_b <= warm_scratch_b + warm_scratch_b / 20);
  CHECK(max_scratch_b < (std::size_t{1} << 20));
}
