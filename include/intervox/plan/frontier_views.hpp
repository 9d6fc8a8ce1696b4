#pragma once
/// \file
/// The mobile planner's frontier and passage strategies and its termination rule (docs/planning.md):
/// the reachable frontiers by path distance, each retired, offered to a lying region's view
/// (lying_region_views.hpp) or given its own ring of candidates (frontier_view); the passages the
/// same way when no frontier or lying region gave a view (PassageViewParams); and, when no view
/// came out of any strategy, why the exploration ends (end_exploration). MobilePlanner::plan()
/// calls them with the step's MobileStepContext (mobile_step.hpp).

#include <intervox/core/key.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/grid/occupancy_grid.hpp>
#include <intervox/plan/candidate_scoring.hpp>
#include <intervox/plan/column_map.hpp>
#include <intervox/plan/conflict_planning.hpp>
#include <intervox/plan/exploration_map.hpp>
#include <intervox/plan/frontier_memory.hpp>
#include <intervox/plan/information_gain.hpp>
#include <intervox/plan/lying_region_views.hpp>
#include <intervox/plan/mobile_plan.hpp>
#include <intervox/plan/mobile_step.hpp>
#include <intervox/plan/view_sampling.hpp>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

namespace intervox::detail {

/// What the frontier strategy met: whether any frontier was tried, and whether any had a
/// candidate position (for the termination reason).
struct FrontierSearch {
  bool any_frontier = false;
  bool any_candidate = false;
};

/// What frontier_view() made of one frontier.
enum class FrontierOutcome : std::uint8_t {
  View,         ///< its best candidate is the plan's view
  NoCandidate,  ///< no reachable cell on its ring (refused, not given up)
  GivenUp,      ///< low gain or visit budget (refused and given up)
};

/// The view of frontier \p f (the \p target-th frontier tried in this call): ring candidates
/// around it (candidate_random, CandidateStream::Gain), scored by gain (score_candidates); the
/// best is the view unless its relative gain is below min_relative_gain or the frontier was
/// selected max_visits_per_frontier times (then the frontier is given up). The passage strategy
/// calls it with its own \p ring and \p stream, and \p gain null when the passage's gain box
/// lies outside the planner's gain bounds (then a frontier with candidates is given up as low gain).
template <OccupancyGrid Grid>
FrontierOutcome frontier_view(const Grid& grid, const ExplorationMap& map, const GainOptions* gain, const Cell2& f,
                              const Key& fk, std::size_t target, MobilePlan& r, const RingSamplerParams& ring,
                              const MobileStepContext& ctx, CandidateStream stream = CandidateStream::Gain) {
  const MobilePlannerParams& params = ctx.params;
  const std::uint64_t seed =
      candidate_random(params.seed, static_cast<std::uint64_t>(ctx.steps), stream, target).next();
  std::vector<PlanarCandidate> cands = sample_ring(map, grid.geometry(), f, ring, seed);
  if (cands.empty()) {
    r.refused.push_back({f, FrontierRefusal::NoCandidate, 0.0, ring_refusals(map, f, ring)});
    return FrontierOutcome::NoCandidate;
  }
  if (!gain) {
    ctx.frontiers.give_up(fk);
    r.refused.push_back({f, FrontierRefusal::LowGain, 0.0, ring_refusals(map, f, ring)});
    return FrontierOutcome::GivenUp;
  }
  // The gain of a frontier's candidates is taken at the cell centres' height (z = 0, as the
  // thesis' planner always did); region_view() takes it at the body's height.
  ScoredCandidates scored = score_candidates(grid, ctx.rays, candidate_paths(cands, 0.0), *gain, params.threads);
  r.considered += scored.gains.size();
  int& visits = ctx.frontiers.visits(fk, map.resolution(), params.frontier_radius);
  if (!scored.best || scored.relative_gain < params.min_relative_gain || visits >= params.max_visits_per_frontier) {
    ctx.frontiers.give_up(fk);
    r.refused.push_back(
        {f, visits >= params.max_visits_per_frontier ? FrontierRefusal::VisitBudget : FrontierRefusal::LowGain,
         scored.relative_gain, ring_refusals(map, f, ring)});
    return FrontierOutcome::GivenUp;
  }
  ++visits;
  choose(r, f, std::move(cands), std::move(scored));
  return FrontierOutcome::View;
}

/// The lying regions frontier \p f belongs to (a column of region_cols[i] within region_reach):
/// the first unresolvable one and the first open one.
struct FrontierRegions {
  std::optional<std::size_t> open, retired;
};
inline FrontierRegions frontier_regions(const Cell2& f, const std::vector<std::vector<Cell2>>& region_cols,
                                        double resolution, const MobilePlan& r, const MobileStepContext& ctx) {
  FrontierRegions out;
  const double reach = ctx.params.conflicts.region_reach / resolution;
  for (std::size_t i = 0; i < region_cols.size(); ++i) {
    bool near_region = false;
    for (const Cell2& c : region_cols[i])
      near_region =
          near_region || double(c.x - f.x) * double(c.x - f.x) + double(c.y - f.y) * double(c.y - f.y) <= reach * reach;
    if (!near_region) continue;
    if (r.regions[i].unresolvable) {
      if (!out.retired) out.retired = i;
    } else if (!out.open) {
      out.open = i;
    }
  }
  return out;
}

/// The frontier strategy: the reachable frontiers by path distance, at most frontier_attempts,
/// skipping those near one tried or given up. A frontier next to an unresolvable region is
/// retired; one next to an open region is offered to region_view() (conflict-aware planning);
/// any other gets frontier_view(). Stops at the first view; records every refusal in r.
template <OccupancyGrid Grid>
FrontierSearch frontier_strategy(const Grid& grid, const ExplorationMap& map, const GainOptions& gain, const Pose& pose,
                                 const std::vector<std::vector<Cell2>>& region_cols, MobilePlan& r,
                                 const MobileStepContext& ctx) {
  const MobilePlannerParams& params = ctx.params;
  FrontierSearch out;
  std::vector<Key> tried;
  for (const Cell2& f : map.borders()) {
    if (static_cast<int>(tried.size()) >= params.frontier_attempts) break;
    const Key fk = map.columns().key_of(f);
    if (ctx.frontiers.near_tried_or_given_up(fk, tried, map.resolution(), params.frontier_radius)) {
      ++r.skipped;
      continue;
    }
    const FrontierRegions near = frontier_regions(f, region_cols, map.resolution(), r, ctx);
    if (near.retired) {
      ctx.frontiers.give_up(fk);
      ++r.retired;
      r.refused.push_back(
          {f,
           r.regions[*near.retired].unexplained ? FrontierRefusal::Unexplained : FrontierRefusal::Unresolvable,
           0.0,
           {}});
      continue;
    }
    out.any_frontier = true;
    tried.push_back(fk);
    if (near.open) {
      if (region_view(grid, map, gain, pose, *near.open, r, ctx)) return out;
      // No view of an unexplained group from a new direction from here, but views left to aim
      // at it: the group stays open (its zone keeps the robot off it) and the frontier is
      // explored like any other; the robot may meet the group from elsewhere later.
      // lying_region_strategy gives it up once no frontier gives a view.
      if (r.regions[*near.open].unexplained && !region_views_spent(r.regions[*near.open], ctx)) {
        const FrontierOutcome o = frontier_view(grid, map, &gain, f, fk, tried.size(), r, params.ring, ctx);
        if (o != FrontierOutcome::NoCandidate) out.any_candidate = true;
        if (o == FrontierOutcome::View) return out;
        continue;
      }
      // No view from a new direction: the region is given up, the frontier retired.
      ctx.regions.give_up(r.regions[*near.open].region);
      r.regions[*near.open].unresolvable = true;
      ctx.frontiers.give_up(fk);
      ++r.retired;
      r.refused.push_back({f, FrontierRefusal::NoNewDirection, 0.0, ring_refusals(map, f, params.ring)});
      continue;
    }
    const FrontierOutcome o = frontier_view(grid, map, &gain, f, fk, tried.size(), r, params.ring, ctx);
    if (o != FrontierOutcome::NoCandidate) out.any_candidate = true;
    if (o == FrontierOutcome::View) return out;
  }
  return out;
}

/// The passage strategy (PassageViewParams, when no frontier or lying region gave a view): the
/// map's passages by path distance, at most frontier_attempts, skipping those near one tried or
/// given up; ring candidates around each (CandidateStream::Passage, the k-th passage tried is
/// target k), scored by the gain inside the passage's box. The first whose best candidate gains
/// enough is the view (reason Passage); records every refusal in r and what it met in \p search.
template <OccupancyGrid Grid>
void passage_strategy(const Grid& grid, const ExplorationMap& map, const GainOptions& gain, FrontierSearch& search,
                      MobilePlan& r, const MobileStepContext& ctx) {
  const MobilePlannerParams& params = ctx.params;
  const PassageViewParams& pv = params.passage_views;
  std::vector<Key> tried;
  for (const Cell2& f : map.passages()) {
    if (static_cast<int>(tried.size()) >= params.frontier_attempts) break;
    const Key fk = map.columns().key_of(f);
    if (ctx.frontiers.near_tried_or_given_up(fk, tried, map.resolution(), params.frontier_radius)) {
      ++r.skipped;
      continue;
    }
    search.any_frontier = true;
    tried.push_back(fk);
    // The gain inside the passage's box (within the planner's gain bounds).
    const Point3 c = cell_center(map.columns(), grid.geometry(), f);
    GainOptions g = gain;
    Bounds box{Point3(c.x() - pv.reach, c.y() - pv.reach, r.region.min.z()),
               Point3(c.x() + pv.reach, c.y() + pv.reach, r.region.max.z())};
    if (gain.bounds) {
      box.min = box.min.cwiseMax(gain.bounds->min);
      box.max = box.max.cwiseMin(gain.bounds->max);
    }
    g.bounds = box;
    const bool inside = (box.min.array() < box.max.array()).all();
    const FrontierOutcome o =
        frontier_view(grid, map, inside ? &g : nullptr, f, fk, tried.size(), r, pv.ring, ctx, CandidateStream::Passage);
    if (o != FrontierOutcome::NoCandidate) search.any_candidate = true;
    if (o == FrontierOutcome::View) {
      r.reason = ViewReason::Passage;
      return;
    }
  }
}

/// No view: why the exploration ends (see MobilePlanner's Termination).
inline void end_exploration(const ExplorationMap& map, const FrontierSearch& search, MobilePlan& r,
                            const MobilePlannerParams& params) {
  r.reason = ViewReason::None;
  if (!r.regions.empty()) {
    // Lying regions remain, but none is worth a view: explored as far as it can be.
    r.termination = Termination::Explored;
    return;
  }
  r.termination = map.borders().empty() && (!params.passage_views.enabled || map.passages().empty())
                      ? Termination::NoReachableFrontier
                  : !search.any_frontier ? Termination::Explored
                  : search.any_candidate ? Termination::Explored
                                         : Termination::Blocked;
}

}  // namespace intervox::detail
