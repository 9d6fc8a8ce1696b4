#pragma once
/// \file
/// A closed probability interval [lower, upper].

#include <algorithm>

namespace intervox {

/// Bounds of the probability of occupancy of a voxel (thesis chapter 4).
///
/// For Bayes policies the interval is degenerate, [p, p]. Policies maintain
/// 0 <= lower <= upper <= 1. Thread safety: a plain value type.
struct Interval {
  double lower = 0.0;  ///< lowest probability of occupancy the data justifies
  double upper = 1.0;  ///< highest probability of occupancy the data justifies

  /// upper - lower: 1 for total ignorance, 0 for a precise probability.
  constexpr double width() const noexcept { return upper - lower; }
  /// The mean of both bounds.
  constexpr double mid() const noexcept { return 0.5 * (lower + upper); }
  /// True if lower <= x <= upper.
  constexpr bool contains(double x) const noexcept { return lower <= x && x <= upper; }
  /// The point of the interval closest to \p x.
  constexpr double closest_to(double x) const noexcept { return std::clamp(x, lower, upper); }

  friend constexpr bool operator==(const Interval&, const Interval&) = default;
};

}  // namespace intervox
