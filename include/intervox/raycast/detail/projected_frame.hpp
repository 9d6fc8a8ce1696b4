#pragma once
/// \file
/// Internal part of projective insertion (raycast/projective.hpp): detail::ProjectedFrame, one
/// depth frame ready for projection (each pixel's reach, its max-reach pyramid, the voxels of the
/// returns) and the per-voxel rule that classifies a block's voxels (scalar and AVX2 forms).

#include <intervox/core/key.hpp>
#include <intervox/core/parallel.hpp>
#include <intervox/core/point.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/raycast/detail/block_marks.hpp>
#include <intervox/raycast/insert_options.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#if (defined(__x86_64__) || defined(_M_X64)) && (defined(__GNUC__) || defined(__clang__)) && \
    !defined(INTERVOX_NO_X86_WALKS)
#define INTERVOX_HAVE_PROJECTIVE_AVX2 1
#include <immintrin.h>
#else
#define INTERVOX_HAVE_PROJECTIVE_AVX2 0
#endif

namespace intervox::detail {

/// One depth frame ready for projection: the camera's rotation and origin, the intrinsics, each
/// pixel's reach (the z-depth up to which its voxels get a miss), the max-reach pyramid over it,
/// and the voxels of the returns. classify_block() is the per-voxel rule of
/// projective.hpp's file comment; everything else in the insertion only decides which blocks to visit.
class ProjectedFrame {
 public:
  /// Builds the reach of every pixel of \p image seen with \p k from \p pose (rigid) by the rules
  /// of \p o (max and min range) and the surface band \p band_m in metres, and the voxels of the
  /// returns, on up to \p threads threads (rows split between them); counts each pixel once in
  /// \p stats (rays, truncated or a skipped_* counter).
  void build(const GridGeometry& g, const DepthImage& image, const PinholeIntrinsics& k, const Pose& pose,
             const InsertOptions& o, double band_m, unsigned threads, InsertStats& stats) {
    set_camera(k, pose);
    const std::size_t n = static_cast<std::size_t>(w_) * static_cast<std::size_t>(h_);
    rays_for(k);
    reach_.resize(n);
    // Rows split between the threads; each keeps its hits, concatenated in row order after.
    const unsigned nt = static_cast<unsigned>(std::clamp<std::size_t>(static_cast<std::size_t>(h_) / 16, 1, threads));
    if (part_hits_.size() < nt) part_hits_.resize(nt);
    std::vector<InsertStats> part(nt);
    std::vector<float> part_far(nt, 0.0f);
    const PixelRule rule = pixel_rule(g, o, band_m);
    run_on_threads(nt, [&](unsigned t) {
      std::vector<Key>& hits = part_hits_[t];
      hits.clear();
      part_far[t] = reach_of_rows(g, image, pose, rule, h_ * static_cast<int>(t) / static_cast<int>(nt),
                                  h_ * static_cast<int>(t + 1) / static_cast<int>(nt), part[t], hits);
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

 private:
  /// How build() reads a pixel: the ranges of InsertOptions and the surface band in metres.
  struct PixelRule {
    double min_range = 0.0, max_range = 0.0;
    bool has_max = false;
    // A return's range (the exact insertion's, a square root) is needed only near min_range and
    // max_range: elsewhere its square decides.
    double lo2 = 0.0, hi2 = 0.0;
    // The range up to which a cut or no-return pixel frees its voxels, in double: the max range,
    // but no farther than any voxel of the key range can lie from the camera (whose voxel is in
    // the key range), which frees the same voxels; so a max range above the largest float (1e39)
    // frees what any range beyond the map frees instead of becoming an infinite float reach.
    double free_range = 0.0;
    double band_m = 0.0;
  };
  static PixelRule pixel_rule(const GridGeometry& g, const InsertOptions& o, double band_m) noexcept {
    PixelRule r;
    r.min_range = o.min_range;
    r.max_range = o.max_range;
    r.has_max = o.has_max_range();
    r.lo2 = o.min_range * o.min_range * (1 + 1e-9);
    r.hi2 = r.has_max ? o.max_range * o.max_range * (1 - 1e-9) : 0.0;
    r.free_range = r.has_max ? std::min(o.max_range, key_range_reach(g)) : 0.0;
    r.band_m = band_m;
    return r;
  }

  /// The camera of the frame: its image size, intrinsics (in float, cx_ and cy_ with the + 1/2 of
  /// the pixel rounding), world to camera rotation and origin.
  void set_camera(const PinholeIntrinsics& k, const Pose& pose) {
    w_ = k.width;
    h_ = k.height;
    fx_ = static_cast<float>(k.fx);
    fy_ = static_cast<float>(k.fy);
    cx_ = static_cast<float>(k.cx + 0.5);
    cy_ = static_cast<float>(k.cy + 0.5);
    rt_ = pose.linear().transpose();
    origin_ = pose.translation();
  }

  /// The reach of every pixel of rows [v0, v1) by \p rule, the voxels of their returns appended
  /// to \p hits (a pixel's dropped when it repeats the previous one's), each pixel counted in
  /// \p st; returns the largest reach of the rows.
  float reach_of_rows(const GridGeometry& g, const DepthImage& image, const Pose& pose, const PixelRule& rule, int v0,
                      int v1, InsertStats& st, std::vector<Key>& hits) {
    float far = 0.0f;
    for (int v = v0; v < v1; ++v) {
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
          const bool near_min = r2 <= rule.lo2, near_max = rule.has_max && r2 >= rule.hi2;
          const double range = near_min || near_max ? std::sqrt(r2) : 0.0;
          if (near_min && range < rule.min_range) {
            ++st.skipped_min_range;
            continue;
          }
          if (near_max && range > rule.max_range) {
            ++st.rays;
            ++st.truncated;
            r = static_cast<float>(rule.free_range * inv_norm_[i]);
          } else {
            Key key;
            if (!key_of(g, end, key)) {
              ++st.skipped_key_range;
              continue;
            }
            ++st.rays;
            if (hits.empty() || hits.back() != key) hits.push_back(key);  // (neighbours often share one)
            r = static_cast<float>(d - rule.band_m * inv_norm_[i]);
          }
        } else if (d == std::numeric_limits<double>::infinity()) {
          if (!rule.has_max) {
            ++st.skipped_no_max_range;
            continue;
          }
          ++st.rays;
          ++st.truncated;
          r = static_cast<float>(rule.free_range * inv_norm_[i]);
        } else {
          ++st.skipped_invalid;
          continue;
        }
        far = std::max(far, r);
      }
    }
    return far;
  }

 public:
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
    return std::min(std::sqrt(3.0) * 2.0 * double(kKeyLimit) * g.resolution(),
                    double(std::numeric_limits<float>::max()));
  }

  /// GridGeometry::try_key() without its calls to floor(): the same key, or false.
  static bool key_of(const GridGeometry& g, const Point3& p, Key& k) noexcept {
    const Point3 v = g.to_voxel_coords(p);
    for (int a = 0; a < 3; ++a) {
      const double x = v[a];
      if (!(x >= -double(kKeyLimit) && x < double(kKeyLimit))) return false;  // false for NaN
      const auto t = static_cast<std::int32_t>(x);                            // towards zero; floor below for negatives
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
  /// \p m by the rule of projective.hpp's file comment (its hit bits are cleared: hits come from the returns'
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
  [[gnu::noinline, gnu::target("avx2,popcnt")]] std::uint64_t classify_avx2(const BlockStart& b,
                                                                            BlockMarks& m) const noexcept {
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
          float& t =
              cur[static_cast<std::size_t>(v / 2) * static_cast<std::size_t>(nw) + static_cast<std::size_t>(u / 2)];
          t = std::max(t,
                       prev[static_cast<std::size_t>(v) * static_cast<std::size_t>(pw) + static_cast<std::size_t>(u)]);
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
        m = std::max(
            m, pyramid_[l][static_cast<std::size_t>(v) * static_cast<std::size_t>(lw) + static_cast<std::size_t>(u)]);
    return m;
  }

  int w_ = 0, h_ = 0;
  float fx_ = 1, fy_ = 1, cx_ = 0, cy_ = 0;           // cx_, cy_ include the + 1/2 of the pixel rounding
  Eigen::Matrix3d rt_ = Eigen::Matrix3d::Identity();  // world to camera rotation
  Point3 origin_ = Point3::Zero();
  float far_ = 0.0f;
  std::vector<float> reach_;  // per pixel: the z-depth up to which its voxels get a miss
  std::vector<Key> hits_;
  std::vector<std::vector<Key>> part_hits_;  // per thread of build()
  PinholeIntrinsics rays_of_;                // the intrinsics of the ray tables
  std::vector<double> ray_x_, ray_y_, inv_norm_;
  std::vector<std::vector<float>> pyramid_;
};

}  // namespace intervox::detail
