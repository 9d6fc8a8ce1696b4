#pragma once
/// \file
/// Explained free space, part 1: what one voxel knows. Every beam of a scan is classed against
/// the map as it stands (explain/explained_space.hpp): *trusted* (its return is explained by the
/// map), *suspect* (it passed through a surface the map supports, returned or not, or returned
/// from mid-air where trusted beams saw free space) or *no return*. A voxel keeps, beside the update
/// policy's own cell, how many scans gave it a hit or a miss in each class (EvidenceCell). The
/// classes are combined as a belief function (Dempster–Shafer):
///
///  - within a class, each scan's miss is a simple support function for {free} of mass
///    `miss_mass` and each hit one for {occupied} of mass `hit_mass`, so n misses support {free}
///    with 1 - (1 - miss_mass)^n;
///  - each class as a whole is then discounted by its reliability r (Shafer discounting: the
///    class's masses are multiplied by r, the rest goes to the whole frame). Discounting the class
///    and not each beam is deliberate: the beams of a mirror lie consistently, so a thousand
///    suspect misses are worth no more than the suspect source's reliability;
///  - the classes' support functions are combined by Dempster's rule. The result depends on the
///    counts only, so it is commutative and associative, and moving a beam's evidence from one
///    class to another is exact.
///
/// The lower probability of *free* is Bel(free): free on explained evidence. The upper one is
/// Pl(free) = 1 - Bel(occupied): free unless some evidence says occupied. With suspect misses
/// only, the interval is [<= suspect reliability, 1]: wide exactly where lying beams carved space.
///
/// Why the thesis' interval cannot carry this: under its update both bounds move by the same
/// log-odds step, l_lower <- l_lower + d and l_upper <- l_upper + d, so the log-odds width
/// l_upper - l_lower never changes; n hits and n misses give back the prior interval, and a voxel
/// of conflicting evidence is indistinguishable from one never seen (docs/concepts.md,
/// "Explained free space").
///
/// Thread safety: plain value types and pure functions.

#include <intervox/core/error.hpp>
#include <intervox/core/interval.hpp>
#include <intervox/core/validate.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>

namespace intervox {

/// How a beam is explained by the map as it stood when the beam was inserted.
enum class BeamClass : std::uint8_t {
  Trusted = 0,   ///< returned, and the map explains it
  Suspect = 1,   ///< crosses a supported surface (returned or not), or returned in explained-free space
  NoReturn = 2,  ///< nothing came back, and no supported surface lies within its range: never evidence that space is
                 ///< free enough to drive
  Skipped = 3,   ///< not inserted (invalid, too short, outside the key range, ...: InsertStats)
};

/// Name of a beam class ("trusted", "suspect", "no-return", "skipped").
constexpr std::string_view to_string(BeamClass c) noexcept {
  switch (c) {
    case BeamClass::Suspect:
      return "suspect";
    case BeamClass::NoReturn:
      return "no-return";
    case BeamClass::Skipped:
      return "skipped";
    case BeamClass::Trusted:
      break;
  }
  return "trusted";
}

/// What one voxel knows: per beam class, the scans that gave it a hit or a miss (at most one of
/// each per class and scan; within a class a hit wins over a miss, as in the insertion). Counts
/// saturate at 65535. 10 bytes.
struct EvidenceCell {
  std::uint16_t trusted_hits = 0;
  std::uint16_t trusted_misses = 0;
  std::uint16_t suspect_hits = 0;
  std::uint16_t suspect_misses = 0;
  std::uint16_t no_return_misses = 0;

  /// True if any evidence reached the voxel.
  constexpr bool any() const noexcept {
    return (trusted_hits | trusted_misses | suspect_hits | suspect_misses | no_return_misses) != 0;
  }
  /// True if trusted evidence reached the voxel.
  constexpr bool any_trusted() const noexcept { return (trusted_hits | trusted_misses) != 0; }
  friend constexpr bool operator==(const EvidenceCell&, const EvidenceCell&) = default;
};

/// Adds one to a saturating count.
constexpr void saturating_increment(std::uint16_t& c) noexcept {
  if (c != std::numeric_limits<std::uint16_t>::max()) ++c;
}

/// The explained state of a voxel (ExplainedSpace::state()).
enum class ExplainedState : std::uint8_t {
  Unknown = 0,      ///< no evidence at all
  Free = 1,         ///< free on explained evidence: Bel(free) >= free_threshold
  Occupied = 2,     ///< occupied on explained evidence: Bel(occupied) >= occupied_threshold
  Unexplained = 3,  ///< evidence, but neither: free only if suspect or no-return beams told the truth, or conflict
};

/// Name of an explained state ("unknown", "free", "occupied", "unexplained").
constexpr std::string_view to_string(ExplainedState s) noexcept {
  switch (s) {
    case ExplainedState::Free:
      return "free";
    case ExplainedState::Occupied:
      return "occupied";
    case ExplainedState::Unexplained:
      return "unexplained";
    case ExplainedState::Unknown:
      break;
  }
  return "unknown";
}

/// The combined belief of a voxel (EvidenceModel::combine()).
struct ExplainedBelief {
  double free = 0.0;      ///< Bel(free): the mass committed to {free}
  double occupied = 0.0;  ///< Bel(occupied): the mass committed to {occupied}
  double conflict = 0.0;  ///< Dempster's conflict K between the free and the occupied support, in [0, 1]

  /// The lower probability of free: free on explained evidence.
  constexpr double lower_free() const noexcept { return free; }
  /// The upper probability of free (plausibility): 1 - Bel(occupied).
  constexpr double upper_free() const noexcept { return 1.0 - occupied; }
  /// The same interval as probabilities of occupancy, [Bel(occupied), Pl(occupied)], the
  /// convention of Interval and VoxelGrid::interval().
  constexpr Interval occupancy() const noexcept { return {occupied, 1.0 - free}; }
};

/// The masses, reliabilities and thresholds of the belief combination (see the file comment).
/// Defaults: a hit supports {occupied} with 0.7, a miss {free} with 0.4; one trusted miss (0.4 >=
/// 0.35) makes a voxel explained free and one trusted hit (0.7 >= 0.5) explained occupied, as one
/// miss or hit decides a voxel of OctoMap's Bayes update; suspect evidence is 10 % reliable, so no
/// amount of it alone reaches either threshold; no-return evidence is not reliable at all (0);
/// trusted evidence fully (1).
struct EvidenceModel {
  double hit_mass = 0.7;               ///< support of one hit for {occupied}, in (0, 1)
  double miss_mass = 0.4;              ///< support of one miss for {free}, in (0, 1)
  double trusted_reliability = 1.0;    ///< discount factor of the trusted class, in [0, 1]
  double suspect_reliability = 0.1;    ///< discount factor of the suspect class, in [0, 1]
  double no_return_reliability = 0.0;  ///< discount factor of the no-return class, in [0, 1]
  double free_threshold = 0.35;        ///< Bel(free) from which a voxel is explained free, in (0, 1]
  double occupied_threshold = 0.5;     ///< Bel(occupied) from which a voxel is explained occupied, in (0, 1]

  /// \throws InvalidArgument naming the first parameter outside its range (NaN included).
  void validate() const {
    const ParamCheck check("intervox::EvidenceModel");
    check.in_range("hit_mass", hit_mass, 0, 1, RangeEnds::Open);
    check.in_range("miss_mass", miss_mass, 0, 1, RangeEnds::Open);
    check.in_range("trusted_reliability", trusted_reliability, 0, 1);
    check.in_range("suspect_reliability", suspect_reliability, 0, 1);
    check.in_range("no_return_reliability", no_return_reliability, 0, 1);
    check.in_range("free_threshold", free_threshold, 0, 1, RangeEnds::OpenClosed);
    check.in_range("occupied_threshold", occupied_threshold, 0, 1, RangeEnds::OpenClosed);
  }

  /// The belief of a voxel with evidence \p c, in closed form and in log space (no count, however
  /// large, gives 0/0 or a rounding to a wrong side).
  ExplainedBelief combine(const EvidenceCell& c) const noexcept {
    const double lm = std::log1p(-miss_mass), lh = std::log1p(-hit_mass);
    // log of the mass a class leaves uncommitted to a focus: log(1 - r (1 - (1 - p)^n)).
    const auto uncommitted = [](double r, double log_keep, std::uint16_t n) {
      if (n == 0 || r == 0.0) return 0.0;
      if (r == 1.0) return log_keep * n;                 // exact, finite for any count
      const double support = -std::expm1(log_keep * n);  // 1 - (1 - p)^n, accurate for small n
      return std::log1p(-r * support);                   // >= log(1 - r) > -inf
    };
    const double la = uncommitted(trusted_reliability, lm, c.trusted_misses) +
                      uncommitted(suspect_reliability, lm, c.suspect_misses) +
                      uncommitted(no_return_reliability, lm, c.no_return_misses);
    const double lb =
        uncommitted(trusted_reliability, lh, c.trusted_hits) + uncommitted(suspect_reliability, lh, c.suspect_hits);
    // Two simple support functions, m(F) = 1 - a and m(O) = 1 - b, by Dempster's rule:
    // Bel(F) = (1 - a) b / N, Bel(O) = (1 - b) a / N, N = 1 - (1 - a)(1 - b) = a + b - ab.
    // Scaled by max(a, b) so that N never underflows.
    const double a = std::exp(la), b = std::exp(lb);
    const double s = std::max(la, lb);  // finite: every term above is
    const double as = std::exp(la - s), bs = std::exp(lb - s);
    const double n = as + bs - a * bs;  // (a + b - ab) / max(a, b): >= 1 when as = 1, >= as when bs = 1
    ExplainedBelief out;
    out.free = std::clamp((1.0 - a) * bs / n, 0.0, 1.0);
    out.occupied = std::clamp((1.0 - b) * as / n, 0.0, 1.0);
    out.conflict = (1.0 - a) * (1.0 - b);
    return out;
  }

  /// The explained state of a voxel with evidence \p c.
  ExplainedState state(const EvidenceCell& c) const noexcept {
    if (!c.any()) return ExplainedState::Unknown;
    const ExplainedBelief b = combine(c);
    if (b.free >= free_threshold) return ExplainedState::Free;
    if (b.occupied >= occupied_threshold) return ExplainedState::Occupied;
    return ExplainedState::Unexplained;
  }
};

}  // namespace intervox
