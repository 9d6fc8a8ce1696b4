#pragma once
/// \file
/// What the conflict-aware planners share (thesis chapter 6, 5.5): the parameters, the state of a
/// conflict region (open, or given up as unresolvable once seen from enough distinct directions)
/// and the score of a view of an open region from a new direction.
///
/// Thread safety: value types and pure functions.

#include <intervox/analysis/conflicts.hpp>
#include <intervox/core/error.hpp>
#include <intervox/core/point.hpp>
#include <intervox/core/validate.hpp>

#include <cmath>
#include <numbers>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace intervox {

/// Parameters of conflict-aware planning. `enabled = false` (the default) gives the plain planner.
struct ConflictPlanningParams {
  bool enabled = false;         ///< plan around conflict regions (docs/planning.md)
  ConflictParams detect{};      ///< detection (thesis defaults)
  ObservationParams observe{};  ///< which recorded sensor origins saw a region
  /// A region seen from this many distinct directions (at least min_angle apart) is given up as
  /// unresolvable (its frontiers are retired), >= 1.
  int resolve_directions = 3;
  double min_angle = std::numbers::pi / 6;  ///< rad (30°) between distinct directions, in (0, pi]
  /// m beyond the robot's radius (mobile base) or the collision margin (arm) kept clear of
  /// conflict regions: space only wrongly seen as free lies there (thesis 5.5), finite, >= 0.
  double safety_margin = 0.2;
  /// m; a frontier with a column of a region this close belongs to the region (its unknown
  /// columns are the region's), finite, >= 0.
  double region_reach = 1.0;
  /// Views aimed at one region before it is given up even if the directions were not all seen
  /// (a view may see the region from no new direction, e.g. through an occluder), >= 1.
  int max_region_views = 5;
  /// Mobile planner: free space that only beams without a return crossed (NoReturnEvidence, kept
  /// by an ExplainedMap: MobilePlanner::make_map(), plan(map, pose)) counts as unknown in the exploration map, so the
  /// robot keeps its maybe-collision distance from it: an absorbing surface and what lies behind it were never
  /// confirmed free ("the robot remains ignorant about the area", thesis 5.2, 5.5).
  bool no_return_unknown = true;
  /// Mobile planner: the exploration map keeps at least half a voxel's diagonal beyond the robot
  /// radius from obstacles and unknown space (ExplorationMapParams::clearance), so that the
  /// map's discretisation cannot put the robot's true footprint into an obstacle.
  bool cell_clearance = true;

  /// \throws InvalidArgument naming the first invalid parameter.
  void validate() const {
    const ParamCheck check("intervox::ConflictPlanningParams");
    detect.validate();
    observe.validate();
    check.at_least("resolve_directions", resolve_directions, 1);
    check.in_range("min_angle", min_angle, 0, std::numbers::pi, RangeEnds::OpenClosed);
    check.nonnegative("safety_margin", safety_margin);
    check.nonnegative("region_reach", region_reach);
    check.at_least("max_region_views", max_region_views, 1);
  }
};

/// A lying region as a planner sees it: a conflict region (conflict-aware planning), or an
/// enclosed group of unexplained columns (MobilePlanner with explained planning and
/// ExplainedPlanningParams::unexplained_hazards; its voxels are the group's unexplained voxels in
/// the robot's height band, without a normal).
struct PlannedRegion {
  ConflictRegion region;
  int directions = 0;         ///< distinct directions it was observed from (distinct_directions)
  bool unresolvable = false;  ///< seen from resolve_directions directions, or given up
  bool unexplained = false;   ///< an unexplained group (explained planning), not a conflict region
};

/// What a conflict-aware planner remembers of conflict regions from call to call: the regions it
/// gave up and how often it aimed at each. A region found again (its voxels change as the map
/// does) is recognised by its bounds grown by `reach` containing the remembered centroid.
///
/// Thread safety: a plain value type.
class RegionMemory {
 public:
  /// \param reach m by which a region's bounds are grown to recognise it, finite, >= 0
  explicit RegionMemory(double reach = 0.0) : reach_(reach) {}
  /// True if a region given up earlier lies in \p reg.
  bool given_up(const ConflictRegion& reg) const {
    const Bounds b = grown(reg);
    for (const Point3& c : given_up_)
      if (b.contains(c)) return true;
    return false;
  }
  void give_up(const ConflictRegion& reg) { given_up_.push_back(reg.centroid); }
  /// The number of views aimed at \p reg so far (a new entry at 0 for a new region).
  int& views(const ConflictRegion& reg) {
    const Bounds b = grown(reg);
    for (auto& [c, n] : views_)
      if (b.contains(c)) return n;
    views_.push_back({reg.centroid, 0});
    return views_.back().second;
  }

 private:
  Bounds grown(const ConflictRegion& reg) const {
    const Point3 m = Point3::Constant(reach_);
    return {reg.bounds.min - m, reg.bounds.max + m};
  }
  double reach_;
  std::vector<Point3> given_up_;
  std::vector<std::pair<Point3, int>> views_;
};

/// True if the direction from \p centroid to \p origin lies at least \p min_angle from every
/// view direction of \p views (a new direction for the region).
inline bool new_direction(const Point3& centroid, const Point3& origin, std::span<const RegionView> views,
                          double min_angle) {
  const Point3 v = origin - centroid;
  if (!(v.norm() > 0)) return false;
  const Point3 u = v.normalized();
  const double c = std::cos(min_angle);
  for (const auto& w : views)
    if (u.dot(w.direction) > c + 1e-12) return false;
  return true;
}

/// The score of a view of a conflict region from the sensor origin \p origin: flat viewing angles
/// and short paths first (thesis ch. 6, Fig. 6.1: a flat angle shows the free space around the
/// noisy surface rather than the surface itself), the gain breaking ties:
/// (0.5 + 0.5 (1 - |n . d|)) (1 + gain / max_gain) / (1 + path / reach), with d the unit direction
/// from the centroid to the origin and n the region's normal (flatness 1 without a normal).
inline double conflict_view_score(const ConflictRegion& r, const Point3& origin, double path, double reach, double gain,
                                  double max_gain) {
  double flat = 1.0;
  const Point3 v = origin - r.centroid;
  if (r.normal && v.norm() > 0) flat = 1.0 - std::abs(r.normal->dot(v.normalized()));
  const double g = max_gain > 0 ? gain / max_gain : 0.0;
  return (0.5 + 0.5 * flat) * (1.0 + g) / (1.0 + path / std::max(reach, 1e-9));
}

}  // namespace intervox
