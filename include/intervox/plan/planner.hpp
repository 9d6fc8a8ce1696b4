#pragma once
/// \file
/// What every planner returns: the next view as body poses to sense at, the drivable path to it,
/// why it was chosen, what it gains, or why the episode ends. The planners only decide; an episode
/// runner (plan/episode.hpp) or the user's own loop moves the robot and senses.

#include <intervox/core/sensor_data.hpp>

#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

namespace intervox {

/// Why an episode ended.
enum class Termination : std::uint8_t {
  Running = 0,          ///< not ended yet: the plan holds a view
  Explored,             ///< frontiers remain (or candidates), but no view gains enough
  NoReachableFrontier,  ///< no reachable cell borders unknown space (the thesis' criterion)
  Blocked,              ///< frontiers remain, but no collision-free candidate pose was found
  Budget,               ///< the step (or view) budget is used up
};

/// Name of a termination reason, for reports.
constexpr std::string_view to_string(Termination t) noexcept {
  switch (t) {
    case Termination::Running:
      return "running";
    case Termination::Explored:
      return "explored";
    case Termination::NoReachableFrontier:
      return "no reachable frontier";
    case Termination::Blocked:
      return "blocked";
    case Termination::Budget:
      return "budget";
  }
  return "?";
}

/// Why a view was chosen.
enum class ViewReason : std::uint8_t {
  None = 0,  ///< no view (the plan terminates the episode)
  Initial,   ///< the fixed first view (the mobile base's look-around, the arm's initial sweep)
  Frontier,  ///< the best view of the closest reachable frontier that gains enough
  Gain,      ///< the candidate of highest gain (no frontier: the arm's sphere of views)
  Conflict,  ///< a view of an open conflict region from a direction not used yet (conflict-aware planners)
  Normals,   ///< the arm's sweep chosen for seeing undecided surfaces near the specular condition over a higher gain
  Passage,   ///< a view that opens a passage closed by unknown columns seen too few times (MobilePlanner's
             ///< PassageViewParams)
};

/// Name of a view reason, for reports.
constexpr std::string_view to_string(ViewReason r) noexcept {
  switch (r) {
    case ViewReason::None:
      return "none";
    case ViewReason::Initial:
      return "initial";
    case ViewReason::Frontier:
      return "frontier";
    case ViewReason::Gain:
      return "gain";
    case ViewReason::Conflict:
      return "conflict";
    case ViewReason::Normals:
      return "normals";
    case ViewReason::Passage:
      return "passage";
  }
  return "?";
}

/// The decision of one planning call, common to every planner.
///
/// Thread safety: a plain value type.
struct ViewPlan {
  /// Running if the plan holds a view; otherwise why the episode ends (then `scans` is empty).
  Termination termination = Termination::Running;
  ViewReason reason = ViewReason::None;
  /// Body poses from the current pose to the view, to be driven through in order: the current
  /// pose first and the view's first scan pose last (empty when the robot does not move, e.g. the
  /// look-around, or when the planner plans no motion, e.g. the arm between sweeps).
  std::vector<Pose> path;
  /// Body poses to sense at, in order (one scan each): the turns on the spot at a view of the
  /// mobile base, the profiles of a sweep of the arm's striper.
  std::vector<Pose> scans;
  double path_length = 0;  ///< m along `path` (the sum of its straight segments)
  double gain = 0;         ///< the chosen view's gain (the utility policy's sum)
  /// gain / the same view's gain in a world of unobserved voxels (unknown_path_gain), in [0, 1]
  /// for utilities that peak at the unobserved state; the termination thresholds use it.
  double relative_gain = 0;
  std::size_t considered = 0;  ///< candidate views whose gain was evaluated
  double seconds = 0;          ///< time spent deciding
};

}  // namespace intervox
