#pragma once
// The precompiled header of every test suite (tests/CMakeLists.txt): what nearly every test file
// parses — Catch2, Eigen, the standard headers the tests use, the grid and insertion headers and
// the typed tests' grid list with the test-support library's instantiation declarations
// (instantiations.hpp). Each test file still includes what it uses; this only makes the
// common part cost once per suite instead of once per file.
#include <catch2/catch.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <set>
#include <span>
#include <sstream>
#include <string>
#include <thread>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include <intervox/grid/voxel_grid.hpp>
#include <intervox/raycast/insert.hpp>

#include "grid_types.hpp"
#include "instantiations.hpp"
