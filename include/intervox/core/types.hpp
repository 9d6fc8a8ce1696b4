#pragma once
/// \file
/// Small enumerations shared by every layer.
/// Thread safety: enumerations and constexpr functions only.

#include <cstdint>
#include <string_view>

namespace intervox {

/// What a measurement says about one voxel.
enum class Observation : std::uint8_t {
  Miss = 0,  ///< a beam passed through the voxel: evidence for free space
  Hit = 1,   ///< a beam ended in the voxel: evidence for an obstacle
};

/// The classification of a voxel by its update policy's thresholds.
enum class Occupancy : std::uint8_t {
  Unknown = 0,   ///< never observed, or the state lies between the thresholds
  Free = 1,      ///< the state is at or below the free threshold
  Occupied = 2,  ///< the state is at or above the occupied threshold
};

/// Name of an occupancy class, for messages and files.
constexpr std::string_view to_string(Occupancy o) noexcept {
  switch (o) {
    case Occupancy::Free:
      return "free";
    case Occupancy::Occupied:
      return "occupied";
    case Occupancy::Unknown:
      break;
  }
  return "unknown";
}

/// Name of an observation, for messages and files.
constexpr std::string_view to_string(Observation o) noexcept { return o == Observation::Hit ? "hit" : "miss"; }

}  // namespace intervox
