#pragma once
/// \file
/// Counter-based random numbers for the simulator: every beam draws from its own stream, derived
/// from (seed, stream, beam), so results never depend on evaluation order or thread count.
///
/// The transforms are our own (not the standard library's distributions), so results are the
/// same with every compiler and standard library:
///  - 64-bit words: splitmix64 (Steele, Lea, Flood 2014) of a counter (core/random.hpp's mix);
///  - uniform in [0, 1): the top 53 bits of a word times 2^-53;
///  - standard normal: Box–Muller, sqrt(-2 ln u1) cos(2 pi u2) with u1 in (0, 1].

#include <intervox/core/random.hpp>

#include <cmath>
#include <cstdint>
#include <numbers>

namespace intervox::sim {

namespace detail {
using intervox::detail::kGamma;
using intervox::detail::mix64;
}  // namespace detail

/// A small counter-based generator for one beam.
///
/// Thread safety: a value type; use one instance per thread (they are cheap to create).
class BeamRng {
 public:
  /// The stream of beam \p beam of stream \p stream (a sensor, or a profile of a sweep) under
  /// \p seed. Different triples give statistically independent streams.
  constexpr BeamRng(std::uint64_t seed, std::uint64_t stream, std::uint64_t beam) noexcept
      : key_(detail::mix64(detail::mix64(detail::mix64(seed + detail::kGamma) ^ (stream + 0x632BE59BD9B4E019ULL)) ^
                           (beam + 0xD1B54A32D192ED03ULL))) {}

  /// The next 64-bit word.
  constexpr std::uint64_t next() noexcept { return detail::mix64(key_ + detail::kGamma * ++counter_); }

  /// Uniform in [0, 1).
  constexpr double uniform() noexcept { return intervox::detail::unit_double(next()); }

  /// Uniform in [a, b).
  constexpr double uniform(double a, double b) noexcept { return a + (b - a) * uniform(); }

  /// True with probability \p p (p <= 0: never, p >= 1: always).
  constexpr bool bernoulli(double p) noexcept { return uniform() < p; }

  /// Standard normal by Box–Muller (one value per two uniforms; the second is discarded so that
  /// every draw consumes a fixed number of words).
  double normal() noexcept {
    const double u1 = 1.0 - uniform();  // (0, 1]
    const double u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
  }

 private:
  std::uint64_t key_;
  std::uint64_t counter_ = 0;
};

}  // namespace intervox::sim
