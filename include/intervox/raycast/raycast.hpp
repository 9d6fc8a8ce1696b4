#pragma once
/// \file
/// The raycast layer: exact voxel traversal, ray insertion (with the vector walks, see
/// vector_walks.hpp), the projective insertion of depth images, and ray casting.

#include <intervox/raycast/cast.hpp>
#include <intervox/raycast/insert.hpp>
#include <intervox/raycast/projective.hpp>
#include <intervox/raycast/traversal.hpp>
#include <intervox/raycast/vector_walks.hpp>
