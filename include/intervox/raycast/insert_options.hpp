#pragma once
/// \file
/// The options and the statistics of ray insertion (insert.hpp), and the insertion budget.
///
/// The insertion budget (InsertOptions::max_grid_bytes): how much memory one call may add to a
/// sparse map, checked after the rays are prepared and before the map allocates anything, so
/// that bad input (a depth image in millimetres read as metres, a stray return kilometres away,
/// no max range) is refused with an error naming the likely cause instead of taking the
/// machine's memory. What is counted: the new 8^3 blocks of cells the scan's rays may touch, a
/// cheap upper bound computed once per call from the rays' lengths (their walks' voxel counts)
/// and the key box they span (clipped to a bounded grid's box), whichever is smaller, at the
/// grid's bytes per block (cells plus table overhead). Blocks the map already holds are counted
/// too (the bound does not look at the map), so the bound may exceed what is really added, never
/// fall short of it. Dense (bounded storage) grids never grow and are not checked. The default,
/// kDefaultInsertBudgetBytes (4 GiB), is far above what a depth camera or lidar scan with a set
/// max range adds, and above the whole box of a bounded 10 m room at 2 cm (about 1 GiB of interval
/// cells, which a scan of stray returns can span: bench_long_rays), and far below what a depth
/// image in millimetres read as metres demands (tens of GiB and more); raise max_grid_bytes for larger scans, or set it
/// to kUnlimitedInsertBudget to switch the check off.

#include <intervox/core/error.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/core/validate.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>

namespace intervox {

/// Default insertion budget (InsertOptions::max_grid_bytes): 4 GiB of new cells per call.
inline constexpr std::uint64_t kDefaultInsertBudgetBytes = std::uint64_t{1} << 32;
/// An insertion budget that never refuses a scan.
inline constexpr std::uint64_t kUnlimitedInsertBudget = ~std::uint64_t{0};

/// Options of ray insertion.
struct InsertOptions {
  /// Rays longer than this are cut at this distance from their origin and carry misses only
  /// (no hit); beams without a return are free up to it. Negative or +inf: no max range (then
  /// beams without a return are skipped).
  double max_range = -1.0;
  /// Points closer than this to their origin are skipped (counted in skipped_min_range).
  double min_range = 0.0;
  /// Threads for traversal and update: 1 (default) runs on the calling thread, 0 uses
  /// std::thread::hardware_concurrency(); larger counts are capped at it (resolve_threads()).
  /// The result is identical for every value.
  unsigned threads = 1;
  /// Scratch budget of the block-hash marks, per thread (default 128 MiB, at least 4 KiB; at most
  /// max_mark_bytes / ScanMarks::kBytesPerBlock blocks, 400 k by default). The
  /// hash marks scans whose key box is too large for the box bitmaps (long rays); a scan whose
  /// distinct 8^3 blocks would need more is marked and applied region by region (its key box
  /// split in halves until each part fits), so no ray, however long, makes the scratch grow past
  /// it. Smaller budgets walk long rays more often; results are the same for any budget.
  std::size_t max_mark_bytes = std::size_t{128} << 20;
  /// The insertion budget (see the file comment): the bytes of new cells one call may add to a
  /// sparse map, by a cheap upper bound computed before anything is allocated. A scan whose bound
  /// exceeds it is refused with InvalidArgument (nothing is inserted), naming the extent of the
  /// rays and the likely cause (depth in millimetres? no max range?). Default 4 GiB.
  std::uint64_t max_grid_bytes = kDefaultInsertBudgetBytes;

  /// True if a finite, non-negative max range is set.
  bool has_max_range() const noexcept { return max_range >= 0.0 && std::isfinite(max_range); }

  /// \throws InvalidArgument if max_range is NaN, min_range is NaN, negative or infinite,
  ///         min_range exceeds a set max_range, or max_mark_bytes is below kMinMarkBytes.
  void validate() const {
    const ParamCheck check("intervox::InsertOptions");
    if (std::isnan(max_range)) check.fail("max_range is NaN");  // +inf or negative: no max range
    check.nonnegative("min_range", min_range);
    if (has_max_range() && min_range > max_range)
      check.fail("min_range " + detail::param_text(min_range) + " exceeds max_range " + detail::param_text(max_range));
    check.at_least("max_mark_bytes", max_mark_bytes, kMinMarkBytes);
  }
  /// These options for a frame whose sensor reaches \p frame_max_range (DepthFrame::max_range):
  /// the max range is the smaller of the frame's (when finite) and these options' (when set).
  InsertOptions for_frame(double frame_max_range) const noexcept {
    InsertOptions o = *this;
    if (std::isfinite(frame_max_range) && !(has_max_range() && max_range <= frame_max_range))
      o.max_range = frame_max_range;
    return o;
  }
  /// The smallest accepted max_mark_bytes.
  static constexpr std::size_t kMinMarkBytes = 4096;
};

/// What one insertion did. Every input ray is counted exactly once: either in `rays` or in one
/// of the `skipped_*` counters.
struct InsertStats {
  std::uint64_t rays = 0;         ///< rays traversed (with a hit, or cut at max range)
  std::uint64_t truncated = 0;    ///< of those, rays cut at max range (misses only)
  std::uint64_t voxel_steps = 0;  ///< voxels enumerated by the traversals, before de-duplication
  std::uint64_t hits = 0;         ///< voxels updated with a hit (after de-duplication)
  std::uint64_t misses = 0;       ///< voxels updated with a miss (after de-duplication)
  /// Voxel updates dropped: outside a bounded grid's box. The exact insertion cuts each ray's walk
  /// where it leaves the box (and walks no ray that cannot enter it): the updates its walks still
  /// enumerate outside the box are counted once per voxel and scan, those beyond the cut once per
  /// ray (so two rays that would pass one voxel beyond the box count it twice).
  std::uint64_t outside_bounds = 0;

  std::uint64_t skipped_invalid = 0;       ///< NaN/Inf point or origin, invalid depth pixel
  std::uint64_t skipped_zero_length = 0;   ///< point equal to its origin
  std::uint64_t skipped_min_range = 0;     ///< point closer than min_range
  std::uint64_t skipped_key_range = 0;     ///< origin or (cut) end outside the key range
  std::uint64_t skipped_no_max_range = 0;  ///< beam without a return, but no max range set

  /// Beams per class of the explained-free-space channel (ExplainedSpace: explain/); zero for
  /// the plain insertion, which classes nothing. Their sum is `rays`.
  std::uint64_t beams_trusted = 0;
  std::uint64_t beams_suspect = 0;    ///< returned, but not explained by the map
  std::uint64_t beams_no_return = 0;  ///< no return (free up to max range, never explained free)

  /// Input rays not traversed, for any reason.
  std::uint64_t skipped() const noexcept {
    return skipped_invalid + skipped_zero_length + skipped_min_range + skipped_key_range + skipped_no_max_range;
  }
  InsertStats& operator+=(const InsertStats& o) noexcept {
    rays += o.rays;
    truncated += o.truncated;
    voxel_steps += o.voxel_steps;
    hits += o.hits;
    misses += o.misses;
    outside_bounds += o.outside_bounds;
    skipped_invalid += o.skipped_invalid;
    skipped_zero_length += o.skipped_zero_length;
    skipped_min_range += o.skipped_min_range;
    skipped_key_range += o.skipped_key_range;
    skipped_no_max_range += o.skipped_no_max_range;
    beams_trusted += o.beams_trusted;
    beams_suspect += o.beams_suspect;
    beams_no_return += o.beams_no_return;
    return *this;
  }
  friend bool operator==(const InsertStats&, const InsertStats&) = default;
};

namespace detail {

/// The cause a budget refusal of a depth image names when its intrinsics, not its depths, make its
/// rays reach far: a field of view of 170 degrees or more along x or y (the outer pixels' rays run
/// nearly along the image plane, so near depths lie kilometres aside: focal lengths given in metres
/// rather than pixels, say); empty for any other intrinsics, where the refusal names its usual
/// causes (depth in millimetres, no max range).
inline std::string wide_intrinsics_cause(const PinholeIntrinsics& k) {
  const double deg = 180.0 / 3.14159265358979323846, fx = k.fov_x() * deg, fy = k.fov_y() * deg;
  if (!(fx >= 170.0 || fy >= 170.0)) return {};
  const auto text = [](double v) {
    std::string t = std::to_string(v);
    return t.substr(0, t.find('.') + 2);
  };
  const auto g = [](double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return std::string(buf);
  };
  return "The intrinsics (fx = " + g(k.fx) + ", fy = " + g(k.fy) + " pixels) give a field of view of " + text(fx) +
         " x " + text(fy) +
         " degrees: the outer pixels' rays run nearly along the image plane, so even near depths land far "
         "aside. Focal lengths in metres rather than pixels (fx = focal length / pixel pitch)? ";
}

/// Runs \p f() with \p slot set to \p temp and restores it after, also when f throws: how an
/// inserter applies a depth frame's own max range for one call.
template <class F>
decltype(auto) with_options(InsertOptions& slot, const InsertOptions& temp, F&& f) {
  struct Restore {
    InsertOptions& slot;
    InsertOptions saved;
    ~Restore() { slot = saved; }
  } restore{slot, std::exchange(slot, temp)};
  return f();
}

}  // namespace detail

}  // namespace intervox
