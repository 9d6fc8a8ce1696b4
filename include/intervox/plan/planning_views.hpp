#pragma once
/// \file
/// How the mobile planner's exploration map reads a voxel (project_columns() takes any of these
/// views): with the planner's own rules on unknown voxels (PlanningRulesView: hits as obstacles,
/// the start rule), with free space needing a return (ConfirmedView, conflict-aware planning's
/// no-return evidence), or free only where the explained evidence explains it
/// (ExplainedOccupancyView, explained planning). Each view only reads what it refers to.

#include <intervox/analysis/no_return_evidence.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/explain/explained_space.hpp>
#include <intervox/grid/occupancy_grid.hpp>
#include <intervox/plan/look_around.hpp>

namespace intervox {

/// A view with the planner's own rules on unknown voxels: with \p hits_block, a voxel with net
/// hit evidence (probability above \p prior) is occupied (MobilePlannerParams::hits_block);
/// with a \p zone, the start rule (MobilePlannerParams::start_free_radius): within the zone's
/// radius of the start, an unknown voxel without a hit is free if the look-around could not see
/// it or if beams crossed it.
template <class View, class Grid>
struct PlanningRulesView {
  const View& view;
  const Grid& grid;
  const BlindZone* zone;  ///< null: no start rule on voxels
  Pose to_start;          ///< world to the start's body frame (planar: position and heading)
  double prior;           ///< the probability of an unobserved voxel
  bool hits_block;
  const GridGeometry& geometry() const noexcept { return view.geometry(); }
  Occupancy occupancy(const Key& k) const {
    const Occupancy o = view.occupancy(k);
    if (o != Occupancy::Unknown) return o;
    if (grid.probability(k) > prior + 1e-12) return hits_block ? Occupancy::Occupied : o;
    if (!zone) return o;
    const Point3 p = to_start * geometry().center(k);
    const double half = 0.5 * geometry().resolution();
    if (!zone->contains(p, half)) return o;
    return grid.is_observed(k) || zone->blind_voxel(k, p, half) ? Occupancy::Free : o;
  }
};
/// The probability of an unobserved voxel of \p grid (0.5 for a grid without update_policy()).
template <class Grid>
double prior_probability(const Grid& grid) {
  if constexpr (requires { grid.update_policy().state(grid.update_policy().unobserved()); })
    return grid.update_policy().state(grid.update_policy().unobserved());
  else
    return 0.5;
}
/// The grid as the exploration map sees it when free space needs a return to be trusted: a free
/// voxel that only beams without a return crossed is Unknown.
template <class Grid>
struct ConfirmedView {
  const Grid& grid;
  const NoReturnEvidence& evidence;
  const GridGeometry& geometry() const noexcept { return grid.geometry(); }
  Occupancy occupancy(const Key& k) const {
    const Occupancy o = grid.occupancy(k);
    return o == Occupancy::Free && evidence.unconfirmed(k) ? Occupancy::Unknown : o;
  }
};
/// The grid as the exploration map sees it when planning on explained free space: occupied if
/// the grid or the explained evidence says so, free only if both do, unknown otherwise.
template <class Grid>
struct ExplainedOccupancyView {
  const Grid& grid;
  const ExplainedSpace& explained;
  const GridGeometry& geometry() const noexcept { return grid.geometry(); }
  Occupancy occupancy(const Key& k) const {
    const Occupancy o = grid.occupancy(k);
    const ExplainedState e = explained.state(k);
    if (o == Occupancy::Occupied || e == ExplainedState::Occupied) return Occupancy::Occupied;
    return o == Occupancy::Free && e == ExplainedState::Free ? Occupancy::Free : Occupancy::Unknown;
  }
};
/// The former name of ExplainedOccupancyView, kept for one release (CHANGELOG.md).
template <class Grid>
using ExplainedView [[deprecated("renamed ExplainedOccupancyView")]] = ExplainedOccupancyView<Grid>;

}  // namespace intervox
