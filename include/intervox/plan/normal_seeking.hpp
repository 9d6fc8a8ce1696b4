#pragma once
/// \file
/// Views that seek normals (docs/planning.md, "Views that seek normals"): a triangulation striper
/// sees a polished surface only where the surface normal bisects the directions towards the laser
/// and towards its camera (the half-vector, LaserStriper, docs/platforms.md). Surfaces the striper
/// hit now and then but whose voxels are not decided yet are the ones a view near that specular
/// condition can settle. The hits are an ExplainedMap's (HitRecord, analysis/hit_record.hpp); this file finds those
/// surfaces with their normals estimated from neighbouring hits (glint_targets), and scores a sweep by how close to the
/// specular condition it would see them (glint_score). ArmPlanner uses it when ArmPlannerParams::normals is enabled.
///
/// Thread safety: HitRecord is a value type (not thread-safe for concurrent writes); the free
/// functions only read their arguments.

#include <intervox/analysis/hit_record.hpp>
#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/key_set.hpp>
#include <intervox/core/plane_fit.hpp>
#include <intervox/core/point.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/core/sensors.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/grid/occupancy_grid.hpp>

#include <algorithm>
#include <cmath>
#include <optional>
#include <span>
#include <vector>

namespace intervox {

/// Options of normal-seeking views (ArmPlannerParams::normals).
struct NormalSeekingParams {
  bool enabled = false;  ///< off: candidates are chosen by gain alone, as in the thesis
  /// Weight of the glint score against the gain, >= 0: a candidate's score is
  /// gain / max gain + weight * glint / max glint over the step's candidates.
  double weight = 1.0;
  /// Exponent n of the specular condition's lobe cos^n θ_h (θ_h: angle between the half-vector
  /// and the normal), finite and >= 0; the default is the simulator's polished-metal lobe
  /// (sim::Material::kPolishedExponent: 0.43 at 10°, 0.066 at 20°).
  double lobe_exponent = 40.0;
  /// Half-width (voxels, Chebyshev) of the neighbourhood whose hit voxels estimate a normal, >= 1.
  int neighbourhood = 2;
  /// Hit voxels (the target included) a neighbourhood needs for a normal, >= 3.
  int min_hits = 5;

  /// \throws InvalidArgument naming the first invalid parameter.
  void validate() const {
    const ParamCheck check("intervox::NormalSeekingParams");
    check.nonnegative("weight", weight);
    check.nonnegative("lobe_exponent", lobe_exponent);
    check.at_least("neighbourhood", neighbourhood, 1);
    check.at_least("min_hits", min_hits, 3);
  }
};

/// A voxel with hits but no decided state, and its surface normal estimated from the hit voxels
/// around it.
struct GlintTarget {
  Key key;
  Point3 center;
  Point3 normal;  ///< unit; turned away from the `outward_from` point given to glint_targets()
};

/// The glint targets of \p grid inside \p bounds: the voxels \p hits holds that the grid does not
/// classify occupied, each with the normal of the plane fitted (least squares, the eigenvector of
/// the smallest eigenvalue of the centres' covariance) to the hit voxels within
/// params.neighbourhood of it, when there are at least params.min_hits, turned away from
/// \p outward_from (e.g. the object's centre). Voxels with too few hits around them are left
/// out; so are those whose fitted hit voxels lie on a line (no plane). In key order. Cost: one
/// grid lookup per voxel of the bounds, and a neighbourhood scan per hit voxel among them.
/// \tparam Grid a VoxelGrid
/// \throws InvalidArgument if \p bounds is not valid or the params are invalid.
template <OccupancyGrid Grid>
std::vector<GlintTarget> glint_targets(const Grid& grid, const HitRecord& hits, const Bounds& bounds,
                                       const Point3& outward_from, const NormalSeekingParams& params) {
  params.validate();
  const GridGeometry& g = grid.geometry();
  const KeyBox box = g.key_box(bounds);
  std::vector<GlintTarget> out;
  const int r = params.neighbourhood;
  std::vector<Point3> near;
  for (std::int32_t x = box.min.x; x <= box.max.x; ++x)
    for (std::int32_t y = box.min.y; y <= box.max.y; ++y)
      for (std::int32_t z = box.min.z; z <= box.max.z; ++z) {
        const Key k{x, y, z};
        if (!hits.contains(k) || grid.occupancy(k) == Occupancy::Occupied) continue;
        near.clear();
        for (int dx = -r; dx <= r; ++dx)
          for (int dy = -r; dy <= r; ++dy)
            for (int dz = -r; dz <= r; ++dz) {
              const Key n{k.x + dx, k.y + dy, k.z + dz};
              if (hits.contains(n)) near.push_back(g.center(n));
            }
        if (static_cast<int>(near.size()) < params.min_hits) continue;
        const std::optional<Point3> fitted = plane_normal(near, 1e-3);  // none for hits along a line
        if (!fitted) continue;
        Point3 normal = *fitted;
        const Point3 c = g.center(k);
        if (normal.dot(c - outward_from) < 0) normal = -normal;
        out.push_back({k, c, normal});
      }
  return out;
}

/// How close to the specular condition the striper pose \p sensor (optical frame to world) sees
/// \p target: cos^\p lobe_exponent θ_h, θ_h the angle between the target's normal and the
/// half-vector of the directions from the target's centre to the laser (the pose's origin) and to
/// the camera (pose * striper.camera_position()); 0 if the target lies outside the striper's fan
/// (beyond half the opening from the sensor's z axis in the x-z plane), outside its range window,
/// or on a surface facing away from the laser or the camera. Whether the target lies in the laser
/// plane is not checked (glint_score does).
inline double specular_match(const LaserStriper& striper, const Pose& sensor, const GlintTarget& target,
                             double lobe_exponent) noexcept {
  const Point3 q = sensor.inverse() * target.center;  // target in the sensor frame
  if (!(q.z() > 0)) return 0.0;
  const double range = std::hypot(q.x(), q.z());
  if (range < striper.min_range || range > striper.max_range) return 0.0;
  if (std::abs(std::atan2(q.x(), q.z())) > 0.5 * striper.opening) return 0.0;
  const Point3 laser = sensor.translation(), camera = sensor * striper.camera_position();
  const Point3 l = (laser - target.center).normalized(), v = (camera - target.center).normalized();
  if (target.normal.dot(l) <= 0 || target.normal.dot(v) <= 0) return 0.0;
  const Point3 h = (l + v).normalized();
  return std::pow(std::clamp(h.dot(target.normal), 0.0, 1.0), lobe_exponent);
}

/// The glint score of a sweep of striper poses \p sweep (a straight sweep, linear_sweep): for each
/// target, the specular_match() at the profile whose laser plane passes through it (the pose of
/// the sweep nearest to the target along the sweep's axis), counted if the target lies within
/// half the profile spacing (at least half a voxel, \p voxel) of that plane and within the sweep;
/// the sum over the targets. Targets without a finite centre add nothing. Occlusion is not checked: a target behind
/// another surface scores as if visible. \throws InvalidArgument if \p sweep is empty.
inline double glint_score(const LaserStriper& striper, const std::vector<Pose>& sweep,
                          std::span<const GlintTarget> targets, double lobe_exponent, double voxel) {
  if (sweep.empty()) ParamCheck("intervox::glint_score").fail("the sweep has no pose");
  const Pose& first = sweep.front();
  const Point3 axis = first.linear().col(1);  // linear_sweep moves along the sensor's y axis
  const double spacing = sweep.size() > 1 ? (Point3(sweep.back().translation()) - first.translation()).norm() /
                                                static_cast<double>(sweep.size() - 1)
                                          : 0.0;
  const double tolerance = std::max(0.5 * spacing, 0.5 * voxel);
  double score = 0;
  for (const GlintTarget& t : targets) {
    const double s = (t.center - first.translation()).dot(axis);  // position along the sweep
    if (!std::isfinite(s)) continue;                              // a target without a finite centre scores nothing
    // The nearest profile; beyond either end, the end profile (within the tolerance below).
    const double last = static_cast<double>(sweep.size() - 1);
    const auto k = static_cast<std::size_t>(spacing > 0 ? std::clamp(std::round(s / spacing), 0.0, last) : 0.0);
    if (std::abs((t.center - sweep[k].translation()).dot(axis)) > tolerance) continue;
    score += specular_match(striper, sweep[k], t, lobe_exponent);
  }
  return score;
}

}  // namespace intervox
