#pragma once
/// \file
/// Candidate views: positions in a ring around a frontier of the exploration map (mobile base,
/// thesis 3.3.3) and scan poses on a sphere around an object outside a collision space (arm,
/// thesis 5.1). Every sampler takes a seed; the same seed gives the same candidates on every
/// platform (the generator and the draws are defined here, not by the standard library).

#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/point.hpp>
#include <intervox/core/random.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/core/types.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/grid/occupancy_grid.hpp>
#include <intervox/plan/column_map.hpp>
#include <intervox/plan/exploration_map.hpp>
#include <intervox/core/sensors.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace intervox {

/// A planar robot pose: a map cell, its metric position and the heading (yaw, rad).
struct PlanarCandidate {
  Cell2 cell;
  Point3 position = Point3::Zero();  ///< x, y of the cell centre; z = 0
  double yaw = 0.0;
};

/// Parameters of the ring sampler.
struct RingSamplerParams {
  double inner_radius = 0.8;  ///< m; the ring is the set of cells whose centre lies at a
  double outer_radius = 1.6;  ///< m; distance in [inner, outer] from the frontier's centre
  int positions = 12;         ///< positions drawn (fewer if the ring has fewer reachable cells)
  int orientations = 2;       ///< headings per position: facing the frontier, then evenly spaced
  /// \throws InvalidArgument unless 0 <= inner <= outer (finite), positions >= 1, orientations >= 1.
  void validate() const {
    const ParamCheck check("intervox::RingSamplerParams");
    check.nonnegative("inner_radius", inner_radius);
    check.finite("outer_radius", outer_radius);
    if (!(inner_radius <= outer_radius)) check.fail("need inner_radius <= outer_radius");
    check.at_least("positions", positions, 1);
    check.at_least("orientations", orientations, 1);
  }
};

/// Calls `f(const Cell2&)` for every cell of the ring around \p frontier: centre distance in
/// [inner_radius, outer_radius] on a map of \p resolution, rows (y) then x in increasing order.
template <class F>
void for_each_ring_cell(const Cell2& frontier, const RingSamplerParams& p, double resolution, F&& f) {
  const int r = static_cast<int>(std::ceil(p.outer_radius / resolution));
  for (int dy = -r; dy <= r; ++dy)
    for (int dx = -r; dx <= r; ++dx) {
      const double d = std::sqrt(double(dx * dx + dy * dy)) * resolution;
      if (d >= p.inner_radius && d <= p.outer_radius) f(Cell2{frontier.x + dx, frontier.y + dy});
    }
}

/// The reachable cells of the ring around \p frontier (in index order: y, then x).
inline std::vector<Cell2> ring_cells(const ExplorationMap& map, const Cell2& frontier, const RingSamplerParams& p) {
  p.validate();
  std::vector<Cell2> out;
  for_each_ring_cell(frontier, p, map.resolution(), [&](const Cell2& c) {
    if (map.reachable(c)) out.push_back(c);
  });
  return out;
}

/// The cells of the ring around \p frontier that ring_cells() leaves out (not reachable free
/// space), counted by their label (index: MapLabel; cells outside the map count as Unknown): why
/// no candidate stands there.
inline std::array<std::uint32_t, kMapLabelCount> ring_refusals(const ExplorationMap& map, const Cell2& frontier,
                                                               const RingSamplerParams& p) {
  p.validate();
  std::array<std::uint32_t, kMapLabelCount> counts{};
  for_each_ring_cell(frontier, p, map.resolution(), [&](const Cell2& c) {
    if (!map.reachable(c)) ++counts[static_cast<std::size_t>(map.label(c))];
  });
  return counts;
}

/// Samples candidate poses in a ring around \p frontier: reachable, collision-free cells (the
/// exploration map's reachable space excludes collision and maybe-collision space) at a viewing
/// distance in [inner, outer]; each with `orientations` headings, the first facing the frontier.
/// Positions are drawn without repetition with \p seed.
/// \throws InvalidArgument for invalid parameters.
inline std::vector<PlanarCandidate> sample_ring(const ExplorationMap& map, const GridGeometry& geometry,
                                                const Cell2& frontier, const RingSamplerParams& params,
                                                std::uint64_t seed) {
  std::vector<Cell2> cells = ring_cells(map, frontier, params);
  SeededRandom rng(seed);
  const std::size_t n = std::min<std::size_t>(cells.size(), static_cast<std::size_t>(params.positions));
  for (std::size_t i = 0; i < n; ++i) std::swap(cells[i], cells[i + rng.below(cells.size() - i)]);
  cells.resize(n);
  const Point3 f = cell_center(map.columns(), geometry, frontier);
  std::vector<PlanarCandidate> out;
  const double two_pi = 6.283185307179586;
  for (const Cell2& c : cells) {
    const Point3 p = cell_center(map.columns(), geometry, c);
    const double facing = std::atan2(f.y() - p.y(), f.x() - p.x());
    for (int o = 0; o < params.orientations; ++o)
      out.push_back({c, p, std::remainder(facing + two_pi * o / params.orientations, two_pi)});
  }
  return out;
}

/// A body pose at (x, y, z) with heading \p yaw about +z.
inline Pose planar_pose(const Point3& position, double yaw) {
  Pose p = Pose::Identity();
  p.translation() = position;
  p.linear() = Eigen::AngleAxisd(yaw, Point3::UnitZ()).toRotationMatrix();
  return p;
}

/// Parameters of the sphere sampler (arm object modelling).
struct SphereSamplerParams {
  Point3 center = Point3::Zero();  ///< the object's centre; every view looks at it
  double radius = 0.6;             ///< m; distance of the sensor from the centre, > 0
  int views = 24;                  ///< candidates drawn before filtering, >= 1
  double min_elevation = 0.1;      ///< rad; keep views at least this far above the horizontal
  double max_elevation = 1.4;      ///< rad; and at most this far (1.57 = straight down)
  double clearance = 0.1;          ///< m; collision space: no occupied voxel within this distance
  /// \throws InvalidArgument for a non-positive radius or views, inconsistent elevations,
  ///         a negative clearance or a non-finite centre.
  void validate() const {
    const ParamCheck check("intervox::SphereSamplerParams");
    if (!is_finite(center)) check.fail("center must be finite");
    check.positive("radius", radius);
    check.at_least("views", views, 1);
    if (!(min_elevation >= -1.5707963267948966 && min_elevation <= max_elevation &&
          max_elevation <= 1.5707963267948966))
      check.fail("need -pi/2 <= min_elevation <= max_elevation <= pi/2");
    check.nonnegative("clearance", clearance);
  }
};

/// True if \p blocked(key) holds for no voxel of \p g whose centre lies within \p clearance of
/// \p p (the voxels are visited in key order, z slowest, until one is blocked).
/// \tparam Blocked callable as `bool(const Key&)`
template <class Blocked>
bool no_voxel_within(const GridGeometry& g, const Point3& p, double clearance, Blocked&& blocked) {
  const Key lo = g.key(p - Point3::Constant(clearance)), hi = g.key(p + Point3::Constant(clearance));
  for (std::int32_t z = lo.z; z <= hi.z; ++z)
    for (std::int32_t y = lo.y; y <= hi.y; ++y)
      for (std::int32_t x = lo.x; x <= hi.x; ++x) {
        const Key k{x, y, z};
        if ((g.center(k) - p).norm() <= clearance && blocked(k)) return false;
      }
  return true;
}

/// True if no occupied voxel of \p grid lies within \p clearance of \p p (voxel centres).
/// \tparam Grid a VoxelGrid
template <OccupancyGrid Grid>
bool outside_collision_space(const Grid& grid, const Point3& p, double clearance) {
  return no_voxel_within(grid.geometry(), p, clearance,
                         [&](const Key& k) { return grid.occupancy(k) == Occupancy::Occupied; });
}

/// Samples scan poses on a sphere around the object (uniform in area over the allowed elevation
/// band, seeded), each looking at the centre, and drops those inside the collision space around
/// occupied voxels.
/// \tparam Grid a VoxelGrid
/// \throws InvalidArgument for invalid parameters.
template <OccupancyGrid Grid>
std::vector<Pose> sample_sphere(const Grid& grid, const SphereSamplerParams& params, std::uint64_t seed) {
  params.validate();
  SeededRandom rng(seed);
  std::vector<Pose> out;
  const double s0 = std::sin(params.min_elevation), s1 = std::sin(params.max_elevation);
  for (int i = 0; i < params.views; ++i) {
    const double s = s0 + (s1 - s0) * rng.uniform();  // sin(elevation): uniform in area
    const double az = 6.283185307179586 * rng.uniform();
    const double c = std::sqrt(std::max(0.0, 1.0 - s * s));
    const Point3 eye = params.center + params.radius * Point3(c * std::cos(az), c * std::sin(az), s);
    if (outside_collision_space(grid, eye, params.clearance)) out.push_back(look_at(eye, params.center));
  }
  return out;
}

}  // namespace intervox
