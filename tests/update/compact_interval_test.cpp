// CompactIntervalUpdate: the interval update with 16-bit fixed-point bounds, against the float
// IntervalUpdate on the same random observations, and its own rules (sentinel, latching, range).
#include <intervox/update/interval_update.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <vector>

namespace iv = intervox;

TEMPLATE_TEST_CASE("the compact interval update follows the float interval update within its fixed-point step",
                   "[core][interval][compact][property]", iv::LowerState, iv::MeanState, iv::UpperState) {
  for (bool thesis : {false, true}) {
    const iv::IntervalParams p = thesis ? iv::IntervalParams::thesis() : iv::IntervalParams{};
    const iv::IntervalUpdate<TestType> f(p);
    const iv::CompactIntervalUpdate<TestType> c(p);
    constexpr int kCells = 1000;
    std::vector<iv::IntervalCell> fc(kCells, f.unobserved());
    std::vector<iv::CompactIntervalCell> cc(kCells, c.unobserved());
    std::mt19937_64 rng(thesis ? 5 : 6);
    std::uniform_int_distribution<int> pick(0, kCells - 1);
    std::vector<double> bias(kCells);  // each cell its own hit rate, conflicting ones included
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    for (auto& b : bias) b = u01(rng);
    std::size_t far = 0, bad_bounds = 0, bad_class = 0;
    for (int i = 0; i < 300000; ++i) {
      const int v = pick(rng);
      const auto o = u01(rng) < bias[v] ? iv::Observation::Hit : iv::Observation::Miss;
      f.update(fc[v], o);
      c.update(cc[v], o);
      const iv::Interval a = f.interval(fc[v]), b = c.interval(cc[v]);
      bad_bounds += std::abs(a.lower - b.lower) > 2e-3 || std::abs(a.upper - b.upper) > 2e-3;
      const double s = f.state(fc[v]);
      if (std::abs(s - p.free_threshold) > 5e-3 && std::abs(s - p.occupied_threshold) > 5e-3) {
        ++far;
        bad_class += f.occupancy(fc[v]) != c.occupancy(cc[v]);
      }
    }
    CHECK(bad_bounds == 0);
    CHECK(bad_class == 0);
    CHECK(far > 200000);  // the class comparison covered most updates
  }
}

TEST_CASE("a compact interval cell takes 4 bytes, starts at the prior and latches at exactly 0 and 1",
          "[core][interval][compact]") {
  STATIC_REQUIRE(sizeof(iv::CompactIntervalUpdate<>::Cell) == 4);
  const iv::CompactIntervalUpdate<> u;
  auto cell = u.unobserved();
  CHECK_FALSE(u.is_observed(cell));
  CHECK(u.occupancy(cell) == iv::Occupancy::Unknown);
  CHECK(u.interval(cell).lower == Approx(0.05).margin(1e-4));
  CHECK(u.interval(cell).upper == Approx(0.95).margin(1e-4));
  u.update(cell, iv::Observation::Hit);
  CHECK(u.is_observed(cell));
  // One hit: both bounds' log-odds rise by ln 3 (eq. 4.3), to the 1/2048 step.
  CHECK(std::log(u.interval(cell).lower / (1 - u.interval(cell).lower)) ==
        Approx(std::log(0.05 / 0.95) + std::log(3.0)).margin(1e-3));
  // Thesis parameters: four misses latch the lower bound at exactly 0 (not yet the upper one),
  // and it stays there when hits follow; the upper bound latches at 1 under the hits: the
  // interval widens to [0, 1], as with the float policy.
  const auto t = iv::CompactIntervalUpdate<>::thesis();
  const auto tf = iv::IntervalUpdate<>::thesis();
  auto c = t.unobserved();
  auto cf = tf.unobserved();
  for (int i = 0; i < 4; ++i) t.update(c, iv::Observation::Miss), tf.update(cf, iv::Observation::Miss);
  CHECK(t.interval(c).lower == 0.0);
  CHECK(t.interval(c).upper > 0.1);
  for (int i = 0; i < 20; ++i) t.update(c, iv::Observation::Hit), tf.update(cf, iv::Observation::Hit);
  CHECK(t.interval(c).lower == 0.0);
  CHECK(t.interval(c).upper == 1.0);
  CHECK(tf.interval(cf).lower == 0.0);
  CHECK(tf.interval(cf).upper == 1.0);
}

TEST_CASE("compact interval parameters beyond the 16-bit range are rejected", "[core][interval][compact][errors]") {
  iv::IntervalParams p;
  p.clamp_min = 1e-9;  // log-odds -20.7: beyond +-15.99
  p.free_threshold = 0.05;
  CHECK_NOTHROW(iv::IntervalUpdate<>(p));
  CHECK_THROWS_AS(iv::CompactIntervalUpdate<>(p), iv::InvalidArgument);
  iv::IntervalParams q;
  q.p_hit = 1.5;  // the float policy's rules apply too
  CHECK_THROWS_AS(iv::CompactIntervalUpdate<>(q), iv::InvalidArgument);
}
