#pragma once
/// \file
/// Internal part of ray insertion: the vector walks of the box bitmaps on x86-64, sixteen rays
/// at once with AVX-512 (two groups of eight lanes) or eight with AVX2 (two groups of four),
/// compiled with function target attributes (no compiler flag needed) and registered for
/// walks.hpp's dispatch when the processor runs them. Both run one control flow, walk_lanes();
/// they differ only in the lane operations (Avx2Lanes, Avx512Lanes). Each lane takes
/// SegmentDda's steps with the same floating-point operations, so every walk marks the voxels
/// traverse() visits. Include <intervox/raycast/vector_walks.hpp> and call use_vector_walks(), not
/// this header.
/// Defining INTERVOX_NO_X86_WALKS leaves them out.
///
/// Thread safety: the walks only touch the bitmap they are given.

#include <intervox/raycast/detail/walks.hpp>

#include <cstdint>
#include <limits>

#if (defined(__x86_64__) || defined(_M_X64)) && (defined(__GNUC__) || defined(__clang__)) && \
    !defined(INTERVOX_NO_X86_WALKS)
#define INTERVOX_HAVE_X86_WALKS 1
#include <immintrin.h>
#else
#define INTERVOX_HAVE_X86_WALKS 0
#endif

#if INTERVOX_HAVE_X86_WALKS

namespace intervox::detail {

/// The \p L lanes of one group of a vector walk in memory, for loading rays into them.
template <int L>
struct alignas(64) WalkLanes {
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
  /// Loads the next ray of \p rays with at least one step into lane \p l (marking its first
  /// voxel in \p words), walking one-voxel rays on the way; false if there is none (the lane is
  /// then idle, marking \p scratch).
  bool fill(int l, BoxRaySource& rays, std::uint64_t* words, std::int64_t scratch) {
    BoxRay r;
    while (rays.next(r)) {
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

/// The registers of one group of lanes (WalkLanes' fields): vectors of doubles Lanes::D and of
/// 64-bit integers Lanes::I (typedefs, which keep the vector types' attributes).
template <class Lanes>
struct LaneRegisters {
  typename Lanes::D t0, t1, t2, d0, d1, d2;
  typename Lanes::I l0, l1, l2, rem, id, i0, i1, i2;
};

/// Loads lanes \p s into the registers \p g (Lanes::ld and ldi: aligned loads of doubles and of
/// 64-bit integers).
template <class Lanes, class Group, class Memory>
void load_group(Group& g, const Memory& s) noexcept {
  Lanes::ld(g.t0, s.t[0]);
  Lanes::ld(g.t1, s.t[1]);
  Lanes::ld(g.t2, s.t[2]);
  Lanes::ld(g.d0, s.dt[0]);
  Lanes::ld(g.d1, s.dt[1]);
  Lanes::ld(g.d2, s.dt[2]);
  Lanes::ldi(g.l0, s.left[0]);
  Lanes::ldi(g.l1, s.left[1]);
  Lanes::ldi(g.l2, s.left[2]);
  Lanes::ldi(g.rem, s.rem);
  Lanes::ldi(g.id, s.id);
  Lanes::ldi(g.i0, s.did[0]);
  Lanes::ldi(g.i1, s.did[1]);
  Lanes::ldi(g.i2, s.did[2]);
}

/// Stores the registers \p g that change while walking into lanes \p s (dt and did do not).
template <class Lanes, class Group, class Memory>
void store_group(const Group& g, Memory& s) noexcept {
  Lanes::st(s.t[0], g.t0);
  Lanes::st(s.t[1], g.t1);
  Lanes::st(s.t[2], g.t2);
  Lanes::sti(s.left[0], g.l0);
  Lanes::sti(s.left[1], g.l1);
  Lanes::sti(s.left[2], g.l2);
  Lanes::sti(s.rem, g.rem);
  Lanes::sti(s.id, g.id);
}

/// The control flow of both vector walks: two groups of lanes (as many as Lanes::D holds) in
/// registers; each
/// iteration marks every lane's voxel, refills the lanes whose ray ended (rare: once per ray)
/// and takes one step in every lane. Lanes provides the vector types (`D`, `I`), the
/// loads and stores of load_group() and store_group(), `mark`, `done` (bit l set if lane l
/// marked its last voxel) and `step`. Only called from the target-attributed, flattened entry
/// points below, which inline it with the lane operations.
template <class Lanes>
void walk_lanes(std::uint64_t* words, std::int64_t scratch, BoxRaySource& rays) {
  constexpr int n = sizeof(typename Lanes::D) / sizeof(double);
  WalkLanes<n> s[2];
  int active = 0;
  for (auto& lanes : s)
    for (int l = 0; l < n; ++l) active += lanes.fill(l, rays, words, scratch) ? 1 : 0;
  if (active == 0) return;
  LaneRegisters<Lanes> g[2];
  load_group<Lanes>(g[0], s[0]);
  load_group<Lanes>(g[1], s[1]);
  for (;;) {
    Lanes::mark(words, g[0]);
    Lanes::mark(words, g[1]);
    const unsigned done[2] = {Lanes::done(g[0]), Lanes::done(g[1])};
    if (done[0] | done[1]) {
      for (int k = 0; k < 2; ++k) {
        if (!done[k]) continue;
        store_group<Lanes>(g[k], s[k]);
        for (int l = 0; l < n; ++l)
          if (done[k] >> l & 1) active -= s[k].fill(l, rays, words, scratch) ? 0 : 1;
        load_group<Lanes>(g[k], s[k]);
      }
      if (active == 0) return;
    }
    Lanes::step(g[0]);
    Lanes::step(g[1]);
  }
}

#define INTERVOX_AVX2 __attribute__((target("avx2")))

/// The lane operations of the AVX2 walk: four lanes per group.
struct Avx2Lanes {
  using D = __m256d;
  using I = __m256i;

  // Vectors go by reference: by value they would cross walk_lanes(), which has no target.
  INTERVOX_AVX2 static void ld(__m256d& v, const double* p) noexcept { v = _mm256_load_pd(p); }
  INTERVOX_AVX2 static void ldi(__m256i& v, const std::int64_t* p) noexcept {
    v = _mm256_load_si256(reinterpret_cast<const __m256i*>(p));
  }
  INTERVOX_AVX2 static void st(double* p, const __m256d& v) noexcept { _mm256_store_pd(p, v); }
  INTERVOX_AVX2 static void sti(std::int64_t* p, const __m256i& v) noexcept {
    _mm256_store_si256(reinterpret_cast<__m256i*>(p), v);
  }

  INTERVOX_AVX2 static void mark(std::uint64_t* words, const LaneRegisters<Avx2Lanes>& g) noexcept {
    alignas(32) std::int64_t v[4];
    _mm256_store_si256(reinterpret_cast<__m256i*>(v), g.id);
    for (int l = 0; l < 4; ++l) set_bit(words, v[l]);
  }

  INTERVOX_AVX2 static unsigned done(const LaneRegisters<Avx2Lanes>& g) noexcept {
    return static_cast<unsigned>(
        _mm256_movemask_pd(_mm256_castsi256_pd(_mm256_cmpeq_epi64(g.rem, _mm256_setzero_si256()))));
  }

  /// One SegmentDda::advance() in each lane, with the same floating-point operations: the axis
  /// is x if t0 < t1 and t0 < t2, y if not t0 < t1 and t1 < t2, else z; the chosen t becomes
  /// +inf on its axis' last step, else t + dt.
  INTERVOX_AVX2 static void step(LaneRegisters<Avx2Lanes>& g) noexcept {
    const __m256d inf = _mm256_set1_pd(std::numeric_limits<double>::infinity());
    const __m256d ones = _mm256_castsi256_pd(_mm256_set1_epi64x(-1));
    const __m256i one = _mm256_set1_epi64x(1);
    const __m256d xy = _mm256_cmp_pd(g.t0, g.t1, _CMP_LT_OQ);
    const __m256d m = _mm256_blendv_pd(g.t1, g.t0, xy);
    const __m256d sz = _mm256_cmp_pd(g.t2, m, _CMP_LE_OQ);  // !(m < t2): no t is ever NaN
    const __m256d sx = _mm256_andnot_pd(sz, xy);
    const __m256d sy = _mm256_xor_pd(_mm256_or_pd(xy, sz), ones);
    const __m256d dxy = _mm256_blendv_pd(_mm256_castsi256_pd(g.i1), _mm256_castsi256_pd(g.i0), xy);
    const __m256d did = _mm256_blendv_pd(dxy, _mm256_castsi256_pd(g.i2), sz);
    g.id = _mm256_add_epi64(g.id, _mm256_castpd_si256(did));
    const __m256d n0 =
        _mm256_blendv_pd(_mm256_add_pd(g.t0, g.d0), inf, _mm256_castsi256_pd(_mm256_cmpeq_epi64(g.l0, one)));
    const __m256d n1 =
        _mm256_blendv_pd(_mm256_add_pd(g.t1, g.d1), inf, _mm256_castsi256_pd(_mm256_cmpeq_epi64(g.l1, one)));
    const __m256d n2 =
        _mm256_blendv_pd(_mm256_add_pd(g.t2, g.d2), inf, _mm256_castsi256_pd(_mm256_cmpeq_epi64(g.l2, one)));
    g.t0 = _mm256_blendv_pd(g.t0, n0, sx);
    g.t1 = _mm256_blendv_pd(g.t1, n1, sy);
    g.t2 = _mm256_blendv_pd(g.t2, n2, sz);
    g.l0 = _mm256_add_epi64(g.l0, _mm256_castpd_si256(sx));  // a selected mask is -1
    g.l1 = _mm256_add_epi64(g.l1, _mm256_castpd_si256(sy));
    g.l2 = _mm256_add_epi64(g.l2, _mm256_castpd_si256(sz));
    g.rem = _mm256_sub_epi64(g.rem, one);
  }
};

/// The AVX2 walk (registered when the processor has AVX2).
INTERVOX_AVX2 __attribute__((flatten)) inline void walk_avx2(std::uint64_t* words, std::int64_t scratch,
                                                             BoxRaySource& rays) {
  walk_lanes<Avx2Lanes>(words, scratch, rays);
}

#undef INTERVOX_AVX2

#define INTERVOX_AVX512 __attribute__((target("avx512f")))

/// The lane operations of the AVX-512 walk: eight lanes per group, mask registers instead of
/// blends (the 32 vector registers hold both groups without spilling).
struct Avx512Lanes {
  using D = __m512d;
  using I = __m512i;

  INTERVOX_AVX512 static void ld(__m512d& v, const double* p) noexcept { v = _mm512_load_pd(p); }
  INTERVOX_AVX512 static void ldi(__m512i& v, const std::int64_t* p) noexcept { v = _mm512_load_si512(p); }
  INTERVOX_AVX512 static void st(double* p, const __m512d& v) noexcept { _mm512_store_pd(p, v); }
  INTERVOX_AVX512 static void sti(std::int64_t* p, const __m512i& v) noexcept { _mm512_store_si512(p, v); }

  INTERVOX_AVX512 static void mark(std::uint64_t* words, const LaneRegisters<Avx512Lanes>& g) noexcept {
    alignas(64) std::int64_t v[8];
    _mm512_store_si512(v, g.id);
    for (int l = 0; l < 8; ++l) set_bit(words, v[l]);
  }

  INTERVOX_AVX512 static unsigned done(const LaneRegisters<Avx512Lanes>& g) noexcept {
    return _mm512_cmpeq_epi64_mask(g.rem, _mm512_setzero_si512());
  }

  /// Avx2Lanes::step() for eight lanes, with mask registers instead of blends.
  INTERVOX_AVX512 static void step(LaneRegisters<Avx512Lanes>& g) noexcept {
    const __m512d inf = _mm512_set1_pd(std::numeric_limits<double>::infinity());
    const __m512i one = _mm512_set1_epi64(1);
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
};

/// The AVX-512 walk (registered when the processor has AVX-512 Foundation).
INTERVOX_AVX512 __attribute__((flatten)) inline void walk_avx512(std::uint64_t* words, std::int64_t scratch,
                                                                 BoxRaySource& rays) {
  walk_lanes<Avx512Lanes>(words, scratch, rays);
}

#undef INTERVOX_AVX512

/// Registers the vector walks this processor runs with walks.hpp's dispatch (called by
/// use_vector_walks(); registering again stores the same pointers).
inline void register_vector_walks() noexcept {
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx2")) registered_walks.avx2.store(&walk_avx2, std::memory_order_release);
  if (__builtin_cpu_supports("avx512f")) registered_walks.avx512.store(&walk_avx512, std::memory_order_release);
}

}  // namespace intervox::detail

#endif  // INTERVOX_HAVE_X86_WALKS
