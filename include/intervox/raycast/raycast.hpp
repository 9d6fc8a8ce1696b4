#pragma once
/// \file
/// The raycast layer: exact voxel traversal, ray insertion, and ray casting.

#include <intervox/raycast/cast.hpp>
#include <intervox/raycast/insert.hpp>
#include <intervox/raycast/traversal.hpp>
