// The credal update policies (imprecise Dirichlet counts, Dempster–Shafer belief) and the total
// uncertainty utility: closed forms worked by hand, and properties over 10^6 seeded updates.
#include <catch2/catch.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/update/dempster_shafer.hpp>
#include <intervox/update/imprecise_dirichlet.hpp>
#include <intervox/update/interval_update.hpp>

#include <cmath>
#include <cstdint>
#include <random>

namespace iv = intervox;
using iv::Observation;

namespace {
constexpr auto kHit = Observation::Hit;
constexpr auto kMiss = Observation::Miss;

template <class U>
typename U::Cell apply(const U& u, std::initializer_list<Observation> obs) {
  auto c = u.unobserved();
  for (const auto o : obs) u.update(c, o);
  return c;
}
}  // namespace

TEST_CASE("the imprecise Dirichlet interval is [h / (N + s), (h + s) / (N + s)]", "[update][dirichlet]") {
  const iv::ImpreciseDirichletUpdate<iv::MeanState> u;  // s = 2
  const auto none = u.unobserved();
  CHECK_FALSE(u.is_observed(none));
  CHECK(u.interval(none) == iv::Interval{0.0, 1.0});
  CHECK(u.occupancy(none) == iv::Occupancy::Unknown);

  const auto c = apply(u, {kHit, kHit, kMiss, kHit});  // h = 3, m = 1, N = 4
  CHECK(c.hits == 3);
  CHECK(c.misses == 1);
  CHECK(u.interval(c).lower == Approx(3.0 / 6.0));
  CHECK(u.interval(c).upper == Approx(5.0 / 6.0));
  CHECK(u.interval(c).width() == Approx(2.0 / 6.0));
  CHECK(u.state(c) == Approx(4.0 / 6.0));
  // Thresholds 0.15 / 0.85 with the mean rule: five hits make a voxel occupied, five misses free.
  CHECK(u.occupancy(apply(u, {kHit, kHit, kHit, kHit})) == iv::Occupancy::Unknown);          // 5/6
  CHECK(u.occupancy(apply(u, {kHit, kHit, kHit, kHit, kHit})) == iv::Occupancy::Occupied);   // 6/7
  CHECK(u.occupancy(apply(u, {kMiss, kMiss, kMiss, kMiss})) == iv::Occupancy::Unknown);      // 1/6
  CHECK(u.occupancy(apply(u, {kMiss, kMiss, kMiss, kMiss, kMiss})) == iv::Occupancy::Free);  // 1/7
  // A conflict: 50 hits and 50 misses give a narrow interval around 0.5, unknown.
  auto k = u.unobserved();
  for (int i = 0; i < 50; ++i) {
    u.update(k, kHit);
    u.update(k, kMiss);
  }
  CHECK(u.interval(k).lower == Approx(50.0 / 102.0));
  CHECK(u.interval(k).upper == Approx(52.0 / 102.0));
  CHECK(u.occupancy(k) == iv::Occupancy::Unknown);

  // The rules take the lower bound, the mean or the upper bound; s scales the width.
  const iv::ImpreciseDirichletUpdate<iv::LowerState> lo(iv::DirichletParams{4.0});
  const iv::ImpreciseDirichletUpdate<iv::UpperState> hi(iv::DirichletParams{4.0});
  const auto c4 = apply(lo, {kHit, kMiss});  // h = 1, N = 2, s = 4
  CHECK(lo.state(c4) == Approx(1.0 / 6.0));
  CHECK(hi.state(c4) == Approx(5.0 / 6.0));
}

TEST_CASE("a full Dirichlet counter saturates or halves both counts as chosen", "[update][dirichlet]") {
  iv::DirichletParams p;
  p.max_count = 10;
  const iv::ImpreciseDirichletUpdate<iv::MeanState> sat(p);
  auto c = sat.unobserved();
  for (int i = 0; i < 25; ++i) sat.update(c, kHit);
  sat.update(c, kMiss);
  CHECK(c.hits == 10);
  CHECK(c.misses == 1);
  p.forgetting = iv::DirichletForgetting::HalveAtMax;
  const iv::ImpreciseDirichletUpdate<iv::MeanState> halve(p);
  c = halve.unobserved();
  for (int i = 0; i < 10; ++i) halve.update(c, kHit);  // h = 10
  halve.update(c, kMiss);                              // m = 1
  halve.update(c, kHit);                               // full: (10, 1) -> (5, 1), then h = 6
  CHECK(c.hits == 6);
  CHECK(c.misses == 1);
  CHECK_THROWS_AS(iv::ImpreciseDirichletUpdate<>(iv::DirichletParams{0.0}), iv::InvalidArgument);
  CHECK_THROWS_AS(iv::ImpreciseDirichletUpdate<>(iv::DirichletParams{2.0, 0.9, 0.1}), iv::InvalidArgument);
  iv::DirichletParams bad;
  bad.max_count = 70000;
  CHECK_THROWS_AS(iv::ImpreciseDirichletUpdate<>(bad), iv::InvalidArgument);
}

TEST_CASE("Dempster's rule combines simple support functions as worked by hand", "[update][belief]") {
  iv::BeliefParams p;  // hit 0.6 on {occ}, miss 0.4 on {free}
  p.discount = 0.0;
  const iv::DempsterShaferUpdate<iv::MeanState> u(p);
  CHECK(u.interval(u.unobserved()) == iv::Interval{0.0, 1.0});

  // One hit: m = (0.6, 0, 0.4): [Bel, Pl] = [0.6, 1].
  const auto h = apply(u, {kHit});
  CHECK(h.occ == Approx(0.6));
  CHECK(h.free == Approx(0.0).margin(1e-12));
  CHECK(u.interval(h).upper == Approx(1.0));
  // Two hits: occ = 1 - 0.4^2 = 0.84.
  CHECK(apply(u, {kHit, kHit}).occ == Approx(0.84));
  // Hit then miss: K = 0.6 * 0.4 = 0.24; occ = 0.36 / 0.76, free = 0.16 / 0.76, Θ = 0.24 / 0.76.
  const auto hm = apply(u, {kHit, kMiss});
  CHECK(hm.occ == Approx(0.36 / 0.76));
  CHECK(hm.free == Approx(0.16 / 0.76));
  CHECK(u.interval(hm).lower == Approx(0.36 / 0.76));
  CHECK(u.interval(hm).upper == Approx(1.0 - 0.16 / 0.76));
  CHECK(u.conflict(hm) == 0.0);  // Dempster's rule keeps no conflict mass
  // Order does not matter (Dempster's rule is commutative).
  const auto mh = apply(u, {kMiss, kHit});
  CHECK(mh.occ == Approx(hm.occ));
  CHECK(mh.free == Approx(hm.free));

  // The conjunctive rule: the same masses, and the conflict 1 - (1 - 0.24) = 0.24; a further hit
  // adds K2 = free * 0.6 = (0.16 / 0.76) * 0.6 to it: m(∅) = 0.24 + 0.76 * K2 = 0.24 + 0.096.
  p.combination = iv::BeliefCombination::Conjunctive;
  const iv::DempsterShaferUpdate<iv::MeanState> conj(p);
  const auto chm = apply(conj, {kHit, kMiss});
  CHECK(chm.occ == Approx(hm.occ));
  CHECK(conj.conflict(chm) == Approx(0.24));
  CHECK(conj.conflict(apply(conj, {kHit, kMiss, kHit})) == Approx(0.24 + 0.76 * (0.16 / 0.76) * 0.6));

  // Discounting keeps ignorance of at least α: after many hits occ reaches the fixed point of
  // o = (1 - α)(0.6 + 0.4 o), o* = 0.6 (1 - α) / (1 - 0.4 (1 - α)) = 0.98344 for α = 0.01, not 1.
  iv::BeliefParams d;
  d.discount = 0.01;
  const iv::DempsterShaferUpdate<iv::MeanState> disc(d);
  auto c = disc.unobserved();
  for (int i = 0; i < 100; ++i) disc.update(c, kHit);
  CHECK(c.occ == Approx(0.6 * 0.99 / (1 - 0.4 * 0.99)).epsilon(1e-5));
  disc.update(c, kMiss);  // still revisable
  CHECK(c.free > 0.0f);

  CHECK_THROWS_AS(iv::DempsterShaferUpdate<>(iv::BeliefParams{1.0}), iv::InvalidArgument);
  iv::BeliefParams bad;
  bad.discount = 0.5;
  CHECK_THROWS_AS(iv::DempsterShaferUpdate<>(bad), iv::InvalidArgument);
}

TEMPLATE_TEST_CASE("credal cells stay valid over a million seeded updates", "[update][credal][property]",
                   iv::ImpreciseDirichletUpdate<iv::MeanState>, iv::DempsterShaferUpdate<iv::MeanState>) {
  for (const double hit_rate : {0.5, 0.9, 0.02}) {
    CAPTURE(hit_rate);
    TestType u;
    if constexpr (std::is_same_v<TestType, iv::DempsterShaferUpdate<iv::MeanState>>) {
      iv::BeliefParams p;
      p.combination = iv::BeliefCombination::Conjunctive;
      u = TestType(p);
    }
    std::mt19937_64 rng(42);
    std::bernoulli_distribution hit(hit_rate);
    auto c = u.unobserved();
    double last_width = 1.0, last_conflict = 0.0;
    bool ok = true;
    for (int i = 0; i < 1000000 && ok; ++i) {
      u.update(c, hit(rng) ? kHit : kMiss);
      const iv::Interval in = u.interval(c);
      ok = 0.0 <= in.lower && in.lower <= in.upper && in.upper <= 1.0 && std::isfinite(u.state(c));
      if constexpr (std::is_same_v<TestType, iv::ImpreciseDirichletUpdate<iv::MeanState>>) {
        ok = ok && in.width() <= last_width + 1e-15;  // non-increasing without forgetting
        last_width = in.width();
      } else {
        const double t = 1.0 - double(c.occ) - double(c.free);
        ok = ok && c.occ >= 0 && c.free >= 0 && t >= u.params().discount - 1e-6 && t <= 1.0 + 1e-7;
        ok = ok && u.conflict(c) >= last_conflict && u.conflict(c) <= 1.0;
        last_conflict = u.conflict(c);
      }
      if (!ok) FAIL_CHECK("invalid cell after update " << i << ": [" << in.lower << ", " << in.upper << "]");
    }
    CHECK(ok);
  }
}

TEST_CASE("Dirichlet counts with forgetting follow the halving rule over a million seeded updates",
          "[update][dirichlet][property]") {
  for (const std::uint32_t max_count : {2u, 7u, 100u, 65535u}) {
    for (const double hit_rate : {0.5, 0.97}) {
      CAPTURE(max_count, hit_rate);
      iv::DirichletParams p;
      p.forgetting = iv::DirichletForgetting::HalveAtMax;
      p.max_count = max_count;
      const iv::ImpreciseDirichletUpdate<iv::MeanState> u(p);
      std::mt19937_64 rng(7);
      std::bernoulli_distribution hit(hit_rate);
      auto c = u.unobserved();
      std::uint64_t h = 0, m = 0;  // the documented rule, in wide integers
      bool ok = true;
      for (int i = 0; i < 1000000 && ok; ++i) {
        const bool is_hit = hit(rng);
        u.update(c, is_hit ? kHit : kMiss);
        std::uint64_t& n = is_hit ? h : m;
        if (n >= max_count) {
          h = (h + 1) / 2;
          m = (m + 1) / 2;
        }
        ++n;
        const iv::Interval in = u.interval(c);
        const double total = double(h + m), s = p.prior_strength;
        ok = c.hits == h && c.misses == m && h <= max_count && m <= max_count && 0.0 <= in.lower &&
             in.lower <= in.upper && in.upper <= 1.0 && in.lower == double(h) / (total + s) &&
             in.upper == (double(h) + s) / (total + s);
        if (!ok)
          FAIL_CHECK("update " << i << ": cell (" << c.hits << ", " << c.misses << "), rule (" << h << ", " << m
                               << ")");
      }
      CHECK(ok);
    }
  }
}

TEST_CASE("total uncertainty is max-entropy plus the interval width", "[utility]") {
  const iv::TotalUncertainty tu;
  CHECK(tu.value(0.5, {0.0, 1.0}) == Approx(2.0));  // vacuous
  CHECK(tu.value(0.5, {0.5, 0.5}) == Approx(1.0));  // precise 0.5
  CHECK(tu.value(0.3, {0.2, 0.4}) == Approx(iv::binary_entropy(0.4) + 0.2));
  CHECK(tu.value(0.9, {0.9, 0.9}) == Approx(iv::Entropy{}.value(0.9, {0.9, 0.9})));  // Bayes: entropy
  CHECK(tu.value(1.0, {1.0, 1.0}) == 0.0);
}

TEMPLATE_TEST_CASE(
    "credal grids update, classify and count voxels through VoxelGrid", "[update][credal][grid]",
    (iv::VoxelGrid<iv::ImpreciseDirichletUpdate<iv::MeanState>, iv::TotalUncertainty, iv::SparseStorage>),
    (iv::VoxelGrid<iv::ImpreciseDirichletUpdate<iv::UpperState>, iv::MaxEntropy, iv::DenseStorage>),
    (iv::VoxelGrid<iv::DempsterShaferUpdate<iv::MeanState>, iv::TotalUncertainty, iv::SparseStorage>),
    (iv::VoxelGrid<iv::DempsterShaferUpdate<iv::LowerState>, iv::Entropy, iv::DenseStorage>)) {
  TestType g(0.1, iv::Bounds{{-1, -1, -1}, {1, 1, 1}});
  const iv::Point3 p(0.25, 0.25, 0.25);
  CHECK(g.utility(p) == Approx(typename TestType::UtilityType{}.value(g.probability(p), g.interval(p))));
  for (int i = 0; i < 8; ++i) REQUIRE(g.update(p, kHit));
  CHECK(g.occupancy(p) == iv::Occupancy::Occupied);
  CHECK(g.interval(p).width() < 0.3);
  CHECK(g.counts().occupied == 1);
}
