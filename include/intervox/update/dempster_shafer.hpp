#pragma once
/// \file
/// Dempster–Shafer belief as an update policy: masses on {occupied}, {free} and {occupied, free}
/// (ignorance), each measurement a simple support function, combined by Dempster's rule or by
/// the conjunctive rule that keeps the conflict mass. The interval is [Bel(occ), Pl(occ)].

#include <intervox/core/error.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/update/concepts.hpp>
#include <intervox/update/interval_update.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <string>

namespace intervox {

/// How a Dempster–Shafer cell combines a measurement with its masses.
enum class BeliefCombination : std::uint8_t {
  /// Dempster's rule: the conflicting product mass K is removed and the rest renormalised.
  Dempster = 0,
  /// The conjunctive rule (Smets' unnormalised combination): the masses on {occ}, {free} and
  /// ignorance evolve as under Dempster's rule, and the mass of the empty set, the accumulated
  /// conflict 1 − Π(1 − K_i), is kept in the cell (DempsterShaferUpdate::conflict()).
  Conjunctive = 1,
};

/// Parameters of the Dempster–Shafer update.
///
/// A hit is the simple support function m({occ}) = hit_support, m(Θ) = 1 − hit_support; a miss
/// m({free}) = miss_support, m(Θ) = 1 − miss_support. Combining masses (o, f, t) with a
/// measurement (o2, f2, t2) by Dempster's rule: K = o f2 + f o2,
/// o' = (o o2 + o t2 + t o2) / (1 − K), f' = (f f2 + f t2 + t f2) / (1 − K), t' = t t2 / (1 − K).
/// After each step the masses are discounted by `discount` α (Shafer's discounting):
/// o'' = (1 − α) o', f'' = (1 − α) f', t'' = 1 − o'' − f'' >= α, so that no voxel becomes
/// certain beyond revision (a mass of 1 on {occ} would absorb every later miss) and the masses
/// stay normalised in floating point over any number of updates.
struct BeliefParams {
  double hit_support = 0.6;         ///< mass a hit puts on {occupied}, in (0, 1)
  double miss_support = 0.4;        ///< mass a miss puts on {free}, in (0, 1)
  double discount = 0.001;          ///< α in [0, 0.5): minimum ignorance kept after each step
  double free_threshold = 0.2;      ///< state at or below: free
  double occupied_threshold = 0.8;  ///< state at or above: occupied
  BeliefCombination combination = BeliefCombination::Dempster;
};

/// Masses of {occupied} and {free} (ignorance is 1 − occ − free) and, for the conjunctive rule,
/// the accumulated conflict mass; 12 bytes per voxel. A NaN bit pattern in `occ` marks an
/// unobserved voxel.
struct BeliefCell {
  float occ;
  float free;
  float conflict;
};

/// The Dempster–Shafer update policy.
///
/// Invariants: occ, free >= 0; occ + free <= 1 − discount; Bel(occ) = occ <= Pl(occ) = 1 − free;
/// 0 <= conflict <= 1 and non-decreasing (conjunctive rule; 0 under Dempster's rule).
///
/// \tparam Rule how the state is taken from [Bel, Pl]: LowerState, MeanState or UpperState.
///
/// Thread safety: immutable after construction; const members may be called concurrently.
template <StateRule Rule = MeanState>
class DempsterShaferUpdate {
 public:
  using Cell = BeliefCell;
  using StateRuleType = Rule;
  static constexpr std::string_view kName = Rule::kName == "lower"   ? "belief-lower"
                                            : Rule::kName == "upper" ? "belief-upper"
                                                                     : "belief-mean";

  /// \throws InvalidArgument if the parameters are inconsistent (see validate()).
  explicit DempsterShaferUpdate(const BeliefParams& p = {}) : params_(validate(p)) {}

  /// Checks \p p and returns it.
  /// \throws InvalidArgument naming the violated rule: supports in (0, 1); discount in [0, 0.5);
  /// 0 < free_threshold <= occupied_threshold < 1; a known combination rule.
  static const BeliefParams& validate(const BeliefParams& p) {
    const ParamCheck check("intervox::BeliefParams");
    check.in_range("hit_support", p.hit_support, 0, 1, RangeEnds::Open);
    check.in_range("miss_support", p.miss_support, 0, 1, RangeEnds::Open);
    check.in_range("discount", p.discount, 0, 0.5, RangeEnds::ClosedOpen);
    if (!(p.free_threshold > 0 && p.occupied_threshold < 1 && p.free_threshold <= p.occupied_threshold))
      check.fail("thresholds must satisfy 0 < free_threshold <= occupied_threshold < 1");
    if (static_cast<int>(p.combination) > 1) check.fail("unknown combination rule");
    return p;
  }

  const BeliefParams& params() const noexcept { return params_; }

  static Cell unobserved() noexcept { return {std::bit_cast<float>(kUnobservedBits), 0.0f, 0.0f}; }
  static bool is_observed(const Cell& c) noexcept { return std::bit_cast<std::uint32_t>(c.occ) != kUnobservedBits; }

  /// Combines one measurement (see BeliefParams), computed in double precision.
  void update(Cell& c, Observation o) const noexcept {
    double m_o = 0, m_f = 0, k_acc = 0;  // the vacuous prior for an unobserved voxel
    if (is_observed(c)) {
      m_o = c.occ;
      m_f = c.free;
      k_acc = c.conflict;
    }
    const double m_t = std::max(0.0, 1.0 - m_o - m_f);
    const bool hit = o == Observation::Hit;
    const double o2 = hit ? params_.hit_support : 0.0, f2 = hit ? 0.0 : params_.miss_support;
    const double t2 = 1.0 - o2 - f2;
    const double k = m_o * f2 + m_f * o2;  // < 1: a measurement never has full mass on one side
    const double norm = 1.0 / (1.0 - k);
    double no = (m_o * o2 + m_o * t2 + m_t * o2) * norm, nf = (m_f * f2 + m_f * t2 + m_t * f2) * norm;
    const double keep = 1.0 - params_.discount;
    no = std::clamp(no * keep, 0.0, 1.0);
    nf = std::clamp(nf * keep, 0.0, 1.0 - no);
    c.occ = static_cast<float>(no);
    c.free = static_cast<float>(nf);
    c.conflict = params_.combination == BeliefCombination::Conjunctive
                     ? static_cast<float>(std::min(1.0, k_acc + (1.0 - k_acc) * k))
                     : 0.0f;
  }

  /// [Bel(occ), Pl(occ)] = [occ, 1 − free]; [0, 1] for an unobserved voxel.
  Interval interval(const Cell& c) const noexcept {
    if (!is_observed(c)) return {0.0, 1.0};
    return {double(c.occ), 1.0 - double(c.free)};
  }
  double state(const Cell& c) const noexcept { return Rule::state(interval(c)); }
  Occupancy occupancy(const Cell& c) const noexcept {
    if (!is_observed(c)) return Occupancy::Unknown;
    return classify(state(c), params_.free_threshold, params_.occupied_threshold);
  }
  /// The accumulated conflict mass m(∅) of the conjunctive rule (0 for Dempster's rule and for
  /// an unobserved voxel): itself a conflict measure, near 1 for a voxel seen both ways often.
  static double conflict(const Cell& c) noexcept { return is_observed(c) ? double(c.conflict) : 0.0; }

  friend bool operator==(const DempsterShaferUpdate& a, const DempsterShaferUpdate& b) noexcept {
    const auto &p = a.params_, &q = b.params_;
    return p.hit_support == q.hit_support && p.miss_support == q.miss_support && p.discount == q.discount &&
           p.free_threshold == q.free_threshold && p.occupied_threshold == q.occupied_threshold &&
           p.combination == q.combination;
  }

 private:
  static constexpr std::uint32_t kUnobservedBits = 0x7FC0'DE55u;
  BeliefParams params_;
};

static_assert(UpdatePolicy<DempsterShaferUpdate<LowerState>>);
static_assert(UpdatePolicy<DempsterShaferUpdate<MeanState>>);
static_assert(UpdatePolicy<DempsterShaferUpdate<UpperState>>);
static_assert(sizeof(BeliefCell) == 12);

}  // namespace intervox
