#pragma once
/// \file
/// Exact 3D voxel traversal of a segment (Amanatides & Woo, "A Fast Voxel Traversal Algorithm
/// for Ray Tracing", 1987): every voxel whose interior the segment crosses, in order.

#include <intervox/core/key.hpp>
#include <intervox/core/point.hpp>

#include <cmath>
#include <concepts>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <type_traits>

namespace intervox {

/// How a traversal ended.
enum class TraverseStatus : std::uint8_t {
  Completed = 0,  ///< every voxel from the first to the last was visited
  Stopped = 1,    ///< the visitor returned false
  Invalid = 2,    ///< an endpoint is not finite or lies outside the key range: nothing visited
};

/// Result of traverse(): the status and the number of voxels handed to the visitor.
struct TraverseResult {
  TraverseStatus status = TraverseStatus::Completed;
  std::uint64_t voxels = 0;
};

/// A ray visitor: called with each voxel's key, returns true to continue, false to stop.
/// \tparam V the candidate visitor type
template <class V>
concept RayVisitor = std::is_invocable_r_v<bool, V&, const Key&>;

namespace detail {

/// The Amanatides–Woo stepper between two voxels of known keys, in voxel coordinates.
///
/// Termination does not depend on floating-point luck: each axis steps exactly
/// |end - start| times (an exhausted axis is never chosen again), so the walk always ends in the
/// end voxel after the Manhattan distance between both keys, and every step moves to a
/// face-adjacent voxel. Ties (the segment passes exactly through an edge or a corner) step the
/// higher axis first (z before y before x), as OctoMap's computeRayKeys does.
struct SegmentDda {
  Key key;                  ///< current voxel
  std::int32_t step[3];     ///< +1, -1 or 0 per axis
  std::int32_t left[3];     ///< steps still to take per axis
  double t_max[3];          ///< parameter (0 at start, 1 at end) of the next face crossing per axis
  double t_delta[3];        ///< parameter between two face crossings per axis
  std::uint64_t remaining;  ///< steps still to take in total

  /// \param v0, v1 endpoints in voxel coordinates ((p - origin) / resolution)
  /// \param k0, k1 their keys (floor of v0 and v1)
  SegmentDda(const Point3& v0, const Point3& v1, const Key& k0, const Key& k1) noexcept : key(k0) {
    constexpr double inf = std::numeric_limits<double>::infinity();
    remaining = 0;
    for (int a = 0; a < 3; ++a) {
      const double d = v1[a] - v0[a];
      const std::int32_t n = k1[a] - k0[a];
      if (n > 0) {
        step[a] = 1;
        left[a] = n;
        t_delta[a] = 1.0 / d;
        t_max[a] = (double(k0[a]) + 1.0 - v0[a]) * t_delta[a];
      } else if (n < 0) {
        step[a] = -1;
        left[a] = -n;
        t_delta[a] = -1.0 / d;
        t_max[a] = (v0[a] - double(k0[a])) * t_delta[a];
      } else {
        step[a] = 0;
        left[a] = 0;
        t_delta[a] = inf;
        t_max[a] = inf;
      }
      remaining += static_cast<std::uint64_t>(left[a]);
    }
  }

  /// The axis of the next face crossing (precondition: remaining > 0).
  int next_axis() const noexcept {
    return t_max[0] < t_max[1] ? (t_max[0] < t_max[2] ? 0 : 2) : (t_max[1] < t_max[2] ? 1 : 2);
  }

  /// Moves to the next voxel (precondition: remaining > 0).
  void advance() noexcept {
    const int a = next_axis();
    key[a] += step[a];
    if (--left[a] == 0) {
      t_max[a] = std::numeric_limits<double>::infinity();
    } else {
      t_max[a] += t_delta[a];
    }
    --remaining;
  }
};

/// Voxel coordinates and key of a point, or false if the point is not finite or lies outside
/// the key range.
inline bool voxel_of(const GridGeometry& g, const Point3& p, Point3& v, Key& k) noexcept {
  v = g.to_voxel_coords(p);
  for (int a = 0; a < 3; ++a) {
    const double f = std::floor(v[a]);
    if (!(f >= -double(kKeyLimit) && f < double(kKeyLimit))) return false;  // false for NaN
    k[a] = static_cast<std::int32_t>(f);
  }
  return true;
}

}  // namespace detail

/// Visits, in order from \p from to \p to, every voxel the segment crosses: the voxel of
/// \p from first, the voxel of \p to last (both included; once if they coincide).
///
/// Exactness: the visited voxels are those whose interior the segment intersects, except where
/// the segment passes exactly through a voxel edge or corner (a set of measure zero): there one
/// of the voxels touching that edge is visited as well, the one on the higher axis first (the
/// OctoMap rule), so the path is always face-connected. A point on a face belongs to the voxel
/// on its positive side (as GridGeometry::key).
///
/// Cost: O(number of voxels), no allocation; the visitor is inlined.
///
/// \tparam P, Q any PointLike type
/// \tparam V a RayVisitor: `bool(const Key&)`, true to continue
/// \returns the status (Invalid if an endpoint is not finite or outside the key range, in which
///          case nothing is visited) and the number of voxels visited
///
/// Thread safety: reentrant; the geometry is only read.
template <PointLike P, PointLike Q, RayVisitor V>
TraverseResult traverse(const GridGeometry& geometry, const P& from, const Q& to, V&& visitor) {
  Point3 v0, v1;
  Key k0, k1;
  if (!detail::voxel_of(geometry, to_point(from), v0, k0) || !detail::voxel_of(geometry, to_point(to), v1, k1))
    return {TraverseStatus::Invalid, 0};
  detail::SegmentDda dda(v0, v1, k0, k1);
  std::uint64_t n = 0;
  for (;;) {
    ++n;
    if (!visitor(static_cast<const Key&>(dda.key))) return {TraverseStatus::Stopped, n};
    if (dda.remaining == 0) return {TraverseStatus::Completed, n};
    dda.advance();
  }
}

}  // namespace intervox
