#pragma once
/// \file
/// The vector walks of ray insertion (AVX-512 and AVX2 on x86-64 processors that have them):
/// including this header compiles them into the translation unit; calling use_vector_walks()
/// once makes every insertion of the program use the fastest one the processor runs
/// (docs/raycasting.md). They mark the same voxels as the portable walk, 1.7 (AVX2) to 2.5
/// (AVX-512) times faster. Including the header alone changes nothing: a program chooses them
/// by the call, never by an include. Without x86-64 (or with INTERVOX_NO_X86_WALKS defined) the
/// call keeps the portable walk.

#include <intervox/raycast/detail/walk_x86.hpp>
#include <intervox/raycast/detail/walks.hpp>

namespace intervox {

/// Makes every ray insertion of this program (every ScanInserter, every thread, from the next
/// scan on) walk with the fastest vector walk this processor runs; the inserted voxels are the
/// same with any walk. Returns the walk insertions now use: "AVX-512", "AVX2", or "table" where
/// the processor (or the build: not x86-64, INTERVOX_NO_X86_WALKS) has none.
///
/// Thread safety: may be called from any thread, any number of times, also while other threads
/// insert (their scans use the portable walk until the call, the vector walk after it).
inline const char* use_vector_walks() noexcept {
#if INTERVOX_HAVE_X86_WALKS
  detail::register_vector_walks();
#endif
  return detail::walk_name(detail::WalkKind::Fastest);
}

/// The walk ray insertion uses now: "AVX-512", "AVX2" (after use_vector_walks()) or "table".
inline const char* insertion_walk() noexcept { return detail::walk_name(detail::WalkKind::Fastest); }

}  // namespace intervox
