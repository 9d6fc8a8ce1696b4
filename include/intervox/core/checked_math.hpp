#pragma once
/// \file
/// Overflow-checked integer arithmetic for sizes formed from untrusted numbers (boxes from files,
/// declared counts, image dimensions, offsets). Every product or sum of such numbers goes through
/// one of these helpers, so that a crafted file can never make a size wrap to a small value.
///
///  - checked_mul / checked_add: the exact result, or std::nullopt if it does not fit in T;
///  - saturating_mul / saturating_add: the exact result clamped to T's range;
///  - mul_or_throw / add_or_throw: the exact result, or an exception of the given type naming what
///    was being computed.
///
/// Thread safety: stateless functions.

#include <intervox/core/error.hpp>

#include <concepts>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>

namespace intervox {

/// a * b, or nothing if the product does not fit in T.
template <std::integral T>
constexpr std::optional<T> checked_mul(T a, T b) noexcept {
  T r{};
  if (__builtin_mul_overflow(a, b, &r)) return std::nullopt;
  return r;
}

/// a + b, or nothing if the sum does not fit in T.
template <std::integral T>
constexpr std::optional<T> checked_add(T a, T b) noexcept {
  T r{};
  if (__builtin_add_overflow(a, b, &r)) return std::nullopt;
  return r;
}

/// a * b clamped to [min, max] of T (the sign of the exact product decides which end).
template <std::integral T>
constexpr T saturating_mul(T a, T b) noexcept {
  if (const auto r = checked_mul(a, b)) return *r;
  if constexpr (std::is_signed_v<T>) {
    if ((a < 0) != (b < 0)) return std::numeric_limits<T>::min();
  }
  return std::numeric_limits<T>::max();
}

/// a + b clamped to [min, max] of T.
template <std::integral T>
constexpr T saturating_add(T a, T b) noexcept {
  if (const auto r = checked_add(a, b)) return *r;
  if constexpr (std::is_signed_v<T>) {
    if (a < 0) return std::numeric_limits<T>::min();
  }
  return std::numeric_limits<T>::max();
}

/// a * b. \throws E (constructed from a message naming \p what) if the product does not fit in T.
template <class E = IoError, std::integral T>
T mul_or_throw(T a, T b, const std::string& what) {
  if (const auto r = checked_mul(a, b)) return *r;
  throw E(what + ": " + std::to_string(a) + " x " + std::to_string(b) + " overflows a " +
          std::to_string(std::numeric_limits<T>::digits + (std::is_signed_v<T> ? 1 : 0)) + "-bit integer");
}

/// a + b. \throws E (constructed from a message naming \p what) if the sum does not fit in T.
template <class E = IoError, std::integral T>
T add_or_throw(T a, T b, const std::string& what) {
  if (const auto r = checked_add(a, b)) return *r;
  throw E(what + ": " + std::to_string(a) + " + " + std::to_string(b) + " overflows a " +
          std::to_string(std::numeric_limits<T>::digits + (std::is_signed_v<T> ? 1 : 0)) + "-bit integer");
}

}  // namespace intervox
