#pragma once
/// \file
/// Internal part of ray insertion: the one dispatch of the walks that mark a scan's misses into
/// the box bitmaps (box_marks.hpp). The portable walks (walk_portable.hpp) are always there; the
/// vector walks (walk_x86.hpp: AVX-512 and AVX2, x86-64 only) are compiled only in the
/// translation units that include <intervox/raycast/vector_walks.hpp>, and used only after the
/// program calls intervox::use_vector_walks() (never as a side effect of an include). A program
/// that does not runs the portable table walk: the same voxels, 1.7 to 2.5 times slower.
/// walk_name() tells which walk runs.
///
/// Thread safety: the registry's entries are atomic; once set they never change, and
/// walk_rays() only touches the marks it is given.

#include <intervox/raycast/detail/box_marks.hpp>
#include <intervox/raycast/detail/walk_portable.hpp>

#include <atomic>
#include <cstdint>
#include <type_traits>

namespace intervox::detail {

/// Hands out the rays of one marking pass to a vector walk, one at a time (called once per ray,
/// never per step, so the virtual call costs nothing measurable).
class BoxRaySource {
 public:
  /// Writes the next ray into \p r; false when there are no more.
  virtual bool next(BoxRay& r) = 0;

 protected:
  ~BoxRaySource() = default;
};

/// A BoxRaySource over a callable `bool next(BoxRay&)`.
template <class Next>
class BoxRaySourceOf final : public BoxRaySource {
 public:
  explicit BoxRaySourceOf(Next& next) noexcept : next_(&next) {}
  bool next(BoxRay& r) override { return (*next_)(r); }

 private:
  Next* next_;
};

/// A vector walk: marks the misses of every ray \p rays hands out into the bitmap \p words;
/// idle lanes mark the bit \p scratch (BoxMarks::scratch_id()).
using VectorWalk = void (*)(std::uint64_t* words, std::int64_t scratch, BoxRaySource& rays);

/// The vector walks this program has and this processor runs (null where not), set by
/// use_vector_walks() (vector_walks.hpp).
struct VectorWalks {
  std::atomic<VectorWalk> avx512{nullptr};
  std::atomic<VectorWalk> avx2{nullptr};
};
inline constinit VectorWalks registered_walks{};

/// The walks of walk_rays().
enum class WalkKind : std::uint8_t {
  Fastest,  ///< the fastest available: Avx512, else Avx2, else Table
  Avx512,   ///< the AVX-512 walk (Table where the processor or the program lacks it)
  Avx2,     ///< the AVX2 walk (Table where the processor or the program lacks it)
  Table,    ///< TableWalk: portable, two rays side by side
  Single,   ///< walk_single(): one ray at a time, the plainest form
};

/// The walk that \p kind runs in this program on this processor (never Fastest).
inline WalkKind resolve_walk(WalkKind kind) noexcept {
  const bool avx512 = registered_walks.avx512.load(std::memory_order_acquire) != nullptr;
  const bool avx2 = registered_walks.avx2.load(std::memory_order_acquire) != nullptr;
  if (kind == WalkKind::Fastest) kind = avx512 ? WalkKind::Avx512 : WalkKind::Avx2;
  if (kind == WalkKind::Avx512 && !avx512) kind = WalkKind::Table;
  if (kind == WalkKind::Avx2 && !avx2) kind = WalkKind::Table;
  return kind;
}

/// A short name of a walk ("AVX-512", "AVX2", "table", "single"), after resolve_walk().
inline const char* walk_name(WalkKind kind) noexcept {
  switch (resolve_walk(kind)) {
    case WalkKind::Avx512:
      return "AVX-512";
    case WalkKind::Avx2:
      return "AVX2";
    case WalkKind::Single:
      return "single";
    default:
      return "table";
  }
}

/// Walks every ray \p next hands out (`bool next(BoxRay&)`, false when there are no more) into
/// \p marks' miss bitmap with the walk resolve_walk(\p kind). The result is the same bits for
/// every walk.
template <class Next>
void walk_rays(BoxMarks& marks, WalkKind kind, Next&& next) {
  kind = resolve_walk(kind);
  if (kind == WalkKind::Avx512 || kind == WalkKind::Avx2) {
    BoxRaySourceOf<std::remove_reference_t<Next>> source(next);
    // Set entries never change back, so the walk resolve_walk() saw is there.
    const VectorWalk walk =
        (kind == WalkKind::Avx512 ? registered_walks.avx512 : registered_walks.avx2).load(std::memory_order_acquire);
    walk(marks.miss(), marks.scratch_id(), source);
    return;
  }
  BoxRay r;
  if (kind == WalkKind::Single) {
    while (next(r)) walk_single(marks.miss(), r);
    return;
  }
  TableWalk walk(marks.miss());
  while (next(r)) walk.add(r);
  walk.flush();
}

}  // namespace intervox::detail
