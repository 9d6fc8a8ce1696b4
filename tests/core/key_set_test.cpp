// KeySet (core/key_set.hpp) against std::set on random keys, through growth and many clears.
#include <catch2/catch.hpp>
#include <intervox/core/key_set.hpp>

#include <random>
#include <set>

namespace iv = intervox;

TEST_CASE("a key set holds exactly the keys inserted since the last clear, through growth", "[core][keyset]") {
  std::mt19937_64 rng(42);
  iv::KeySet set;
  for (int round = 0; round < 40; ++round) {
    // Rounds of different sizes (growth in the large ones), keys from a small cube (many
    // repeats) and from the whole key range (negative coordinates, extremes).
    const int n = round % 5 == 4 ? 20000 : 1 + static_cast<int>(rng() % 700);
    const bool wide = round % 2 == 1;
    std::set<iv::Key> want;
    for (int i = 0; i < n; ++i) {
      iv::Key k;
      for (int a = 0; a < 3; ++a)
        k[a] = wide ? static_cast<std::int32_t>(rng() % (2 * static_cast<std::uint64_t>(iv::kKeyLimit))) - iv::kKeyLimit
                    : static_cast<std::int32_t>(rng() % 12) - 6;
      const bool fresh = want.insert(k).second;
      REQUIRE(set.insert(k) == fresh);
    }
    REQUIRE(set.size() == want.size());
    for (const iv::Key& k : want) REQUIRE(set.contains(k));
    const iv::Key probe{iv::kKeyLimit - 1, -iv::kKeyLimit, 7};  // almost never inserted
    CHECK(set.contains(probe) == (want.count(probe) == 1));
    set.clear();
    CHECK(set.size() == 0);
    for (const iv::Key& k : want) REQUIRE_FALSE(set.contains(k));
  }
}
