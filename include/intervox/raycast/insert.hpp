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
#include <intervox/raycast/traversal.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
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
  /// std::thread::hardware_concurrency(). The result is identical for every value.
  unsigned threads = 1;

  /// True if a finite, non-negative max range is set.
  bool has_max_range() const noexcept { return max_range >= 0.0 && std::isfinite(max_range); }

  /// \throws InvalidArgument if max_range is NaN, min_range is NaN, negative or infinite, or
  ///         min_range exceeds a set max_range.
  void validate() const {
    if (std::isnan(max_range)) throw InvalidArgument("intervox::InsertOptions: max_range is NaN");
    if (!(min_range >= 0.0 && std::isfinite(min_range)))
      throw InvalidArgument("intervox::InsertOptions: min_range must be finite and >= 0, got " +
                            std::to_string(min_range));
    if (has_max_range() && min_range > max_range)
      throw InvalidArgument("intervox::InsertOptions: min_range " + std::to_string(min_range) +
                            " exceeds max_range " + std::to_string(max_range));
  }
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

/// Per-scan marks of one 8x8x8 block: bit (x | y << 3) of word z, for misses and for hits.
struct BlockMarks {
  std::uint64_t miss[8];
  std::uint64_t hit[8];
};

/// The set of voxels one scan touches, as 8^3-block bitmaps in an open-addressing table keyed
/// by the packed block coordinate. Cleared exactly between scans (no stamps, no wrap-around).
class ScanMarks {
 public:
  static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};  // never a packed id (63 bits)

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

  /// Adds every mark of \p o (set union).
  void merge(const ScanMarks& o) {
    for (std::size_t j = 0; j < o.ids_.size(); ++j) {
      BlockMarks* m = get(o.ids_[j]);
      const BlockMarks& s = o.marks_[j];
      for (int w = 0; w < 8; ++w) {
        m->miss[w] |= s.miss[w];
        m->hit[w] |= s.hit[w];
      }
    }
  }

  std::size_t size() const noexcept { return ids_.size(); }
  std::uint64_t id(std::size_t j) const noexcept { return ids_[j]; }
  const BlockMarks& marks(std::size_t j) const noexcept { return marks_[j]; }
  std::size_t memory_bytes() const noexcept {
    return table_.capacity() * sizeof(Slot) + ids_.capacity() * sizeof(std::uint64_t) +
           marks_.capacity() * sizeof(BlockMarks);
  }

 private:
  struct Slot {
    std::uint64_t id;
    std::uint32_t index;
  };
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

/// Marks rays into a ScanMarks, caching the current block.
class RayMarker {
 public:
  explicit RayMarker(ScanMarks& marks) : marks_(&marks) {}

  /// Traverses one prepared segment: misses from the first voxel up to, not including, the last;
  /// a hit in the last if \p hit. Returns the number of voxels enumerated.
  std::uint64_t mark(const Point3& v0, const Point3& v1, const Key& k0, const Key& k1, bool hit) {
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
      std::uint64_t* word = &block_of(id)->miss[kz & 7];
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
          *word |= acc;
          acc = 0;
          id = next;
          word = &block_of(id)->miss[kz & 7];
        }
      }
      *word |= acc;
    }
    if (hit) {  // the walk ends exactly in k1 (SegmentDda)
      const Key& k = k1;
      block_of(ScanMarks::block_id(k))->hit[k.z & 7] |= std::uint64_t{1} << ((k.x & 7) | ((k.y & 7) << 3));
    }
    return n + (hit ? 1 : 0);
  }

 private:
  BlockMarks* block_of(std::uint64_t id) {
    if (id != last_id_) {
      last_ = marks_->get(id);
      last_id_ = id;
    }
    return last_;
  }

  ScanMarks* marks_;
  std::uint64_t last_id_ = ScanMarks::kEmpty;
  BlockMarks* last_ = nullptr;
};

/// The per-scan marks as a dense array of BlockMarks over the scan's bounding box (in 8^3
/// blocks, x fastest), used when that box is small enough (kMaxBlocks). A voxel's mark is bit
/// `id & 63` of word `id >> 6` of the array seen as 64-bit words, where `id` is the sum of one
/// offset per axis (offset()): the inner loop adds three table entries instead of hashing.
class DenseMarks {
 public:
  /// Largest box handled (blocks of 128 bytes: 32 MiB per thread); larger scans use ScanMarks.
  static constexpr std::size_t kMaxBlocks = std::size_t{1} << 18;

  /// Clears every mark, then covers the keys [lo, hi] (inclusive) with clear marks; false if
  /// the box is too large (then the object is empty).
  bool reset(const Key& lo, const Key& hi) {
    clear();  // also after an exception left marks behind
    used_ = 0;
    std::int64_t n[3];
    for (int a = 0; a < 3; ++a) {
      base_[a] = lo[a] & ~7;  // floor to a multiple of 8 (two's complement)
      n[a] = (std::int64_t{hi[a]} - base_[a]) / 8 + 1;
      if (n[a] > static_cast<std::int64_t>(kMaxBlocks)) return false;
    }
    if (n[0] * n[1] * n[2] > static_cast<std::int64_t>(kMaxBlocks)) return false;
    for (int a = 0; a < 3; ++a) blocks_[a] = static_cast<std::int32_t>(n[a]);
    used_ = static_cast<std::size_t>(n[0] * n[1] * n[2]);
    if (marks_.size() < used_) marks_.resize(used_, BlockMarks{});
    stride_[0] = 1024;  // bits per block
    stride_[1] = 1024 * std::int64_t{blocks_[0]};
    stride_[2] = stride_[1] * blocks_[1];
    return true;
  }

  /// The part of a voxel's bit id contributed by its coordinate \p k on axis \p a.
  std::int64_t offset(int a, std::int32_t k) const noexcept {
    static constexpr std::int64_t kUnit[3] = {1, 8, 64};
    const std::int64_t r = std::int64_t{k} - base_[a];
    return (r >> 3) * stride_[a] + (r & 7) * kUnit[a];
  }
  /// The minimum key of the box on axis \p a (a multiple of 8).
  std::int32_t base(int a) const noexcept { return base_[a]; }
  /// The bit-id distance between two neighbouring blocks along axis \p a.
  std::int64_t block_stride(int a) const noexcept { return stride_[a]; }
  /// Bit id of the miss mark of \p k; the hit mark is kHit bits further.
  std::int64_t id(const Key& k) const noexcept { return offset(0, k.x) + offset(1, k.y) + offset(2, k.z); }
  static constexpr std::int64_t kHit = 512;

  std::uint64_t* words() noexcept { return reinterpret_cast<std::uint64_t*>(marks_.data()); }
  void set(std::int64_t id) noexcept {
    words()[id >> 6] |= std::uint64_t{1} << (id & 63);
  }

  /// Adds every mark of \p o (same box).
  void merge(const DenseMarks& o) noexcept {
    for (std::size_t j = 0; j < used_; ++j)
      for (int w = 0; w < 8; ++w) {
        marks_[j].miss[w] |= o.marks_[j].miss[w];
        marks_[j].hit[w] |= o.marks_[j].hit[w];
      }
  }
  /// Clears every mark of the current box.
  void clear() noexcept {
    std::fill_n(marks_.begin(), used_, BlockMarks{});
  }

  std::size_t blocks() const noexcept { return used_; }
  const BlockMarks& marks(std::size_t j) const noexcept { return marks_[j]; }
  /// Minimum key of block \p j.
  Key block_base(std::size_t j) const noexcept {
    const auto bx = static_cast<std::int32_t>(j % std::size_t(blocks_[0]));
    const auto by = static_cast<std::int32_t>(j / std::size_t(blocks_[0]) % std::size_t(blocks_[1]));
    const auto bz = static_cast<std::int32_t>(j / (std::size_t(blocks_[0]) * std::size_t(blocks_[1])));
    return Key{base_[0] + 8 * bx, base_[1] + 8 * by, base_[2] + 8 * bz};
  }
  std::size_t memory_bytes() const noexcept { return marks_.capacity() * sizeof(BlockMarks); }

 private:
  std::vector<BlockMarks> marks_;
  std::int32_t base_[3] = {0, 0, 0};
  std::int32_t blocks_[3] = {0, 0, 0};
  std::int64_t stride_[3] = {0, 0, 0};
  std::size_t used_ = 0;
};

/// Marks rays into a DenseMarks. The walk is SegmentDda's, with the same floating-point
/// operations in the same order (so the same voxels), reorganised for speed:
///  - the face-crossing parameters of each axis are a fixed sequence (t_max, t_max + t_delta,
///    ..., then +inf once the axis is exhausted), computed up front into a small table next to
///    the bit-id offset of each coordinate (DenseMarks::offset());
///  - SegmentDda's walk is a three-way merge of these sequences by (parameter, then the higher
///    axis first on ties). Merging is associative, so the two minor axes are merged first into
///    one table (fewer entries), and the walk is a branch-free two-way merge of the dominant
///    axis with it: one compare per voxel. Parameters compare as integers (non-negative doubles
///    order as their bit patterns); keys are `2 * bits`, plus one on the minor table's entries
///    whose axis is lower than the dominant one (so that a tie steps the higher axis first);
///  - the walk is a chain of dependent operations (load, compare, advance), so two rays are
///    walked side by side to give the processor two independent chains.
class DenseRayMarker {
 public:
  /// Rays longer than this (in steps) take the plain SegmentDda walk (no tables).
  static constexpr std::uint64_t kMaxTableSteps = std::uint64_t{1} << 16;

  explicit DenseRayMarker(DenseMarks& marks) : marks_(&marks) {}

  /// Queues one prepared segment (see RayMarker::mark()); marks it now or with the next one.
  /// Returns the number of voxels it enumerates. Call flush() after the last segment.
  std::uint64_t mark(const Point3& v0, const Point3& v1, const Key& k0, const Key& k1, bool hit) {
    DenseMarks& dm = *marks_;
    const SegmentDda dda(v0, v1, k0, k1);
    const std::uint64_t n = dda.remaining;
    if (hit) dm.set(dm.id(k1) + DenseMarks::kHit);  // the walk ends exactly in k1 (SegmentDda)
    if (n > kMaxTableSteps) {
      SegmentDda d = dda;
      for (std::uint64_t i = 0; i < n; ++i) {
        dm.set(dm.id(d.key));
        d.advance();
      }
    } else if (n != 0) {
      slot_[pending_].dda = dda;
      if (pending_ == 1) {
        run_pair();
        pending_ = 0;
      } else {
        pending_ = 1;
      }
    }
    return n + (hit ? 1 : 0);
  }

  /// Marks a queued segment.
  void flush() {
    if (pending_ == 1) {
      Slot& sl = slot_[0];
      AxisFill f[3];
      for (int a = 0; a < 3; ++a) {
        f[a] = start_axis(sl, a);
        f[a].finish();
      }
      MinorMerge m = start_minor(sl);
      m.finish();
      std::uint64_t* words = marks_->words();
      Walk w = walk_of(sl);
      for (;;) {
        w.mark(words);
        if (--w.left == 0) break;
        w.step();
      }
      pending_ = 0;
    }
  }

  // No flush in the destructor: it may allocate, and a destructor must not throw. A queued
  // segment not flushed is dropped (mark_range() always flushes it).
  ~DenseRayMarker() = default;
  DenseRayMarker(const DenseRayMarker&) = delete;
  DenseRayMarker& operator=(const DenseRayMarker&) = delete;

 private:
  static constexpr std::uint64_t kInfKey = std::uint64_t{0x7FF0000000000000ULL} << 1;  // +inf
  static constexpr std::uint64_t kEndKey = ~std::uint64_t{0};  // after every other key

  /// The state of one walk: the dominant axis' table (keys, offsets) and the minor one, the
  /// positions in both, and the voxels still to mark.
  struct Walk {
    const std::uint64_t* dk;
    const std::int64_t* doff;
    const std::uint64_t* mk;
    const std::int64_t* moff;
    std::size_t i, k;
    std::uint64_t left;

    void mark(std::uint64_t* words) const noexcept {
      const std::int64_t id = doff[i] + moff[k];
      words[id >> 6] |= std::uint64_t{1} << (id & 63);
    }
    void step() noexcept {
      const std::size_t c = dk[i] < mk[k];
      i += c;
      k += c ^ 1;
    }
  };

  /// Tables of one ray: per axis the keys and offsets, and the minor axes merged.
  struct Slot {
    SegmentDda dda{Point3::Zero(), Point3::Zero(), Key{}, Key{}};
    std::vector<std::uint64_t> key[4];
    std::vector<std::int64_t> off[4];
    int d = 0, a = 1, b = 2;  // dominant and minor axes (a < b)
  };

  /// Writes one axis' table: entry j holds the key of its (j+1)-th face crossing and the
  /// offset of the coordinate before it; entry cnt the +inf key and the last coordinate.
  struct AxisFill {
    std::uint64_t* kk;
    std::int64_t* oo;
    double t, dt;
    // The coordinate after j crossings, relative to the dense box, is r0 + s * j; its offset
    // is (r >> 3) * stride + (r & 7) << shift (DenseMarks::offset()), computed directly (no
    // carried state, no branch at block borders).
    std::int64_t r0, s, stride;
    int shift;
    std::size_t cnt, j;

    std::int64_t offset(std::size_t i) const noexcept {
      const std::int64_t r = r0 + s * static_cast<std::int64_t>(i);
      return (r >> 3) * stride + ((r & 7) << shift);
    }
    void step() noexcept {
      kk[j] = std::bit_cast<std::uint64_t>(t) << 1;
      oo[j] = offset(j);
      t += dt;
      ++j;
    }
    void finish() noexcept {
      while (j < cnt) step();
      kk[cnt] = kInfKey;
      oo[cnt] = offset(cnt);
    }
  };

  /// Merges the minor axes' tables (b first on ties) into table 3: entry j holds the key of
  /// the (j+1)-th minor crossing (plus one if its axis is below the dominant one) and the sum
  /// of both minor offsets before it.
  struct MinorMerge {
    const std::uint64_t *ka, *kb;
    const std::int64_t *oa, *ob;
    std::uint64_t* km;
    std::int64_t* om;
    std::uint64_t pa, pb;
    std::size_t ia, ib, j, n;

    void step() noexcept {
      // Branch-free: which minor axis crosses next is unpredictable.
      const std::uint64_t x = ka[ia], y = kb[ib];
      const std::size_t sb = y <= x;
      const std::uint64_t m = std::uint64_t{0} - sb;  // all ones if b crosses next
      km[j] = (x ^ ((x ^ y) & m)) | (pa ^ ((pa ^ pb) & m));
      om[j] = oa[ia] + ob[ib];
      ib += sb;
      ia += sb ^ 1;
      ++j;
    }
    void finish() noexcept {
      while (j < n) step();
      km[n] = kEndKey;
      om[n] = oa[ia] + ob[ib];
    }
  };

  AxisFill start_axis(Slot& sl, int a) {
    const SegmentDda& dda = sl.dda;
    const DenseMarks& dm = *marks_;
    const auto cnt = static_cast<std::size_t>(dda.left[a]);
    if (sl.key[a].size() < cnt + 1) {
      sl.key[a].resize(cnt + 1);
      sl.off[a].resize(cnt + 1);
    }
    return AxisFill{sl.key[a].data(), sl.off[a].data(), dda.t_max[a], dda.t_delta[a],
                    std::int64_t{dda.key[a]} - dm.base(a), dda.step[a], dm.block_stride(a), 3 * a, cnt, 0};
  }

  MinorMerge start_minor(Slot& sl) {
    const SegmentDda& dda = sl.dda;
    int d = 0;
    for (int a = 1; a < 3; ++a)
      if (dda.left[a] > dda.left[d]) d = a;
    sl.d = d;
    sl.a = d == 0 ? 1 : 0;
    sl.b = d == 2 ? 1 : 2;
    const std::size_t nm = static_cast<std::size_t>(dda.left[sl.a]) + static_cast<std::size_t>(dda.left[sl.b]);
    if (sl.key[3].size() < nm + 1) {
      sl.key[3].resize(nm + 1);
      sl.off[3].resize(nm + 1);
    }
    return MinorMerge{sl.key[sl.a].data(), sl.key[sl.b].data(), sl.off[sl.a].data(), sl.off[sl.b].data(),
                      sl.key[3].data(), sl.off[3].data(), sl.a < d ? 1u : 0u, sl.b < d ? 1u : 0u, 0, 0, 0, nm};
  }

  static Walk walk_of(const Slot& sl) noexcept {
    return Walk{sl.key[sl.d].data(), sl.off[sl.d].data(), sl.key[3].data(), sl.off[3].data(), 0, 0, sl.dda.remaining};
  }

  /// Fills, merges and walks the two queued segments side by side (two independent chains of
  /// dependent operations for the processor to overlap), then the rest of the longer one.
  void run_pair() {
    Slot &s0 = slot_[0], &s1 = slot_[1];
    for (int a = 0; a < 3; ++a) {
      AxisFill f0 = start_axis(s0, a), f1 = start_axis(s1, a);
      const std::size_t both = std::min(f0.cnt, f1.cnt);
      for (std::size_t j = 0; j < both; ++j) {
        f0.step();
        f1.step();
      }
      f0.finish();
      f1.finish();
    }
    {
      MinorMerge m0 = start_minor(s0), m1 = start_minor(s1);
      const std::size_t both = std::min(m0.n, m1.n);
      for (std::size_t j = 0; j < both; ++j) {
        m0.step();
        m1.step();
      }
      m0.finish();
      m1.finish();
    }
    std::uint64_t* words = marks_->words();
    Walk a = walk_of(s0), b = walk_of(s1);
    const std::uint64_t both = std::min(a.left, b.left);
    a.left -= both;
    b.left -= both;
    for (std::uint64_t i = both;;) {
      a.mark(words);
      b.mark(words);
      if (--i == 0) break;
      a.step();
      b.step();
    }
    Walk& r = a.left ? a : b;
    while (r.left) {
      r.step();
      r.mark(words);
      --r.left;
    }
  }

  DenseMarks* marks_;
  Slot slot_[2];
  int pending_ = 0;
};

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
};

/// True for containers laid out in 8^3 blocks exactly as ScanMarks (SparseBlocks).
template <class C>
concept BlockContainer = requires(C& c, const Key& k) {
  { c.touch_block(k) };
  { C::cell_index(k) } -> std::convertible_to<std::size_t>;
} && (C::kBlockSize == 8);

}  // namespace detail

/// A reusable inserter: keeps its scratch buffers (the per-scan voxel marks, one set per
/// thread) across scans, so repeated insertion allocates nothing once warmed up.
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

  /// Bytes held by the scratch buffers.
  std::size_t scratch_bytes() const noexcept {
    std::size_t n = 0;
    for (const auto& m : marks_) n += m.memory_bytes();
    for (const auto& m : dense_) n += m.memory_bytes();
    return n;
  }

 private:
  static constexpr std::size_t kMinRaysPerThread = 2048;

  unsigned thread_count(std::size_t rays) const {
    unsigned t = options_.threads;
    t = resolve_threads(t);
    t = std::min(t, 64u);
    const std::size_t useful = std::max<std::size_t>(1, rays / kMinRaysPerThread);
    return static_cast<unsigned>(std::min<std::size_t>(t, useful));
  }

  /// Marks rays [begin, end) of \p source into \p marks (a ScanMarks hash or DenseMarks, with
  /// its RayMarker / DenseRayMarker); a marker that buffers is flushed at the end.
  template <class Marker, class Source, class Marks>
  static void mark_range(const GridGeometry& g, const InsertOptions& o, const Source& source, std::size_t begin,
                         std::size_t end, Marks& marks, InsertStats& st) {
    Marker marker(marks);
    Point3 v0, v1;
    Key k0, k1;
    bool hit = false;
    for (std::size_t i = begin; i < end; ++i) {
      if (detail::prepare_ray(g, o, source(i), v0, v1, k0, k1, hit, st))
        st.voxel_steps += marker.mark(v0, v1, k0, k1, hit);
    }
    if constexpr (requires { marker.flush(); }) marker.flush();
  }

  /// Runs \p f(t) for t in [0, n) on n threads (t = 0 on the caller), rethrowing the first error.
  template <class F>
  static void parallel(unsigned n, F&& f) {
    run_on_threads(n, f);
  }

  /// The key box of every traversed voxel of rays [begin, end) (the box of their end keys).
  template <class Source>
  static bool key_box(const GridGeometry& g, const InsertOptions& o, const Source& source, std::size_t begin,
                      std::size_t end, Key& lo, Key& hi) {
    Point3 v0, v1;
    Key k0, k1;
    bool hit = false, any = false;
    InsertStats ignored;
    for (std::size_t i = begin; i < end; ++i) {
      if (!detail::prepare_ray(g, o, source(i), v0, v1, k0, k1, hit, ignored)) continue;
      if (!any) lo = hi = k0;
      any = true;
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min({lo[a], k0[a], k1[a]});
        hi[a] = std::max({hi[a], k0[a], k1[a]});
      }
    }
    return any;
  }

  template <class G, class Source>
  InsertStats run(G& grid, std::size_t count, const Source& source) {
    const unsigned nt = thread_count(count);
    if (marks_.size() < nt) marks_.resize(nt);
    if (dense_.size() < nt) dense_.resize(nt);
    std::vector<InsertStats> part(nt);
    const GridGeometry& g = grid.geometry();

    // The scan's key box decides the marks: a dense bitmap over it if small enough, else the
    // block hash. The choice does not depend on the thread count.
    std::vector<Key> lo(nt), hi(nt);
    std::vector<char> any(nt, 0);
    parallel(nt, [&](unsigned t) {
      const std::size_t b = count * t / nt, e = count * (t + 1) / nt;
      any[t] = key_box(g, options_, source, b, e, lo[t], hi[t]) ? 1 : 0;
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
    for (unsigned t = 0; dense && t < nt; ++t) dense = dense_[t].reset(blo, bhi);

    if (dense) {
      parallel(nt, [&](unsigned t) {
        const std::size_t b = count * t / nt, e = count * (t + 1) / nt;
        mark_range<detail::DenseRayMarker>(g, options_, source, b, e, dense_[t], part[t]);
      });
      detail::DenseMarks& all = dense_[0];
      for (unsigned t = 1; t < nt; ++t) all.merge(dense_[t]);  // cleared by the next reset()
      // Blocks in index order (z, then y, then x): the order of the packed block ids below.
      list_.clear();
      for (std::size_t j = 0; j < all.blocks(); ++j) {
        const detail::BlockMarks& m = all.marks(j);
        std::uint64_t acc = 0;
        for (int w = 0; w < 8; ++w) acc |= m.miss[w] | m.hit[w];
        if (acc) list_.emplace_back(all.block_base(j), &m);
      }
    } else {
      parallel(nt, [&](unsigned t) {
        const std::size_t b = count * t / nt, e = count * (t + 1) / nt;
        mark_range<detail::RayMarker>(g, options_, source, b, e, marks_[t], part[t]);
      });
      detail::ScanMarks& all = marks_[0];
      for (unsigned t = 1; t < nt; ++t) {
        all.merge(marks_[t]);
        marks_[t].clear();
      }
      // Deterministic order: by packed block id, whatever the thread count or ray order.
      order_.resize(all.size());
      for (std::size_t j = 0; j < all.size(); ++j) order_[j] = {all.id(j), static_cast<std::uint32_t>(j)};
      std::sort(order_.begin(), order_.end());
      list_.clear();
      for (const auto& [id, j] : order_) list_.emplace_back(detail::ScanMarks::block_base(id), &all.marks(j));
    }
    InsertStats st;
    for (const auto& p : part) st += p;
    apply(grid, nt, st);
    if (!dense) marks_[0].clear();
    return st;
  }

  /// Applies the merged marks of list_: a hit where a hit bit is set, else a miss where a miss
  /// bit is set.
  template <class G>
  void apply(G& grid, unsigned nt, InsertStats& st) {
    auto& storage = grid.storage();
    const auto& policy = grid.update_policy();
    using Container = std::remove_reference_t<decltype(storage)>;
    using Cell = typename G::Cell;

    bool by_block = false;
    if constexpr (detail::BlockContainer<Container>) by_block = !storage.box();  // a box may cut blocks
    if (by_block) {
      if constexpr (detail::BlockContainer<Container>) {
      // Allocate every block first (the only step that changes the storage's table), then
      // update the cells, in parallel over blocks.
      blocks_.resize(list_.size());
      for (std::size_t j = 0; j < list_.size(); ++j) {
        auto* b = storage.touch_block(list_[j].first);
        blocks_[j] = b ? static_cast<void*>(b->data()) : nullptr;
      }
      std::vector<InsertStats> part(nt);
      parallel(nt, [&](unsigned t) {
        const std::size_t b = list_.size() * t / nt, e = list_.size() * (t + 1) / nt;
        InsertStats& s = part[t];
        for (std::size_t j = b; j < e; ++j) {
          const detail::BlockMarks& m = *list_[j].second;
          Cell* cells = static_cast<Cell*>(blocks_[j]);
          for (int w = 0; w < 8; ++w) {
            const std::uint64_t h = m.hit[w], f = m.miss[w] & ~h;
            if (!cells) {
              s.outside_bounds += static_cast<std::uint64_t>(std::popcount(h) + std::popcount(f));
              continue;
            }
            Cell* row = cells + 64 * w;
            for (std::uint64_t bits = h; bits; bits &= bits - 1) policy.update(row[std::countr_zero(bits)], Observation::Hit);
            for (std::uint64_t bits = f; bits; bits &= bits - 1) policy.update(row[std::countr_zero(bits)], Observation::Miss);
            s.hits += static_cast<std::uint64_t>(std::popcount(h));
            s.misses += static_cast<std::uint64_t>(std::popcount(f));
          }
        }
      });
      for (const auto& p : part) {
        st.hits += p.hits;
        st.misses += p.misses;
        st.outside_bounds += p.outside_bounds;
      }
      }
    } else {
      // Any other storage (dense), or a bounded sparse one: touch() per cell; distinct cells, so blocks may be split
      // across threads.
      std::vector<InsertStats> part(nt);
      parallel(nt, [&](unsigned t) {
        const std::size_t b = list_.size() * t / nt, e = list_.size() * (t + 1) / nt;
        InsertStats& s = part[t];
        for (std::size_t j = b; j < e; ++j) {
          const detail::BlockMarks& m = *list_[j].second;
          const Key base = list_[j].first;
          for (int w = 0; w < 8; ++w) {
            const std::uint64_t h = m.hit[w], f = m.miss[w] & ~h;
            auto visit = [&](std::uint64_t bits, Observation obs, std::uint64_t& count) {
              for (; bits; bits &= bits - 1) {
                const int i = std::countr_zero(bits);
                const Key k{base.x + (i & 7), base.y + (i >> 3), base.z + w};
                if (Cell* c = storage.touch(k)) {
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
      });
      for (const auto& p : part) {
        st.hits += p.hits;
        st.misses += p.misses;
        st.outside_bounds += p.outside_bounds;
      }
    }
  }

  InsertOptions options_;
  std::vector<detail::ScanMarks> marks_;
  std::vector<detail::DenseMarks> dense_;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> order_;
  std::vector<std::pair<Key, const detail::BlockMarks*>> list_;
  std::vector<void*> blocks_;
  bool force_hash_ = false;

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
