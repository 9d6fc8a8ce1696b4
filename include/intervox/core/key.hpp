#pragma once
/// \file
/// Voxel keys, axis-aligned boxes and the grid geometry that maps points to keys.

#include <intervox/core/checked_math.hpp>
#include <intervox/core/error.hpp>
#include <intervox/core/point.hpp>
#include <intervox/core/validate.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>

namespace intervox {

/// Integer coordinates of a voxel. Voxel (x, y, z) covers
/// [origin + x * res, origin + (x + 1) * res) on each axis.
struct Key {
  std::int32_t x = 0;
  std::int32_t y = 0;
  std::int32_t z = 0;

  constexpr std::int32_t operator[](int axis) const noexcept { return axis == 0 ? x : (axis == 1 ? y : z); }
  constexpr std::int32_t& operator[](int axis) noexcept { return axis == 0 ? x : (axis == 1 ? y : z); }
  friend constexpr bool operator==(const Key&, const Key&) = default;
  /// Lexicographic order (x, then y, then z), for sorted containers and deterministic output.
  friend constexpr auto operator<=>(const Key&, const Key&) = default;
};

/// Keys are limited to [-kKeyLimit, kKeyLimit) on each axis: 2^23 voxels either side of the
/// origin (168 km at 2 cm). Points beyond that are rejected, never wrapped.
inline constexpr std::int32_t kKeyLimit = std::int32_t{1} << 23;

/// True if every coordinate of \p k lies in [-kKeyLimit, kKeyLimit).
constexpr bool in_key_range(const Key& k) noexcept {
  return k.x >= -kKeyLimit && k.x < kKeyLimit && k.y >= -kKeyLimit && k.y < kKeyLimit && k.z >= -kKeyLimit &&
         k.z < kKeyLimit;
}

/// Hash for Key (for std::unordered_map and friends).
struct KeyHash {
  std::size_t operator()(const Key& k) const noexcept {
    std::uint64_t h = static_cast<std::uint32_t>(k.x);
    h = h * 0x9E3779B97F4A7C15ULL ^ static_cast<std::uint32_t>(k.y);
    h = h * 0x9E3779B97F4A7C15ULL ^ static_cast<std::uint32_t>(k.z);
    return static_cast<std::size_t>(h ^ (h >> 29));
  }
};

/// An inclusive box of keys [min, max].
struct KeyBox {
  Key min;
  Key max;
  /// True if \p k lies in the box.
  constexpr bool contains(const Key& k) const noexcept {
    return k.x >= min.x && k.x <= max.x && k.y >= min.y && k.y <= max.y && k.z >= min.z && k.z <= max.z;
  }
  /// Number of keys along \p axis.
  constexpr std::int64_t extent(int axis) const noexcept {
    return std::int64_t{max[axis]} - std::int64_t{min[axis]} + 1;
  }
  /// Number of keys in the box, or nothing if it does not fit in 64 bits (keys are 32-bit, so a
  /// box can hold up to 2^96 keys); 0 for an empty box (max < min on some axis).
  constexpr std::optional<std::uint64_t> checked_volume() const noexcept {
    std::uint64_t v = 1;
    for (int a = 0; a < 3; ++a) {
      if (extent(a) <= 0) return std::uint64_t{0};
      const auto next = checked_mul(v, static_cast<std::uint64_t>(extent(a)));
      if (!next) return std::nullopt;
      v = *next;
    }
    return v;
  }
  /// Number of keys in the box, saturating at INT64_MAX (never wraps: a box of more keys than
  /// that reports INT64_MAX); 0 for an empty box. Size checks compare this with their limit.
  constexpr std::int64_t volume() const noexcept {
    constexpr auto kMax = static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max());
    const auto v = checked_volume();
    return static_cast<std::int64_t>(v && *v <= kMax ? *v : kMax);
  }
  friend constexpr bool operator==(const KeyBox&, const KeyBox&) = default;
};

/// An axis-aligned box in metres, [min, max].
struct Bounds {
  Point3 min = Point3::Zero();
  Point3 max = Point3::Zero();
  /// True if every coordinate is finite and min <= max on every axis.
  bool valid() const noexcept { return is_finite(min) && is_finite(max) && (min.array() <= max.array()).all(); }
  /// True if \p p lies in the closed box.
  bool contains(const Point3& p) const noexcept {
    return (p.array() >= min.array()).all() && (p.array() <= max.array()).all();
  }
};

/// Resolution and origin of a grid: the mapping between metric points and keys.
///
/// Thread safety: immutable after construction.
class GridGeometry {
 public:
  /// \param resolution edge length of a voxel in metres, finite and > 0
  /// \param origin corner of voxel (0, 0, 0), finite
  /// \throws InvalidArgument if resolution or origin is not valid
  explicit GridGeometry(double resolution, const Point3& origin = Point3::Zero())
      : resolution_(resolution), inv_resolution_(1.0 / resolution), origin_(origin) {
    const ParamCheck check("intervox::GridGeometry");
    check.positive("resolution", resolution);
    if (!is_finite(origin)) check.fail("origin must be finite");
  }

  double resolution() const noexcept { return resolution_; }
  double inv_resolution() const noexcept { return inv_resolution_; }
  const Point3& origin() const noexcept { return origin_; }

  /// Continuous voxel coordinates of a point ((p - origin) / resolution).
  Point3 to_voxel_coords(const Point3& p) const noexcept { return (p - origin_) * inv_resolution_; }

  /// The key of the voxel containing \p p, or nothing if p is not finite or lies outside the key
  /// range. A point exactly on a voxel face belongs to the voxel on its positive side.
  std::optional<Key> try_key(const Point3& p) const noexcept {
    const Point3 v = to_voxel_coords(p);
    Key k;
    for (int a = 0; a < 3; ++a) {
      const double f = std::floor(v[a]);
      // The comparison is false for NaN, so non-finite points fail here too.
      if (!(f >= -double(kKeyLimit) && f < double(kKeyLimit))) return std::nullopt;
      k[a] = static_cast<std::int32_t>(f);
    }
    return k;
  }

  /// The key of the voxel containing \p p.
  /// \throws InvalidArgument if p is not finite; OutOfRange if it lies outside the key range.
  Key key(const Point3& p) const {
    if (!is_finite(p)) ParamCheck("intervox").fail("point has a NaN or infinite coordinate");
    if (auto k = try_key(p)) return *k;
    throw OutOfRange("intervox: point (" + std::to_string(p.x()) + ", " + std::to_string(p.y()) + ", " +
                     std::to_string(p.z()) + ") lies outside the representable key range");
  }

  /// Centre of the voxel \p k.
  Point3 center(const Key& k) const noexcept { return origin_ + Point3(k.x + 0.5, k.y + 0.5, k.z + 0.5) * resolution_; }
  /// Minimum corner of the voxel \p k.
  Point3 corner(const Key& k) const noexcept {
    return origin_ + Point3(double(k.x), double(k.y), double(k.z)) * resolution_;
  }

  /// The keys of every voxel that intersects the metric box \p b.
  /// \throws InvalidArgument if b is not valid; OutOfRange if it leaves the key range.
  KeyBox key_box(const Bounds& b) const {
    ParamCheck("intervox::GridGeometry::key_box").valid_bounds("bounds", b);
    const auto lo = try_key(b.min);
    // The max corner itself belongs to the next voxel when it lies on a face; step back by a
    // relative epsilon so that a box [0, 1] at 0.1 m covers exactly ten voxels per axis.
    Point3 hi_p = b.max;
    for (int a = 0; a < 3; ++a) {
      const double v = (b.max[a] - origin_[a]) * inv_resolution_;
      if (v == std::floor(v) && b.max[a] > b.min[a]) hi_p[a] = origin_[a] + (v - 0.5) * resolution_;
    }
    const auto hi = try_key(hi_p);
    if (!lo || !hi) throw OutOfRange("intervox: bounds leave the representable key range");
    return {*lo, *hi};
  }

  friend bool operator==(const GridGeometry& a, const GridGeometry& b) noexcept {
    return a.resolution_ == b.resolution_ && a.origin_ == b.origin_;
  }

 private:
  double resolution_;
  double inv_resolution_;
  Point3 origin_;
};

}  // namespace intervox
