#include <catch2/catch.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/update/bayes_log_odds.hpp>
#include <intervox/update/interval_update.hpp>

#include <cmath>
#include <random>

namespace iv = intervox;

namespace {
template <class U>
typename U::Cell apply(const U& u, int hits, int misses) {
  auto c = u.unobserved();
  for (int i = 0; i < hits; ++i) u.update(c, iv::Observation::Hit);
  for (int i = 0; i < misses; ++i) u.update(c, iv::Observation::Miss);
  return c;
}
template <class U>
int updates_until(const U& u, iv::Observation o, iv::Occupancy target) {
  auto c = u.unobserved();
  for (int n = 1; n <= 100; ++n) {
    u.update(c, o);
    if (u.occupancy(c) == target) return n;
  }
  return -1;
}
}  // namespace

TEST_CASE("an unobserved Bayes voxel is unknown at its prior", "[core][bayes]") {
  const iv::BayesLogOdds u;
  const auto c = u.unobserved();
  CHECK_FALSE(u.is_observed(c));
  CHECK(u.state(c) == 0.5);
  CHECK(u.occupancy(c) == iv::Occupancy::Unknown);
  CHECK(u.interval(c) == iv::Interval{0.5, 0.5});
}

TEST_CASE("the OctoMap preset adds OctoMap's log-odds and clamps at 0.1192 and 0.971", "[core][bayes]") {
  const auto u = iv::BayesLogOdds::octomap();
  CHECK(u.hit_log_odds() == static_cast<float>(std::log(0.7 / 0.3)));
  CHECK(u.miss_log_odds() == static_cast<float>(std::log(0.4 / 0.6)));
  CHECK(u.state(apply(u, 1, 0)) == Approx(0.7).epsilon(1e-6));
  CHECK(u.state(apply(u, 0, 1)) == Approx(0.4).epsilon(1e-6));
  CHECK(u.state(apply(u, 20, 0)) == Approx(0.971).epsilon(1e-6));
  CHECK(u.state(apply(u, 0, 20)) == Approx(0.1192).epsilon(1e-6));
  // OctoMap has no unknown band: occupied at or above 0.5, free below.
  CHECK(u.occupancy(apply(u, 1, 0)) == iv::Occupancy::Occupied);
  CHECK(u.occupancy(apply(u, 0, 1)) == iv::Occupancy::Free);
  CHECK(u.occupancy(apply(u, 1, 2)) == iv::Occupancy::Occupied);  // 0.847 - 2 * 0.405 > 0
  CHECK(u.occupancy(apply(u, 1, 3)) == iv::Occupancy::Free);      // 0.847 - 3 * 0.405 < 0
}

TEST_CASE("a voxel hit often enough becomes occupied, one passed through often enough becomes free", "[core][bayes]") {
  const iv::BayesLogOdds u;  // thesis likelihoods lq = 3 and 1/3, thresholds 0.05 / 0.95
  CHECK(updates_until(u, iv::Observation::Hit, iv::Occupancy::Occupied) == 3);
  CHECK(updates_until(u, iv::Observation::Miss, iv::Occupancy::Free) == 3);
  CHECK(u.occupancy(apply(u, 2, 0)) == iv::Occupancy::Unknown);
  // Without latching, the clamp at 0.99 keeps the voxel revisable: four misses undo it.
  auto c = apply(u, 50, 0);
  CHECK(u.state(c) == Approx(0.99).epsilon(1e-6));
  for (int i = 0; i < 4; ++i) u.update(c, iv::Observation::Miss);
  CHECK(u.occupancy(c) != iv::Occupancy::Occupied);
}

TEST_CASE("with the thesis' latching a voxel crossing a threshold is set to 0 or 1 for good", "[core][bayes]") {
  const auto u = iv::BayesLogOdds::thesis();
  auto c = apply(u, 3, 0);
  CHECK(u.state(c) == 1.0);
  for (int i = 0; i < 100; ++i) u.update(c, iv::Observation::Miss);
  CHECK(u.state(c) == 1.0);  // eq. 3.14
  CHECK(u.occupancy(c) == iv::Occupancy::Occupied);
  auto f = apply(u, 0, 3);
  CHECK(u.state(f) == 0.0);
  for (int i = 0; i < 100; ++i) u.update(f, iv::Observation::Hit);
  CHECK(u.state(f) == 0.0);  // eq. 3.13
  CHECK(u.occupancy(f) == iv::Occupancy::Free);
  CHECK(u.occupancy(apply(u, 2, 0)) == iv::Occupancy::Unknown);
}

TEST_CASE("inconsistent Bayes parameters are rejected with a message naming the rule", "[core][bayes][errors]") {
  auto bad = [](auto mutate) {
    iv::BayesParams p;
    mutate(p);
    return p;
  };
  CHECK_THROWS_AS(iv::BayesLogOdds(bad([](auto& p) { p.p_hit = 0.4; })), iv::InvalidArgument);
  CHECK_THROWS_AS(iv::BayesLogOdds(bad([](auto& p) { p.p_miss = 0.6; })), iv::InvalidArgument);
  CHECK_THROWS_AS(iv::BayesLogOdds(bad([](auto& p) { p.p_hit = NAN; })), iv::InvalidArgument);
  CHECK_THROWS_AS(iv::BayesLogOdds(bad([](auto& p) { p.clamp_min = 0.9; })), iv::InvalidArgument);
  CHECK_THROWS_AS(iv::BayesLogOdds(bad([](auto& p) { p.free_threshold = 0.99; })), iv::InvalidArgument);
  CHECK_THROWS_WITH(iv::BayesLogOdds(bad([](auto& p) { p.clamp_max = 0.9; })), Catch::Contains("unreachable"));
  CHECK_THROWS_WITH(iv::BayesLogOdds(bad([](auto& p) { p.clamp_min = 0.1; })), Catch::Contains("free_threshold"));
  CHECK_THROWS_AS(iv::BayesLogOdds(bad([](auto& p) { p.prior = 1.0; })), iv::InvalidArgument);
  // Latching ignores the clamps, so unreachable clamps are fine there.
  CHECK_NOTHROW(iv::BayesLogOdds(bad([](auto& p) {
    p.latch = true;
    p.clamp_max = 0.6;
  })));
  CHECK_NOTHROW(iv::BayesLogOdds::octomap());
  CHECK_NOTHROW(iv::BayesLogOdds::thesis());
}

TEST_CASE("the thesis' worked example (Fig. 4.1): interval mean 0.55 -> about 0.41, Bayes 0.55 -> about 0.29",
          "[core][interval]") {
  iv::IntervalParams ip;
  ip.initial_lower = 0.2;
  ip.initial_upper = 0.9;
  ip.p_miss = 0.33 / 1.33;  // likelihood quotient 0.33
  const iv::IntervalUpdate<iv::MeanState> u(ip);
  auto c = u.unobserved();
  CHECK(u.state(c) == Approx(0.55));
  u.update(c, iv::Observation::Miss);
  CHECK(u.state(c) == Approx(0.41).margin(0.005));
  CHECK(u.interval(c).lower == Approx(iv::bayes_step(0.2, 0.33)).epsilon(1e-5));
  CHECK(u.interval(c).upper == Approx(iv::bayes_step(0.9, 0.33)).epsilon(1e-5));

  iv::BayesParams bp;
  bp.prior = 0.55;
  bp.p_miss = ip.p_miss;
  const iv::BayesLogOdds b(bp);
  auto s = b.unobserved();
  b.update(s, iv::Observation::Miss);
  CHECK(b.state(s) == Approx(0.29).margin(0.005));
}

TEST_CASE("an unobserved interval voxel is unknown with the initial interval and its rule's state",
          "[core][interval]") {
  const iv::IntervalUpdate<iv::LowerState> lo;
  const iv::IntervalUpdate<iv::MeanState> mid;
  const iv::IntervalUpdate<iv::UpperState> up;
  CHECK(lo.interval(lo.unobserved()).lower == Approx(0.05));
  CHECK(lo.interval(lo.unobserved()).upper == Approx(0.95));
  CHECK(lo.state(lo.unobserved()) == Approx(0.05));
  CHECK(mid.state(mid.unobserved()) == Approx(0.5));
  CHECK(up.state(up.unobserved()) == Approx(0.95));
  // By default unobserved is unknown whatever the rule, even where the rule's prior state sits at a
  // threshold (IntervalParams::classify_unobserved changes that).
  CHECK(lo.occupancy(lo.unobserved()) == iv::Occupancy::Unknown);
  CHECK(up.occupancy(up.unobserved()) == iv::Occupancy::Unknown);
}

TEMPLATE_TEST_CASE("with the thesis' classification never-observed space is free under the lower rule, occupied under "
                   "the upper and unknown under the mean",
                   "[core][interval]", iv::IntervalUpdate<iv::LowerState>, iv::IntervalUpdate<iv::MeanState>,
                   iv::IntervalUpdate<iv::UpperState>, iv::CompactIntervalUpdate<iv::LowerState>,
                   iv::CompactIntervalUpdate<iv::MeanState>, iv::CompactIntervalUpdate<iv::UpperState>) {
  using Rule = typename TestType::StateRuleType;
  iv::IntervalParams p;
  p.classify_unobserved = true;
  const TestType u(p);
  // The defaults put the lower and upper rules' prior states exactly on the thresholds (0.05, 0.95).
  const iv::Occupancy expected = Rule::kName == "lower"   ? iv::Occupancy::Free
                                 : Rule::kName == "upper" ? iv::Occupancy::Occupied
                                                          : iv::Occupancy::Unknown;
  CHECK(u.occupancy(u.unobserved()) == expected);
  CHECK_FALSE(u == TestType());  // the flag is part of the parameters
  // An initial interval away from the thresholds: unknown under every rule.
  p.initial_lower = 0.2;
  p.initial_upper = 0.8;
  CHECK(TestType(p).occupancy(TestType(p).unobserved()) == iv::Occupancy::Unknown);
  // Observed voxels are classified as without the flag.
  const TestType plain;
  for (int hits = 0; hits <= 6; ++hits) {
    CHECK(u.occupancy(apply(u, hits, 6 - hits)) == plain.occupancy(apply(plain, hits, 6 - hits)));
  }
}

TEST_CASE("the lower state is optimistic, the upper pessimistic, the mean in between", "[core][interval]") {
  const iv::IntervalUpdate<iv::LowerState> lo;
  const iv::IntervalUpdate<iv::MeanState> mid;
  const iv::IntervalUpdate<iv::UpperState> up;
  CHECK(updates_until(lo, iv::Observation::Miss, iv::Occupancy::Free) == 1);
  CHECK(updates_until(mid, iv::Observation::Miss, iv::Occupancy::Free) == 5);
  CHECK(updates_until(up, iv::Observation::Miss, iv::Occupancy::Free) == 6);
  CHECK(updates_until(lo, iv::Observation::Hit, iv::Occupancy::Occupied) == 6);
  CHECK(updates_until(mid, iv::Observation::Hit, iv::Occupancy::Occupied) == 5);
  CHECK(updates_until(up, iv::Observation::Hit, iv::Occupancy::Occupied) == 1);
  // The interval update is more inert than Bayes (thesis 4.2): Bayes needs 3 of either.
  CHECK(updates_until(iv::BayesLogOdds{}, iv::Observation::Miss, iv::Occupancy::Free) == 3);
}

TEST_CASE("with consistent data the interval converges to a narrow free or occupied state", "[core][interval]") {
  const iv::IntervalUpdate<iv::MeanState> u;
  const auto f = apply(u, 0, 12);
  CHECK(u.occupancy(f) == iv::Occupancy::Free);
  CHECK(u.interval(f).width() < 1e-6);
  CHECK(u.interval(f).lower == Approx(0.01));
  const auto o = apply(u, 12, 0);
  CHECK(u.occupancy(o) == iv::Occupancy::Occupied);
  CHECK(u.interval(o).width() < 1e-6);
}

TEST_CASE("with conflicting data the interval narrows while the state stays unknown", "[core][interval]") {
  // 2000 voxels, each seen 200 times; every observation is a fair coin between hit and miss.
  const iv::IntervalUpdate<iv::MeanState> u;
  std::mt19937_64 rng(42);
  int narrow = 0, conflict = 0;
  constexpr int kVoxels = 2000;
  for (int v = 0; v < kVoxels; ++v) {
    auto c = u.unobserved();
    for (int i = 0; i < 200; ++i) u.update(c, (rng() >> 63) ? iv::Observation::Hit : iv::Observation::Miss);
    const bool is_narrow = u.interval(c).width() < 0.05;
    narrow += is_narrow;
    conflict += is_narrow && u.occupancy(c) == iv::Occupancy::Unknown;
  }
  // Almost every conflicting voxel ends narrow (the clamps cut the interval), and about half of them
  // remain unknown: the signature that tells a conflict from ignorance (width 0.9).
  CHECK(narrow >= kVoxels * 95 / 100);
  CHECK(conflict >= kVoxels * 40 / 100);
  CHECK(u.interval(u.unobserved()).width() == Approx(0.9));
  // Consistent data never shows the signature.
  const auto f = apply(u, 0, 30);
  CHECK(u.occupancy(f) == iv::Occupancy::Free);
}

TEST_CASE("with the thesis' 8-bit latching a conflicted interval can widen to [0, 1]", "[core][interval]") {
  const auto u = iv::IntervalUpdate<iv::MeanState>::thesis();
  auto c = u.unobserved();
  for (int i = 0; i < 3; ++i) u.update(c, iv::Observation::Hit);  // upper bound reaches 1 and latches
  CHECK(u.interval(c).upper == 1.0);
  for (int i = 0; i < 12; ++i) u.update(c, iv::Observation::Miss);  // lower bound reaches 0 and latches
  CHECK(u.interval(c).lower == 0.0);
  CHECK(u.interval(c).upper == 1.0);
  for (int i = 0; i < 20; ++i) u.update(c, iv::Observation::Hit);
  CHECK(u.interval(c) == iv::Interval{0.0, 1.0});
  CHECK(u.occupancy(c) == iv::Occupancy::Unknown);
}

TEST_CASE("inconsistent interval parameters are rejected", "[core][interval][errors]") {
  auto make = [](auto mutate) {
    iv::IntervalParams p;
    mutate(p);
    return iv::IntervalUpdate<iv::MeanState>(p);
  };
  CHECK_THROWS_AS(make([](auto& p) { p.initial_lower = 0.96; }), iv::InvalidArgument);
  CHECK_THROWS_AS(make([](auto& p) { p.initial_upper = 0.999; }), iv::InvalidArgument);
  CHECK_THROWS_AS(make([](auto& p) { p.p_hit = 1.0; }), iv::InvalidArgument);
  CHECK_THROWS_AS(make([](auto& p) { p.clamp_max = NAN; }), iv::InvalidArgument);
  CHECK_THROWS_AS(make([](auto& p) { p.occupied_threshold = 0.995; }), iv::InvalidArgument);
  CHECK_THROWS_AS(make([](auto& p) {
                    p.free_threshold = 0.5;
                    p.occupied_threshold = 0.4;
                  }),
                  iv::InvalidArgument);
  CHECK_NOTHROW(iv::IntervalUpdate<iv::UpperState>::thesis());
}
