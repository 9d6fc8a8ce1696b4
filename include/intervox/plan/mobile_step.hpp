#pragma once
/// \file
/// What one planning step of the mobile planner hands to its strategies (frontier_views.hpp,
/// lying_region_views.hpp): the planner's parameters, its gain rays and sensor centre, the step
/// count that seeds the candidates and the memories the strategies update (frontiers and lying
/// regions given up, their visit counts), in one MobileStepContext instead of long parameter
/// lists; and the candidate helpers every strategy shares. MobilePlanner makes the context for
/// every plan(); the strategies change nothing else of the planner.

#include <intervox/core/key.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/plan/candidate_scoring.hpp>
#include <intervox/plan/conflict_planning.hpp>
#include <intervox/plan/frontier_memory.hpp>
#include <intervox/plan/information_gain.hpp>
#include <intervox/plan/mobile_plan.hpp>
#include <intervox/plan/view_sampling.hpp>

#include <cstddef>
#include <utility>
#include <vector>

namespace intervox::detail {

/// What a strategy of one MobilePlanner::plan() call reads of the planner, and the memories it
/// updates.
struct MobileStepContext {
  const MobilePlannerParams& params;
  const RayBundle& rays;        ///< the rig's gain rays
  const Point3& sensor_centre;  ///< the rig's mean mount position (body frame)
  int steps = 0;                ///< views planned before this call (seeds the candidates)
  FrontierMemory& frontiers;    ///< the frontiers (and passages) given up and their visit counts
  RegionMemory& regions;        ///< the lying regions given up and the views aimed at each
};

/// The body pose of a planar candidate at height \p z.
inline Pose candidate_pose(const PlanarCandidate& c, double z) {
  return planar_pose(Point3(c.position.x(), c.position.y(), z), c.yaw);
}

/// The scan paths the scoring step evaluates: one pose per candidate (candidate_pose at \p z).
inline std::vector<std::vector<Pose>> candidate_paths(const std::vector<PlanarCandidate>& cands, double z) {
  std::vector<std::vector<Pose>> paths;
  paths.reserve(cands.size());
  for (const PlanarCandidate& c : cands) paths.push_back({candidate_pose(c, z)});
  return paths;
}

/// Makes the scored candidates around \p target (a frontier, or a region's centre column) the
/// plan's choice.
inline void choose(MobilePlan& r, const Cell2& target, std::vector<PlanarCandidate> cands, ScoredCandidates scored) {
  r.frontier = target;
  r.candidates = std::move(cands);
  r.gains = std::move(scored.gains);
  r.selected = scored.best;
  r.gain = r.gains[*scored.best].gain;
  r.relative_gain = scored.relative_gain;
}

}  // namespace intervox::detail
