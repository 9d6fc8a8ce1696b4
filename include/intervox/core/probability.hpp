#pragma once
/// \file
/// Probability, odds and log-odds conversions and the Shannon entropy of a binary variable.
///
/// All functions are pure and thread-safe.

#include <cmath>
#include <limits>

namespace intervox {

/// Log-odds of a probability, \f$ \log(p / (1 - p)) \f$ (natural logarithm).
/// Returns -inf for p = 0 and +inf for p = 1; NaN for p outside [0, 1] or NaN.
inline double log_odds(double p) noexcept {
  if (!(p >= 0.0 && p <= 1.0)) return std::numeric_limits<double>::quiet_NaN();
  return std::log(p / (1.0 - p));
}

/// Log-odds as float, computed exactly as OctoMap's `octomap::logodds` does (double math, then a
/// cast), so that grids configured with the same probabilities hold bit-identical values.
inline float log_odds_f(double p) noexcept { return static_cast<float>(log_odds(p)); }

/// Probability from log-odds, \f$ 1 - 1 / (1 + e^{l}) \f$ (the form OctoMap uses).
/// Maps -inf to 0, +inf to 1, NaN to NaN.
inline double probability(double l) noexcept { return 1.0 - 1.0 / (1.0 + std::exp(l)); }

/// One Bayes update step in probability space (thesis eq. 3.12): the posterior probability of
/// occupancy from the prior \p p and the likelihood quotient \p lq = Pr(data|occ) / Pr(data|free).
/// p = 0 and p = 1 are fixed points (eq. 3.13, 3.14).
inline double bayes_step(double p, double lq) noexcept {
  if (p >= 1.0) return 1.0;
  const double o = p / (1.0 - p) * lq;
  return o / (1.0 + o);
}

/// Shannon entropy of a binary variable with probability \p p, in bits (thesis eq. 3.16):
/// \f$ H(p) = -(p \log_2 p + (1 - p) \log_2 (1 - p)) \f$, with 0 log 0 = 0, so H(0) = H(1) = 0 and
/// H(0.5) = 1. Values outside [0, 1] are clamped to it; NaN gives NaN.
inline double binary_entropy(double p) noexcept {
  if (p != p) return p;
  if (p <= 0.0 || p >= 1.0) return 0.0;
  return -(p * std::log2(p) + (1.0 - p) * std::log2(1.0 - p));
}

}  // namespace intervox
