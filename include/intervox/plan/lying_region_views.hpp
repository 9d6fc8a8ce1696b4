#pragma once
/// \file
/// The mobile planner's views of lying regions (conflict-aware planning, explained planning with
/// unexplained_hazards; docs/planning.md, "Conflicts"): a view of an open region from a direction
/// not used yet (region_view, used by the frontier strategy and by the lying-region strategy),
/// the rule that says when the views aimed at a region are spent, and the lying-region strategy
/// that tries the open regions in the robot's band when no frontier gave a view. The regions
/// themselves are found by plan/lying_region_analysis.hpp; these read them from the plan.

#include <intervox/core/key.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/grid/occupancy_grid.hpp>
#include <intervox/plan/candidate_scoring.hpp>
#include <intervox/plan/conflict_planning.hpp>
#include <intervox/plan/exploration_map.hpp>
#include <intervox/plan/information_gain.hpp>
#include <intervox/plan/mobile_plan.hpp>
#include <intervox/plan/mobile_step.hpp>
#include <intervox/plan/view_sampling.hpp>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace intervox::detail {

/// Whether the views aimed at a region are spent: max_region_views; for an unexplained group
/// at most resolve_directions (a view from a new direction that leaves it unexplained is one
/// more direction, seen or occluded).
inline bool region_views_spent(const PlannedRegion& pr, const MobileStepContext& ctx) {
  const ConflictPlanningParams& cp = ctx.params.conflicts;
  const int max_views = pr.unexplained ? std::min(cp.max_region_views, cp.resolve_directions) : cp.max_region_views;
  return ctx.regions.views(pr.region) >= max_views;
}

/// A view of the open region r.regions[i] from a new direction (the lying-region step, used by
/// both strategies): ring candidates around its centroid's column (candidate_random,
/// CandidateStream::Conflict) whose sensor origin sees it from a direction not used yet, scored
/// by conflict_view_score(). Fills r (reason Conflict) and returns true, or returns false if
/// there is none (or the region was aimed at max_region_views times).
template <OccupancyGrid Grid>
bool region_view(const Grid& grid, const ExplorationMap& map, const GainOptions& gain, const Pose& pose, std::size_t i,
                 MobilePlan& r, const MobileStepContext& ctx) {
  const MobilePlannerParams& params = ctx.params;
  const ConflictRegion& reg = r.regions[i].region;
  if (region_views_spent(r.regions[i], ctx)) return false;
  int& views = ctx.regions.views(reg);
  const Key ck = grid.geometry().key(Point3(reg.centroid.x(), reg.centroid.y(), r.region.min.z()));
  const Cell2 centre = map.columns().cell_of_key(ck);
  const std::uint64_t seed =
      candidate_random(params.seed, static_cast<std::uint64_t>(ctx.steps), CandidateStream::Conflict, i + 1).next();
  const double z = pose.translation().z();
  std::vector<PlanarCandidate> cands;
  for (const PlanarCandidate& c : sample_ring(map, grid.geometry(), centre, params.ring, seed)) {
    const Point3 origin = candidate_pose(c, z) * ctx.sensor_centre;
    if (new_direction(reg.centroid, origin, reg.views, params.conflicts.min_angle) &&
        (origin - reg.centroid).norm() <= params.conflicts.observe.max_range)
      cands.push_back(c);
  }
  if (cands.empty()) return false;
  const std::vector<std::vector<Pose>> paths = candidate_paths(cands, z);
  ScoredCandidates scored =
      score_candidates(grid, ctx.rays, paths, gain, params.threads, [&](std::size_t k, double g, double max_gain) {
        return conflict_view_score(reg, paths[k].front() * ctx.sensor_centre, map.path_distance(cands[k].cell),
                                   params.ring.outer_radius, g, max_gain);
      });
  ++views;
  r.considered += scored.gains.size();
  r.reason = ViewReason::Conflict;
  r.conflict_region = i;
  choose(r, centre, std::move(cands), std::move(scored));
  return true;
}

/// The lying-region strategy (conflict-aware planning, when no frontier gave a view): the open
/// regions whose centroid lies in the robot's band are targets of their own (their margin hides
/// the unknown columns behind them from the frontier rule), the closest centroid first; a
/// region without a view from a new direction is given up.
template <OccupancyGrid Grid>
void lying_region_strategy(const Grid& grid, const ExplorationMap& map, const GainOptions& gain, const Pose& pose,
                           MobilePlan& r, const MobileStepContext& ctx) {
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < r.regions.size(); ++i) {
    const Point3& c = r.regions[i].region.centroid;
    if (!r.regions[i].unresolvable && c.z() >= r.region.min.z() && c.z() <= r.region.max.z()) order.push_back(i);
  }
  const Point3 at = pose.translation();
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const Point3 ca = r.regions[a].region.centroid - at, cb = r.regions[b].region.centroid - at;
    return ca.head<2>().squaredNorm() < cb.head<2>().squaredNorm();
  });
  for (const std::size_t i : order) {
    if (region_view(grid, map, gain, pose, i, r, ctx)) break;
    ctx.regions.give_up(r.regions[i].region);
    r.regions[i].unresolvable = true;
    ++r.retired;
  }
}

}  // namespace intervox::detail
