#pragma once
/// \file
/// The vector walks of ray insertion (AVX-512 and AVX2 on x86-64 processors that have them,
/// chosen at run time): including this header in any one translation unit of a program makes
/// every insertion of that program use them (docs/raycasting.md). They mark the same voxels as
/// the portable walk, 1.7 (AVX2) to 2.5 (AVX-512) times faster. raycast.hpp, intervox.hpp and
/// plan/episode.hpp include it; a translation unit that includes only insert.hpp stays lighter
/// to compile. Without x86-64 (or with INTERVOX_NO_X86_WALKS defined) it adds nothing.

#include <intervox/raycast/detail/walk_x86.hpp>
