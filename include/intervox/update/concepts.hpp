#pragma once
/// \file
/// The UpdatePolicy concept: how a voxel's cell is initialised, updated and interpreted.

#include <intervox/core/interval.hpp>
#include <intervox/core/types.hpp>

#include <concepts>
#include <string_view>
#include <type_traits>

namespace intervox {

/// An update policy owns the per-voxel storage type and the rules that act on it.
///
/// Required members (with `u` a const policy, `c` a Cell):
///  - `typename U::Cell`: trivially copyable per-voxel storage;
///  - `U::kName`: a short name, used in files and reports;
///  - `u.unobserved()`: the sentinel cell of a voxel no measurement has touched;
///  - `u.is_observed(c)`: false exactly for the sentinel;
///  - `u.update(c, Observation)`: one measurement step; must accept the sentinel;
///  - `u.state(c)`: the state, a probability of occupancy in [0, 1] (the prior for the sentinel);
///  - `u.interval(c)`: the probability interval (degenerate for Bayes policies);
///  - `u.occupancy(c)`: the classification (Unknown for the sentinel).
///
/// \tparam U the candidate policy type
template <class U>
concept UpdatePolicy = std::copy_constructible<U> && std::is_trivially_copyable_v<typename U::Cell> &&
    requires(const U& u, typename U::Cell& c, const typename U::Cell& cc) {
  { U::kName } -> std::convertible_to<std::string_view>;
  { u.unobserved() } -> std::same_as<typename U::Cell>;
  { u.is_observed(cc) } -> std::same_as<bool>;
  { u.update(c, Observation::Hit) } -> std::same_as<void>;
  { u.state(cc) } -> std::same_as<double>;
  { u.interval(cc) } -> std::same_as<Interval>;
  { u.occupancy(cc) } -> std::same_as<Occupancy>;
};

/// Classifies a probability by thresholds: occupied at or above \p occupied, otherwise free at or
/// below \p free, otherwise unknown. With free == occupied there is no unknown band (OctoMap).
constexpr Occupancy classify(double state, double free, double occupied) noexcept {
  if (state >= occupied) return Occupancy::Occupied;
  if (state <= free) return Occupancy::Free;
  return Occupancy::Unknown;
}

}  // namespace intervox
