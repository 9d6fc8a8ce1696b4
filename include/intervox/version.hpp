#pragma once
/// \file
/// Library version. The CMake project reads its version from the three macros below.

#define INTERVOX_VERSION_MAJOR 0
#define INTERVOX_VERSION_MINOR 1
#define INTERVOX_VERSION_PATCH 0

namespace intervox {
/// Version as a single integer, major * 10000 + minor * 100 + patch.
inline constexpr int kVersion = INTERVOX_VERSION_MAJOR * 10000 + INTERVOX_VERSION_MINOR * 100 + INTERVOX_VERSION_PATCH;
}  // namespace intervox
