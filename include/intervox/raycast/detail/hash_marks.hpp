#pragma once
/// \file
/// Internal part of ray insertion: the per-scan voxel marks of scans whose key box is too large
/// for the box bitmaps (box_marks.hpp): 8x8x8-block bitmaps in an open-addressing table
/// (ScanMarks), the part of the key box one pass covers (BlockRegion), and the walk that fills
/// them (RayMarker: SegmentDda's steps, branch-free, one ray at a time).
///
/// Thread safety: a ScanMarks and its RayMarker are used by one thread at a time.

#include <intervox/core/key.hpp>
#include <intervox/grid/sparse_storage.hpp>
#include <intervox/raycast/detail/block_marks.hpp>
#include <intervox/raycast/detail/prepare_ray.hpp>
#include <intervox/raycast/traversal.hpp>

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

namespace intervox::detail {

/// The set of voxels one scan touches, as 8^3-block bitmaps in an open-addressing table keyed
/// by the packed block coordinate (the sparse storage's block id, block_id_of()). Cleared
/// exactly between scans (no stamps, no wrap-around).
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

  /// The packed block coordinate of a key: the sparse storage's block id (block_id_of()).
  static std::uint64_t block_id(const Key& k) noexcept { return block_id_of(k); }
  /// Minimum key of the block with packed id \p id.
  static Key block_base(std::uint64_t id) noexcept { return block_base_of(id); }

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
  /// a hit in the last if it has one; each only inside the region. A walk that leaves the region
  /// after having been inside stops there (an axis-aligned box is convex).
  void mark(const PreparedRay& p) {
    const Key &k0 = p.k0, &k1 = p.k1;
    if (overflow_ || !region_.meets(k0, k1)) return;
    const SegmentDda dda(p.v0, p.v1, k0, k1);
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
    if (p.hit && region_.contains(k1.x >> 3, k1.y >> 3, k1.z >> 3)) {  // the walk ends exactly in k1 (SegmentDda)
      const Key& k = k1;
      if (BlockMarks* b = block_of(ScanMarks::block_id(k)))
        b->hit[k.z & 7] |= std::uint64_t{1} << ((k.x & 7) | ((k.y & 7) << 3));
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

}  // namespace intervox::detail
