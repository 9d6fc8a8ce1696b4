#pragma once
/// \file
/// The Bayes update in log-odds form (thesis section 3.3.2, OctoMap).

#include <intervox/core/error.hpp>
#include <intervox/core/probability.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/update/concepts.hpp>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <limits>
#include <string>

namespace intervox {

/// Parameters of the Bayes log-odds update. Probabilities are of occupancy.
///
/// A hit adds log-odds(p_hit), a miss adds log-odds(p_miss) (thesis eq. 3.7 with the likelihood
/// quotients lq = p/(1-p)). The result is clamped to [clamp_min, clamp_max]. A voxel is occupied
/// at or above occupied_threshold, otherwise free at or below free_threshold, otherwise unknown.
/// With `latch` (thesis Table 3.1) a voxel crossing a threshold is set to exactly 0 or 1 and never
/// changes again (eq. 3.13, 3.14); the clamps are then not applied.
struct BayesParams {
  double p_hit = 0.75;               ///< Pr(occ) after one hit from 0.5: lq_hit = 3
  double p_miss = 0.25;              ///< Pr(occ) after one miss from 0.5: lq_miss = 1/3 (Fig. 4.1)
  double clamp_min = 0.01;           ///< lower clamping bound, < free_threshold
  double clamp_max = 0.99;           ///< upper clamping bound, > occupied_threshold
  double free_threshold = 0.05;      ///< free at or below (Table 3.1)
  double occupied_threshold = 0.95;  ///< occupied at or above (Table 3.1)
  double prior = 0.5;                ///< state of an unobserved voxel
  bool latch = false;                ///< Table 3.1 latching at 0 and 1

  /// OctoMap's defaults: p_hit 0.7, p_miss 0.4, clamping [0.1192, 0.971], occupied at or above
  /// 0.5 and free below it (no unknown band for observed voxels).
  static BayesParams octomap() noexcept { return {0.7, 0.4, 0.1192, 0.971, 0.5, 0.5, 0.5, false}; }
  /// The thesis: lq 3 and 1/3, free at or below 0.05, occupied at or above 0.95, latching.
  static BayesParams thesis() noexcept {
    BayesParams p;
    p.latch = true;
    return p;
  }
};

/// The Bayes log-odds update policy.
///
/// Cell: one `float` of log-odds, 4 bytes per voxel; a NaN bit pattern marks unobserved voxels,
/// +-inf are the latched states. Do not compile with -ffast-math / -ffinite-math-only.
///
/// Thread safety: immutable after construction; all members are const and may be called
/// concurrently (on distinct cells for update()).
class BayesLogOdds {
 public:
  using Cell = float;
  static constexpr std::string_view kName = "bayes";

  /// \throws InvalidArgument if the parameters are inconsistent (see validate()).
  explicit BayesLogOdds(const BayesParams& p = {}) : params_(validate(p)) {
    hit_ = log_odds_f(p.p_hit);
    miss_ = log_odds_f(p.p_miss);
    prior_ = log_odds_f(p.prior);
    free_ = log_odds_f(p.free_threshold);
    occupied_ = log_odds_f(p.occupied_threshold);
    if (p.latch) {
      min_ = -std::numeric_limits<float>::infinity();
      max_ = std::numeric_limits<float>::infinity();
    } else {
      min_ = log_odds_f(p.clamp_min);
      max_ = log_odds_f(p.clamp_max);
    }
  }

  /// OctoMap's parameters (BayesParams::octomap()).
  static BayesLogOdds octomap() { return BayesLogOdds(BayesParams::octomap()); }
  /// The thesis' parameters (BayesParams::thesis()).
  static BayesLogOdds thesis() { return BayesLogOdds(BayesParams::thesis()); }

  /// Checks \p p and returns it.
  /// \throws InvalidArgument naming the first violated rule: every value finite;
  /// 0 < p_miss < 0.5 < p_hit < 1; 0 < clamp_min < clamp_max < 1 (unless latching);
  /// 0 < free_threshold <= occupied_threshold < 1; thresholds reachable inside the clamps
  /// (clamp_min <= free_threshold, occupied_threshold <= clamp_max); prior inside the clamps.
  static const BayesParams& validate(const BayesParams& p) {
    const ParamCheck check("intervox::BayesParams");
    auto prob = [](double v) { return v > 0.0 && v < 1.0; };  // false for NaN
    check.in_range("p_hit", p.p_hit, 0.5, 1, RangeEnds::Open);
    check.in_range("p_miss", p.p_miss, 0, 0.5, RangeEnds::Open);
    if (!(prob(p.free_threshold) && prob(p.occupied_threshold) && p.free_threshold <= p.occupied_threshold))
      check.fail("thresholds must satisfy 0 < free_threshold <= occupied_threshold < 1");
    check.in_range("prior", p.prior, 0, 1, RangeEnds::Open);
    if (!p.latch) {
      if (!(prob(p.clamp_min) && prob(p.clamp_max) && p.clamp_min < p.clamp_max))
        check.fail("clamps must satisfy 0 < clamp_min < clamp_max < 1");
      if (log_odds_f(p.clamp_min) > log_odds_f(p.free_threshold))
        check.fail("free_threshold " + detail::param_text(p.free_threshold) + " is unreachable above clamp_min " +
                   detail::param_text(p.clamp_min));
      if (log_odds_f(p.clamp_max) < log_odds_f(p.occupied_threshold))
        check.fail("occupied_threshold " + detail::param_text(p.occupied_threshold) +
                   " is unreachable below clamp_max " + detail::param_text(p.clamp_max));
      if (p.prior < p.clamp_min || p.prior > p.clamp_max) check.fail("prior must lie inside the clamps");
    }
    return p;
  }

  const BayesParams& params() const noexcept { return params_; }

  static Cell unobserved() noexcept { return std::bit_cast<float>(kUnobservedBits); }
  static bool is_observed(Cell c) noexcept { return std::bit_cast<std::uint32_t>(c) != kUnobservedBits; }

  /// One Bayes step in log-odds: add, clamp, latch.
  void update(Cell& c, Observation o) const noexcept {
    float l = is_observed(c) ? c : prior_;
    l += (o == Observation::Hit) ? hit_ : miss_;
    l = std::min(std::max(l, min_), max_);
    if (params_.latch) {
      if (l >= occupied_)
        l = std::numeric_limits<float>::infinity();
      else if (l <= free_)
        l = -std::numeric_limits<float>::infinity();
    }
    c = l;
  }

  /// Log-odds of the cell (the prior's for an unobserved one).
  float log_odds(Cell c) const noexcept { return is_observed(c) ? c : prior_; }
  double state(Cell c) const noexcept { return probability(log_odds(c)); }
  Interval interval(Cell c) const noexcept {
    const double p = state(c);
    return {p, p};
  }
  Occupancy occupancy(Cell c) const noexcept {
    if (!is_observed(c)) return Occupancy::Unknown;
    if (c >= occupied_) return Occupancy::Occupied;
    if (c <= free_) return Occupancy::Free;
    return Occupancy::Unknown;
  }

  /// Log-odds added by a hit / a miss, and the clamps, as stored (float).
  float hit_log_odds() const noexcept { return hit_; }
  float miss_log_odds() const noexcept { return miss_; }
  float clamp_min_log_odds() const noexcept { return min_; }
  float clamp_max_log_odds() const noexcept { return max_; }

  friend bool operator==(const BayesLogOdds& a, const BayesLogOdds& b) noexcept {
    const auto& p = a.params_;
    const auto& q = b.params_;
    return p.p_hit == q.p_hit && p.p_miss == q.p_miss && p.clamp_min == q.clamp_min && p.clamp_max == q.clamp_max &&
           p.free_threshold == q.free_threshold && p.occupied_threshold == q.occupied_threshold && p.prior == q.prior &&
           p.latch == q.latch;
  }

 private:
  static constexpr std::uint32_t kUnobservedBits = 0x7FC0'1EE7u;  // a quiet NaN
  BayesParams params_;
  float hit_ = 0, miss_ = 0, prior_ = 0, free_ = 0, occupied_ = 0, min_ = 0, max_ = 0;
};

static_assert(UpdatePolicy<BayesLogOdds>);

}  // namespace intervox
