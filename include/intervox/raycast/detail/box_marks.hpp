#pragma once
/// \file
/// Internal part of ray insertion: the per-scan voxel marks as two plain bitmaps over the scan's
/// key box (BoxMarks), and the state of one ray walking them (BoxRay). The walks that fill them
/// are in walks.hpp.
///
/// Thread safety: a BoxMarks is used by one thread at a time.

#include <intervox/core/key.hpp>
#include <intervox/core/point.hpp>
#include <intervox/raycast/detail/block_marks.hpp>
#include <intervox/raycast/traversal.hpp>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace intervox::detail {

/// One segment ready to walk in a BoxMarks: SegmentDda's state, with bit ids instead of keys.
struct BoxRay {
  double t[3];           ///< SegmentDda::t_max
  double dt[3];          ///< SegmentDda::t_delta
  std::int64_t left[3];  ///< SegmentDda::left
  std::int64_t rem;      ///< steps still to take: the walk marks rem + 1 voxels
  std::int64_t id;       ///< bit id of the current voxel
  std::int64_t did[3];   ///< bit-id change of one step along each axis (0 if the axis never steps)
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

  std::size_t memory_bytes() const noexcept { return (miss_.capacity() + hit_.capacity()) * sizeof(std::uint64_t); }

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

}  // namespace intervox::detail
