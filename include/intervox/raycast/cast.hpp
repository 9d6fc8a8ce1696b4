#pragma once
/// \file
/// cast_ray: the first occupied voxel along a direction (for visibility and information gain).

#include <intervox/core/key.hpp>
#include <intervox/core/point.hpp>
#include <intervox/core/types.hpp>
#include <intervox/grid/accessor.hpp>
#include <intervox/grid/occupancy_grid.hpp>
#include <intervox/raycast/traversal.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

namespace intervox {

/// What cast_ray does at a voxel whose occupancy is Unknown (never observed, or between the
/// policy's thresholds).
enum class UnknownVoxels : std::uint8_t {
  Pass = 0,  ///< treat it as free and continue (OctoMap's castRay with ignoreUnknown = true)
  Stop = 1,  ///< stop there with CastStatus::Unknown (OctoMap's default)
};

/// Options of cast_ray.
struct CastOptions {
  /// Voxels whose entry distance exceeds this are not examined. Negative or +inf: none; the ray
  /// then ends where it leaves the grid's bounds (bounded grids) or the key range (see
  /// kKeyLimit; that can be millions of voxels, so set a max range on unbounded grids).
  double max_range = -1.0;
  UnknownVoxels unknown = UnknownVoxels::Pass;
  /// Skip the voxel containing the origin (e.g. a sensor inside an occupied voxel).
  bool ignore_origin_voxel = false;

  bool has_max_range() const noexcept { return max_range >= 0.0 && std::isfinite(max_range); }
};

/// How a cast ended.
enum class CastStatus : std::uint8_t {
  Occupied = 0,  ///< stopped at an occupied voxel (`key`)
  Unknown = 1,   ///< stopped at an unknown voxel (UnknownVoxels::Stop)
  MaxRange = 2,  ///< reached max range without stopping
  LeftGrid = 3,  ///< left the grid's bounds or the key range without stopping
  Invalid = 4,   ///< origin or direction not finite, zero direction, or origin outside the key range
};

/// Result of cast_ray.
struct CastResult {
  CastStatus status = CastStatus::Invalid;
  Key key;                   ///< the voxel where the cast stopped (the last one examined otherwise)
  double distance = 0.0;     ///< distance from the origin to where the ray enters `key` (0 for the origin voxel)
  std::uint64_t voxels = 0;  ///< voxels examined
  /// True if an occupied voxel was found.
  bool hit() const noexcept { return status == CastStatus::Occupied; }
};

/// Walks from \p origin along \p direction (any length, not zero) through \p grid and returns the
/// first voxel whose occupancy is Occupied (or Unknown, with UnknownVoxels::Stop).
///
/// The walk is the exact traversal of traverse() (same tie rule), starting with the origin's
/// voxel; it examines voxels in order of their entry distance, up to max_range, and ends where
/// the ray leaves the grid's bounds for good (bounded grids) or the key range. Allocation-free.
///
/// \tparam G a VoxelGrid; \tparam O, D PointLike
/// \returns the result; CastStatus::Invalid (nothing examined) for a non-finite origin or
///          direction, a zero direction, or an origin outside the key range. Never throws.
///
/// Thread safety: reads the grid only; concurrent casts on an unchanging grid are safe.
template <OccupancyGrid G, PointLike O, PointLike D>
CastResult cast_ray(const G& grid, const O& origin, const D& direction, const CastOptions& options = {}) {
  CastResult r;
  const Point3 o = to_point(origin);
  const Point3 d = to_point(direction);
  const double len = d.norm();
  Point3 v0;
  if (!is_finite(o) || !is_finite(d) || !(len > 0.0) || !std::isfinite(len) ||
      !detail::voxel_of(grid.geometry(), o, v0, r.key))
    return r;
  const Point3 u = d / len;
  const double res = grid.geometry().resolution();
  constexpr double inf = std::numeric_limits<double>::infinity();
  const double max_range = options.has_max_range() ? options.max_range : inf;

  std::int32_t step[3];
  double t_max[3], t_delta[3];
  for (int a = 0; a < 3; ++a) {
    if (u[a] > 0) {
      step[a] = 1;
      t_delta[a] = res / u[a];
      t_max[a] = (double(r.key[a]) + 1.0 - v0[a]) * t_delta[a];
    } else if (u[a] < 0) {
      step[a] = -1;
      t_delta[a] = -res / u[a];
      t_max[a] = (v0[a] - double(r.key[a])) * t_delta[a];
    } else {
      step[a] = 0;
      t_delta[a] = inf;
      t_max[a] = inf;
    }
  }
  KeyBox box{Key{-kKeyLimit, -kKeyLimit, -kKeyLimit}, Key{kKeyLimit - 1, kKeyLimit - 1, kKeyLimit - 1}};
  if (const auto& b = grid.key_box()) box = *b;
  GridAccessor<G> read(grid);  // one hash lookup per 8^3 block on sparse grids
  bool check = !options.ignore_origin_voxel;
  for (;;) {
    if (check) {
      ++r.voxels;
      const Occupancy occ = read.occupancy(r.key);
      if (occ == Occupancy::Occupied) {
        r.status = CastStatus::Occupied;
        return r;
      }
      if (occ == Occupancy::Unknown && options.unknown == UnknownVoxels::Stop) {
        r.status = CastStatus::Unknown;
        return r;
      }
    }
    check = true;
    const int a = t_max[0] < t_max[1] ? (t_max[0] < t_max[2] ? 0 : 2) : (t_max[1] < t_max[2] ? 1 : 2);
    if (t_max[a] > max_range) {
      r.status = CastStatus::MaxRange;
      return r;
    }
    // Leaving the box on an axis it moves away on: it never comes back.
    const std::int32_t next = r.key[a] + step[a];
    if ((next < box.min[a] && step[a] < 0) || (next > box.max[a] && step[a] > 0)) {
      r.status = CastStatus::LeftGrid;
      return r;
    }
    r.key[a] = next;
    r.distance = t_max[a];
    t_max[a] += t_delta[a];
  }
}

}  // namespace intervox
