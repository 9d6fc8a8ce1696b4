#pragma once
/// \file
/// Ray insertion: point clouds, depth images, beams and single rays into any VoxelGrid, with the
/// semantics of OctoMap's `insertPointCloud` (exact traversal, per-scan de-duplication, a hit
/// wins over a miss), exact for any number of scans and any number of threads.

#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/parallel.hpp>
#include <intervox/core/point.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/core/types.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/raycast/detail/box_marks.hpp>
#include <intervox/raycast/traversal.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <exception>
#include <iterator>
#include <limits>
#include <ranges>
#include <span>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace intervox {

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

  /// True if a finite, non-negative max range is set.
  bool has_max_range() const noexcept { return max_range >= 0.0 && std::isfinite(max_range); }

  /// \throws InvalidArgument if max_range is NaN, min_range is NaN, negative or infinite,
  ///         min_range exceeds a set max_range, or max_mark_bytes is below kMinMarkBytes.
  void validate() const {
    if (std::isnan(max_range)) throw InvalidArgument("intervox::InsertOptions: max_range is NaN");
    if (!(min_range >= 0.0 && std::isfinite(min_range)))
      throw InvalidArgument("intervox::InsertOptions: min_range must be finite and >= 0, got " +
                            std::to_string(min_range));
    if (has_max_range() && min_range > max_range)
      throw InvalidArgument("intervox::InsertOptions: min_range " + std::to_string(min_range) +
                            " exceeds max_range " + std::to_string(max_range));
    if (max_mark_bytes < kMinMarkBytes)
      throw InvalidArgument("intervox::InsertOptions: max_mark_bytes must be at least " + std::to_string(kMinMarkBytes) +
                            ", got " + std::to_string(max_mark_bytes));
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
  std::uint64_t outside_bounds = 0;  ///< voxel updates dropped: outside a bounded grid's box

  std::uint64_t skipped_invalid = 0;       ///< NaN/Inf point or origin, invalid depth pixel
  std::uint64_t skipped_zero_length = 0;   ///< point equal to its origin
  std::uint64_t skipped_min_range = 0;     ///< point closer than min_range
  std::uint64_t skipped_key_range = 0;     ///< origin or (cut) end outside the key range
  std::uint64_t skipped_no_max_range = 0;  ///< beam without a return, but no max range set

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
    return *this;
  }
  friend bool operator==(const InsertStats&, const InsertStats&) = default;
};

namespace detail {

/// One input ray before validation. `hit == false`: no return; `end` is any point along the
/// beam's direction.
struct RayInput {
  Point3 origin;
  Point3 end;
  bool hit;
};

/// The set of voxels one scan touches, as 8^3-block bitmaps in an open-addressing table keyed
/// by the packed block coordinate. Cleared exactly between scans (no stamps, no wrap-around).
class ScanMarks {
  struct Slot {
    std::uint64_t id;
    std::uint32_t index;
  };

 public:
  static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};  // never a packed id (63 bits)
  /// Bytes one marked block may take at most: its marks and its id in vectors that grow by
  /// doubling (at most twice the size), and four table slots (the table is a power of two kept
  /// at most half full). n blocks never take more than n * kBytesPerBlock (memory_bytes()).
  static constexpr std::size_t kBytesPerBlock = 2 * (sizeof(BlockMarks) + sizeof(std::uint64_t)) + 4 * sizeof(Slot);

  ScanMarks() { reset_table(256); }

  /// Packs the block coordinate of a key, 21 bits per axis (keys are within +-2^23).
  static std::uint64_t block_id(const Key& k) noexcept {
    auto c = [](std::int32_t v) {
      return static_cast<std::uint64_t>(static_cast<std::uint32_t>((v >> 3) + (1 << 20)) & 0x1FFFFFu);
    };
    return c(k.x) | (c(k.y) << 21) | (c(k.z) << 42);
  }
  /// Minimum key of the block with packed id \p id.
  static Key block_base(std::uint64_t id) noexcept {
    auto c = [](std::uint64_t v) {
      return static_cast<std::int32_t>(static_cast<std::int64_t>(v & 0x1FFFFFu) - (1 << 20)) * 8;
    };
    return Key{c(id), c(id >> 21), c(id >> 42)};
  }

  /// The marks of block \p id, created (zeroed) if new. The pointer stays valid until the next
  /// call that creates a block, or clear().
  BlockMarks* get(std::uint64_t id) {
    std::size_t i = slot(id);
    for (;; i = (i + 1) & mask_) {
      const Slot& s = table_[i];
      if (s.id == id) return &marks_[s.index];
      if (s.id == kEmpty) break;
    }
    if ((ids_.size() + 1) * 2 > table_.size()) {
      grow();
      i = slot(id);
      while (table_[i].id != kEmpty) i = (i + 1) & mask_;
    }
    table_[i] = Slot{id, static_cast<std::uint32_t>(ids_.size())};
    ids_.push_back(id);
    marks_.push_back(BlockMarks{});
    return &marks_.back();
  }

  /// Forgets every mark; keeps the memory.
  void clear() noexcept {
    for (std::uint64_t id : ids_) {
      std::size_t i = slot(id);
      while (table_[i].id != id) i = (i + 1) & mask_;
      table_[i].id = kEmpty;
    }
    // Removing entries from a linear-probing table may leave holes in other chains, but every
    // entry is removed here, so the table ends fully empty.
    ids_.clear();
    marks_.clear();
  }

  /// Adds every mark of \p o (set union); stops, returning false, once more than \p limit
  /// blocks are marked (the union is then incomplete).
  bool merge(const ScanMarks& o, std::size_t limit = ~std::size_t{0}) {
    for (std::size_t j = 0; j < o.ids_.size(); ++j) {
      if (ids_.size() > limit) return false;
      BlockMarks* m = get(o.ids_[j]);
      const BlockMarks& s = o.marks_[j];
      for (int w = 0; w < 8; ++w) {
        m->miss[w] |= s.miss[w];
        m->hit[w] |= s.hit[w];
      }
    }
    return ids_.size() <= limit;
  }

  std::size_t size() const noexcept { return ids_.size(); }
  std::uint64_t id(std::size_t j) const noexcept { return ids_[j]; }
  const BlockMarks& marks(std::size_t j) const noexcept { return marks_[j]; }
  std::size_t memory_bytes() const noexcept {
    return table_.capacity() * sizeof(Slot) + ids_.capacity() * sizeof(std::uint64_t) +
           marks_.capacity() * sizeof(BlockMarks);
  }

 private:
  std::size_t slot(std::uint64_t id) const noexcept {
    return static_cast<std::size_t>((id * 0x9E3779B97F4A7C15ULL) >> shift_);
  }
  void reset_table(std::size_t n) {
    table_.assign(n, Slot{kEmpty, 0});
    mask_ = n - 1;
    shift_ = 64 - std::countr_zero(n);
  }
  void grow() {
    reset_table(table_.size() * 2);
    for (std::size_t j = 0; j < ids_.size(); ++j) {
      std::size_t i = slot(ids_[j]);
      while (table_[i].id != kEmpty) i = (i + 1) & mask_;
      table_[i] = Slot{ids_[j], static_cast<std::uint32_t>(j)};
    }
  }

  std::vector<Slot> table_;
  std::vector<std::uint64_t> ids_;
  std::vector<BlockMarks> marks_;
  std::size_t mask_ = 0;
  int shift_ = 64;
};

/// A box of 8^3 blocks, in block coordinates (key >> 3), bounds included: the part of a scan's
/// key box that one pass of the block-hash marks covers.
struct BlockRegion {
  std::int32_t lo[3], hi[3];

  /// Every block of the key range (keys within +-2^23).
  static constexpr BlockRegion everywhere() noexcept {
    return BlockRegion{{-(1 << 20), -(1 << 20), -(1 << 20)}, {(1 << 20) - 1, (1 << 20) - 1, (1 << 20) - 1}};
  }

  bool contains(std::int32_t bx, std::int32_t by, std::int32_t bz) const noexcept {
    return bx >= lo[0] && bx <= hi[0] && by >= lo[1] && by <= hi[1] && bz >= lo[2] && bz <= hi[2];
  }
  /// True if the blocks of keys [a, b] (per axis, either order) meet the region.
  bool meets(const Key& a, const Key& b) const noexcept {
    for (int i = 0; i < 3; ++i) {
      const std::int32_t l = std::min(a[i], b[i]) >> 3, h = std::max(a[i], b[i]) >> 3;
      if (h < lo[i] || l > hi[i]) return false;
    }
    return true;
  }
  std::int64_t blocks() const noexcept {
    std::int64_t n = 1;
    for (int i = 0; i < 3; ++i) n *= std::int64_t{hi[i]} - lo[i] + 1;
    return n;
  }
  /// Splits the region in halves across its longest axis (precondition: blocks() > 1).
  std::pair<BlockRegion, BlockRegion> split() const noexcept {
    int a = 0;
    for (int i = 1; i < 3; ++i)
      if (hi[i] - lo[i] > hi[a] - lo[a]) a = i;
    BlockRegion first = *this, second = *this;
    const std::int32_t mid = lo[a] + (hi[a] - lo[a]) / 2;
    first.hi[a] = mid;
    second.lo[a] = mid + 1;
    return {first, second};
  }
};

/// Marks rays into a ScanMarks, caching the current block. Only voxels inside a BlockRegion are
/// marked, and marking stops (overflowed()) once the marks hold more than a given number of
/// blocks: the bound that keeps the scratch of a scan finite whatever the length of its rays.
class RayMarker {
 public:
  RayMarker(ScanMarks& marks, const BlockRegion& region, std::size_t max_blocks)
      : marks_(&marks), region_(region), max_blocks_(max_blocks) {}

  /// True once the marks exceeded the block budget (the marks are then incomplete).
  bool overflowed() const noexcept { return overflow_; }

  /// Traverses one prepared segment: misses from the first voxel up to, not including, the last;
  /// a hit in the last if \p hit; each only inside the region. A walk that leaves the region
  /// after having been inside stops there (an axis-aligned box is convex).
  void mark(const Point3& v0, const Point3& v1, const Key& k0, const Key& k1, bool hit) {
    if (overflow_ || !region_.meets(k0, k1)) return;
    const SegmentDda dda(v0, v1, k0, k1);
    const std::uint64_t n = dda.remaining;
    if (n != 0) {
      // The same walk as SegmentDda::advance(), written branch-free in registers: the axis
      // choice of a ray is unpredictable, so a branch there costs a misprediction per step.
      constexpr double inf = std::numeric_limits<double>::infinity();
      std::int32_t kx = k0.x, ky = k0.y, kz = k0.z;
      const std::int32_t sx = dda.step[0], sy = dda.step[1], sz = dda.step[2];
      const std::int32_t ex = k1.x, ey = k1.y, ez = k1.z;
      double tx = dda.t_max[0], ty = dda.t_max[1], tz = dda.t_max[2];
      const double dx = dda.t_delta[0], dy = dda.t_delta[1], dz = dda.t_delta[2];
      std::uint64_t id = ScanMarks::block_id(k0);
      // Bits of the current 64-bit word (one z-slice of a block) gather in a register and are
      // written when the walk leaves that word: no store-to-load chain through memory per step.
      // Outside the region the word is null and the bits are dropped.
      std::uint64_t* word = word_of(id, kx, ky, kz);
      if (overflow_) return;
      std::uint64_t acc = 0;
      for (std::uint64_t i = n;;) {
        acc |= std::uint64_t{1} << ((kx & 7) | ((ky & 7) << 3));
        if (--i == 0) break;
        // Ties step the higher axis (OctoMap's rule); an axis that reached its end key never
        // steps again (its t becomes inf), so the walk ends exactly in k1.
        const bool xy = tx < ty;
        const double m = xy ? tx : ty;
        const bool selz = !(m < tz);
        const bool selx = xy && !selz;
        const bool sely = !xy && !selz;
        kx += selx ? sx : 0;
        ky += sely ? sy : 0;
        kz += selz ? sz : 0;
        tx = selx ? (kx == ex ? inf : tx + dx) : tx;
        ty = sely ? (ky == ey ? inf : ty + dy) : ty;
        tz = selz ? (kz == ez ? inf : tz + dz) : tz;
        const std::uint64_t next = ScanMarks::block_id(Key{kx, ky, kz});
        if (selz || next != id) {
          if (word) *word |= acc;
          acc = 0;
          const bool was_in = word != nullptr;
          if (next != id || !was_in) {
            word = word_of(next, kx, ky, kz);
            if (overflow_ || (was_in && !word)) return;  // budget spent, or left the region for good
          } else {
            word = &last_->miss[kz & 7];
          }
          id = next;
        }
      }
      if (word) *word |= acc;
    }
    if (hit && region_.contains(k1.x >> 3, k1.y >> 3, k1.z >> 3)) {  // the walk ends exactly in k1 (SegmentDda)
      const Key& k = k1;
      if (BlockMarks* b = block_of(ScanMarks::block_id(k))) b->hit[k.z & 7] |= std::uint64_t{1} << ((k.x & 7) | ((k.y & 7) << 3));
    }
  }

 private:
  /// The miss word of voxel (kx, ky, kz) in block \p id, or nullptr outside the region.
  std::uint64_t* word_of(std::uint64_t id, std::int32_t kx, std::int32_t ky, std::int32_t kz) {
    if (!region_.contains(kx >> 3, ky >> 3, kz >> 3)) return nullptr;
    BlockMarks* b = block_of(id);
    return b ? &b->miss[kz & 7] : nullptr;
  }
  BlockMarks* block_of(std::uint64_t id) {
    if (id != last_id_) {
      last_ = marks_->get(id);
      last_id_ = id;
      if (marks_->size() > max_blocks_) {
        overflow_ = true;
        return nullptr;
      }
    }
    return last_;
  }

  ScanMarks* marks_;
  BlockRegion region_;
  std::size_t max_blocks_;
  std::uint64_t last_id_ = ScanMarks::kEmpty;
  BlockMarks* last_ = nullptr;
  bool overflow_ = false;
};

/// One input ray that passed prepare_ray(): its segment in voxel coordinates and keys.
struct PreparedRay {
  Point3 v0, v1;
  Key k0, k1;
  bool hit;

  /// The voxels its walk enumerates (the work it takes): the key distance plus one.
  std::uint64_t cost() const noexcept {
    std::uint64_t n = 1;
    for (int a = 0; a < 3; ++a) n += static_cast<std::uint64_t>(std::abs(std::int64_t{k1[a]} - k0[a]));
    return n;
  }
};

/// A position in a list of prepared-ray lists taken as one sequence (list, index).
struct RayPos {
  std::size_t list = 0, index = 0;
  friend bool operator==(const RayPos&, const RayPos&) = default;
};

/// Hands out the prepared rays from \p begin up to \p end of the lists, in order.
class RayCursor {
 public:
  RayCursor(const std::vector<std::vector<PreparedRay>>& lists, RayPos begin, RayPos end) noexcept
      : lists_(&lists), at_(begin), end_(end) {}
  /// The next ray, or nullptr after the last.
  const PreparedRay* next() noexcept {
    for (;;) {
      if (at_ == end_) return nullptr;
      const auto& l = (*lists_)[at_.list];
      if (at_.index < l.size()) return &l[at_.index++];
      ++at_.list;
      at_.index = 0;
    }
  }

 private:
  const std::vector<std::vector<PreparedRay>>* lists_;
  RayPos at_, end_;
};

/// Splits the first \p n lists of prepared rays, taken as one sequence, into \p n runs of
/// about equal cost (PreparedRay::cost()), given each list's total \p cost: run t is
/// [bounds[t], bounds[t + 1]), so that threads get equal work whatever the scan's layout (in an
/// image, rows that see the near floor and rows that see far walls differ several times in cost).
inline std::vector<RayPos> balanced_runs(const std::vector<std::vector<PreparedRay>>& lists,
                                         const std::vector<std::uint64_t>& cost, unsigned n) {
  std::vector<RayPos> bounds(n + 1);
  bounds[n] = RayPos{n, 0};
  std::uint64_t total = 0;
  for (unsigned t = 0; t < n; ++t) total += cost[t];
  std::size_t list = 0;
  std::uint64_t before = 0;  // cost of the lists before `list`
  for (unsigned t = 1; t < n; ++t) {
    const std::uint64_t target = total * t / n;
    while (list < n && before + cost[list] <= target) before += cost[list++];
    if (list == n) {
      bounds[t] = RayPos{n, 0};
      continue;
    }
    std::uint64_t acc = before;
    std::size_t i = 0;
    const auto& l = lists[list];
    while (i < l.size() && acc < target) acc += l[i++].cost();
    bounds[t] = RayPos{list, i};
  }
  return bounds;
}

/// Checks one input ray against the options; on success fills the segment to traverse.
inline bool prepare_ray(const GridGeometry& g, const InsertOptions& o, const RayInput& r, Point3& v0,
                        Point3& v1, Key& k0, Key& k1, bool& hit, InsertStats& st) noexcept {
  if (!is_finite(r.origin) || !is_finite(r.end)) {
    ++st.skipped_invalid;
    return false;
  }
  const Point3 d = r.end - r.origin;
  const double len = d.norm();
  if (len == 0.0) {
    ++st.skipped_zero_length;
    return false;
  }
  if (!std::isfinite(len)) {  // coordinates near the double limit: far outside the key range
    ++st.skipped_key_range;
    return false;
  }
  Point3 end = r.end;
  hit = r.hit;
  bool cut = false;
  if (hit) {
    if (len < o.min_range) {
      ++st.skipped_min_range;
      return false;
    }
    if (o.has_max_range() && len > o.max_range) {
      end = r.origin + d * (o.max_range / len);
      hit = false;
      cut = true;
    }
  } else {
    if (!o.has_max_range()) {
      ++st.skipped_no_max_range;
      return false;
    }
    end = r.origin + d * (o.max_range / len);
    cut = true;
  }
  if (!voxel_of(g, r.origin, v0, k0) || !voxel_of(g, end, v1, k1)) {
    ++st.skipped_key_range;
    return false;
  }
  ++st.rays;
  if (cut) ++st.truncated;
  return true;
}

/// Test access to ScanInserter's internals (forces the block-hash marks).
struct ScanInserterAccess {
  template <class I>
  static void force_hash(I& inserter, bool on) noexcept {
    inserter.force_hash_ = on;
  }
  /// Sets the largest scan whose prepared rays are kept between the two passes, and the chunk
  /// of rays prepared again at a time in larger scans.
  template <class I>
  static void set_max_kept_rays(I& inserter, std::size_t n, std::size_t chunk) noexcept {
    inserter.max_kept_rays_ = n;
    inserter.chunk_rays_ = chunk;
  }
  /// Chooses the marking walk (detail::walk_rays()); all give the same result.
  template <class I>
  static void set_walk(I& inserter, WalkKind walk) noexcept {
    inserter.walk_ = walk;
  }
};

/// True for containers laid out in 8^3 blocks exactly as ScanMarks (SparseBlocks).
template <class C>
concept BlockContainer = requires(C& c, const Key& k) {
  { c.touch_block(k) };
  { C::cell_index(k) } -> std::convertible_to<std::size_t>;
} && (C::kBlockSize == 8);

/// True for containers whose touch() never allocates (C::kConcurrentTouch), so that several
/// threads may touch distinct keys at once (DenseArray).
template <class C>
concept ConcurrentTouch = requires {
  requires C::kConcurrentTouch;
};

/// The bits of word \p w (z = base.z + w) of the BlockMarks of the block at \p base whose
/// voxels lie inside \p box (bit x + 8 y).
inline std::uint64_t box_word_mask(const KeyBox& box, const Key& base, int w) noexcept {
  const std::int32_t z = base.z + w;
  if (z < box.min.z || z > box.max.z) return 0;
  auto range = [&](int a) {  // the in-box offsets [l, h] of the block along axis a
    const std::int32_t l = std::max(0, box.min[a] - base[a]), h = std::min(7, box.max[a] - base[a]);
    return std::pair{l, h};
  };
  const auto [xl, xh] = range(0);
  const auto [yl, yh] = range(1);
  if (xl > xh || yl > yh) return 0;
  const std::uint64_t row = ((std::uint64_t{1} << (xh + 1)) - 1) & ~((std::uint64_t{1} << xl) - 1);
  std::uint64_t m = 0;
  for (std::int32_t y = yl; y <= yh; ++y) m |= row << (8 * y);
  return m;
}

}  // namespace detail

/// A reusable inserter: keeps its scratch buffers (the per-scan voxel marks, one set per
/// thread) across scans, so repeated insertion allocates nothing once warmed up. Scratch is
/// bounded whatever the scan: per thread two bitmaps over the scan's key box (at most 32 MiB;
/// larger boxes use a block hash of at most InsertOptions::max_mark_bytes, marked region by
/// region when a scan needs more), and the prepared rays of scans of up to 2^20 rays (80 bytes
/// each; larger scans prepare each ray twice instead, 2^16 at a time per thread).
/// scratch_bytes() reports the total, release_scratch() frees it. The grid itself grows with
/// what the rays cross (a sparse grid allocates 2 KiB per 8^3 block at 4 bytes per cell): set a
/// max range or bounds when rays may be long.
///
/// Semantics (those of OctoMap's `insertPointCloud(cloud, origin, maxrange)`):
///  - each ray is traversed exactly (traverse()) from the voxel of its origin to the voxel of its
///    end; every voxel on the way gets a miss, the end voxel a hit and no miss. If origin and end
///    share a voxel, that voxel only gets the hit;
///  - a point farther than max_range gives a ray cut at max_range with misses only; as in
///    OctoMap, the voxel containing the cut end is not updated. A beam without a return (depth
///    +inf, Beam::hit == false) is free up to max_range in the same way;
///  - per scan (one call) each voxel is updated at most once, and a hit wins over a miss. The
///    marks are cleared exactly after each scan, so this holds for any number of scans;
///  - bad input is skipped and counted, never thrown: NaN/Inf points or origins, points equal
///    to their origin, points closer than min_range, origins or (cut) ends outside the key range.
///    A ray therefore never exceeds the key range (at most 3 * 2^24 voxels); with a max range it
///    is at most about 1.8 * max_range / resolution voxels;
///  - on a bounded grid, updates outside its box are dropped and counted (outside_bounds).
///
/// Determinism: the updated voxels, their values and the grid's block allocation order are the
/// same for every thread count.
///
/// Thread safety: one inserter per thread; the grid needs exclusive access during a call.
class ScanInserter {
 public:
  /// \throws InvalidArgument for invalid options (InsertOptions::validate()).
  explicit ScanInserter(const InsertOptions& options = {}) { set_options(options); }

  const InsertOptions& options() const noexcept { return options_; }
  /// \throws InvalidArgument for invalid options.
  void set_options(const InsertOptions& options) {
    options.validate();
    options_ = options;
  }

  /// Inserts a point cloud seen from \p origin.
  /// \tparam G a VoxelGrid; \tparam O a PointLike origin
  /// \tparam R a random-access sized range of PointLike points (std::vector<Eigen::Vector3f>,
  ///           std::vector<std::array<double, 3>>, std::span of your struct, ...)
  template <class G, PointLike O, std::ranges::random_access_range R>
    requires std::ranges::sized_range<R> && PointLike<std::ranges::range_value_t<R>>
  InsertStats insert_point_cloud(G& grid, const O& origin, const R& points) {
    const Point3 o = to_point(origin);
    const auto first = std::ranges::begin(points);
    return run(grid, static_cast<std::size_t>(std::ranges::size(points)), [&](std::size_t i) {
      return detail::RayInput{o, to_point(first[static_cast<std::ptrdiff_t>(i)]), true};
    });
  }

  /// Inserts a depth image taken from \p pose (camera to world, optical frame: x right, y down,
  /// z forward). Pixels follow the DepthImage rules: finite > 0 is a return at that z-depth,
  /// +inf is no return (free up to max_range), anything else is invalid and skipped.
  /// \throws InvalidArgument if the intrinsics are invalid or do not match the image size, or
  ///         the image buffer is inconsistent.
  template <class G>
  InsertStats insert_depth_image(G& grid, const DepthImage& image, const PinholeIntrinsics& intrinsics,
                                 const Pose& pose) {
    intrinsics.validate();
    if (!image.consistent()) throw InvalidArgument("intervox::insert_depth_image: depth buffer size does not match width x height");
    if (image.width != intrinsics.width || image.height != intrinsics.height)
      throw InvalidArgument("intervox::insert_depth_image: image is " + std::to_string(image.width) + "x" +
                            std::to_string(image.height) + " but the intrinsics are " +
                            std::to_string(intrinsics.width) + "x" + std::to_string(intrinsics.height));
    const Point3 o = pose.translation();
    const Eigen::Matrix3d r = pose.linear();
    const auto w = static_cast<std::size_t>(image.width);
    constexpr double nan = std::numeric_limits<double>::quiet_NaN();
    return run(grid, image.depth.size(), [&](std::size_t i) {
      const double z = image.depth[i];
      const Point3 ray = intrinsics.ray(double(i % w), double(i / w));
      if (z > 0.0 && std::isfinite(z)) return detail::RayInput{o, o + r * (ray * z), true};
      if (z == std::numeric_limits<double>::infinity()) return detail::RayInput{o, o + r * ray, false};
      return detail::RayInput{o, Point3(nan, nan, nan), true};  // invalid pixel
    });
  }

  /// Inserts beams with their own origins (Beam::hit false: free up to max_range).
  template <class G>
  InsertStats insert_beams(G& grid, std::span<const Beam> beams) {
    return run(grid, beams.size(), [&](std::size_t i) {
      const Beam& b = beams[i];
      return detail::RayInput{b.origin, b.end, b.hit};
    });
  }

  /// Inserts one ray from \p origin with a return at \p end (a scan of one ray).
  template <class G, PointLike O, PointLike E>
  InsertStats insert_ray(G& grid, const O& origin, const E& end) {
    const detail::RayInput in{to_point(origin), to_point(end), true};
    return run(grid, 1, [&](std::size_t) { return in; });
  }

  /// Bytes held by the scratch buffers (kept between scans; see the class comment for bounds).
  std::size_t scratch_bytes() const noexcept {
    std::size_t n = 0;
    for (const auto& m : marks_) n += m.memory_bytes();
    for (const auto& m : box_) n += m.memory_bytes();
    for (const auto& r : rays_) n += r.capacity() * sizeof(detail::PreparedRay);
    for (const auto& b : box_blocks_) n += b.capacity() * sizeof(b[0]);
    return n + order_.capacity() * sizeof(order_[0]) + list_.capacity() * sizeof(list_[0]) +
           blocks_.capacity() * sizeof(blocks_[0]);
  }

  /// Frees every scratch buffer (the next scan allocates them again). Call it after a large
  /// scan when the memory is needed elsewhere.
  void release_scratch() {
    decltype(marks_)().swap(marks_);
    decltype(box_)().swap(box_);
    decltype(rays_)().swap(rays_);
    decltype(box_blocks_)().swap(box_blocks_);
    decltype(order_)().swap(order_);
    decltype(list_)().swap(list_);
    decltype(blocks_)().swap(blocks_);
  }

 private:
  static constexpr std::size_t kMinRaysPerThread = 2048;
  /// Scans with more rays prepare each ray twice instead of keeping them (80 bytes per ray)...
  static constexpr std::size_t kMaxKeptRays = std::size_t{1} << 20;
  /// ... the second time this many at a time per thread.
  static constexpr std::size_t kChunkRays = std::size_t{1} << 16;

  unsigned thread_count(std::size_t rays) const {
    const unsigned t = resolve_threads(options_.threads);
    const std::size_t useful = std::max<std::size_t>(1, rays / kMinRaysPerThread);
    return static_cast<unsigned>(std::min<std::size_t>(t, useful));
  }

  /// Prepares rays [begin, end) of \p source into \p out (counting the skipped ones in \p st),
  /// sums their cost and returns the key box of every voxel their walks visit (that of their
  /// end keys); false if no ray is left.
  /// With \p keep false nothing is stored (\p out is left empty).
  template <class Source>
  static bool prepare_range(const GridGeometry& g, const InsertOptions& o, const Source& source, std::size_t begin,
                            std::size_t end, bool keep, std::vector<detail::PreparedRay>& out, InsertStats& st,
                            Key& lo, Key& hi, std::uint64_t& cost) {
    out.clear();
    cost = 0;
    bool any = false;
    detail::PreparedRay p;
    for (std::size_t i = begin; i < end; ++i) {
      if (!detail::prepare_ray(g, o, source(i), p.v0, p.v1, p.k0, p.k1, p.hit, st)) continue;
      if (!any) lo = hi = p.k0;
      any = true;
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min({lo[a], p.k0[a], p.k1[a]});
        hi[a] = std::max({hi[a], p.k0[a], p.k1[a]});
      }
      if (keep) out.push_back(p);
      cost += p.cost();
    }
    return any;
  }

  /// Marks the prepared rays of \p rays into a BoxMarks: hits directly, misses by walk_rays().
  /// (Not a template on the scan's source: the walks are compiled once per program.)
  static void mark_box(detail::RayCursor rays, detail::BoxMarks& marks, detail::WalkKind walk, InsertStats& st) {
    std::uint64_t steps = 0;
    detail::walk_rays(marks, walk, [&](detail::BoxRay& r) {
      while (const detail::PreparedRay* p = rays.next()) {
        if (p->hit) {
          marks.set_hit(marks.id(p->k1));
          ++steps;
        }
        if (detail::make_box_ray(marks, p->v0, p->v1, p->k0, p->k1, r)) {
          steps += static_cast<std::uint64_t>(r.rem) + 1;
          return true;
        }
      }
      return false;
    });
    st.voxel_steps += steps;
  }

  /// Marks the voxels of the prepared rays of \p rays that lie in \p region into a ScanMarks
  /// block hash; false if the marks outgrew \p max_blocks (they are then incomplete).
  static bool mark_hash(detail::RayCursor rays, detail::ScanMarks& marks, const detail::BlockRegion& region,
                        std::size_t max_blocks) {
    detail::RayMarker marker(marks, region, max_blocks);
    while (const detail::PreparedRay* p = rays.next()) {
      marker.mark(p->v0, p->v1, p->k0, p->k1, p->hit);
      if (marker.overflowed()) return false;
    }
    return true;
  }

  /// Runs \p f(t) for t in [0, n) on n threads (t = 0 on the caller), rethrowing the first error.
  template <class F>
  static void parallel(unsigned n, F&& f) {
    run_on_threads(n, f);
  }

  template <class G, class Source>
  InsertStats run(G& grid, std::size_t count, const Source& source) {
    const unsigned nt = thread_count(count);
    if (marks_.size() < nt) marks_.resize(nt);
    if (box_.size() < nt) box_.resize(nt);
    if (rays_.size() < nt) rays_.resize(nt);
    if (box_blocks_.size() < nt) box_blocks_.resize(nt);
    std::vector<InsertStats> part(nt);
    const GridGeometry& g = grid.geometry();

    // Pass 1: validate and prepare every ray, count the skipped ones and find the scan's key
    // box. The prepared rays are kept for pass 2 unless the scan has more than max_kept_rays_
    // (bounded scratch: they are then prepared again). The box decides the marks: two bitmaps
    // over it if small enough, else the block hash. No choice depends on the thread count.
    const bool keep = count <= max_kept_rays_;
    std::vector<Key> lo(nt), hi(nt);
    std::vector<char> any(nt, 0);
    std::vector<std::uint64_t> cost(nt, 0);
    parallel(nt, [&](unsigned t) {
      const std::size_t b = count * t / nt, e = count * (t + 1) / nt;
      any[t] = prepare_range(g, options_, source, b, e, keep, rays_[t], part[t], lo[t], hi[t], cost[t]) ? 1 : 0;
    });
    bool have = false;
    Key blo, bhi;
    for (unsigned t = 0; t < nt; ++t) {
      if (!any[t]) continue;
      if (!have) blo = lo[t], bhi = hi[t];
      have = true;
      for (int a = 0; a < 3; ++a) {
        blo[a] = std::min(blo[a], lo[t][a]);
        bhi[a] = std::max(bhi[a], hi[t][a]);
      }
    }
    bool dense = have && !force_hash_;
    for (unsigned t = 0; dense && t < nt; ++t) dense = box_[t].reset(blo, bhi);

    // Each thread's rays for pass 2: runs of the kept rays of equal walk length.
    const std::vector<detail::RayPos> runs = nt > 1 && keep ? detail::balanced_runs(rays_, cost, nt)
                                                            : std::vector<detail::RayPos>{{0, 0}, {nt, 0}};
    // Calls f(cursor) with thread t's rays: its run of the kept rays, or its chunk of pass 1
    // prepared again, chunk_rays_ at a time into its ray list.
    auto with_rays = [&](unsigned t, auto&& f) {
      if (keep) {
        f(detail::RayCursor(rays_, runs[t], runs[t + 1]));
        return;
      }
      const std::size_t b = count * t / nt, e = count * (t + 1) / nt;
      for (std::size_t c = b; c < e; c += chunk_rays_) {
        InsertStats counted_before;
        Key l, h;
        std::uint64_t ignored = 0;
        prepare_range(g, options_, source, c, std::min(e, c + chunk_rays_), true, rays_[t], counted_before, l, h, ignored);
        f(detail::RayCursor(rays_, detail::RayPos{t, 0}, detail::RayPos{t, rays_[t].size()}));
      }
    };
    list_.clear();
    if (dense) {
      // Pass 2: mark, each thread a run of the prepared rays of equal walk length (or, not
      // kept, its chunk of pass 1) into its own bitmaps, OR-merged: the split changes nothing.
      parallel(nt, [&](unsigned t) { with_rays(t, [&](auto rays) { mark_box(rays, box_[t], walk_, part[t]); }); });
      // The blocks with a mark, the threads' bitmaps OR-ed, in block order (z, y, x): the order
      // of the packed block ids below. Each thread converts a slab of block layers.
      const std::int64_t layers = box_[0].block_layers();
      parallel(nt, [&](unsigned t) {
        auto& out = box_blocks_[t];
        out.clear();
        detail::BoxMarks::for_each_block(box_.data(), nt, layers * t / nt, layers * (t + 1) / nt,
                                         [&](const Key& base, const detail::BlockMarks& m) { out.emplace_back(base, m); });
      });
      for (unsigned t = 0; t < nt; ++t)
        for (const auto& [base, m] : box_blocks_[t]) list_.emplace_back(base, &m);
      InsertStats st;
      for (const auto& p : part) st += p;
      apply(grid, nt, st);
      return st;
    }
    // The block hash, one region of the key box at a time: a region whose marks would hold more
    // than max_mark_blocks() blocks is split in halves and each half marked and applied in
    // turn (depth first), so the scratch stays bounded however long the rays are. Each voxel
    // lies in exactly one region, so the per-scan semantics hold. Whether a region is split
    // depends only on its distinct blocks (a thread that overflows implies the union does), so
    // the regions, and the block allocation order, are the same for every thread count.
    InsertStats st;
    for (const auto& p : part) st += p;
    std::uint64_t total_cost = 0;
    for (unsigned t = 0; t < nt; ++t) total_cost += cost[t];
    if (!have) return st;
    st.voxel_steps = total_cost - st.truncated;  // every walk's misses, plus the hits
    const std::size_t max_blocks = max_mark_blocks();
    std::vector<detail::BlockRegion> pending{detail::BlockRegion{{blo.x >> 3, blo.y >> 3, blo.z >> 3}, {bhi.x >> 3, bhi.y >> 3, bhi.z >> 3}}};
    std::vector<char> fits(nt);
    while (!pending.empty()) {
      const detail::BlockRegion region = pending.back();
      pending.pop_back();
      parallel(nt, [&](unsigned t) {
        fits[t] = 1;
        with_rays(t, [&](auto rays) {
          if (fits[t]) fits[t] = mark_hash(rays, marks_[t], region, max_blocks) ? 1 : 0;
        });
      });
      detail::ScanMarks& all = marks_[0];
      bool fit = std::all_of(fits.begin(), fits.end(), [](char f) { return f != 0; });
      for (unsigned t = 1; t < nt; ++t) {
        fit = fit && all.merge(marks_[t], max_blocks);
        marks_[t].clear();
      }
      if (!fit && region.blocks() > 1) {  // (one block always fits: max_blocks >= 1)
        all.clear();
        const auto [first, second] = region.split();
        pending.push_back(second);
        pending.push_back(first);
        continue;
      }
      // Deterministic order: by packed block id, whatever the thread count or ray order.
      order_.resize(all.size());
      for (std::size_t j = 0; j < all.size(); ++j) order_[j] = {all.id(j), static_cast<std::uint32_t>(j)};
      std::sort(order_.begin(), order_.end());
      list_.clear();
      for (const auto& [id, j] : order_) list_.emplace_back(detail::ScanMarks::block_base(id), &all.marks(j));
      InsertStats applied;
      apply(grid, nt, applied);
      st.hits += applied.hits;
      st.misses += applied.misses;
      st.outside_bounds += applied.outside_bounds;
      all.clear();
    }
    return st;
  }

  /// The block budget of the hash marks per thread (InsertOptions::max_mark_bytes), at least 1.
  std::size_t max_mark_blocks() const noexcept {
    return std::max<std::size_t>(1, options_.max_mark_bytes / detail::ScanMarks::kBytesPerBlock);
  }

  /// Applies the marks of list_ to the grid: a hit where a hit bit is set, else a miss where a
  /// miss bit is set; marks outside a bounded grid's box are counted in outside_bounds. One loop
  /// for every storage: block containers get their blocks allocated first (serially: the only
  /// step that changes their table) and are then updated block by block on \p nt threads;
  /// other containers go through touch() per cell, on several threads only if their touch()
  /// never allocates (detail::ConcurrentTouch).
  template <class G>
  void apply(G& grid, unsigned nt, InsertStats& st) {
    auto& storage = grid.storage();
    const auto& policy = grid.update_policy();
    using Container = std::remove_reference_t<decltype(storage)>;
    using Cell = typename G::Cell;
    constexpr bool by_block = detail::BlockContainer<Container>;
    const std::optional<KeyBox>& box = storage.box();

    if constexpr (by_block) {
      blocks_.resize(list_.size());
      for (std::size_t j = 0; j < list_.size(); ++j) {
        // A key of the block inside the box (a box may cut blocks), or none.
        Key k = list_[j].first;
        bool meets = true;
        if (box) {
          for (int a = 0; a < 3; ++a) {
            k[a] = std::max(k[a], box->min[a]);
            meets = meets && k[a] <= std::min(box->max[a], list_[j].first[a] + 7);
          }
        }
        auto* b = meets ? storage.touch_block(k) : nullptr;
        blocks_[j] = b ? b->data() : nullptr;
      }
    }
    const unsigned workers = by_block || detail::ConcurrentTouch<Container> ? nt : 1u;
    std::vector<InsertStats> part(workers);
    parallel(workers, [&](unsigned t) {
      const std::size_t b = list_.size() * t / workers, e = list_.size() * (t + 1) / workers;
      InsertStats& s = part[t];
      for (std::size_t j = b; j < e; ++j) {
        const detail::BlockMarks& m = *list_[j].second;
        const Key base = list_[j].first;
        [[maybe_unused]] Cell* cells = nullptr;
        if constexpr (by_block) cells = static_cast<Cell*>(blocks_[j]);
        for (int w = 0; w < 8; ++w) {
          std::uint64_t h = m.hit[w], f = m.miss[w] & ~h;
          if ((h | f) == 0) continue;
          std::uint64_t in = box ? detail::box_word_mask(*box, base, w) : ~std::uint64_t{0};
          if constexpr (by_block) {
            if (!cells) in = 0;
          }
          s.outside_bounds += static_cast<std::uint64_t>(std::popcount((h | f) & ~in));
          h &= in;
          f &= in;
          if constexpr (by_block) {
            Cell* row = cells + 64 * w;
            for (std::uint64_t bits = h; bits; bits &= bits - 1) policy.update(row[std::countr_zero(bits)], Observation::Hit);
            for (std::uint64_t bits = f; bits; bits &= bits - 1) policy.update(row[std::countr_zero(bits)], Observation::Miss);
            s.hits += static_cast<std::uint64_t>(std::popcount(h));
            s.misses += static_cast<std::uint64_t>(std::popcount(f));
          } else {
            auto visit = [&](std::uint64_t bits, Observation obs, std::uint64_t& count) {
              for (; bits; bits &= bits - 1) {
                const int i = std::countr_zero(bits);
                if (Cell* c = storage.touch(Key{base.x + (i & 7), base.y + (i >> 3), base.z + w})) {
                  policy.update(*c, obs);
                  ++count;
                } else {
                  ++s.outside_bounds;
                }
              }
            };
            visit(h, Observation::Hit, s.hits);
            visit(f, Observation::Miss, s.misses);
          }
        }
      }
    });
    for (const auto& p : part) {
      st.hits += p.hits;
      st.misses += p.misses;
      st.outside_bounds += p.outside_bounds;
    }
  }

  InsertOptions options_;
  std::vector<detail::ScanMarks> marks_;
  std::vector<detail::BoxMarks> box_;
  std::vector<std::vector<detail::PreparedRay>> rays_;
  std::vector<std::vector<std::pair<Key, detail::BlockMarks>>> box_blocks_;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> order_;
  std::vector<std::pair<Key, const detail::BlockMarks*>> list_;
  std::vector<void*> blocks_;
  bool force_hash_ = false;
  std::size_t max_kept_rays_ = kMaxKeptRays;
  std::size_t chunk_rays_ = kChunkRays;
  detail::WalkKind walk_ = detail::WalkKind::Fastest;

  friend struct detail::ScanInserterAccess;
};

/// Inserts a point cloud seen from \p origin (see ScanInserter for the semantics). Allocates
/// scratch buffers per call: use a ScanInserter for repeated scans.
/// \tparam G a VoxelGrid; \tparam O PointLike; \tparam R a random-access sized range of PointLike
/// \throws InvalidArgument for invalid options
template <class G, PointLike O, std::ranges::random_access_range R>
  requires std::ranges::sized_range<R> && PointLike<std::ranges::range_value_t<R>>
InsertStats insert_point_cloud(G& grid, const O& origin, const R& points, const InsertOptions& options = {}) {
  return ScanInserter(options).insert_point_cloud(grid, origin, points);
}

/// Inserts a depth image (see ScanInserter::insert_depth_image).
/// \tparam G a VoxelGrid
/// \throws InvalidArgument for invalid options, intrinsics or image
template <class G>
InsertStats insert_depth_image(G& grid, const DepthImage& image, const PinholeIntrinsics& intrinsics,
                               const Pose& pose, const InsertOptions& options = {}) {
  return ScanInserter(options).insert_depth_image(grid, image, intrinsics, pose);
}

/// Inserts beams with their own origins as one scan (see ScanInserter::insert_beams).
/// \tparam G a VoxelGrid
/// \throws InvalidArgument for invalid options
template <class G>
InsertStats insert_beams(G& grid, std::span<const Beam> beams, const InsertOptions& options = {}) {
  return ScanInserter(options).insert_beams(grid, beams);
}

/// Inserts a single ray with a return at \p end (misses along it, a hit at its end).
/// \tparam G a VoxelGrid; \tparam O, E PointLike
/// \throws InvalidArgument for invalid options
template <class G, PointLike O, PointLike E>
InsertStats insert_ray(G& grid, const O& origin, const E& end, const InsertOptions& options = {}) {
  return ScanInserter(options).insert_ray(grid, origin, end);
}

}  // namespace intervox
