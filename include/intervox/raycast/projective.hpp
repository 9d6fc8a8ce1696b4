#pragma once
/// \file
/// Projective insertion of depth images: every voxel of the camera's view frustum is projected
/// into the image once and freed by the depth of the pixel its centre falls in, instead of
/// walking every pixel's ray (insert.hpp); the voxel of each return gets its hit as in the exact
/// insertion. For dense depth images at sensor rate; the exact insertion stays the one that
/// equals OctoMap. docs/raycasting.md ("Projective insertion") compares the two, with the
/// agreement and the speed measured.
///
/// The rule, per frame:
///  - hits: the voxel of each return (a finite depth > 0 whose range lies in [min_range,
///    max_range], max_range when one is set), the voxel the exact insertion hits (the same
///    end point, pixel_point(), and the same key);
///  - misses: each voxel whose centre c lies in front of the camera (z-depth z > 0 in the optical
///    frame) and projects into pixel (u, v) = (floor(fx x / z + cx + 1/2), floor(fy y / z + cy +
///    1/2)) of the image gets a miss if z <= d - b for a pixel with a return at z-depth d, where b
///    is the surface band (surface_band voxel edges, measured along the pixel's ray and converted
///    to z-depth): voxels just in front of a surface, and all behind it, get no miss. A pixel whose
///    return lies beyond max_range, or without a return (+inf) when a max range is set, frees its
///    voxels up to max_range along its ray (as the exact insertion frees a cut ray);
///  - nothing from a return closer than min_range, a no-return pixel without a max range, an
///    invalid pixel (NaN, 0, negative, -inf) or a voxel whose centre projects outside the image;
///  - each voxel is updated at most once per frame, a hit winning over a miss (as the exact
///    insertion).
/// Voxels are visited block by block (8^3), and whole blocks (and 64^3 superblocks) are skipped
/// from their corners' projections: when they lie behind the camera, outside the image, or
/// behind the reach of every pixel they cover (a max-reach pyramid of the image).
///
/// Where it differs from the exact insertion (measured in docs/raycasting.md): a voxel a ray only
/// grazes, whose centre projects into another pixel, gets no miss from that ray; far from the
/// camera, where a voxel covers several pixels, one of them decides its miss (the exact walks
/// leave gaps there instead, between diverging rays); voxels near the camera whose centres
/// project outside the image (the camera's own voxel among them) get nothing.
///
/// Explained free space (explain/) does not apply: its classes belong to beams, walked through
/// the map one by one, and a projective frame has no beams. Use ExplainedSpace's insertion
/// (exact) where the explained channel is wanted.

#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/parallel.hpp>
#include <intervox/core/point.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/grid/occupancy_grid.hpp>
#include <intervox/raycast/detail/apply_marks.hpp>
#include <intervox/raycast/detail/block_marks.hpp>
#include <intervox/raycast/detail/walks.hpp>
#include <intervox/raycast/insert_options.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#if (defined(__x86_64__) || defined(_M_X64)) && (defined(__GNUC__) || defined(__clang__)) && \
    !defined(INTERVOX_NO_X86_WALKS)
#define INTERVOX_HAVE_PROJECTIVE_AVX2 1
#include <immintrin.h>
#else
#define INTERVOX_HAVE_PROJECTIVE_AVX2 0
#endif

namespace intervox {

/// Default surface band of projective insertion: voxel edges in front of a return whose voxels
/// get no miss (docs/raycasting.md measures the choice against the exact insertion).
inline constexpr double kDefaultSurfaceBand = 0.5;

/// The most 64^3 superblocks the key box of a frame's view frustum may span, whatever the insertion
/// budget (kUnlimitedInsertBudget included): each is projected once before any block is, and each
/// costs 4 bytes of scratch, so this bounds a frame's cost at a few seconds and 64 MiB (a box of
/// 256^3 superblocks: 820 m a side at 5 cm, 330 m at 2 cm; a frame near that frees far more voxels
/// than any budget holds). A frustum the image's reach makes larger (a return hundreds of
/// kilometres away with the budget off: 1.7e15 superblocks) is refused; the exact insertion walks
/// such rays one by one.
inline constexpr std::uint64_t kMaxProjectiveSuperblocks = std::uint64_t{1} << 24;

namespace detail {

struct ScanInserterAccess;  // insert.hpp: test access (set_walk() chooses the scalar form here)

/// One depth frame ready for projection: the camera's rotation and origin, the intrinsics, each
/// pixel's reach (the z-depth up to which its voxels get a miss), the max-reach pyramid over it,
/// and the voxels of the returns. classify_block() is the per-voxel rule of the
/// file comment; everything else in the insertion only decides which blocks to visit.
class ProjectedFrame {
 public:
  /// Builds the reach of every pixel of \p image seen with \p k from \p pose (rigid) by the rules
  /// of \p o (max and min range) and the surface band \p band_m in metres, and the voxels of the
  /// returns, on up to \p threads threads (rows split between them); counts each pixel once in
  /// \p stats (rays, truncated or a skipped_* counter).
  void build(const GridGeometry& g, const DepthImage& image, const PinholeIntrinsics& k, const Pose& pose,
             const InsertOptions& o, double band_m, unsigned threads, InsertStats& stats) {
    w_ = k.width;
    h_ = k.height;
    fx_ = static_cast<float>(k.fx);
    fy_ = static_cast<float>(k.fy);
    cx_ = static_cast<float>(k.cx + 0.5);
    cy_ = static_cast<float>(k.cy + 0.5);
    rt_ = pose.linear().transpose();
    origin_ = pose.translation();
    const std::size_t n = static_cast<std::size_t>(w_) * static_cast<std::size_t>(h_);
    rays_for(k);
    reach_.resize(n);
    // Rows split between the threads; each keeps its hits, concatenated in row order after.
    const unsigned nt = static_cast<unsigned>(std::clamp<std::size_t>(static_cast<std::size_t>(h_) / 16, 1, threads));
    if (part_hits_.size() < nt) part_hits_.resize(nt);
    std::vector<InsertStats> part(nt);
    std::vector<float> part_far(nt, 0.0f);
    const bool has_max = o.has_max_range();
    // A return's range (the exact insertion's, a square root) is needed only near min_range and
    // max_range: elsewhere its square decides.
    const double lo2 = o.min_range * o.min_range * (1 + 1e-9), hi2 = has_max ? o.max_range * o.max_range * (1 - 1e-9) : 0.0;
    // The range up to which a cut or no-return pixel frees its voxels, in double: the max range,
    // but no farther than any voxel of the key range can lie from the camera (whose voxel is in
    // the key range), which frees the same voxels; so a max range above the largest float (1e39)
    // frees what any range beyond the map frees instead of becoming an infinite float reach.
    const double free_range = has_max ? std::min(o.max_range, key_range_reach(g)) : 0.0;
    run_on_threads(nt, [&](unsigned t) {
      InsertStats& st = part[t];
      std::vector<Key>& hits = part_hits_[t];
      hits.clear();
      float far = 0.0f;
      for (int v = h_ * static_cast<int>(t) / static_cast<int>(nt); v < h_ * static_cast<int>(t + 1) / static_cast<int>(nt); ++v) {
        const double ry = ray_y_[static_cast<std::size_t>(v)];
        for (int u = 0; u < w_; ++u) {
          const std::size_t i = static_cast<std::size_t>(v) * static_cast<std::size_t>(w_) + static_cast<std::size_t>(u);
          const double d = image.depth[i];
          float& r = reach_[i];  // the z-depth up to which the pixel's voxels get a miss
          r = 0.0f;
          if (d > 0.0 && std::isfinite(d)) {
            // The exact insertion's end point, range and hit voxel (depth_pixel_beam(), prepare_ray()).
            // (pixel_point(k, pose, u, v, d) with k.ray(u, v) read from the table: the same operations)
            const Point3 end = pose * (Point3(ray_x_[static_cast<std::size_t>(u)], ry, 1.0) * d);
            const double r2 = (end - origin_).squaredNorm();
            const bool near_min = r2 <= lo2, near_max = has_max && r2 >= hi2;
            const double range = near_min || near_max ? std::sqrt(r2) : 0.0;
            if (near_min && range < o.min_range) {
              ++st.skipped_min_range;
              continue;
            }
            if (near_max && range > o.max_range) {
              ++st.rays;
              ++st.truncated;
              r = static_cast<float>(free_range * inv_norm_[i]);
            } else {
              Key key;
              if (!key_of(g, end, key)) {
                ++st.skipped_key_range;
                continue;
              }
              ++st.rays;
              if (hits.empty() || hits.back() != key) hits.push_back(key);  // (neighbours often share one)
              r = static_cast<float>(d - band_m * inv_norm_[i]);
            }
          } else if (d == std::numeric_limits<double>::infinity()) {
            if (!has_max) {
              ++st.skipped_no_max_range;
              continue;
            }
            ++st.rays;
            ++st.truncated;
            r = static_cast<float>(free_range * inv_norm_[i]);
          } else {
            ++st.skipped_invalid;
            continue;
          }
          far = std::max(far, r);
        }
      }
      part_far[t] = far;
    });
    hits_.clear();
    far_ = 0.0f;
    for (unsigned t = 0; t < nt; ++t) {
      stats += part[t];
      hits_.insert(hits_.end(), part_hits_[t].begin(), part_hits_[t].end());
      far_ = std::max(far_, part_far[t]);
    }
    build_pyramid();
  }

  /// Fills the ray tables for \p k unless they hold them already: ray_x_ and ray_y_ as
  /// PinholeIntrinsics::ray() computes them, inv_norm_ the z-depth per unit of range per pixel.
  void rays_for(const PinholeIntrinsics& k) {
    if (k.width == rays_of_.width && k.height == rays_of_.height && k.fx == rays_of_.fx && k.fy == rays_of_.fy &&
        k.cx == rays_of_.cx && k.cy == rays_of_.cy && !inv_norm_.empty())
      return;
    ray_x_.resize(static_cast<std::size_t>(k.width));
    ray_y_.resize(static_cast<std::size_t>(k.height));
    for (int u = 0; u < k.width; ++u) ray_x_[static_cast<std::size_t>(u)] = k.ray(u, 0).x();
    for (int v = 0; v < k.height; ++v) ray_y_[static_cast<std::size_t>(v)] = k.ray(0, v).y();
    inv_norm_.resize(static_cast<std::size_t>(k.width) * static_cast<std::size_t>(k.height));
    for (int v = 0; v < k.height; ++v)
      for (int u = 0; u < k.width; ++u) {
        const double x = ray_x_[static_cast<std::size_t>(u)], y = ray_y_[static_cast<std::size_t>(v)];
        inv_norm_[static_cast<std::size_t>(v) * static_cast<std::size_t>(k.width) + static_cast<std::size_t>(u)] =
            1.0 / std::sqrt(x * x + y * y + 1.0);
      }
    rays_of_ = k;
  }

  /// The farthest a voxel centre of the key range can lie from a point of the key range: its
  /// diagonal, 2^24 voxels a side (and at most the largest float, for absurd resolutions).
  static double key_range_reach(const GridGeometry& g) noexcept {
    return std::min(std::sqrt(3.0) * 2.0 * double(kKeyLimit) * g.resolution(), double(std::numeric_limits<float>::max()));
  }

  /// GridGeometry::try_key() without its calls to floor(): the same key, or false.
  static bool key_of(const GridGeometry& g, const Point3& p, Key& k) noexcept {
    const Point3 v = g.to_voxel_coords(p);
    for (int a = 0; a < 3; ++a) {
      const double x = v[a];
      if (!(x >= -double(kKeyLimit) && x < double(kKeyLimit))) return false;  // false for NaN
      const auto t = static_cast<std::int32_t>(x);  // towards zero; floor below for negatives
      k[a] = t - (static_cast<double>(t) > x ? 1 : 0);
    }
    return true;
  }

  /// The voxels of the returns (in pixel order, a pixel's dropped when it repeats the previous
  /// one's), as the exact insertion's hits.
  std::span<const Key> hits() const noexcept { return hits_; }

  /// The largest miss reach of any pixel (0: the frame's projection misses nothing).
  float far() const noexcept { return far_; }
  const Point3& origin() const noexcept { return origin_; }

  /// The world box of the view frustum up to z-depth far(): the origin and the image's four
  /// corners at that depth.
  Bounds frustum_bounds() const noexcept {
    Bounds b{origin_, origin_};
    const double z = far_;
    for (const double u : {-0.5, w_ - 0.5})
      for (const double v : {-0.5, h_ - 0.5}) {
        const Point3 dir((u + 0.5 - cx_) / fx_, (v + 0.5 - cy_) / fy_, 1.0);
        const Point3 p = origin_ + rt_.transpose() * (dir * z);
        b.min = b.min.cwiseMin(p);
        b.max = b.max.cwiseMax(p);
      }
    return b;
  }

  /// False if no voxel whose centre lies in the world box [lo, hi] can be updated: the box lies
  /// behind the camera, beyond far(), outside the image, or behind the reach of every pixel it
  /// covers. Conservative (one pixel of slack against rounding).
  bool may_update(const Point3& lo, const Point3& hi) const noexcept {
    double zmin = std::numeric_limits<double>::infinity(), zmax = -zmin;
    double umin = zmin, umax = -zmin, vmin = zmin, vmax = -zmin;
    std::array<Point3, 8> q;
    for (int c = 0; c < 8; ++c) {
      const Point3 p((c & 1) ? hi.x() : lo.x(), (c & 2) ? hi.y() : lo.y(), (c & 4) ? hi.z() : lo.z());
      q[c] = rt_ * (p - origin_);
      zmin = std::min(zmin, q[c].z());
      zmax = std::max(zmax, q[c].z());
    }
    if (zmax <= 0.0 || zmin > far_ + 1e-5 * far_ + 1e-4) return false;
    if (zmin <= 1e-9) return true;  // straddles the camera plane: no bounded projection
    for (const Point3& p : q) {
      const double u = fx_ * p.x() / p.z() + cx_, v = fy_ * p.y() / p.z() + cy_;
      umin = std::min(umin, u);
      umax = std::max(umax, u);
      vmin = std::min(vmin, v);
      vmax = std::max(vmax, v);
    }
    if (umax < -1.0 || vmax < -1.0 || umin > w_ + 1.0 || vmin > h_ + 1.0) return false;
    // Clamped in double before the conversion: a corner a hair in front of the camera plane
    // projects far beyond what an int holds.
    const auto pixel = [](double x, int last) { return static_cast<int>(std::clamp(x, 0.0, double(last))); };
    const int u0 = pixel(std::floor(umin) - 1.0, w_ - 1), u1 = pixel(std::floor(umax) + 1.0, w_ - 1);
    const int v0 = pixel(std::floor(vmin) - 1.0, h_ - 1), v1 = pixel(std::floor(vmax) + 1.0, h_ - 1);
    const float reach = max_reach(u0, u1, v0, v1);
    return zmin <= reach + 1e-5 * reach + 1e-4;  // slack: classify_block() works in float
  }

  /// Marks the misses of the voxels of the 8^3 block at \p base (a multiple of 8 per axis) in
  /// \p m by the rule of the file comment (its hit bits are cleared: hits come from the returns'
  /// voxels); returns the voxels whose centre projected into the image. With \p vector true
  /// (only where the processor runs AVX2) the AVX2 form runs; both give the same bits (the same
  /// single-precision operations in the same order, no fused multiply-add).
  std::uint64_t classify_block(const GridGeometry& g, const Key& base, BlockMarks& m, bool vector) const noexcept {
    const BlockStart b = start(g, base);
#if INTERVOX_HAVE_PROJECTIVE_AVX2
    if (vector) return classify_avx2(b, m);
#else
    (void)vector;
#endif
    return classify_scalar(b, m);
  }

 private:
  /// The camera-frame centre of a block's first voxel and one voxel step along each world axis
  /// (e[axis][component]), in single precision.
  struct BlockStart {
    float p0[3];
    float e[3][3];
  };
  BlockStart start(const GridGeometry& g, const Key& base) const noexcept {
    const Point3 c0 = rt_ * (g.center(base) - origin_);
    const float res = static_cast<float>(g.resolution());
    BlockStart b;
    for (int c = 0; c < 3; ++c) b.p0[c] = static_cast<float>(c0[c]);
    for (int a = 0; a < 3; ++a)
      for (int c = 0; c < 3; ++c) b.e[a][c] = static_cast<float>(rt_(c, a)) * res;
    return b;
  }
  /// Component c of the camera-frame centre of voxel (0, y, z) of the block.
  static float row_start(const BlockStart& b, int c, int y, int z) noexcept {
    return b.p0[c] + static_cast<float>(y) * b.e[1][c] + static_cast<float>(z) * b.e[2][c];
  }

  [[gnu::noinline]] std::uint64_t classify_scalar(const BlockStart& b, BlockMarks& m) const noexcept {
    const float wf = static_cast<float>(w_), hf = static_cast<float>(h_);
    std::uint64_t seen = 0;
    for (int z = 0; z < 8; ++z) {
      std::uint64_t miss = 0;
      for (int y = 0; y < 8; ++y) {
        const float rx = row_start(b, 0, y, z), ry = row_start(b, 1, y, z), rz = row_start(b, 2, y, z);
        for (int x = 0; x < 8; ++x) {
          const float xf = static_cast<float>(x);
          const float pz = rz + xf * b.e[0][2];
          if (!(pz > 0.0f)) continue;
          const float px = rx + xf * b.e[0][0];
          const float py = ry + xf * b.e[0][1];
          const float inv = 1.0f / pz;
          const float u = fx_ * px * inv + cx_, v = fy_ * py * inv + cy_;
          if (!(u >= 0.0f && u < wf && v >= 0.0f && v < hf)) continue;
          ++seen;
          const float r = reach_[static_cast<std::size_t>(static_cast<int>(v) * w_ + static_cast<int>(u))];
          if (pz <= r) miss |= std::uint64_t{1} << (x + 8 * y);
        }
      }
      m.hit[z] = 0;
      m.miss[z] = miss;
    }
    return seen;
  }

#if INTERVOX_HAVE_PROJECTIVE_AVX2
  /// classify_scalar() eight voxels (one x row) at a time.
  [[gnu::noinline, gnu::target("avx2,popcnt")]] std::uint64_t classify_avx2(const BlockStart& b, BlockMarks& m) const noexcept {
    const __m256 xs = _mm256_setr_ps(0.f, 1.f, 2.f, 3.f, 4.f, 5.f, 6.f, 7.f);
    const __m256 ex = _mm256_mul_ps(xs, _mm256_set1_ps(b.e[0][0])), ey = _mm256_mul_ps(xs, _mm256_set1_ps(b.e[0][1])),
                 ez = _mm256_mul_ps(xs, _mm256_set1_ps(b.e[0][2]));
    const __m256 fx = _mm256_set1_ps(fx_), fy = _mm256_set1_ps(fy_), cx = _mm256_set1_ps(cx_), cy = _mm256_set1_ps(cy_);
    const __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f);
    const __m256 wf = _mm256_set1_ps(static_cast<float>(w_)), hf = _mm256_set1_ps(static_cast<float>(h_));
    const __m256i wi = _mm256_set1_epi32(w_);
    std::uint64_t seen = 0;
    for (int z = 0; z < 8; ++z) {
      std::uint64_t miss = 0;
      for (int y = 0; y < 8; ++y) {
        const __m256 pz = _mm256_add_ps(_mm256_set1_ps(row_start(b, 2, y, z)), ez);
        const __m256 px = _mm256_add_ps(_mm256_set1_ps(row_start(b, 0, y, z)), ex);
        const __m256 py = _mm256_add_ps(_mm256_set1_ps(row_start(b, 1, y, z)), ey);
        const __m256 inv = _mm256_div_ps(one, pz);
        const __m256 u = _mm256_add_ps(_mm256_mul_ps(_mm256_mul_ps(fx, px), inv), cx);
        const __m256 v = _mm256_add_ps(_mm256_mul_ps(_mm256_mul_ps(fy, py), inv), cy);
        __m256 in = _mm256_and_ps(_mm256_cmp_ps(pz, zero, _CMP_GT_OQ), _mm256_cmp_ps(u, zero, _CMP_GE_OQ));
        in = _mm256_and_ps(in, _mm256_cmp_ps(u, wf, _CMP_LT_OQ));
        in = _mm256_and_ps(in, _mm256_cmp_ps(v, zero, _CMP_GE_OQ));
        in = _mm256_and_ps(in, _mm256_cmp_ps(v, hf, _CMP_LT_OQ));
        const int lanes = _mm256_movemask_ps(in);
        if (lanes == 0) continue;
        seen += static_cast<std::uint64_t>(__builtin_popcount(static_cast<unsigned>(lanes)));
        const __m256i idx = _mm256_add_epi32(_mm256_mullo_epi32(_mm256_cvttps_epi32(v), wi), _mm256_cvttps_epi32(u));
        const __m256 r = _mm256_mask_i32gather_ps(zero, reach_.data(), idx, in, 4);
        const int hit = _mm256_movemask_ps(_mm256_and_ps(in, _mm256_cmp_ps(pz, r, _CMP_LE_OQ)));
        miss |= static_cast<std::uint64_t>(static_cast<unsigned>(hit)) << (8 * y);
      }
      m.hit[z] = 0;
      m.miss[z] = miss;
    }
    return seen;
  }
#endif

 public:
  std::size_t memory_bytes() const noexcept {
    std::size_t n = reach_.capacity() * sizeof(float) + hits_.capacity() * sizeof(Key) +
                    (ray_x_.capacity() + ray_y_.capacity() + inv_norm_.capacity()) * sizeof(double);
    for (const auto& l : pyramid_) n += l.capacity() * sizeof(float);
    for (const auto& h : part_hits_) n += h.capacity() * sizeof(Key);
    return n;
  }

 private:
  /// Level l holds the largest miss reach of each 2^l x 2^l tile (level 0: per pixel).
  void build_pyramid() {
    std::size_t levels = 1;
    for (int s = std::max(w_, h_); s > 1; s = (s + 1) / 2) ++levels;
    pyramid_.resize(levels);
    pyramid_[0].resize(reach_.size());
    pyramid_[0] = reach_;
    int pw = w_, ph = h_;
    for (std::size_t l = 1; l < levels; ++l) {
      const int nw = (pw + 1) / 2, nh = (ph + 1) / 2;
      const auto& prev = pyramid_[l - 1];
      auto& cur = pyramid_[l];
      cur.assign(static_cast<std::size_t>(nw) * static_cast<std::size_t>(nh), 0.0f);
      for (int v = 0; v < ph; ++v)
        for (int u = 0; u < pw; ++u) {
          float& t = cur[static_cast<std::size_t>(v / 2) * static_cast<std::size_t>(nw) + static_cast<std::size_t>(u / 2)];
          t = std::max(t, prev[static_cast<std::size_t>(v) * static_cast<std::size_t>(pw) + static_cast<std::size_t>(u)]);
        }
      pw = nw;
      ph = nh;
    }
  }

  /// The largest miss reach over the pixels [u0, u1] x [v0, v1] (or over a few more: whole tiles).
  float max_reach(int u0, int u1, int v0, int v1) const noexcept {
    std::size_t l = 0;
    while (l + 1 < pyramid_.size() && ((u1 >> l) - (u0 >> l) + 1) * ((v1 >> l) - (v0 >> l) + 1) > 16) ++l;
    const int lw = (w_ + (1 << l) - 1) >> l;
    float m = 0.0f;
    for (int v = v0 >> l; v <= (v1 >> l); ++v)
      for (int u = u0 >> l; u <= (u1 >> l); ++u)
        m = std::max(m, pyramid_[l][static_cast<std::size_t>(v) * static_cast<std::size_t>(lw) + static_cast<std::size_t>(u)]);
    return m;
  }

  int w_ = 0, h_ = 0;
  float fx_ = 1, fy_ = 1, cx_ = 0, cy_ = 0;  // cx_, cy_ include the + 1/2 of the pixel rounding
  Eigen::Matrix3d rt_ = Eigen::Matrix3d::Identity();  // world to camera rotation
  Point3 origin_ = Point3::Zero();
  float far_ = 0.0f;
  std::vector<float> reach_;  // per pixel: the z-depth up to which its voxels get a miss
  std::vector<Key> hits_;
  std::vector<std::vector<Key>> part_hits_;  // per thread of build()
  PinholeIntrinsics rays_of_;       // the intrinsics of the ray tables
  std::vector<double> ray_x_, ray_y_, inv_norm_;
  std::vector<std::vector<float>> pyramid_;
};

}  // namespace detail

/// A reusable projective inserter (see the file comment for the rule and how it differs from
/// the exact insertion): keeps its scratch (the pixel reach, its pyramid and the block marks)
/// across frames.
///
/// Options: InsertOptions' max_range, min_range, threads and max_grid_bytes mean what they mean
/// for the exact insertion (max_mark_bytes is not used); \p surface_band is the surface band in
/// voxel edges (default kDefaultSurfaceBand; see the file comment).
///
/// Statistics: every pixel is counted once, in `rays` (and `truncated` when cut at max range or
/// without a return) or in skipped_invalid, skipped_min_range, skipped_no_max_range or
/// skipped_key_range (a return outside the key range, or every pixel when the camera is);
/// `voxel_steps` counts the voxels projected into the image; hits and misses as for the exact
/// insertion; outside_bounds: the marked voxels of blocks that a bounded grid's box cuts and the
/// returns outside it (blocks wholly outside the box are never visited).
///
/// Memory: the scratch holds about 20 bytes per pixel (its reach, ray table and pyramid, and the
/// voxel of its return), 160 bytes per visited 8^3 block, 2 KiB per 64^3 superblock with a
/// visited block and 4 bytes per superblock of the frustum's box. The visited blocks are those of
/// the frustum in front of the measured surfaces, so cost and scratch grow with the observed
/// volume, (range / resolution)^3: for long ranges the exact insertion costs less. On a sparse
/// grid, a frame whose blocks to update exceed the insertion budget (max_grid_bytes, at the
/// grid's bytes per block) throws InvalidArgument before the grid changes, as does a frame whose
/// frustum box holds more 64^3 superblocks than the budget has blocks (depth in millimetres read
/// as metres, or no max range with far returns). A dense grid clips the frustum to its box.
/// Whatever the budget (kUnlimitedInsertBudget included), a frustum box of more than
/// kMaxProjectiveSuperblocks superblocks (after that clip) is refused the same way: its voxels are
/// too many to project in bounded time. A max range beyond the key range frees what the key range
/// holds (a max range of 1e39, beyond the largest float, frees the same voxels as one of 1e6 m).
///
/// Determinism: the blocks are applied in block order (z, y, x), as by the exact insertion,
/// and nothing depends on the thread count: the grid (values and block allocation order) is
/// bit-identical for any number of threads.
///
/// Thread safety: one inserter per thread; the grid needs exclusive access during a call.
class ProjectiveInserter {
 public:
  /// \throws InvalidArgument for invalid options (InsertOptions::validate()) or a hit band that
  ///         is not finite and >= 0.
  explicit ProjectiveInserter(const InsertOptions& options = {}, double surface_band = kDefaultSurfaceBand) {
    set_options(options, surface_band);
  }

  const InsertOptions& options() const noexcept { return options_; }
  double surface_band() const noexcept { return surface_band_; }
  /// \throws InvalidArgument as the constructor.
  void set_options(const InsertOptions& options, double surface_band = kDefaultSurfaceBand) {
    options.validate();
    ParamCheck("intervox::ProjectiveInserter").nonnegative("surface_band", surface_band);
    options_ = options;
    surface_band_ = surface_band;
  }

  /// Inserts a depth image taken from \p pose (camera to world, optical frame) by projection.
  /// A pose with a NaN or infinite entry skips every pixel (counted in skipped_invalid), as the
  /// exact insertion skips rays with a NaN origin.
  /// \tparam G a VoxelGrid (any update policy and storage)
  /// \throws InvalidArgument if the intrinsics are invalid or do not match the image size, the
  ///         image buffer is inconsistent, the pose is finite but not rigid, or the frame exceeds
  ///         the insertion budget or kMaxProjectiveSuperblocks (see the class comment); the grid is
  ///         then unchanged.
  template <OccupancyGrid G>
  [[gnu::noinline]] InsertStats insert_depth_image(G& grid, const DepthImage& image, const PinholeIntrinsics& intrinsics,
                                                   const Pose& pose) {
    intrinsics.validate();
    if (!image.consistent())
      ParamCheck("intervox::insert_depth_image_projective").fail("depth buffer size does not match width x height");
    if (image.width != intrinsics.width || image.height != intrinsics.height)
      ParamCheck("intervox::insert_depth_image_projective")
          .fail("image is " + std::to_string(image.width) + "x" +
                std::to_string(image.height) + " but the intrinsics are " +
                std::to_string(intrinsics.width) + "x" + std::to_string(intrinsics.height));
    InsertStats st;
    if (!pose.matrix().allFinite()) {
      st.skipped_invalid = image.depth.size();
      return st;
    }
    detail::validate_pose(pose, "projective insertion pose");
    if (!grid.geometry().try_key(pose.translation())) {
      st.skipped_key_range = image.depth.size();
      return st;
    }
    frame_.build(grid.geometry(), image, intrinsics, pose, options_, surface_band_ * grid.resolution(),
                 resolve_threads(options_.threads), st);
    cause_ = detail::wide_intrinsics_cause(intrinsics);
    if (frame_.far() <= 0.0f && frame_.hits().empty()) return st;
    return st += run(grid);
  }

  /// Inserts a depth frame by projection, with the max range the smaller of the frame's and
  /// options().max_range (as ScanInserter::insert_depth_image(G&, const DepthFrame&)).
  /// \throws InvalidArgument for an invalid frame, if options().min_range exceeds the frame's
  ///         max range, or as the image overload.
  template <OccupancyGrid G>
  [[gnu::noinline]] InsertStats insert_depth_image(G& grid, const DepthFrame& frame) {
    frame.validate();
    const InsertOptions capped = options_.for_frame(frame.max_range);
    capped.validate();
    return detail::with_options(options_, capped,
                                [&] { return insert_depth_image(grid, frame.image, frame.intrinsics, frame.pose); });
  }

  /// Bytes held by the scratch (kept between frames).
  std::size_t scratch_bytes() const noexcept {
    std::size_t n = frame_.memory_bytes() + (supers_.capacity() + blocks_.capacity()) * sizeof(Key) +
                    (super_slot_.capacity() + slots_.capacity()) * sizeof(std::int32_t) +
                    marks_.capacity() * sizeof(detail::BlockMarks) +
                    list_.capacity() * sizeof(detail::MarkedBlock);
    for (const auto& c : candidates_) n += c.capacity() * sizeof(Key);
    return n;
  }
  /// Frees the scratch (the next frame allocates it again).
  void release_scratch() {
    const detail::WalkKind walk = walk_;
    *this = ProjectiveInserter(options_, surface_band_);
    walk_ = walk;
  }

 private:
  /// Blocks per superblock edge (a superblock is 64^3 voxels).
  static constexpr int kSuper = 8;

  /// The bytes a new block costs a sparse grid (cells plus table overhead); 0 for a dense one.
  template <OccupancyGrid G>
  static std::uint64_t bytes_per_block() noexcept {
    if constexpr (G::StorageType::kBounded) {
      return 0;
    } else {
      using Block = typename G::StorageType::template Container<typename G::Cell>::Block;
      return std::uint64_t{sizeof(Block)} + 64;
    }
  }

  [[noreturn]] void over_budget(const char* what, std::uint64_t blocks, std::uint64_t budget, double far, double res) const {
    ParamCheck("intervox::insert_depth_image_projective")
        .fail(std::string("this frame's view frustum ") + what + " (" + std::to_string(blocks) +
              " blocks of 8^3 voxels) than the insertion budget of " + std::to_string(budget >> 20) +
              " MiB allows (InsertOptions::max_grid_bytes); it reaches " + std::to_string(far) +
              " m in z-depth at a resolution of " + std::to_string(res * 1000.0) + " mm. " +
              (cause_.empty() ? std::string("Depth in millimetres read as metres, or no max_range with far returns? ")
                              : cause_) +
              "Set max_range, or raise max_grid_bytes if the frame is meant to be that large.");
  }

  [[noreturn]] static void too_many_superblocks(std::uint64_t supers, double far, double res) {
    ParamCheck("intervox::insert_depth_image_projective")
        .fail("this frame's view frustum spans " + std::to_string(supers) +
              " superblocks of 64^3 voxels, more than projective insertion visits (kMaxProjectiveSuperblocks = " +
              std::to_string(kMaxProjectiveSuperblocks) + ", whatever the insertion budget); it reaches " +
              std::to_string(far) + " m in z-depth at a resolution of " + std::to_string(res * 1000.0) +
              " mm. Set max_range, or insert such frames with the exact insertion (ScanInserter), which walks "
              "each pixel's ray alone.");
  }

  template <OccupancyGrid G>
  InsertStats run(G& grid) {
    const GridGeometry& g = grid.geometry();
    const double res = g.resolution();
    // The key box of the frustum, clipped to the key range and to a bounded grid's box.
    const Bounds fb = frame_.frustum_bounds();
    Key lo, hi;
    for (int a = 0; a < 3; ++a) {
      const double l = std::floor((fb.min[a] - g.origin()[a]) / res) - 1, h = std::floor((fb.max[a] - g.origin()[a]) / res) + 1;
      lo[a] = static_cast<std::int32_t>(std::clamp(l, -double(kKeyLimit), double(kKeyLimit) - 1));
      hi[a] = static_cast<std::int32_t>(std::clamp(h, -double(kKeyLimit), double(kKeyLimit) - 1));
    }
    for (const Key& k : frame_.hits())
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min(lo[a], k[a]);
        hi[a] = std::max(hi[a], k[a]);
      }
    if (const auto& box = grid.key_box()) {
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::max(lo[a], box->min[a]);
        hi[a] = std::min(hi[a], box->max[a]);
        if (lo[a] > hi[a]) return {};
      }
    }
    const std::uint64_t per_block = bytes_per_block<G>();
    const bool check = !G::StorageType::kBounded && options_.max_grid_bytes != kUnlimitedInsertBudget;
    const std::uint64_t budget_blocks = check ? options_.max_grid_bytes / std::max<std::uint64_t>(per_block, 1) : ~std::uint64_t{0};

    // Superblocks (64^3 voxels) of the box that may be updated, in z, y, x order.
    std::int64_t s_lo[3], s_n[3];
    std::uint64_t s_total = 1;
    for (int a = 0; a < 3; ++a) {
      s_lo[a] = lo[a] >> 6;
      s_n[a] = (hi[a] >> 6) - s_lo[a] + 1;
      s_total *= static_cast<std::uint64_t>(s_n[a]);  // < 2^18 per axis: no overflow
    }
    if (check && s_total > budget_blocks) over_budget("spans more superblocks", s_total, options_.max_grid_bytes, frame_.far(), res);
    if (s_total > kMaxProjectiveSuperblocks) too_many_superblocks(s_total, frame_.far(), res);
    const auto centre_box = [&](const Key& k0, std::int32_t n) {  // the box of the centres of [k0, k0 + n)
      return std::pair{g.center(k0), g.center(Key{k0.x + n - 1, k0.y + n - 1, k0.z + n - 1})};
    };
    supers_.clear();
    for (std::int64_t z = 0; z < s_n[2]; ++z)
      for (std::int64_t y = 0; y < s_n[1]; ++y)
        for (std::int64_t x = 0; x < s_n[0]; ++x) {
          const Key s{static_cast<std::int32_t>((s_lo[0] + x) * 64), static_cast<std::int32_t>((s_lo[1] + y) * 64),
                      static_cast<std::int32_t>((s_lo[2] + z) * 64)};
          const auto [a, b] = centre_box(s, 64);
          if (frame_.may_update(a, b)) supers_.push_back(s);
        }

    // Blocks of those superblocks inside the box that may be updated, each thread a contiguous
    // run of superblocks; concatenated in superblock order (the same for any thread count).
    const unsigned nt = resolve_threads(options_.threads);
    const auto capped = [nt](std::size_t n) { return static_cast<unsigned>(std::clamp<std::size_t>(n, 1, nt)); };
    const unsigned nc = capped(supers_.size());
    if (candidates_.size() < nc) candidates_.resize(nc);
    run_on_threads(nc, [&](unsigned t) {
      auto& out = candidates_[t];
      out.clear();
      const std::size_t b = supers_.size() * t / nc, e = supers_.size() * (t + 1) / nc;
      for (std::size_t j = b; j < e; ++j) {
        const Key& s = supers_[j];
        for (int bz = 0; bz < kSuper; ++bz)
          for (int by = 0; by < kSuper; ++by)
            for (int bx = 0; bx < kSuper; ++bx) {
              const Key base{s.x + 8 * bx, s.y + 8 * by, s.z + 8 * bz};
              if (base.x + 7 < lo.x || base.x > hi.x || base.y + 7 < lo.y || base.y > hi.y || base.z + 7 < lo.z ||
                  base.z > hi.z)
                continue;
              const auto [a, c] = centre_box(base, 8);
              if (frame_.may_update(a, c)) out.push_back(base);
            }
      }
    });
    std::size_t total = 0;
    for (unsigned t = 0; t < nc; ++t) total += candidates_[t].size();
    if (check && total > budget_blocks) over_budget("has more blocks to update", total, options_.max_grid_bytes, frame_.far(), res);
    blocks_.resize(total);
    std::size_t at = 0;
    for (unsigned t = 0; t < nc; ++t) {
      std::copy(candidates_[t].begin(), candidates_[t].end(), blocks_.begin() + static_cast<std::ptrdiff_t>(at));
      at += candidates_[t].size();
    }

    // Classify every voxel of the candidate blocks, split evenly between the threads; the AVX2
    // form where the program chose the vector walks (use_vector_walks()) and walk_ allows it.
    const detail::WalkKind kind = detail::resolve_walk(walk_);
    const bool vector = kind == detail::WalkKind::Avx512 || kind == detail::WalkKind::Avx2;
    marks_.resize(total);
    const unsigned nm = capped(total / 16);
    std::vector<std::uint64_t> seen(nm, 0);
    run_on_threads(nm, [&](unsigned t) {
      const std::size_t b = total * t / nm, e = total * (t + 1) / nm;
      for (std::size_t j = b; j < e; ++j) seen[t] += frame_.classify_block(g, blocks_[j], marks_[j], vector);
    });

    // The hits: the voxel of each return (the exact insertion's), found through a superblock
    // index; blocks that the projection skipped are added after the others, in pixel order.
    InsertStats st;
    super_slot_.assign(s_total, -1);
    slots_.clear();
    const auto slot_of = [&](const Key& base) -> std::int32_t& {
      const std::uint64_t si = static_cast<std::uint64_t>(
          ((std::int64_t{base.z >> 6} - s_lo[2]) * s_n[1] + (std::int64_t{base.y >> 6} - s_lo[1])) * s_n[0] +
          (std::int64_t{base.x >> 6} - s_lo[0]));
      std::int32_t& slot = super_slot_[si];
      if (slot < 0) {
        slot = static_cast<std::int32_t>(slots_.size() / 512);
        slots_.resize(slots_.size() + 512, -1);
      }
      return slots_[static_cast<std::size_t>(slot) * 512 + static_cast<std::size_t>(((base.z >> 3) & 7) * 64 + ((base.y >> 3) & 7) * 8 + ((base.x >> 3) & 7))];
    };
    for (std::size_t j = 0; j < total; ++j) slot_of(blocks_[j]) = static_cast<std::int32_t>(j);
    for (const Key& k : frame_.hits()) {
      if (k.x < lo.x || k.x > hi.x || k.y < lo.y || k.y > hi.y || k.z < lo.z || k.z > hi.z) {
        ++st.outside_bounds;  // (only where a bounded grid's box cut the key box)
        continue;
      }
      const Key base{k.x & ~7, k.y & ~7, k.z & ~7};
      std::int32_t& j = slot_of(base);
      if (j < 0) {
        j = static_cast<std::int32_t>(blocks_.size());
        blocks_.push_back(base);
        marks_.push_back(detail::BlockMarks{});
      }
      detail::set_bit(marks_[static_cast<std::size_t>(j)].hit, (k.x - base.x) + 8 * (k.y - base.y) + 64 * (k.z - base.z));
    }
    if (check && blocks_.size() > budget_blocks)
      over_budget("has more blocks to update", blocks_.size(), options_.max_grid_bytes, frame_.far(), res);

    list_.clear();
    for (std::size_t j = 0; j < blocks_.size(); ++j) {
      const detail::BlockMarks& m = marks_[j];
      std::uint64_t any = 0;
      for (int w = 0; w < 8; ++w) any |= m.hit[w] | m.miss[w];
      if (any) list_.emplace_back(blocks_[j], &m);
    }
    // Applied in block order (z, y, x), as the exact insertion applies its marks: the grid's
    // blocks are allocated in the same order, and a saved and loaded grid keeps it.
    std::sort(list_.begin(), list_.end(), [](const detail::MarkedBlock& a, const detail::MarkedBlock& b) {
      return std::tie(a.first.z, a.first.y, a.first.x) < std::tie(b.first.z, b.first.y, b.first.x);
    });
    st += detail::apply_marks(grid, std::span<const detail::MarkedBlock>(list_), capped(list_.size() / 16));
    for (const auto s : seen) st.voxel_steps += s;
    return st;
  }

  InsertOptions options_;
  double surface_band_ = kDefaultSurfaceBand;
  std::string cause_;  ///< what a budget refusal of the current frame names (wide_intrinsics_cause())
  detail::ProjectedFrame frame_;
  std::vector<Key> supers_;
  std::vector<std::vector<Key>> candidates_;
  std::vector<Key> blocks_;
  std::vector<detail::BlockMarks> marks_;
  std::vector<detail::MarkedBlock> list_;
  std::vector<std::int32_t> super_slot_;  // per superblock of the key box: its slot, or -1
  std::vector<std::int32_t> slots_;       // per slot, 512 blocks: the index into blocks_, or -1
  detail::WalkKind walk_ = detail::WalkKind::Fastest;

  friend struct detail::ScanInserterAccess;
};

/// Inserts a depth image by projection (see ProjectiveInserter). Allocates scratch per call: use
/// a ProjectiveInserter for a stream of frames.
/// \tparam G a VoxelGrid
/// \throws InvalidArgument as ProjectiveInserter::insert_depth_image
template <OccupancyGrid G>
InsertStats insert_depth_image_projective(G& grid, const DepthImage& image, const PinholeIntrinsics& intrinsics,
                                          const Pose& pose, const InsertOptions& options = {},
                                          double surface_band = kDefaultSurfaceBand) {
  return ProjectiveInserter(options, surface_band).insert_depth_image(grid, image, intrinsics, pose);
}

/// Inserts a depth frame by projection, the max range the smaller of the frame's and
/// \p options.max_range (see ProjectiveInserter).
/// \tparam G a VoxelGrid
/// \throws InvalidArgument as ProjectiveInserter::insert_depth_image
template <OccupancyGrid G>
InsertStats insert_depth_image_projective(G& grid, const DepthFrame& frame, const InsertOptions& options = {},
                                          double surface_band = kDefaultSurfaceBand) {
  return ProjectiveInserter(options, surface_band).insert_depth_image(grid, frame);
}

}  // namespace intervox
