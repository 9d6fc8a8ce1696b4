#pragma once
/// \file
/// The hit-and-miss count policy: a voxel keeps how many scans hit it and how many crossed it.
/// The raw evidence beneath every other policy, kept per beam class by the explained-free-space
/// channel (explain/explained_space.hpp); usable on its own as a count map.

#include <intervox/core/interval.hpp>
#include <intervox/core/types.hpp>
#include <intervox/update/concepts.hpp>

#include <cstdint>
#include <limits>
#include <string_view>

namespace intervox {

/// Counts of hits and misses; 4 bytes per voxel, each count saturating at 65535.
///
/// State: the Laplace estimate (hits + 1) / (hits + misses + 2) (0.5 for an unobserved voxel);
/// interval: degenerate at the state; occupancy: occupied if hits >= misses, free otherwise,
/// unknown for an unobserved voxel.
///
/// Thread safety: stateless; all members may be called concurrently (on distinct cells for
/// update()).
struct HitMissCount {
  /// The counts of one voxel.
  struct Cell {
    std::uint16_t hits = 0;
    std::uint16_t misses = 0;
    friend constexpr bool operator==(const Cell&, const Cell&) = default;
  };
  static constexpr std::string_view kName = "hit-miss-count";

  Cell unobserved() const noexcept { return {}; }
  bool is_observed(const Cell& c) const noexcept { return (c.hits | c.misses) != 0; }
  void update(Cell& c, Observation o) const noexcept {
    std::uint16_t& n = o == Observation::Hit ? c.hits : c.misses;
    if (n != std::numeric_limits<std::uint16_t>::max()) ++n;
  }
  double state(const Cell& c) const noexcept { return (c.hits + 1.0) / (double(c.hits) + double(c.misses) + 2.0); }
  Interval interval(const Cell& c) const noexcept {
    const double s = state(c);
    return {s, s};
  }
  Occupancy occupancy(const Cell& c) const noexcept {
    if (!is_observed(c)) return Occupancy::Unknown;
    return c.hits >= c.misses ? Occupancy::Occupied : Occupancy::Free;
  }
};

static_assert(UpdatePolicy<HitMissCount>);

}  // namespace intervox
