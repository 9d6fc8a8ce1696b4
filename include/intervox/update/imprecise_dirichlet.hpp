#pragma once
/// \file
/// The imprecise Dirichlet model (Walley 1996) as an update policy: a cell counts hits and misses,
/// and its interval [h / (N + s), (h + s) / (N + s)] narrows with the amount of evidence whatever
/// the evidence says, so a narrow interval around 0.5 is an unambiguous conflict.

#include <intervox/core/error.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/update/concepts.hpp>
#include <intervox/update/interval_update.hpp>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

namespace intervox {

/// What an imprecise Dirichlet cell does when a counter would overflow.
enum class DirichletForgetting : std::uint8_t {
  /// The full counter stays at max_count and stops counting (the other one still counts): no
  /// evidence is forgotten, the width s / (N + s) never grows.
  Saturate = 0,
  /// Both counters are halved (rounded up) before the step: old evidence loses half its weight,
  /// so a voxel that changes (a door opened) follows within about max_count observations. The
  /// width may grow at that moment.
  HalveAtMax = 1,
};

/// Parameters of the imprecise Dirichlet model. Probabilities are of occupancy.
///
/// With h hits and m misses (N = h + m) and prior strength s the interval is
/// [h / (N + s), (h + s) / (N + s)]; an unobserved voxel has N = 0 and the vacuous interval [0, 1].
/// Each measurement adds one count: there is no sensor likelihood. The state is taken from the
/// interval by the StateRule, then classified by the thresholds.
struct DirichletParams {
  double prior_strength = 2.0;       ///< s > 0: the width after N observations is s / (N + s)
  double free_threshold = 0.15;      ///< state at or below: free (mean rule, s = 2: 5 misses, 1/7)
  double occupied_threshold = 0.85;  ///< state at or above: occupied (mean rule, s = 2: 5 hits, 6/7)
  DirichletForgetting forgetting = DirichletForgetting::Saturate;
  std::uint32_t max_count = 65535;  ///< counter limit, in [2, 65535]
};

/// Hit and miss counters, 16 bits each: 4 bytes per voxel. {0, 0} is an unobserved voxel.
struct DirichletCell {
  std::uint16_t hits;
  std::uint16_t misses;
};

/// The imprecise Dirichlet update policy.
///
/// Invariants: 0 <= lower <= upper <= 1; width = s / (N + s), non-increasing under
/// DirichletForgetting::Saturate.
///
/// \tparam Rule how the state is taken from the interval: LowerState, MeanState or UpperState.
///
/// Thread safety: immutable after construction; const members may be called concurrently.
template <StateRule Rule = MeanState>
class ImpreciseDirichletUpdate {
 public:
  using Cell = DirichletCell;
  using StateRuleType = Rule;
  static constexpr std::string_view kName = Rule::kName == "lower"   ? "dirichlet-lower"
                                            : Rule::kName == "upper" ? "dirichlet-upper"
                                                                     : "dirichlet-mean";

  /// \throws InvalidArgument if the parameters are inconsistent (see validate()).
  explicit ImpreciseDirichletUpdate(const DirichletParams& p = {}) : params_(validate(p)) {}

  /// Checks \p p and returns it.
  /// \throws InvalidArgument naming the violated rule: prior_strength finite and > 0;
  /// 0 < free_threshold <= occupied_threshold < 1; max_count in [2, 65535]; a known forgetting mode.
  static const DirichletParams& validate(const DirichletParams& p) {
    const ParamCheck check("intervox::DirichletParams");
    check.positive("prior_strength", p.prior_strength);
    if (!(p.free_threshold > 0 && p.occupied_threshold < 1 && p.free_threshold <= p.occupied_threshold))
      check.fail("thresholds must satisfy 0 < free_threshold <= occupied_threshold < 1");
    check.in_range("max_count", p.max_count, 2, 65535);
    if (static_cast<int>(p.forgetting) > 1) check.fail("unknown forgetting mode");
    return p;
  }

  const DirichletParams& params() const noexcept { return params_; }

  static Cell unobserved() noexcept { return {0, 0}; }
  static bool is_observed(const Cell& c) noexcept { return c.hits != 0 || c.misses != 0; }

  /// Adds one hit or miss (see DirichletForgetting for a full counter).
  void update(Cell& c, Observation o) const noexcept {
    std::uint32_t h = c.hits, m = c.misses;
    std::uint32_t& n = (o == Observation::Hit) ? h : m;
    if (n >= params_.max_count) {
      if (params_.forgetting == DirichletForgetting::Saturate) return;
      h = (h + 1) / 2;
      m = (m + 1) / 2;
    }
    ++n;
    c = {static_cast<std::uint16_t>(h), static_cast<std::uint16_t>(m)};
  }

  Interval interval(const Cell& c) const noexcept {
    const double s = params_.prior_strength, n = double(c.hits) + double(c.misses);
    return {double(c.hits) / (n + s), (double(c.hits) + s) / (n + s)};
  }
  double state(const Cell& c) const noexcept { return Rule::state(interval(c)); }
  Occupancy occupancy(const Cell& c) const noexcept {
    if (!is_observed(c)) return Occupancy::Unknown;
    return classify(state(c), params_.free_threshold, params_.occupied_threshold);
  }
  /// Observations counted in the cell, N = hits + misses.
  static std::uint32_t evidence(const Cell& c) noexcept { return std::uint32_t(c.hits) + c.misses; }

  friend bool operator==(const ImpreciseDirichletUpdate& a, const ImpreciseDirichletUpdate& b) noexcept {
    const auto &p = a.params_, &q = b.params_;
    return p.prior_strength == q.prior_strength && p.free_threshold == q.free_threshold &&
           p.occupied_threshold == q.occupied_threshold && p.forgetting == q.forgetting && p.max_count == q.max_count;
  }

 private:
  DirichletParams params_;
};

static_assert(UpdatePolicy<ImpreciseDirichletUpdate<LowerState>>);
static_assert(UpdatePolicy<ImpreciseDirichletUpdate<MeanState>>);
static_assert(UpdatePolicy<ImpreciseDirichletUpdate<UpperState>>);
static_assert(sizeof(DirichletCell) == 4);

}  // namespace intervox
