#pragma once
/// \file
/// Utility policies: the value of observing a voxel, from its state and interval (thesis 3.4,
/// 4.3.2). The information gain of a view sums them over the voxels its beams cross.

#include <intervox/core/interval.hpp>
#include <intervox/core/probability.hpp>

#include <concepts>
#include <string_view>

namespace intervox {

/// A utility policy maps (state, interval) of a voxel to a non-negative value.
///
/// Required: `h.value(double state, const Interval&) -> double` (const) and `H::kName`.
/// \tparam H the candidate policy type
template <class H>
concept UtilityPolicy = std::copy_constructible<H> && requires(const H& h, double s, const Interval& i) {
  { h.value(s, i) } -> std::same_as<double>;
  { H::kName } -> std::convertible_to<std::string_view>;
};

/// Shannon entropy of the state, in bits (eq. 3.16): 1 for a state of 0.5, 0 for 0 or 1.
/// Thread safety: stateless.
struct Entropy {
  static constexpr std::string_view kName = "entropy";
  double value(double state, const Interval&) const noexcept { return binary_entropy(state); }
};

/// The maximum of the entropy over the interval (eq. 4.4, 4.5): H(0.5) = 1 if 0.5 lies in
/// [lower, upper], otherwise H at the bound closest to 0.5. Equals Entropy for a degenerate
/// interval (Bayes). Thread safety: stateless.
struct MaxEntropy {
  static constexpr std::string_view kName = "max-entropy";
  double value(double, const Interval& i) const noexcept { return binary_entropy(i.closest_to(0.5)); }
};

/// Total uncertainty of the credal set (Abellán–Moral, Klir): the maximum entropy over the
/// interval (MaxEntropy, the conflict/randomness part) plus its non-specificity, which for a
/// binary frame with probability interval [l, u] is the Hartley measure weighted by the
/// imprecision, (u − l) · log2 2 = u − l bits. In [0, 2] bits: 2 for the vacuous [0, 1], 1 for a
/// precise 0.5 (or any interval around 0.5 of width w: 1 + w), and the entropy of the state for a
/// degenerate interval (Bayes). Thread safety: stateless.
struct TotalUncertainty {
  static constexpr std::string_view kName = "total-uncertainty";
  double value(double, const Interval& i) const noexcept {
    return binary_entropy(i.closest_to(0.5)) + (i.upper - i.lower);
  }
};

static_assert(UtilityPolicy<Entropy>);
static_assert(UtilityPolicy<MaxEntropy>);
static_assert(UtilityPolicy<TotalUncertainty>);

}  // namespace intervox
