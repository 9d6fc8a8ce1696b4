#pragma once
/// \file
/// The map a planner reads, made the same way for MobilePlanner and ArmPlanner: the options of
/// an ExplainedMap that explained planning asks for (explained_map_options(), where each planner's
/// map_options() starts), and the insertion options and make_map() every planner offers
/// (detail::PlannerMapMaking, a base of both planners).

#include <intervox/core/plane_patch.hpp>
#include <intervox/grid/occupancy_grid.hpp>
#include <intervox/map/explained_map.hpp>
#include <intervox/plan/explained_planning.hpp>
#include <intervox/raycast/insert_options.hpp>

#include <utility>
#include <vector>

namespace intervox {

/// What an ExplainedMap keeps for explained planning with \p p: the explained channel if
/// p.enabled, with the classing options p.explain and (if enabled) the known surfaces. The
/// planners' map_options() start from it and add what else they read.
inline ExplainedMapOptions explained_map_options(const ExplainedPlanningParams& p) {
  ExplainedMapOptions o;
  o.explained = p.enabled;
  o.explain = p.explain;
  o.known_surfaces = p.enabled ? p.known_surfaces : std::vector<PlanePatch>{};
  return o;
}

namespace detail {

/// insert_options() and make_map() of a planner \p Derived with map_options(), max_range() and
/// params().threads (MobilePlanner, ArmPlanner derive from it).
template <class Derived>
class PlannerMapMaking {
 public:
  /// The insertion's options for this planner's map: its max_range() (beams without a return are
  /// free up to it) on params().threads threads.
  InsertOptions insert_options() const {
    const Derived& planner = static_cast<const Derived&>(*this);
    InsertOptions o;
    o.max_range = planner.max_range();
    o.threads = planner.params().threads;
    return o;
  }
  /// A map of \p grid with what this planner reads (map_options(), insert_options()).
  /// \tparam Grid a VoxelGrid
  template <OccupancyGrid Grid>
  ExplainedMap<Grid> make_map(Grid grid) const {
    return ExplainedMap<Grid>(std::move(grid), static_cast<const Derived&>(*this).map_options(), insert_options());
  }

 protected:
  PlannerMapMaking() = default;
};

}  // namespace detail
}  // namespace intervox
