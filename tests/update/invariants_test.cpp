// Property tests: invariants of every update policy over 10^6 seeded random updates each.
#include <catch2/catch.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/update/bayes_log_odds.hpp>
#include <intervox/update/interval_update.hpp>

#include <cmath>
#include <random>

namespace iv = intervox;

namespace {
constexpr int kVoxels = 1000;
constexpr int kUpdates = 1'000'000;

/// Random observations with a per-voxel hit rate, so some voxels see consistent and some
/// conflicting data.
template <class U, class Check>
void random_updates(const U& u, std::uint64_t seed, Check&& check) {
  std::mt19937_64 rng(seed);
  std::vector<typename U::Cell> cells(kVoxels, u.unobserved());
  std::vector<double> hit_rate(kVoxels);
  for (auto& r : hit_rate) r = static_cast<double>(rng() >> 11) * 0x1.0p-53;
  for (int i = 0; i < kUpdates; ++i) {
    const std::size_t v = rng() % kVoxels;
    const bool hit = static_cast<double>(rng() >> 11) * 0x1.0p-53 < hit_rate[v];
    const auto before = cells[v];
    u.update(cells[v], hit ? iv::Observation::Hit : iv::Observation::Miss);
    check(before, cells[v], hit);
  }
}
}  // namespace

TEMPLATE_TEST_CASE("interval bounds stay ordered inside [0, 1] and never widen under clamping",
                   "[core][interval][property]", iv::LowerState, iv::MeanState, iv::UpperState) {
  for (bool latch : {false, true}) {
    const iv::IntervalUpdate<TestType> u(latch ? iv::IntervalParams::thesis() : iv::IntervalParams{});
    const auto& p = u.params();
    std::size_t violations = 0;
    random_updates(u, latch ? 7 : 11, [&](const auto& before, const auto& after, bool hit) {
      const iv::Interval b = u.interval(before), a = u.interval(after);
      const double s = u.state(after);
      bool ok = 0.0 <= a.lower && a.lower <= a.upper && a.upper <= 1.0 && a.lower <= s && s <= a.upper;
      if (!latch) {
        ok = ok && a.lower >= p.clamp_min - 1e-6 && a.upper <= p.clamp_max + 1e-6;
        const auto lb = u.log_odds(before), la = u.log_odds(after);
        ok = ok && (la.upper - la.lower) <= (lb.upper - lb.lower) + 1e-5f;  // width in log-odds never grows
      }
      // A hit never lowers a bound, a miss never raises one.
      ok = ok && (hit ? (a.lower >= b.lower && a.upper >= b.upper) : (a.lower <= b.lower && a.upper <= b.upper));
      violations += !ok;
    });
    CHECK(violations == 0);
  }
}

TEST_CASE("Bayes states stay inside the clamps and move with the evidence", "[core][bayes][property]") {
  for (const auto& params : {iv::BayesParams{}, iv::BayesParams::octomap(), iv::BayesParams::thesis()}) {
    const iv::BayesLogOdds u(params);
    std::size_t violations = 0;
    random_updates(u, 3, [&](float before, float after, bool hit) {
      const double s = u.state(after), b = u.state(before);
      bool ok = u.is_observed(after) && s >= 0.0 && s <= 1.0;
      if (!params.latch)
        ok = ok && s >= params.clamp_min - 1e-6 && s <= params.clamp_max + 1e-6;
      else
        ok = ok && (s == 0.0 || s == 1.0 || (s > params.free_threshold && s < params.occupied_threshold));
      ok = ok && (hit ? s >= b : s <= b);
      // The update is the closed form: prior log-odds plus the step, clamped.
      const float l0 = u.is_observed(before) ? before : iv::log_odds_f(params.prior);
      if (!params.latch) {
        const float expected =
            std::min(std::max(l0 + (hit ? u.hit_log_odds() : u.miss_log_odds()), u.clamp_min_log_odds()),
                     u.clamp_max_log_odds());
        ok = ok && after == expected;
      }
      violations += !ok;
    });
    CHECK(violations == 0);
  }
}
