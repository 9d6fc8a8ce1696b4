#pragma once
/// \file
/// Internal part of ray insertion (insert.hpp): the per-scan voxel marks as two plain bitmaps
/// over the scan's key box, and the walks that fill them: sixteen rays at once with AVX-512 or
/// eight with AVX2 on x86-64 processors that have them (chosen at run time), else a portable
/// table-driven walk. Every walk takes SegmentDda's steps with the same floating-point
/// operations, so all mark exactly the voxels traverse() visits.
///
/// Thread safety: a BoxMarks is used by one thread at a time; the walks only touch the marks
/// they are given.

#include <intervox/core/key.hpp>
#include <intervox/core/point.hpp>
#include <intervox/raycast/traversal.hpp>

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#if (defined(__x86_64__) || defined(_M_X64)) && (defined(__GNUC__) || defined(__clang__)) && \
    !defined(INTERVOX_NO_X86_WALKS)
#define INTERVOX_HAVE_X86_WALKS 1
#include <immintrin.h>
#else
#define INTERVOX_HAVE_X86_WALKS 0
#endif

namespace intervox::detail {

/// Per-scan marks of one 8x8x8 block: bit (x | y << 3) of word z, for misses and for hits
/// (the layout of a SparseStorage block's cells, 64 per z-slice).
struct BlockMarks {
  std::uint64_t miss[8];
  std::uint64_t hit[8];
};

/// Sets bit \p id of the bitmap \p words (bit id & 63 of word id >> 6).
inline void set_bit(std::uint64_t* words, std::int64_t id) noexcept {
  words[id >> 6] |= std::uint64_t{1} << (id & 63);
}

/// One segment ready to walk in a BoxMarks: SegmentDda's state, with bit ids instead of keys.
struct BoxRay {
  double t[3];            ///< SegmentDda::t_max
  double dt[3];           ///< SegmentDda::t_delta
  std::int64_t left[3];   ///< SegmentDda::left
  std::int64_t rem;       ///< steps still to take: the walk marks rem + 1 voxels
  std::int64_t id;        ///< bit id of the current voxel
  std::int64_t did[3];    ///< bit-id change of one step along each axis (0 if the axis never steps)
};

/// The voxels one scan touches, as two bitmaps (misses, hits) over the scan's key box: bit
/// `x + y * stride(1) + z * stride(2)` (relative to the box's base), rows of whole 64-bit words.
/// A step of a walk is one add to the bit id, whatever the direction. The box starts at a
/// multiple of 8 on every axis, so its 8^3 blocks are the grid's (for_each_block()).
/// reset() clears exactly the box: no stamps, nothing carried from one scan to the next.
class BoxMarks {
 public:
  /// Largest box, in voxels (16 MiB per bitmap, 32 MiB per thread); larger scans use ScanMarks.
  static constexpr std::int64_t kMaxVoxels = std::int64_t{1} << 27;

  /// Covers the keys [lo, hi] (inclusive) with clear marks; false if the box holds more than
  /// kMaxVoxels voxels once padded (then nothing is allocated or cleared).
  bool reset(const Key& lo, const Key& hi) {
    std::int64_t n[3];
    for (int a = 0; a < 3; ++a) {
      base_[a] = lo[a] & ~7;  // floor to a multiple of 8 (two's complement)
      const std::int64_t pad = a == 0 ? 64 : 8;
      n[a] = (std::int64_t{hi[a]} - base_[a] + pad) / pad * pad;
      if (n[a] > kMaxVoxels) return false;
    }
    if (n[0] * n[1] > kMaxVoxels || n[0] * n[1] * n[2] > kMaxVoxels) return false;
    for (int a = 0; a < 3; ++a) size_[a] = n[a];
    stride_[1] = n[0];
    stride_[2] = n[0] * n[1];
    words_ = static_cast<std::size_t>(n[0] * n[1] * n[2] / 64);
    // One more miss word past the box: the target of idle walk lanes (scratch_id()).
    if (miss_.size() < words_ + 1) miss_.resize(words_ + 1);
    if (hit_.size() < words_) hit_.resize(words_);
    std::fill_n(miss_.begin(), words_ + 1, std::uint64_t{0});
    std::fill_n(hit_.begin(), words_, std::uint64_t{0});
    return true;
  }

  /// Bit id of \p k (which must lie in the box).
  std::int64_t id(const Key& k) const noexcept {
    return (std::int64_t{k.x} - base_[0]) + (std::int64_t{k.y} - base_[1]) * stride_[1] +
           (std::int64_t{k.z} - base_[2]) * stride_[2];
  }
  /// The bit-id distance between neighbouring voxels along axis \p a.
  std::int64_t stride(int a) const noexcept { return stride_[a]; }
  /// A bit outside the box, in a miss word of its own: marking it changes nothing.
  std::int64_t scratch_id() const noexcept { return static_cast<std::int64_t>(words_) * 64; }

  std::uint64_t* miss() noexcept { return miss_.data(); }
  void set_hit(std::int64_t id) noexcept { set_bit(hit_.data(), id); }
  void set_miss(std::int64_t id) noexcept { set_bit(miss_.data(), id); }

  /// Minimum key of the box (each coordinate a multiple of 8).
  Key base() const noexcept {
    return Key{static_cast<std::int32_t>(base_[0]), static_cast<std::int32_t>(base_[1]),
               static_cast<std::int32_t>(base_[2])};
  }
  /// Number of 8-voxel block layers along z (for splitting for_each_block() between threads).
  std::int64_t block_layers() const noexcept { return size_[2] / 8; }

  /// Calls \p f(block_base_key, const BlockMarks&) for every block with a mark in any of
  /// marks[0..n) (all reset() to the same box), the marks OR-ed together, for the block layers
  /// [z0, z1) along z, in block order (z, then y, then x).
  template <class F>
  static void for_each_block(const BoxMarks* marks, std::size_t n, std::int64_t z0, std::int64_t z1, F&& f) {
    const BoxMarks& m0 = marks[0];
    const std::int64_t wpr = m0.size_[0] / 64;  // words per row; a word covers 8 blocks along x
    const std::int64_t ny = m0.size_[1];
    std::uint64_t mw[64], hw[64];
    for (std::int64_t bz = z0; bz < z1; ++bz)
      for (std::int64_t by = 0; by < ny / 8; ++by)
        for (std::int64_t c = 0; c < wpr; ++c) {
          std::uint64_t any = 0;
          for (int w = 0; w < 8; ++w)
            for (int y = 0; y < 8; ++y) {
              const auto wi = static_cast<std::size_t>(c + ((by * 8 + y) + (bz * 8 + w) * ny) * wpr);
              std::uint64_t a = 0, h = 0;
              for (std::size_t t = 0; t < n; ++t) {
                a |= marks[t].miss_[wi];
                h |= marks[t].hit_[wi];
              }
              mw[w * 8 + y] = a;
              hw[w * 8 + y] = h;
              any |= a | h;
            }
          for (int b = 0; b < 8; ++b) {
            if (((any >> (8 * b)) & 0xFF) == 0) continue;
            BlockMarks bm;
            for (int w = 0; w < 8; ++w) {
              std::uint64_t a = 0, h = 0;
              for (int y = 0; y < 8; ++y) {
                a |= ((mw[w * 8 + y] >> (8 * b)) & 0xFF) << (8 * y);
                h |= ((hw[w * 8 + y] >> (8 * b)) & 0xFF) << (8 * y);
              }
              bm.miss[w] = a;
              bm.hit[w] = h;
            }
            const Key base{static_cast<std::int32_t>(m0.base_[0] + (c * 8 + b) * 8),
                           static_cast<std::int32_t>(m0.base_[1] + by * 8),
                           static_cast<std::int32_t>(m0.base_[2] + bz * 8)};
            f(base, bm);
          }
        }
  }

  std::size_t memory_bytes() const noexcept {
    return (miss_.capacity() + hit_.capacity()) * sizeof(std::uint64_t);
  }

 private:
  std::vector<std::uint64_t> miss_, hit_;
  std::int64_t base_[3] = {0, 0, 0};
  std::int64_t size_[3] = {0, 0, 0};
  std::int64_t stride_[3] = {1, 0, 0};
  std::size_t words_ = 0;
};

/// Builds the BoxRay of the segment (v0, v1) with keys (k0, k1) in \p marks: false if it marks
/// no miss (origin and end in one voxel).
inline bool make_box_ray(const BoxMarks& marks, const Point3& v0, const Point3& v1, const Key& k0, const Key& k1,
                         BoxRay& r) noexcept {
  const SegmentDda dda(v0, v1, k0, k1);
  if (dda.remaining == 0) return false;
  for (int a = 0; a < 3; ++a) {
    r.t[a] = dda.t_max[a];
    r.dt[a] = dda.t_delta[a];
    r.left[a] = dda.left[a];
    r.did[a] = dda.step[a] * marks.stride(a);
  }
  r.rem = static_cast<std::int64_t>(dda.remaining) - 1;
  r.id = marks.id(k0);
  return true;
}

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

#if INTERVOX_HAVE_X86_WALKS

/// True if this processor runs the AVX2 walk.
inline bool cpu_has_avx2() noexcept {
  static const bool yes = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") != 0;
  }();
  return yes;
}

/// True if this processor runs the AVX-512 walk (AVX-512 Foundation).
inline bool cpu_has_avx512() noexcept {
  static const bool yes = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx512f") != 0;
  }();
  return yes;
}

/// The \p L lanes of one group of a vector walk in memory, for loading rays into them.
template <int L>
struct alignas(64) WalkLanesN {
  double t[3][L], dt[3][L];
  std::int64_t left[3][L], rem[L], id[L], did[3][L];

  void set(int l, const BoxRay& r) noexcept {
    for (int a = 0; a < 3; ++a) {
      t[a][l] = r.t[a];
      dt[a][l] = r.dt[a];
      left[a][l] = r.left[a];
      did[a][l] = r.did[a];
    }
    rem[l] = r.rem;
    id[l] = r.id;
  }
  /// Loads the next ray of \p next with at least one step into lane \p l (marking its first
  /// voxel in \p words), walking one-voxel rays on the way; false if there is none (the lane is
  /// then idle, marking \p scratch).
  template <class Next>
  bool fill(int l, Next& next, std::uint64_t* words, std::int64_t scratch) {
    BoxRay r;
    while (next(r)) {
      set_bit(words, r.id);
      if (r.rem == 0) continue;
      set(l, r);
      return true;
    }
    idle(l, scratch);
    return false;
  }
  /// An idle lane: never steps (every t is +inf and every step 0), never finishes (rem < 0),
  /// marks the scratch bit.
  void idle(int l, std::int64_t scratch) noexcept {
    constexpr double inf = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
      t[a][l] = dt[a][l] = inf;
      left[a][l] = 0;
      did[a][l] = 0;
    }
    rem[l] = -1;
    id[l] = scratch;
  }
};

using WalkLanes = WalkLanesN<4>;

#define INTERVOX_AVX2 __attribute__((target("avx2")))

/// Four walks in the registers of one group of lanes.
struct WalkGroup {
  __m256d t0, t1, t2, d0, d1, d2;
  __m256i l0, l1, l2, rem, id, i0, i1, i2;
};

INTERVOX_AVX2 inline __attribute__((always_inline)) void walk_load(WalkGroup& g, const WalkLanes& s) noexcept {
  g.t0 = _mm256_load_pd(s.t[0]);
  g.t1 = _mm256_load_pd(s.t[1]);
  g.t2 = _mm256_load_pd(s.t[2]);
  g.d0 = _mm256_load_pd(s.dt[0]);
  g.d1 = _mm256_load_pd(s.dt[1]);
  g.d2 = _mm256_load_pd(s.dt[2]);
  g.l0 = _mm256_load_si256(reinterpret_cast<const __m256i*>(s.left[0]));
  g.l1 = _mm256_load_si256(reinterpret_cast<const __m256i*>(s.left[1]));
  g.l2 = _mm256_load_si256(reinterpret_cast<const __m256i*>(s.left[2]));
  g.rem = _mm256_load_si256(reinterpret_cast<const __m256i*>(s.rem));
  g.id = _mm256_load_si256(reinterpret_cast<const __m256i*>(s.id));
  g.i0 = _mm256_load_si256(reinterpret_cast<const __m256i*>(s.did[0]));
  g.i1 = _mm256_load_si256(reinterpret_cast<const __m256i*>(s.did[1]));
  g.i2 = _mm256_load_si256(reinterpret_cast<const __m256i*>(s.did[2]));
}

INTERVOX_AVX2 inline __attribute__((always_inline)) void walk_store(const WalkGroup& g, WalkLanes& s) noexcept {
  _mm256_store_pd(s.t[0], g.t0);
  _mm256_store_pd(s.t[1], g.t1);
  _mm256_store_pd(s.t[2], g.t2);
  // dt and did do not change while walking.
  _mm256_store_si256(reinterpret_cast<__m256i*>(s.left[0]), g.l0);
  _mm256_store_si256(reinterpret_cast<__m256i*>(s.left[1]), g.l1);
  _mm256_store_si256(reinterpret_cast<__m256i*>(s.left[2]), g.l2);
  _mm256_store_si256(reinterpret_cast<__m256i*>(s.rem), g.rem);
  _mm256_store_si256(reinterpret_cast<__m256i*>(s.id), g.id);
}

/// One SegmentDda::advance() in each lane, with the same floating-point operations: the axis
/// is x if t0 < t1 and t0 < t2, y if not t0 < t1 and t1 < t2, else z; the chosen t becomes
/// +inf on its axis' last step, else t + dt.
INTERVOX_AVX2 inline __attribute__((always_inline)) void walk_step(WalkGroup& g, __m256d inf, __m256i one,
                                                                   __m256d ones) noexcept {
  const __m256d xy = _mm256_cmp_pd(g.t0, g.t1, _CMP_LT_OQ);
  const __m256d m = _mm256_blendv_pd(g.t1, g.t0, xy);
  const __m256d sz = _mm256_cmp_pd(g.t2, m, _CMP_LE_OQ);  // !(m < t2): no t is ever NaN
  const __m256d sx = _mm256_andnot_pd(sz, xy);
  const __m256d sy = _mm256_xor_pd(_mm256_or_pd(xy, sz), ones);
  const __m256d dxy = _mm256_blendv_pd(_mm256_castsi256_pd(g.i1), _mm256_castsi256_pd(g.i0), xy);
  const __m256d did = _mm256_blendv_pd(dxy, _mm256_castsi256_pd(g.i2), sz);
  g.id = _mm256_add_epi64(g.id, _mm256_castpd_si256(did));
  const __m256d n0 = _mm256_blendv_pd(_mm256_add_pd(g.t0, g.d0), inf, _mm256_castsi256_pd(_mm256_cmpeq_epi64(g.l0, one)));
  const __m256d n1 = _mm256_blendv_pd(_mm256_add_pd(g.t1, g.d1), inf, _mm256_castsi256_pd(_mm256_cmpeq_epi64(g.l1, one)));
  const __m256d n2 = _mm256_blendv_pd(_mm256_add_pd(g.t2, g.d2), inf, _mm256_castsi256_pd(_mm256_cmpeq_epi64(g.l2, one)));
  g.t0 = _mm256_blendv_pd(g.t0, n0, sx);
  g.t1 = _mm256_blendv_pd(g.t1, n1, sy);
  g.t2 = _mm256_blendv_pd(g.t2, n2, sz);
  g.l0 = _mm256_add_epi64(g.l0, _mm256_castpd_si256(sx));  // a selected mask is -1
  g.l1 = _mm256_add_epi64(g.l1, _mm256_castpd_si256(sy));
  g.l2 = _mm256_add_epi64(g.l2, _mm256_castpd_si256(sz));
  g.rem = _mm256_sub_epi64(g.rem, one);
}

INTERVOX_AVX2 inline __attribute__((always_inline)) void walk_mark(std::uint64_t* words, __m256i id) noexcept {
  alignas(32) std::int64_t v[4];
  _mm256_store_si256(reinterpret_cast<__m256i*>(v), id);
  for (int l = 0; l < 4; ++l) set_bit(words, v[l]);
}

/// Walks every ray \p next hands out (`bool next(BoxRay&)`, false when there are no more),
/// eight at a time in two groups of four AVX2 lanes; a lane takes the next ray as soon as its
/// own ends. Marks the same bits as walk_single() on each ray.
template <class Next>
INTERVOX_AVX2 void walk_avx2(std::uint64_t* words, std::int64_t scratch, Next&& next) {
  WalkLanes s[2];
  int active = 0;
  for (auto& lanes : s)
    for (int l = 0; l < 4; ++l) active += lanes.fill(l, next, words, scratch) ? 1 : 0;
  if (active == 0) return;
  WalkGroup a, b;
  walk_load(a, s[0]);
  walk_load(b, s[1]);
  const __m256d inf = _mm256_set1_pd(std::numeric_limits<double>::infinity());
  const __m256d ones = _mm256_castsi256_pd(_mm256_set1_epi64x(-1));
  const __m256i one = _mm256_set1_epi64x(1);
  const __m256i zero = _mm256_setzero_si256();
  for (;;) {
    walk_mark(words, a.id);
    walk_mark(words, b.id);
    const __m256i da = _mm256_cmpeq_epi64(a.rem, zero), db = _mm256_cmpeq_epi64(b.rem, zero);
    if (!_mm256_testz_si256(_mm256_or_si256(da, db), _mm256_or_si256(da, db))) {
      // Some lanes marked their last voxel: give them new rays (rare: once per ray).
      const int done[2] = {_mm256_movemask_pd(_mm256_castsi256_pd(da)), _mm256_movemask_pd(_mm256_castsi256_pd(db))};
      WalkGroup* g[2] = {&a, &b};
      for (int k = 0; k < 2; ++k) {
        if (!done[k]) continue;
        walk_store(*g[k], s[k]);
        for (int l = 0; l < 4; ++l)
          if (done[k] >> l & 1) active -= s[k].fill(l, next, words, scratch) ? 0 : 1;
        walk_load(*g[k], s[k]);
      }
      if (active == 0) return;
    }
    walk_step(a, inf, one, ones);
    walk_step(b, inf, one, ones);
  }
}

#undef INTERVOX_AVX2

#define INTERVOX_AVX512 __attribute__((target("avx512f")))

/// Eight walks in the registers of one group of AVX-512 lanes.
struct WalkGroup8 {
  __m512d t0, t1, t2, d0, d1, d2;
  __m512i l0, l1, l2, rem, id, i0, i1, i2;
};

INTERVOX_AVX512 inline __attribute__((always_inline)) void walk_load8(WalkGroup8& g, const WalkLanesN<8>& s) noexcept {
  g.t0 = _mm512_load_pd(s.t[0]);
  g.t1 = _mm512_load_pd(s.t[1]);
  g.t2 = _mm512_load_pd(s.t[2]);
  g.d0 = _mm512_load_pd(s.dt[0]);
  g.d1 = _mm512_load_pd(s.dt[1]);
  g.d2 = _mm512_load_pd(s.dt[2]);
  g.l0 = _mm512_load_si512(s.left[0]);
  g.l1 = _mm512_load_si512(s.left[1]);
  g.l2 = _mm512_load_si512(s.left[2]);
  g.rem = _mm512_load_si512(s.rem);
  g.id = _mm512_load_si512(s.id);
  g.i0 = _mm512_load_si512(s.did[0]);
  g.i1 = _mm512_load_si512(s.did[1]);
  g.i2 = _mm512_load_si512(s.did[2]);
}

INTERVOX_AVX512 inline __attribute__((always_inline)) void walk_store8(const WalkGroup8& g, WalkLanesN<8>& s) noexcept {
  _mm512_store_pd(s.t[0], g.t0);
  _mm512_store_pd(s.t[1], g.t1);
  _mm512_store_pd(s.t[2], g.t2);
  _mm512_store_si512(s.left[0], g.l0);
  _mm512_store_si512(s.left[1], g.l1);
  _mm512_store_si512(s.left[2], g.l2);
  _mm512_store_si512(s.rem, g.rem);
  _mm512_store_si512(s.id, g.id);
}

/// walk_step() for eight lanes, with mask registers instead of blends.
INTERVOX_AVX512 inline __attribute__((always_inline)) void walk_step8(WalkGroup8& g, __m512d inf,
                                                                      __m512i one) noexcept {
  const __mmask8 xy = _mm512_cmp_pd_mask(g.t0, g.t1, _CMP_LT_OQ);
  const __m512d m = _mm512_mask_blend_pd(xy, g.t1, g.t0);
  const __mmask8 sz = _mm512_cmp_pd_mask(g.t2, m, _CMP_LE_OQ);  // !(m < t2): no t is ever NaN
  const auto sx = static_cast<__mmask8>(xy & ~sz);
  const auto sy = static_cast<__mmask8>(~(xy | sz));
  const __m512i dxy = _mm512_mask_blend_epi64(xy, g.i1, g.i0);
  g.id = _mm512_add_epi64(g.id, _mm512_mask_blend_epi64(sz, dxy, g.i2));
  // The chosen axis' t + dt, then +inf where that was its last step.
  const auto e0 = static_cast<__mmask8>(sx & _mm512_cmpeq_epi64_mask(g.l0, one));
  const auto e1 = static_cast<__mmask8>(sy & _mm512_cmpeq_epi64_mask(g.l1, one));
  const auto e2 = static_cast<__mmask8>(sz & _mm512_cmpeq_epi64_mask(g.l2, one));
  g.t0 = _mm512_mask_mov_pd(_mm512_mask_add_pd(g.t0, sx, g.t0, g.d0), e0, inf);
  g.t1 = _mm512_mask_mov_pd(_mm512_mask_add_pd(g.t1, sy, g.t1, g.d1), e1, inf);
  g.t2 = _mm512_mask_mov_pd(_mm512_mask_add_pd(g.t2, sz, g.t2, g.d2), e2, inf);
  g.l0 = _mm512_mask_sub_epi64(g.l0, sx, g.l0, one);
  g.l1 = _mm512_mask_sub_epi64(g.l1, sy, g.l1, one);
  g.l2 = _mm512_mask_sub_epi64(g.l2, sz, g.l2, one);
  g.rem = _mm512_sub_epi64(g.rem, one);
}

INTERVOX_AVX512 inline __attribute__((always_inline)) void walk_mark8(std::uint64_t* words, __m512i id) noexcept {
  alignas(64) std::int64_t v[8];
  _mm512_store_si512(v, id);
  for (int l = 0; l < 8; ++l) set_bit(words, v[l]);
}

/// walk_avx2() with AVX-512: sixteen rays at once in two groups of eight lanes (32 vector
/// registers hold both groups without spilling; mask registers replace the blends).
template <class Next>
INTERVOX_AVX512 void walk_avx512(std::uint64_t* words, std::int64_t scratch, Next&& next) {
  WalkLanesN<8> s[2];
  int active = 0;
  for (auto& lanes : s)
    for (int l = 0; l < 8; ++l) active += lanes.fill(l, next, words, scratch) ? 1 : 0;
  if (active == 0) return;
  WalkGroup8 a, b;
  walk_load8(a, s[0]);
  walk_load8(b, s[1]);
  const __m512d inf = _mm512_set1_pd(std::numeric_limits<double>::infinity());
  const __m512i one = _mm512_set1_epi64(1);
  const __m512i zero = _mm512_setzero_si512();
  for (;;) {
    walk_mark8(words, a.id);
    walk_mark8(words, b.id);
    const __mmask8 da = _mm512_cmpeq_epi64_mask(a.rem, zero), db = _mm512_cmpeq_epi64_mask(b.rem, zero);
    if (da | db) {
      const unsigned done[2] = {da, db};
      WalkGroup8* g[2] = {&a, &b};
      for (int k = 0; k < 2; ++k) {
        if (!done[k]) continue;
        walk_store8(*g[k], s[k]);
        for (int l = 0; l < 8; ++l)
          if (done[k] >> l & 1) active -= s[k].fill(l, next, words, scratch) ? 0 : 1;
        walk_load8(*g[k], s[k]);
      }
      if (active == 0) return;
    }
    walk_step8(a, inf, one);
    walk_step8(b, inf, one);
  }
}

#undef INTERVOX_AVX512

#else

inline bool cpu_has_avx2() noexcept { return false; }
inline bool cpu_has_avx512() noexcept { return false; }

#endif  // INTERVOX_HAVE_X86_WALKS

/// The portable walk, for processors without AVX2: SegmentDda's walk with the same
/// floating-point operations in the same order (so the same voxels), reorganised for speed:
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
  static constexpr std::uint64_t kEndKey = ~std::uint64_t{0};  // after every other key

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
    return MinorMerge{sl.key[sl.a].data(), sl.key[sl.b].data(), sl.off[sl.a].data(), sl.off[sl.b].data(),
                      sl.key[3].data(), sl.off[3].data(), sl.a < sl.d ? 1u : 0u, sl.b < sl.d ? 1u : 0u,
                      0, 0, 0, nm};
  }

  static Walk walk_of(const Slot& sl) noexcept {
    return Walk{sl.key[sl.d].data(), sl.off[sl.d].data(), sl.key[3].data(), sl.off[3].data(), 0, 0, sl.ray.rem + 1};
  }

  /// Fills, merges and walks the two queued rays side by side (two independent chains of
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

/// The walks of walk_rays().
enum class WalkKind : std::uint8_t {
  Fastest,   ///< the fastest this processor runs: Avx512, else Avx2, else Table
  Avx512,    ///< walk_avx512() (Table where the processor lacks AVX-512)
  Avx2,      ///< walk_avx2() (Table where the processor lacks AVX2)
  Table,     ///< TableWalk: portable, two rays side by side
  Single,    ///< walk_single(): one ray at a time, the plainest form
};

/// The walk that \p kind runs on this processor (never Fastest).
inline WalkKind resolve_walk(WalkKind kind) noexcept {
  if (kind == WalkKind::Fastest) kind = cpu_has_avx512() ? WalkKind::Avx512 : WalkKind::Avx2;
  if (kind == WalkKind::Avx512 && !cpu_has_avx512()) kind = WalkKind::Table;
  if (kind == WalkKind::Avx2 && !cpu_has_avx2()) kind = WalkKind::Table;
  return kind;
}

/// A short name of a walk ("AVX-512", "AVX2", "table", "single"), after resolve_walk().
inline const char* walk_name(WalkKind kind) noexcept {
  switch (resolve_walk(kind)) {
    case WalkKind::Avx512: return "AVX-512";
    case WalkKind::Avx2: return "AVX2";
    case WalkKind::Single: return "single";
    default: return "table";
  }
}

/// Walks every ray \p next hands out (`bool next(BoxRay&)`, false when there are no more) into
/// \p marks' miss bitmap with the walk resolve_walk(\p kind). The result is the same bits for
/// every walk.
template <class Next>
void walk_rays(BoxMarks& marks, WalkKind kind, Next&& next) {
  kind = resolve_walk(kind);
#if INTERVOX_HAVE_X86_WALKS
  if (kind == WalkKind::Avx512) {
    walk_avx512(marks.miss(), marks.scratch_id(), next);
    return;
  }
  if (kind == WalkKind::Avx2) {
    walk_avx2(marks.miss(), marks.scratch_id(), next);
    return;
  }
#endif
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
