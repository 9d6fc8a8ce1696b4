#pragma once
/// \file
/// The one seeded generator of Intervox: splitmix64 (Steele, Lea, Flood 2014), with our own
/// transforms to [0, 1) so that results are the same with every compiler and standard library.
/// SeededRandom is a sequential stream (view sampling); the simulator's counter-based streams
/// (sim/beam_rng.hpp) use the same mix.

#include <cstddef>
#include <cstdint>

namespace intervox {

namespace detail {
/// The splitmix64 finaliser: a bijective 64-bit mix.
constexpr std::uint64_t mix64(std::uint64_t z) noexcept {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}
/// The splitmix64 increment (the golden ratio in 64 bits).
inline constexpr std::uint64_t kGamma = 0x9E3779B97F4A7C15ULL;
/// The top 53 bits of a word as a double in [0, 1).
constexpr double unit_double(std::uint64_t word) noexcept { return static_cast<double>(word >> 11) * 0x1.0p-53; }
}  // namespace detail

/// A small, portable, seeded generator (SplitMix64). Thread safety: one per thread.
class SeededRandom {
 public:
  explicit SeededRandom(std::uint64_t seed) noexcept : state_(seed) {}
  std::uint64_t next() noexcept { return detail::mix64(state_ += detail::kGamma); }
  /// Uniform in [0, 1).
  double uniform() noexcept { return detail::unit_double(next()); }
  /// Uniform in [0, n) for n > 0 (modulo; the bias is below n / 2^64).
  std::size_t below(std::size_t n) noexcept { return static_cast<std::size_t>(next() % n); }

 private:
  std::uint64_t state_;
};

}  // namespace intervox
