#pragma once
/// \file
/// Internal part of ray insertion: the portable walks of the box bitmaps (box_marks.hpp), for
/// every processor. walk_single() is SegmentDda's loop on bit ids, one ray at a time (the
/// reference); TableWalk is the same walk reorganised as a merge of per-axis tables, two rays
/// side by side. Both mark exactly the voxels traverse() visits, up to the last (the misses).
///
/// Thread safety: a TableWalk is used by one thread at a time.

#include <intervox/raycast/detail/block_marks.hpp>
#include <intervox/raycast/detail/box_marks.hpp>

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace intervox::detail {

/// Marks the misses of one ray: SegmentDda's walk, branch-free (the axis of each step is
/// unpredictable), on bit ids.
inline void walk_single(std::uint64_t* words, BoxRay r) noexcept {
  constexpr double inf = std::numeric_limits<double>::infinity();
  for (;;) {
    set_bit(words, r.id);
    if (r.rem-- == 0) break;
    // SegmentDda::next_axis(): ties step the higher axis.
    const bool xy = r.t[0] < r.t[1];
    const double m = xy ? r.t[0] : r.t[1];
    const int a = !(m < r.t[2]) ? 2 : (xy ? 0 : 1);
    r.id += r.did[a];
    r.t[a] = --r.left[a] == 0 ? inf : r.t[a] + r.dt[a];
  }
}

/// The portable walk, for processors (or programs) without the vector walks (walk_x86.hpp):
/// SegmentDda's walk with the same floating-point operations in the same order (so the same
/// voxels), reorganised for speed:
///  - the face-crossing parameters of each axis are a fixed sequence (t, t + dt, ..., then +inf
///    once the axis is exhausted), computed up front into a small table next to the bit-id
///    offset each crossing leads to;
///  - SegmentDda's walk is a three-way merge of these sequences by (parameter, then the higher
///    axis first on ties). Merging is associative, so the two minor axes are merged first into
///    one table (fewer entries), and the walk is a branch-free two-way merge of the dominant
///    axis with it: one compare per voxel. Parameters compare as integers (non-negative doubles
///    order as their bit patterns); keys are `2 * bits`, plus one on the minor table's entries
///    whose axis is lower than the dominant one (so that a tie steps the higher axis first);
///  - the walk is a chain of dependent operations (load, compare, advance), so two rays are
///    walked side by side to give the processor two independent chains.
class TableWalk {
 public:
  /// Rays longer than this (in steps) take walk_single() (no tables).
  static constexpr std::int64_t kMaxTableSteps = std::int64_t{1} << 16;

  explicit TableWalk(std::uint64_t* words) : words_(words) {}
  TableWalk(const TableWalk&) = delete;
  TableWalk& operator=(const TableWalk&) = delete;

  /// Marks \p r now or together with the next ray; call flush() after the last.
  void add(const BoxRay& r) {
    if (r.rem >= kMaxTableSteps) {
      walk_single(words_, r);
      return;
    }
    slot_[pending_].ray = r;
    if (pending_ == 1) {
      run_pair();
      pending_ = 0;
    } else {
      pending_ = 1;
    }
  }

  /// Marks a queued ray.
  void flush() {
    if (pending_ == 0) return;
    Slot& sl = slot_[0];
    AxisFill f[3];
    for (int a = 0; a < 3; ++a) {
      f[a] = start_axis(sl, a);
      f[a].finish();
    }
    MinorMerge m = start_minor(sl);
    m.finish();
    Walk w = walk_of(sl);
    for (;;) {
      w.mark(words_);
      if (--w.left == 0) break;
      w.step();
    }
    pending_ = 0;
  }

 private:
  static constexpr std::uint64_t kInfKey = std::uint64_t{0x7FF0000000000000ULL} << 1;  // +inf
  static constexpr std::uint64_t kEndKey = ~std::uint64_t{0};                          // after every other key

  /// The state of one walk: the dominant axis' table (keys, offsets) and the minor one, the
  /// positions in both, and the voxels still to mark.
  struct Walk {
    const std::uint64_t* dk;
    const std::int64_t* doff;
    const std::uint64_t* mk;
    const std::int64_t* moff;
    std::size_t i, k;
    std::int64_t left;

    void mark(std::uint64_t* words) const noexcept { set_bit(words, doff[i] + moff[k]); }
    void step() noexcept {
      const std::size_t c = dk[i] < mk[k];
      i += c;
      k += c ^ 1;
    }
  };

  /// Tables of one ray: per axis the keys and offsets, and the minor axes merged.
  struct Slot {
    BoxRay ray{};
    std::vector<std::uint64_t> key[4];
    std::vector<std::int64_t> off[4];
    int d = 0, a = 1, b = 2;  // dominant and minor axes (a < b)
  };

  /// Writes one axis' table: entry j holds the key of its (j+1)-th face crossing and the
  /// offset before it; entry cnt the +inf key and the last offset.
  struct AxisFill {
    std::uint64_t* kk;
    std::int64_t* oo;
    double t, dt;
    std::int64_t o, os;
    std::size_t cnt, j;

    void step() noexcept {
      kk[j] = std::bit_cast<std::uint64_t>(t) << 1;
      oo[j] = o;
      t += dt;
      o += os;
      ++j;
    }
    void finish() noexcept {
      while (j < cnt) step();
      kk[cnt] = kInfKey;
      oo[cnt] = o;
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
    std::size_t ia, ib, j, cnt;

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
      while (j < cnt) step();
      km[cnt] = kEndKey;
      om[cnt] = oa[ia] + ob[ib];
    }
  };

  /// The dominant axis (most steps) and the two minor ones of a ray.
  static void choose_axes(Slot& sl) noexcept {
    int d = 0;
    for (int a = 1; a < 3; ++a)
      if (sl.ray.left[a] > sl.ray.left[d]) d = a;
    sl.d = d;
    sl.a = d == 0 ? 1 : 0;
    sl.b = d == 2 ? 1 : 2;
  }

  /// The start of axis \p a's table; the ray's first bit id is carried by the dominant axis.
  static AxisFill start_axis(Slot& sl, int a) {
    if (a == 0) choose_axes(sl);
    const BoxRay& r = sl.ray;
    const auto cnt = static_cast<std::size_t>(r.left[a]);
    if (sl.key[a].size() < cnt + 1) {
      sl.key[a].resize(cnt + 1);
      sl.off[a].resize(cnt + 1);
    }
    return AxisFill{sl.key[a].data(), sl.off[a].data(), r.t[a], r.dt[a], a == sl.d ? r.id : 0, r.did[a], cnt, 0};
  }

  static MinorMerge start_minor(Slot& sl) {
    const std::size_t nm = static_cast<std::size_t>(sl.ray.left[sl.a] + sl.ray.left[sl.b]);
    if (sl.key[3].size() < nm + 1) {
      sl.key[3].resize(nm + 1);
      sl.off[3].resize(nm + 1);
    }
    return MinorMerge{sl.key[sl.a].data(),
                      sl.key[sl.b].data(),
                      sl.off[sl.a].data(),
                      sl.off[sl.b].data(),
                      sl.key[3].data(),
                      sl.off[3].data(),
                      sl.a < sl.d ? 1u : 0u,
                      sl.b < sl.d ? 1u : 0u,
                      0,
                      0,
                      0,
                      nm};
  }

  static Walk walk_of(const Slot& sl) noexcept {
    return Walk{sl.key[sl.d].data(), sl.off[sl.d].data(), sl.key[3].data(), sl.off[3].data(), 0, 0, sl.ray.rem + 1};
  }

  /// Runs two table fills (AxisFill or MinorMerge, \p cnt entries each) side by side, then
  /// finishes both.
  template <class Fill>
  static void fill_pair(Fill f0, Fill f1) noexcept {
    const std::size_t both = std::min(f0.cnt, f1.cnt);
    for (std::size_t j = 0; j < both; ++j) {
      f0.step();
      f1.step();
    }
    f0.finish();
    f1.finish();
  }

  /// Fills, merges and walks the two queued rays side by side (two independent chains of
  /// dependent operations for the processor to overlap), then the rest of the longer one.
  void run_pair() {
    Slot &s0 = slot_[0], &s1 = slot_[1];
    for (int a = 0; a < 3; ++a) fill_pair(start_axis(s0, a), start_axis(s1, a));
    fill_pair(start_minor(s0), start_minor(s1));
    Walk a = walk_of(s0), b = walk_of(s1);
    const std::int64_t both = std::min(a.left, b.left);
    a.left -= both;
    b.left -= both;
    for (std::int64_t i = both;;) {
      a.mark(words_);
      b.mark(words_);
      if (--i == 0) break;
      a.step();
      b.step();
    }
    Walk& r = a.left ? a : b;
    while (r.left) {
      r.step();
      r.mark(words_);
      --r.left;
    }
  }

  std::uint64_t* words_;
  Slot slot_[2];
  int pending_ = 0;
};

}  // namespace intervox::detail
