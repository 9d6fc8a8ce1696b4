#pragma once
/// \file
/// The interval update (thesis chapter 4): both bounds of a probability interval updated by the
/// Bayes rule, and the three state rules of the thesis.

#include <intervox/core/error.hpp>
#include <intervox/core/probability.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/update/concepts.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <limits>
#include <string>

namespace intervox {

/// A state rule turns a probability interval into the state (a single probability).
/// Requires `R::state(Interval) -> double` and `R::kName`.
/// \tparam R the candidate rule
template <class R>
concept StateRule = requires(const Interval& i) {
  { R::state(i) } -> std::same_as<double>;
  { R::kName } -> std::convertible_to<std::string_view>;
};

/// The lower bound as the state: optimistic, space counts as free early (thesis 4.1).
struct LowerState {
  static constexpr std::string_view kName = "lower";
  static double state(const Interval& i) noexcept { return i.lower; }
};
/// The mean of both bounds as the state (the thesis' main configuration).
struct MeanState {
  static constexpr std::string_view kName = "mean";
  static double state(const Interval& i) noexcept { return i.mid(); }
};
/// The upper bound as the state: pessimistic, space counts as occupied until shown free.
struct UpperState {
  static constexpr std::string_view kName = "upper";
  static double state(const Interval& i) noexcept { return i.upper; }
};
static_assert(StateRule<LowerState> && StateRule<MeanState> && StateRule<UpperState>);

/// Parameters of the interval update. Probabilities are of occupancy.
///
/// A hit adds log-odds(p_hit) to both bounds' log-odds, a miss adds log-odds(p_miss) (eq. 4.3);
/// each bound is then clamped to [clamp_min, clamp_max]. Clamping is what narrows the interval:
/// the log-odds width never grows, and shrinks whenever a bound saturates. With `latch`, a bound
/// reaching a clamp is set to exactly 0 or 1 and stays there (the thesis' 8-bit storage, section
/// 5.3.3); an interval may then widen to [0, 1] under conflicting data.
struct IntervalParams {
  double p_hit = 0.75;               ///< lq_hit = 3, as BayesParams
  double p_miss = 0.25;              ///< lq_miss = 1/3, as BayesParams
  double initial_lower = 0.05;       ///< lower bound of an unobserved voxel (thesis 5.3.3)
  double initial_upper = 0.95;       ///< upper bound of an unobserved voxel
  double clamp_min = 0.01;           ///< bounds never go below (not a threshold)
  double clamp_max = 0.99;           ///< bounds never go above
  double free_threshold = 0.05;      ///< state at or below: free
  double occupied_threshold = 0.95;  ///< state at or above: occupied
  bool latch = false;                ///< bounds stick at 0 / 1 once they reach a clamp
  /// How a never-observed voxel is classified. false (default): always Unknown. true: by the state
  /// rule on the initial interval [initial_lower, initial_upper], as the thesis does (4.1, 5.3.4):
  /// with the defaults the lower rule calls never-observed space free (0.05), the upper rule
  /// occupied (0.95), the mean rule still unknown (0.5). It changes what the planners see: a
  /// lower-rule map then has no unknown space to explore.
  bool classify_unobserved = false;

  /// The thesis' 8-bit behaviour: bounds latch at 0 and 1 once they come within half a
  /// quantisation step (1/510) of them.
  static IntervalParams thesis() noexcept {
    IntervalParams p;
    p.clamp_min = 1.0 / 510.0;
    p.clamp_max = 1.0 - 1.0 / 510.0;
    p.latch = true;
    return p;
  }
};

namespace detail {
/// The class of a never-observed voxel under \p p and state rule Rule (IntervalParams::classify_unobserved).
template <StateRule Rule>
Occupancy unobserved_interval_occupancy(const IntervalParams& p) noexcept {
  if (!p.classify_unobserved) return Occupancy::Unknown;
  return classify(Rule::state(Interval{p.initial_lower, p.initial_upper}), p.free_threshold, p.occupied_threshold);
}
}  // namespace detail

/// Log-odds of the two bounds; 8 bytes per voxel. A NaN bit pattern in `lower` marks an
/// unobserved voxel.
struct IntervalCell {
  float lower;
  float upper;
};

/// The interval update policy.
///
/// Invariant: 0 <= lower <= upper <= 1 after any sequence of updates (both bounds move by the
/// same log-odds and clamping is monotone).
///
/// \tparam Rule how the state is taken from the interval: LowerState, MeanState or UpperState.
///
/// Thread safety: immutable after construction; const members may be called concurrently.
template <StateRule Rule = MeanState>
class IntervalUpdate {
 public:
  using Cell = IntervalCell;
  using StateRuleType = Rule;
  static constexpr std::string_view kName = Rule::kName == "lower"   ? "interval-lower"
                                            : Rule::kName == "upper" ? "interval-upper"
                                                                     : "interval-mean";

  /// \throws InvalidArgument if the parameters are inconsistent (see validate()).
  explicit IntervalUpdate(const IntervalParams& p = {}) : params_(validate(p)) {
    hit_ = log_odds_f(p.p_hit);
    miss_ = log_odds_f(p.p_miss);
    min_ = log_odds_f(p.clamp_min);
    max_ = log_odds_f(p.clamp_max);
    prior_ = {log_odds_f(p.initial_lower), log_odds_f(p.initial_upper)};
  }

  /// The thesis' parameters (IntervalParams::thesis()).
  static IntervalUpdate thesis() { return IntervalUpdate(IntervalParams::thesis()); }

  /// Checks \p p and returns it.
  /// \throws InvalidArgument naming the violated rule: every value finite;
  /// 0 < p_miss < 0.5 < p_hit < 1; 0 < clamp_min < clamp_max < 1;
  /// clamp_min <= initial_lower <= initial_upper <= clamp_max;
  /// 0 < free_threshold <= occupied_threshold < 1; clamp_min <= free_threshold and
  /// occupied_threshold <= clamp_max (both reachable).
  static const IntervalParams& validate(const IntervalParams& p) {
    const ParamCheck check("intervox::IntervalParams");
    auto prob = [](double v) { return v > 0.0 && v < 1.0; };
    check.in_range("p_hit", p.p_hit, 0.5, 1, RangeEnds::Open);
    check.in_range("p_miss", p.p_miss, 0, 0.5, RangeEnds::Open);
    if (!(prob(p.clamp_min) && prob(p.clamp_max) && p.clamp_min < p.clamp_max))
      check.fail("clamps must satisfy 0 < clamp_min < clamp_max < 1");
    if (!(p.clamp_min <= p.initial_lower && p.initial_lower <= p.initial_upper && p.initial_upper <= p.clamp_max))
      check.fail("initial interval must satisfy clamp_min <= initial_lower <= initial_upper <= clamp_max");
    if (!(prob(p.free_threshold) && prob(p.occupied_threshold) && p.free_threshold <= p.occupied_threshold))
      check.fail("thresholds must satisfy 0 < free_threshold <= occupied_threshold < 1");
    if (p.free_threshold < p.clamp_min) check.fail("free_threshold is unreachable above clamp_min");
    if (p.occupied_threshold > p.clamp_max) check.fail("occupied_threshold is unreachable below clamp_max");
    return p;
  }

  const IntervalParams& params() const noexcept { return params_; }

  static Cell unobserved() noexcept {
    return {std::bit_cast<float>(kUnobservedBits), std::bit_cast<float>(kUnobservedBits)};
  }
  static bool is_observed(const Cell& c) noexcept { return std::bit_cast<std::uint32_t>(c.lower) != kUnobservedBits; }

  /// One step of eq. 4.3 on both bounds, then clamping (or latching).
  void update(Cell& c, Observation o) const noexcept {
    Cell v = is_observed(c) ? c : prior_;
    const float d = (o == Observation::Hit) ? hit_ : miss_;
    v.lower = bound(v.lower + d);
    v.upper = bound(v.upper + d);
    c = v;
  }

  /// The bounds' log-odds (the prior's for an unobserved voxel).
  Cell log_odds(const Cell& c) const noexcept { return is_observed(c) ? c : prior_; }
  Interval interval(const Cell& c) const noexcept {
    const Cell v = log_odds(c);
    return {probability(v.lower), probability(v.upper)};
  }
  double state(const Cell& c) const noexcept { return Rule::state(interval(c)); }
  /// The class of the state; a never-observed voxel is Unknown unless
  /// IntervalParams::classify_unobserved (then its rule on the exact initial interval decides).
  Occupancy occupancy(const Cell& c) const noexcept {
    if (!is_observed(c)) return detail::unobserved_interval_occupancy<Rule>(params_);
    return classify(state(c), params_.free_threshold, params_.occupied_threshold);
  }

  float hit_log_odds() const noexcept { return hit_; }
  float miss_log_odds() const noexcept { return miss_; }

  friend bool operator==(const IntervalUpdate& a, const IntervalUpdate& b) noexcept {
    const auto& p = a.params_;
    const auto& q = b.params_;
    return p.p_hit == q.p_hit && p.p_miss == q.p_miss && p.initial_lower == q.initial_lower &&
           p.initial_upper == q.initial_upper && p.clamp_min == q.clamp_min && p.clamp_max == q.clamp_max &&
           p.free_threshold == q.free_threshold && p.occupied_threshold == q.occupied_threshold && p.latch == q.latch &&
           p.classify_unobserved == q.classify_unobserved;
  }

 private:
  float bound(float l) const noexcept {
    if (params_.latch) {
      // -inf and +inf absorb every later addition: a latched bound never moves again.
      if (l <= min_) return -std::numeric_limits<float>::infinity();
      if (l >= max_) return std::numeric_limits<float>::infinity();
      return l;
    }
    return std::min(std::max(l, min_), max_);
  }

  static constexpr std::uint32_t kUnobservedBits = 0x7FC0'1EE7u;
  IntervalParams params_;
  float hit_ = 0, miss_ = 0, min_ = 0, max_ = 0;
  Cell prior_{0, 0};
};

static_assert(UpdatePolicy<IntervalUpdate<LowerState>>);
static_assert(UpdatePolicy<IntervalUpdate<MeanState>>);
static_assert(UpdatePolicy<IntervalUpdate<UpperState>>);

/// Both bounds' log-odds as 16-bit fixed point (CompactIntervalUpdate::kScale steps per unit);
/// 4 bytes per voxel. kUnobserved in `lower` marks an unobserved voxel; kLatchedLow / kLatchedHigh
/// are a bound latched at probability 0 / 1.
struct CompactIntervalCell {
  std::int16_t lower;
  std::int16_t upper;
};

/// The interval update of IntervalUpdate in half the memory: each bound's log-odds is stored as
/// a 16-bit integer in steps of 1/2048 (range +-15.99, probabilities 1.1e-7 ... 1 - 1.1e-7), so
/// a voxel takes 4 bytes, as a BayesLogOdds one. The likelihoods and clamps are rounded to that
/// step once, at construction; the updates themselves are exact integer additions, so the
/// result never drifts: after any sequence of updates each bound differs from IntervalUpdate's
/// by at most the rounding of the hit and miss steps times the number of updates since the bound
/// last touched a clamp (in practice a few 1/2048 steps), and both policies clamp and latch
/// alike (IntervalParams, including thesis()).
///
/// Invariant: 0 <= lower <= upper <= 1 after any sequence of updates.
///
/// \tparam Rule how the state is taken from the interval: LowerState, MeanState or UpperState.
///
/// Thread safety: immutable after construction; const members may be called concurrently.
template <StateRule Rule = MeanState>
class CompactIntervalUpdate {
 public:
  using Cell = CompactIntervalCell;
  using StateRuleType = Rule;
  static constexpr std::string_view kName = Rule::kName == "lower"   ? "compact-interval-lower"
                                            : Rule::kName == "upper" ? "compact-interval-upper"
                                                                     : "compact-interval-mean";
  /// Fixed-point steps per log-odds unit.
  static constexpr double kScale = 2048.0;
  static constexpr std::int16_t kUnobserved = -32768;
  static constexpr std::int16_t kLatchedLow = -32767;  ///< probability 0
  static constexpr std::int16_t kLatchedHigh = 32767;  ///< probability 1

  /// \throws InvalidArgument if the parameters are inconsistent (IntervalUpdate::validate()) or
  ///         a clamp or the initial interval lies beyond the 16-bit range (log-odds magnitude
  ///         at most 15.99, i.e. clamp_min >= 1.2e-7 and clamp_max <= 1 - 1.2e-7).
  explicit CompactIntervalUpdate(const IntervalParams& p = {}) : params_(validate(p)) {
    hit_ = fixed(p.p_hit);
    miss_ = fixed(p.p_miss);
    min_ = fixed(p.clamp_min);
    max_ = fixed(p.clamp_max);
    prior_ = {static_cast<std::int16_t>(fixed(p.initial_lower)), static_cast<std::int16_t>(fixed(p.initial_upper))};
  }

  /// The thesis' parameters (IntervalParams::thesis()).
  static CompactIntervalUpdate thesis() { return CompactIntervalUpdate(IntervalParams::thesis()); }

  /// Checks \p p and returns it (the rules of IntervalUpdate::validate(), plus the 16-bit range).
  static const IntervalParams& validate(const IntervalParams& p) {
    IntervalUpdate<Rule>::validate(p);
    for (const double v : {p.clamp_min, p.clamp_max}) {
      if (!(std::abs(log_odds(v)) * kScale < 32766.0))
        ParamCheck("intervox::CompactIntervalUpdate")
            .fail("clamp " + std::to_string(v) + " lies beyond the 16-bit log-odds range (|log-odds| < 15.99)");
    }
    return p;
  }

  const IntervalParams& params() const noexcept { return params_; }

  static Cell unobserved() noexcept { return {kUnobserved, kUnobserved}; }
  static bool is_observed(const Cell& c) noexcept { return c.lower != kUnobserved; }

  /// One step of eq. 4.3 on both bounds, then clamping (or latching).
  void update(Cell& c, Observation o) const noexcept {
    const Cell v = is_observed(c) ? c : prior_;
    const std::int32_t d = (o == Observation::Hit) ? hit_ : miss_;
    c = {bound(v.lower, d), bound(v.upper, d)};
  }

  /// The bounds' fixed-point log-odds (the prior's for an unobserved voxel).
  Cell log_odds_fixed(const Cell& c) const noexcept { return is_observed(c) ? c : prior_; }
  Interval interval(const Cell& c) const noexcept {
    const Cell v = log_odds_fixed(c);
    return {to_probability(v.lower), to_probability(v.upper)};
  }
  double state(const Cell& c) const noexcept { return Rule::state(interval(c)); }
  /// The class of the state; a never-observed voxel is Unknown unless
  /// IntervalParams::classify_unobserved (then its rule on the exact initial interval decides).
  Occupancy occupancy(const Cell& c) const noexcept {
    if (!is_observed(c)) return detail::unobserved_interval_occupancy<Rule>(params_);
    return classify(state(c), params_.free_threshold, params_.occupied_threshold);
  }

  /// The hit and miss steps in fixed point (log-odds times kScale, rounded).
  std::int32_t hit_step() const noexcept { return hit_; }
  std::int32_t miss_step() const noexcept { return miss_; }

  /// The probability of a stored bound.
  static double to_probability(std::int16_t v) noexcept {
    if (v <= kLatchedLow) return 0.0;
    if (v >= kLatchedHigh) return 1.0;
    return probability(double(v) / kScale);
  }

  friend bool operator==(const CompactIntervalUpdate& a, const CompactIntervalUpdate& b) noexcept {
    return IntervalUpdate<Rule>(a.params_) == IntervalUpdate<Rule>(b.params_);
  }

 private:
  static std::int32_t fixed(double p) noexcept { return static_cast<std::int32_t>(std::lround(log_odds(p) * kScale)); }

  std::int16_t bound(std::int16_t x, std::int32_t d) const noexcept {
    if (params_.latch) {
      // A latched bound never moves again (as +-inf in IntervalUpdate).
      if (x == kLatchedLow || x == kLatchedHigh) return x;
      const std::int32_t l = x + d;
      if (l <= min_) return kLatchedLow;
      if (l >= max_) return kLatchedHigh;
      return static_cast<std::int16_t>(l);
    }
    return static_cast<std::int16_t>(std::clamp<std::int32_t>(x + d, min_, max_));
  }

  IntervalParams params_;
  std::int32_t hit_ = 0, miss_ = 0, min_ = 0, max_ = 0;
  Cell prior_{0, 0};
};

static_assert(UpdatePolicy<CompactIntervalUpdate<LowerState>>);
static_assert(UpdatePolicy<CompactIntervalUpdate<MeanState>>);
static_assert(UpdatePolicy<CompactIntervalUpdate<UpperState>>);
static_assert(sizeof(CompactIntervalCell) == 4);

}  // namespace intervox
