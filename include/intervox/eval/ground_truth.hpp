#pragma once
/// \file
/// Evaluation of a map and an episode against the simulator's ground truth: misclassified voxels,
/// the reachable floor known free (mobile base), the object's visible surface known occupied
/// (arm), and collisions of a driven trajectory. Used by the examples, the experiments and the
/// tests; never by the planners, which only see the map.
///
/// Thread safety: pure functions; the grid and the scene are only read.

#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/grid/occupancy_grid.hpp>
#include <intervox/plan/exploration_map.hpp>
#include <intervox/sim/scene.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <unordered_set>
#include <vector>

namespace intervox {

/// Ground-truth comparison of a grid (see evaluate_voxels()).
struct VoxelErrors {
  std::size_t wrongly_occupied = 0;  ///< classified occupied, free in the scene
  std::size_t wrongly_free = 0;      ///< classified free, occupied in the scene
  std::size_t known_occupied = 0;    ///< occupied in the scene and classified occupied
  std::size_t true_occupied = 0;     ///< voxels occupied in the scene (inside the region)
};

/// Counts misclassified voxels of \p grid inside \p region against the scene's ground truth.
/// \tparam Grid a VoxelGrid
/// \throws InvalidArgument if region is not valid.
template <OccupancyGrid Grid>
VoxelErrors evaluate_voxels(const Grid& grid, const sim::Scene& scene, const Bounds& region) {
  const auto truth = scene.ground_truth(grid.geometry(), region);
  std::unordered_set<Key, KeyHash> occ(truth.begin(), truth.end());
  const KeyBox box = grid.geometry().key_box(region);
  VoxelErrors e;
  e.true_occupied = occ.size();
  grid.for_each_observed([&](const Key& k, const typename Grid::Cell& c) {
    if (!box.contains(k)) return;
    const Occupancy o = grid.update_policy().occupancy(c);
    const bool is_occ = occ.count(k) != 0;
    if (o == Occupancy::Occupied && !is_occ) ++e.wrongly_occupied;
    if (o == Occupancy::Free && is_occ) ++e.wrongly_free;
    if (o == Occupancy::Occupied && is_occ) ++e.known_occupied;
  });
  return e;
}

/// The reachable floor of the ground truth and how much of it the grid knows (mobile base).
struct FloorCoverage {
  double known = 1.0;  ///< fraction of the reachable cells whose column the grid classifies free (1 if none)
  double area = 0.0;   ///< reachable free floor area of the ground truth inside the region, m²
};

/// The ground-truth exploration map of a scene (truth_exploration_map()): the map and where its
/// cells lie in the grid's keys (cell (x, y) holds the column of key (origin.x + x, origin.y + y)).
struct TruthMap {
  ExplorationMap map;
  Key origin;
};

/// The scene's occupied voxels of \p geometry whose centres lie within \p region's heights,
/// projected into columns over \p region grown by the robot radius of \p map plus a cell (so that
/// walls just outside the region make their collision space inside), every other column free, and
/// analysed as the planners analyse the grid's projection from the robot at \p start: which floor
/// the robot can reach, and which it cannot (ExplorationMap::reachable()).
/// \throws InvalidArgument for an invalid region or a start outside the grown region.
inline TruthMap truth_exploration_map(const sim::Scene& scene, const GridGeometry& g, const Bounds& region,
                                      const ExplorationMapParams& map, const Point3& start) {
  ParamCheck("intervox::truth_exploration_map").valid_bounds("region", region);
  const int margin = static_cast<int>(std::ceil(map.robot_radius / g.resolution())) + 1;
  KeyBox box = g.key_box(region);
  box.min.x -= margin;
  box.min.y -= margin;
  box.max.x += margin;
  box.max.y += margin;
  ColumnMap m(static_cast<int>(box.extent(0)), static_cast<int>(box.extent(1)), g.resolution(),
              Key{box.min.x, box.min.y, 0});
  for (int y = 0; y < m.height(); ++y)
    for (int x = 0; x < m.width(); ++x) m.set({x, y}, Occupancy::Free);
  const Bounds grown{g.corner(box.min), g.corner(Key{box.max.x + 1, box.max.y + 1, box.max.z + 1})};
  for (const Key& k : scene.ground_truth(g, grown)) {
    const Point3 c = g.center(k);
    if (c.z() >= region.min.z() && c.z() <= region.max.z()) m.set(m.cell_of_key(k), Occupancy::Occupied);
  }
  const Key sk = g.key(Point3(start.x(), start.y(), region.min.z()));
  return {ExplorationMap(std::move(m), Cell2{sk.x - box.min.x, sk.y - box.min.y}, map), Key{box.min.x, box.min.y, 0}};
}

/// The ground-truth exploration map (truth_exploration_map(): the scene's occupied voxels
/// projected like the grid's, with the robot radius of \p map, from \p start) compared with the
/// grid's projection over \p region. With \p part, only the reachable cells whose centre lies
/// inside part's x-y extent count (e.g. a room behind a doorway: reachable from the start through
/// the region, scored on its own).
/// \tparam Grid a VoxelGrid
/// \throws InvalidArgument for an invalid region or part, or a start outside the region.
template <OccupancyGrid Grid>
FloorCoverage floor_coverage(const Grid& grid, const sim::Scene& scene, const Bounds& region,
                             const ExplorationMapParams& map, const Point3& start,
                             const std::optional<Bounds>& part = std::nullopt) {
  if (part && !part->valid()) ParamCheck("intervox::floor_coverage").valid_bounds("part", *part);
  const GridGeometry& g = grid.geometry();
  const TruthMap truth = truth_exploration_map(scene, g, region, map, start);
  const ColumnMap now = project_columns(grid, region);
  const Key first = g.key_box(region).min;
  const int dx = first.x - truth.origin.x, dy = first.y - truth.origin.y;
  std::size_t reach = 0, known = 0;
  for (int y = 0; y < now.height(); ++y)
    for (int x = 0; x < now.width(); ++x)
      if (truth.map.reachable({x + dx, y + dy})) {
        if (part) {
          const Point3 c = cell_center(now, g, {x, y});
          if (c.x() < part->min.x() || c.x() > part->max.x() || c.y() < part->min.y() || c.y() > part->max.y())
            continue;
        }
        ++reach;
        if (now.at({x, y}) == Occupancy::Free) ++known;
      }
  FloorCoverage f;
  f.known = reach ? double(known) / double(reach) : 1.0;
  f.area = double(reach) * g.resolution() * g.resolution();
  return f;
}

/// The object's visible surface and how much of it the grid knows occupied (arm).
struct SurfaceCoverage {
  double known = 1.0;      ///< fraction of the surface voxels classified occupied (1 if none)
  std::size_t voxels = 0;  ///< surface voxels
};

/// The visible surface of the scene's objects: among the voxels of \p geometry inside \p region
/// that the scene occupies, those with a face neighbour that is free in the scene and whose centre
/// lies above \p support_height (a face a sensor can see from above the support; interior voxels
/// and the underside on the table are left out), in the order of Scene::ground_truth().
/// \throws InvalidArgument if region is not valid.
inline std::vector<Key> visible_surface_voxels(const GridGeometry& geometry, const sim::Scene& scene,
                                               const Bounds& region, double support_height) {
  std::vector<Key> out;
  for (const Key& k : scene.ground_truth(geometry, region)) {
    bool exposed = false;
    for (int a = 0; a < 3 && !exposed; ++a)
      for (int d : {-1, 1}) {
        Key nb = k;
        nb[a] += d;
        if (geometry.center(nb).z() > support_height && !scene.occupied(geometry, nb)) {
          exposed = true;
          break;
        }
      }
    if (exposed) out.push_back(k);
  }
  return out;
}

/// Of visible_surface_voxels(grid.geometry(), scene, region, support_height), the fraction
/// \p grid classifies occupied.
/// \tparam Grid a VoxelGrid
/// \throws InvalidArgument if region is not valid.
template <OccupancyGrid Grid>
SurfaceCoverage surface_coverage(const Grid& grid, const sim::Scene& scene, const Bounds& region,
                                 double support_height) {
  SurfaceCoverage s;
  std::size_t known = 0;
  for (const Key& k : visible_surface_voxels(grid.geometry(), scene, region, support_height)) {
    ++s.voxels;
    if (grid.occupancy(k) == Occupancy::Occupied) ++known;
  }
  s.known = s.voxels ? double(known) / double(s.voxels) : 1.0;
  return s;
}

/// A model of an object (a set of voxels taken as occupied, e.g. a grid's occupied voxels, the
/// model after discarding conflicts, or the explained-occupied voxels) against the ground truth.
struct ModelEvaluation {
  std::size_t voxels = 0;            ///< distinct model voxels inside the region
  std::size_t wrongly_occupied = 0;  ///< of those, free in the scene
  SurfaceCoverage coverage;          ///< the visible surface voxels (visible_surface_voxels()) in the model
};

/// Evaluates the model \p model (keys of \p geometry; duplicates and keys outside \p region are
/// ignored) against \p scene: its size, its voxels the scene leaves free, and the share of the
/// visible surface (above \p support_height) it holds.
/// \throws InvalidArgument if region is not valid.
inline ModelEvaluation evaluate_model(const GridGeometry& geometry, const sim::Scene& scene, const Bounds& region,
                                      double support_height, std::span<const Key> model) {
  const KeyBox box = geometry.key_box(region);
  std::unordered_set<Key, KeyHash> in;
  for (const Key& k : model)
    if (box.contains(k)) in.insert(k);
  ModelEvaluation e;
  e.voxels = in.size();
  for (const Key& k : in)
    if (!scene.occupied(geometry, k)) ++e.wrongly_occupied;
  std::size_t known = 0;
  for (const Key& k : visible_surface_voxels(geometry, scene, region, support_height)) {
    ++e.coverage.voxels;
    if (in.count(k)) ++known;
  }
  e.coverage.known = e.coverage.voxels ? double(known) / double(e.coverage.voxels) : 1.0;
  return e;
}

namespace detail {
/// The robot cylinder of the collision counts: radius finite and >= 0, finite heights in order.
inline void check_collision_params(const char* where, double radius, double min_height, double max_height) {
  const ParamCheck check(where);
  check.nonnegative("radius", radius);
  check.finite("min_height", min_height);
  check.finite("max_height", max_height);
  if (!(min_height <= max_height)) check.fail("need min_height <= max_height");
}
}  // namespace detail

/// Number of poses of \p trajectory (a mobile base's body poses) at which the scene holds an
/// occupied voxel whose centre lies within \p radius of the pose in x, y and between
/// \p min_height and \p max_height above it: the robot's cylinder touches an obstacle.
/// \throws InvalidArgument for a non-finite or negative radius or heights out of order.
inline std::size_t count_collisions(const sim::Scene& scene, const GridGeometry& g, const std::vector<Pose>& trajectory,
                                    double radius, double min_height, double max_height) {
  detail::check_collision_params("intervox::count_collisions", radius, min_height, max_height);
  std::size_t n = 0;
  for (const Pose& p : trajectory) {
    const Point3 c = p.translation();
    const Bounds box{c + Point3(-radius, -radius, min_height), c + Point3(radius, radius, max_height)};
    for (const Key& k : scene.ground_truth(g, box)) {
      const Point3 v = g.center(k);
      if (std::hypot(v.x() - c.x(), v.y() - c.y()) <= radius) {
        ++n;
        break;
      }
    }
  }
  return n;
}

/// Collisions of a mobile base along a trajectory (see count_path_collisions).
struct PathCollisions {
  std::size_t poses = 0;     ///< trajectory poses where the footprint meets the scene
  std::size_t segments = 0;  ///< straight segments between consecutive poses that meet it anywhere
};

/// Collisions of the robot's cylinder (radius \p radius, from \p min_height to \p max_height
/// above the pose) with the scene along \p trajectory: at every pose (as count_collisions) and
/// along every straight segment between consecutive poses, sampled at steps of at most half a
/// voxel of \p g, so that a path through a thin obstacle between two free poses counts too.
/// \throws InvalidArgument for a non-finite or negative radius or heights out of order.
inline PathCollisions count_path_collisions(const sim::Scene& scene, const GridGeometry& g,
                                            const std::vector<Pose>& trajectory, double radius, double min_height,
                                            double max_height) {
  PathCollisions out;
  out.poses = count_collisions(scene, g, trajectory, radius, min_height, max_height);
  const double step = 0.5 * g.resolution();
  std::vector<Pose> samples;
  for (std::size_t i = 1; i < trajectory.size(); ++i) {
    const Point3 a = trajectory[i - 1].translation(), b = trajectory[i].translation();
    const double len = (b - a).norm();
    if (!std::isfinite(len)) ParamCheck("intervox::count_path_collisions").fail("trajectory pose is not finite");
    const int n = std::max(1, static_cast<int>(std::ceil(len / step)));
    samples.clear();
    for (int k = 0; k <= n; ++k) {
      Pose p = Pose::Identity();
      p.translation() = a + (b - a) * (double(k) / n);
      samples.push_back(p);
    }
    out.segments += count_collisions(scene, g, samples, radius, min_height, max_height) > 0;
  }
  return out;
}

/// The robot's collisions with one scene object along a trajectory (collisions_by_object()).
struct ObjectCollisions {
  sim::ObjectId object = 0;
  std::string name;          ///< the object's name in the scene
  std::size_t poses = 0;     ///< trajectory poses where the footprint meets the object
  std::size_t segments = 0;  ///< straight segments between consecutive poses that meet it anywhere
};

/// count_path_collisions() by object: for every scene object the robot's cylinder meets (an
/// occupied voxel of the object, sim::Scene::occupants(), whose centre lies inside the cylinder),
/// the number of poses and of segments that meet it. A pose or segment that meets two objects
/// counts for both, so the sums may exceed count_path_collisions()'s. Objects never met are left
/// out; the rest come in object order.
/// \throws InvalidArgument for a non-finite or negative radius, heights out of order or a
///         non-finite pose.
inline std::vector<ObjectCollisions> collisions_by_object(const sim::Scene& scene, const GridGeometry& g,
                                                          const std::vector<Pose>& trajectory, double radius,
                                                          double min_height, double max_height) {
  detail::check_collision_params("intervox::collisions_by_object", radius, min_height, max_height);
  std::vector<std::size_t> poses(scene.size(), 0), segments(scene.size(), 0);
  std::vector<char> met(scene.size(), 0);
  // Marks in `met` the objects the cylinder around c meets.
  const auto meet = [&](const Point3& c) {
    const Bounds box{c + Point3(-radius, -radius, min_height), c + Point3(radius, radius, max_height)};
    for (const Key& k : scene.ground_truth(g, box)) {
      const Point3 v = g.center(k);
      if (std::hypot(v.x() - c.x(), v.y() - c.y()) > radius) continue;
      for (const sim::ObjectId id : scene.occupants(g, k)) met[id] = 1;
    }
  };
  for (const Pose& p : trajectory) {
    if (!p.translation().allFinite())
      ParamCheck("intervox::collisions_by_object").fail("trajectory pose is not finite");
    std::fill(met.begin(), met.end(), 0);
    meet(p.translation());
    for (std::size_t i = 0; i < met.size(); ++i) poses[i] += met[i];
  }
  const double step = 0.5 * g.resolution();
  for (std::size_t i = 1; i < trajectory.size(); ++i) {
    const Point3 a = trajectory[i - 1].translation(), b = trajectory[i].translation();
    const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / step)));
    std::fill(met.begin(), met.end(), 0);
    for (int k = 0; k <= n; ++k) meet(a + (b - a) * (double(k) / n));
    for (std::size_t j = 0; j < met.size(); ++j) segments[j] += met[j];
  }
  std::vector<ObjectCollisions> out;
  for (std::size_t i = 0; i < scene.size(); ++i)
    if (poses[i] || segments[i])
      out.push_back({static_cast<sim::ObjectId>(i), scene.name(static_cast<sim::ObjectId>(i)), poses[i], segments[i]});
  return out;
}

}  // namespace intervox
