// What a robot with one camera meets (docs/planning.md, "one camera, one frame per heading"): how
// many consistent misses turn a voxel free, per policy and parameter. The docs' tables are these
// numbers.
#include <catch2/catch.hpp>
#include <intervox/update/bayes_log_odds.hpp>
#include <intervox/update/interval_update.hpp>

namespace iv = intervox;

namespace {
template <class U>
int misses_to_free(const U& u) {
  auto c = u.unobserved();
  for (int n = 1; n <= 100; ++n) {
    u.update(c, iv::Observation::Miss);
    if (u.occupancy(c) == iv::Occupancy::Free) return n;
  }
  return -1;
}
int mean_misses(const iv::IntervalParams& p) { return misses_to_free(iv::IntervalUpdate<iv::MeanState>(p)); }
}  // namespace

TEST_CASE("an interval-mean voxel turns free after exactly five consistent misses", "[plan][one-camera]") {
  CHECK(misses_to_free(iv::IntervalUpdate<iv::MeanState>{}) == 5);
  CHECK(misses_to_free(iv::IntervalUpdate<iv::MeanState>::thesis()) == 5);
  CHECK(misses_to_free(iv::IntervalUpdate<iv::LowerState>{}) == 1);
  CHECK(misses_to_free(iv::IntervalUpdate<iv::UpperState>{}) == 6);
  CHECK(misses_to_free(iv::BayesLogOdds{}) == 3);
}

TEST_CASE("a lower miss likelihood, a higher free threshold or a narrower prior interval frees a voxel sooner",
          "[plan][one-camera]") {
  iv::IntervalParams p;
  const double p_miss[] = {0.10, 0.15, 0.20, 0.25, 0.30, 0.40};
  const int by_p_miss[] = {3, 4, 4, 5, 7, 13};
  for (int i = 0; i < 6; ++i) {
    p = {};
    p.p_miss = p_miss[i];
    CHECK(mean_misses(p) == by_p_miss[i]);
  }
  const double thresholds[] = {0.05, 0.10, 0.30};
  const int by_threshold[] = {5, 4, 3};
  for (int i = 0; i < 3; ++i) {
    p = {};
    p.free_threshold = thresholds[i];
    CHECK(mean_misses(p) == by_threshold[i]);
  }
  const double lower[] = {0.05, 0.2, 0.35};
  const int by_prior[] = {5, 4, 3};
  for (int i = 0; i < 3; ++i) {
    p = {};
    p.initial_lower = lower[i];
    p.initial_upper = 1.0 - lower[i];
    CHECK(mean_misses(p) == by_prior[i]);
  }
}
