// KeyBoxSet (core/key_box_set.hpp) against std::set on random keys of random boxes, through many
// resets of different sizes; its refusals (boxes too large or empty, keys outside the box).
#include <catch2/catch.hpp>
#include <intervox/core/error.hpp>
#include <intervox/core/key_box_set.hpp>

#include <random>
#include <set>

namespace iv = intervox;

TEST_CASE("a key box set holds exactly the keys inserted since the last reset, for boxes anywhere in the key range",
          "[core][keyset]") {
  std::mt19937_64 rng(7);
  iv::KeyBoxSet set;
  for (int round = 0; round < 60; ++round) {
    // A box of 1..40 voxels per axis, anywhere (negative keys and the range's ends included).
    iv::Key lo, hi;
    for (int a = 0; a < 3; ++a) {
      const std::int32_t n = 1 + static_cast<std::int32_t>(rng() % 40);
      lo[a] = round % 3 == 0 ? (round % 2 ? iv::kKeyLimit - n : -iv::kKeyLimit)
                             : static_cast<std::int32_t>(rng() % 2000) - 1000;
      hi[a] = lo[a] + n - 1;
    }
    REQUIRE(set.reset(lo, hi));
    REQUIRE(set.size() == 0);
    CHECK(set.box_voxels() == std::int64_t{hi.x - lo.x + 1} * (hi.y - lo.y + 1) * (hi.z - lo.z + 1));
    std::set<iv::Key> want;
    const int n = 1 + static_cast<int>(rng() % 3000);
    for (int i = 0; i < n; ++i) {
      iv::Key k;
      for (int a = 0; a < 3; ++a)
        k[a] = lo[a] + static_cast<std::int32_t>(rng() % static_cast<std::uint64_t>(hi[a] - lo[a] + 1));
      REQUIRE(set.insert(k) == want.insert(k).second);
    }
    REQUIRE(set.size() == want.size());
    for (const iv::Key& k : want) REQUIRE(set.contains(k));
    // Every key of the box not inserted is absent (the bits of the previous, larger boxes were
    // cleared by reset()).
    std::size_t present = 0;
    for (std::int32_t z = lo.z; z <= hi.z; ++z)
      for (std::int32_t y = lo.y; y <= hi.y; ++y)
        for (std::int32_t x = lo.x; x <= hi.x; ++x) present += set.contains(iv::Key{x, y, z}) ? 1 : 0;
    CHECK(present == want.size());
    // Just outside the box on each side of each axis: not contained, and insert refuses.
    for (int a = 0; a < 3; ++a)
      for (const bool below : {true, false}) {
        iv::Key k = lo;
        k[a] = below ? lo[a] - 1 : hi[a] + 1;
        if (below && lo[a] == -iv::kKeyLimit) continue;  // no key below the range
        CHECK_FALSE(set.covers(k));
        CHECK_FALSE(set.contains(k));
        CHECK_THROWS_AS(set.insert(k), iv::InvalidArgument);
      }
  }
}

TEST_CASE("a key box set refuses boxes that are empty or larger than its limit, and then covers nothing",
          "[core][keyset]") {
  iv::KeyBoxSet set;
  REQUIRE(set.reset(iv::Key{0, 0, 0}, iv::Key{9, 9, 9}));
  REQUIRE(set.insert(iv::Key{1, 2, 3}));
  SECTION("lo above hi on an axis") { CHECK_FALSE(set.reset(iv::Key{0, 5, 0}, iv::Key{9, 4, 9})); }
  SECTION("more voxels than the caller allows") { CHECK_FALSE(set.reset(iv::Key{0, 0, 0}, iv::Key{9, 9, 9}, 999)); }
  SECTION("more voxels than kMaxVoxels, without allocating") {
    CHECK_FALSE(
        set.reset(iv::Key{-iv::kKeyLimit, -iv::kKeyLimit, 0}, iv::Key{iv::kKeyLimit - 1, iv::kKeyLimit - 1, 0}));
    CHECK(set.memory_bytes() < 1024);
  }
  CHECK(set.box_voxels() == 0);
  CHECK(set.size() == 0);
  CHECK_FALSE(set.contains(iv::Key{1, 2, 3}));
  CHECK_THROWS_AS(set.insert(iv::Key{1, 2, 3}), iv::InvalidArgument);
  // The exact limit is accepted.
  CHECK(set.reset(iv::Key{0, 0, 0}, iv::Key{9, 9, 9}, 1000));
  CHECK(set.insert(iv::Key{9, 9, 9}));
}
