// Overflow-checked arithmetic (core/checked_math.hpp) and the box volume built on it (core/key.hpp).
#include <catch2/catch.hpp>
#include <intervox/core/checked_math.hpp>
#include <intervox/core/key.hpp>

#include <cstdint>
#include <limits>

namespace iv = intervox;

TEST_CASE("checked arithmetic reports overflow instead of wrapping", "[core][checked_math]") {
  constexpr auto kMaxU = std::numeric_limits<std::uint64_t>::max();
  constexpr auto kMaxI = std::numeric_limits<std::int64_t>::max();
  constexpr auto kMinI = std::numeric_limits<std::int64_t>::min();
  CHECK(iv::checked_mul<std::uint64_t>(1ull << 32, 1ull << 31) == std::uint64_t{1} << 63);
  CHECK_FALSE(iv::checked_mul<std::uint64_t>(1ull << 32, 1ull << 32).has_value());
  CHECK_FALSE(iv::checked_add<std::uint64_t>(kMaxU, 1).has_value());
  CHECK_FALSE(iv::checked_mul<std::int64_t>(std::int64_t{1} << 32, std::int64_t{1} << 31).has_value());
  CHECK(iv::checked_mul<std::int64_t>(-(std::int64_t{1} << 32), std::int64_t{1} << 31) == kMinI);
  CHECK_FALSE(iv::checked_add<std::int64_t>(kMinI, -1).has_value());
  CHECK(iv::saturating_mul<std::uint64_t>(1ull << 40, 1ull << 40) == kMaxU);
  CHECK(iv::saturating_add<std::uint64_t>(kMaxU - 1, 5) == kMaxU);
  CHECK(iv::saturating_mul<std::int64_t>(kMaxI, -2) == kMinI);
  CHECK(iv::saturating_mul<std::int64_t>(-kMaxI, -2) == kMaxI);
  CHECK(iv::saturating_add<std::int64_t>(kMinI, -1) == kMinI);
  CHECK(iv::mul_or_throw<iv::IoError, std::uint64_t>(6, 7, "size") == 42);
  CHECK_THROWS_AS((iv::mul_or_throw<iv::IoError, std::uint64_t>(1ull << 33, 1ull << 33, "size")), iv::IoError);
  CHECK_THROWS_WITH((iv::add_or_throw<iv::InvalidArgument, std::uint32_t>(4000000000u, 400000000u, "offset")),
                    Catch::Contains("offset") && Catch::Contains("overflows a 32-bit integer"));
}

TEST_CASE("a box whose volume overflows 64 bits reports a saturated volume, never a wrapped one",
          "[core][checked_math]") {
  // 2^24 x 2^24 x 2^16 keys: exactly 2^64, which a 64-bit product wraps to 0.
  const iv::KeyBox wraps{{-iv::kKeyLimit, -iv::kKeyLimit, 0}, {iv::kKeyLimit - 1, iv::kKeyLimit - 1, (1 << 16) - 1}};
  CHECK_FALSE(wraps.checked_volume().has_value());
  CHECK(wraps.volume() == std::numeric_limits<std::int64_t>::max());
  // The widest box of 32-bit keys: 2^96 keys.
  const iv::KeyBox widest{{INT32_MIN, INT32_MIN, INT32_MIN}, {INT32_MAX, INT32_MAX, INT32_MAX}};
  CHECK_FALSE(widest.checked_volume().has_value());
  CHECK(widest.volume() == std::numeric_limits<std::int64_t>::max());
  // Exact below the limit, 0 when empty.
  const iv::KeyBox box{{0, 0, 0}, {9, 4, 2}};
  CHECK(box.checked_volume() == std::uint64_t{150});
  CHECK(box.volume() == 150);
  const iv::KeyBox empty{{0, 0, 0}, {-1, 4, 2}};
  CHECK(empty.volume() == 0);
  CHECK(empty.checked_volume() == std::uint64_t{0});
}
