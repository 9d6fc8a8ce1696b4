#include <catch2/catch.hpp>
#include <intervox/grid/voxel_grid.hpp>

#include <cmath>

namespace iv = intervox;

TEST_CASE("log-odds and probability are inverse closed forms", "[core][probability]") {
  for (double p : {0.01, 0.12, 0.3, 0.5, 0.7, 0.971, 0.999}) {
    CHECK(iv::log_odds(p) == Approx(std::log(p / (1 - p))));
    CHECK(iv::probability(iv::log_odds(p)) == Approx(p).epsilon(1e-12));
  }
  CHECK(iv::log_odds(0.5) == 0.0);
  CHECK(iv::log_odds(0.0) == -INFINITY);
  CHECK(iv::log_odds(1.0) == INFINITY);
  CHECK(std::isnan(iv::log_odds(1.5)));
  CHECK(std::isnan(iv::log_odds(NAN)));
  CHECK(iv::probability(-INFINITY) == 0.0);
  CHECK(iv::probability(INFINITY) == 1.0);
}

TEST_CASE("the Bayes step in probability space matches eq. 3.12 and fixes 0 and 1", "[core][probability]") {
  // Thesis Fig. 4.1: a state of 0.55 updated with lq = 0.33 goes to about 0.29.
  CHECK(iv::bayes_step(0.55, 0.33) == Approx(0.2875).margin(0.001));
  CHECK(iv::bayes_step(0.5, 3.0) == Approx(0.75));
  CHECK(iv::bayes_step(0.0, 3.0) == 0.0);  // eq. 3.13
  CHECK(iv::bayes_step(1.0, 0.1) == 1.0);  // eq. 3.14
  // Log-odds addition is the same step.
  const double p = 0.37, lq = 2.5;
  CHECK(iv::probability(iv::log_odds(p) + std::log(lq)) == Approx(iv::bayes_step(p, lq)));
}

TEST_CASE("binary entropy is one bit at 0.5, zero at certainty and symmetric", "[core][probability]") {
  CHECK(iv::binary_entropy(0.5) == Approx(1.0));
  CHECK(iv::binary_entropy(0.0) == 0.0);
  CHECK(iv::binary_entropy(1.0) == 0.0);
  CHECK(iv::binary_entropy(0.25) == Approx(0.8112781245));
  for (double p : {0.01, 0.1, 0.3, 0.45}) CHECK(iv::binary_entropy(p) == Approx(iv::binary_entropy(1 - p)));
  CHECK(iv::binary_entropy(0.1) < iv::binary_entropy(0.3));
  CHECK(std::isnan(iv::binary_entropy(NAN)));
}

TEST_CASE("an interval knows its width, mid point and the point closest to 0.5", "[core][interval]") {
  const iv::Interval i{0.2, 0.9};
  CHECK(i.width() == Approx(0.7));
  CHECK(i.mid() == Approx(0.55));
  CHECK(i.contains(0.5));
  CHECK_FALSE(i.contains(0.95));
  CHECK(i.closest_to(0.5) == 0.5);
  CHECK(iv::Interval{0.6, 0.8}.closest_to(0.5) == 0.6);
  CHECK(iv::Interval{0.1, 0.3}.closest_to(0.5) == 0.3);
}

TEST_CASE("max-entropy is H(0.5) when the interval covers 0.5, else H at the closest bound", "[core][utility]") {
  const iv::MaxEntropy h;
  const iv::Entropy e;
  CHECK(h.value(0.9, {0.2, 0.9}) == Approx(1.0));
  CHECK(h.value(0.8, {0.7, 0.9}) == Approx(iv::binary_entropy(0.7)));
  CHECK(h.value(0.2, {0.1, 0.3}) == Approx(iv::binary_entropy(0.3)));
  // Degenerate (Bayes) intervals: max-entropy equals entropy.
  for (double p : {0.05, 0.3, 0.5, 0.8}) CHECK(h.value(p, {p, p}) == Approx(e.value(p, {p, p})));
}
