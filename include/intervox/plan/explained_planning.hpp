#pragma once
/// \file
/// Planning on explained free space, shared by MobilePlanner and ArmPlanner (docs/planning.md,
/// "Planning on explained free space"): the switch and options (ExplainedPlanningParams) and the
/// collision test on the evidence (outside_explained_collision_space). The evidence is an
/// ExplainedMap's (map/explained_map.hpp): the planners read it and never change it.

#include <intervox/analysis/lying_surfaces.hpp>
#include <intervox/analysis/wall_gaps.hpp>
#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/explain/explained_space.hpp>
#include <intervox/grid/occupancy_grid.hpp>
#include <intervox/plan/view_sampling.hpp>
#include <intervox/raycast/insert_options.hpp>

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace intervox {

/// Planning on explained free space: the planner reads the ExplainedSpace of an ExplainedMap
/// (plan(map, pose); the planner's make_map() gives a map with what these options ask for), and
/// plans only where the beams explain the space.
///  - MobilePlanner: its exploration map counts a column's voxel as free only where the grid says
///    free *and* the beams explain it (ExplainedState::Free); unexplained space, space that only
///    suspect beams or beams without a return crossed, and space no beam crossed are unknown, so
///    the robot keeps its maybe-collision distance from them and never drives or stands there.
///    Voxels that either the grid or the explained evidence holds occupied are occupied. With
///    `unexplained_hazards` (opt-in), enclosed groups of columns with a voxel in the band that only
///    lying beams made free are hazards besides. An
///    unbounded grid's derived region follows the trusted extent
///    (ExplainedSpace::trusted_extent()), so phantom voxels behind a mirror or a window do not
///    widen it.
///  - ArmPlanner: a sweep is refused if a voxel within its collision margin is explained occupied
///    or unexplained (besides the grid's occupied voxels), so the striper and flange never pass
///    through space that only lying beams (a polished surface's folded returns, the void behind a
///    black object) made look free.
/// Any update policy.
struct ExplainedPlanningParams {
  bool enabled = false;  ///< off: the map is the grid's alone, as in the thesis
  /// How the map's channel classes beams and combines their evidence (the defaults of
  /// explained_space.hpp; the planner's map_options() passes it on).
  ExplainOptions explain{};
  /// MobilePlanner, opt-in: columns holding a voxel free only by lying beams
  /// (ExplainedSpace::free_only_by_lying_beams(): unexplained, crossed by suspect beams, and free
  /// were its suspect and no-return evidence trusted) within the robot's height band, outside the
  /// start area, grouped (8-connected) with the unknown columns joined to them that beams without
  /// a return crossed, in a group that no unexplored column (no evidence) and not the map's edge
  /// touches, are hazards of the exploration map: the robot keeps its radius +
  /// `unexplained_margin` from them (of the unexplained columns only those within that distance of
  /// a lying column; occupied columns take no part). Each such group is a lying region of the plan
  /// (PlannedRegion::unexplained) handled with the conflict-aware parameters
  /// (ConflictPlanningParams: observe, min_angle, resolve_directions, region_reach,
  /// max_region_views), whether conflict-aware planning is on or not: while it is open its zone does
  /// not hide the frontier (MapHazards::open) and the planner views it from new directions (reason
  /// Conflict); once seen from resolve_directions distinct directions, or without a view from a new
  /// direction when no frontier gives a view (a frontier next to it without such a view is
  /// planned like any other), or after resolve_directions views aimed at it (a view that cannot
  /// see it through an occluder counts too), it is retired: labelled Unresolvable, its frontiers refused with
  /// FrontierRefusal::Unexplained, so exploration ends around it. Groups of fewer than
  /// `min_unexplained_voxels` voxels are neither. Off (the default),
  /// such a column is merely unknown, and an unknown column away from occupied ones does not
  /// narrow the map (thesis Table 3.2): the body may overlap a black obstacle standing free in the
  /// room (examples/robot_loop: 163 places in collision off, 0 on). Space that only beams without
  /// a return crossed which passed no supported surface within the sensor's range (beyond the
  /// range of what was seen) is no hazard (docs/planning.md, "Planning on explained free space",
  /// has the measurements).
  bool unexplained_hazards = false;
  /// m beyond the robot radius kept from unexplained columns, finite and >= 0 (with
  /// conflict-aware planning too, the larger of this and its safety_margin).
  double unexplained_margin = 0.0;
  /// With unexplained_hazards: an enclosed group with fewer voxels than this in the band is no
  /// hazard and no lying region (its columns stay unknown, as with the option off): a voxel or
  /// two that lying beams crossed at a surface's edge are noise, and each such group would
  /// otherwise cost views and, once retired, hide the frontiers around it (the default, 8, is a
  /// 10 cm cube at 5 cm voxels), >= 1.
  std::size_t min_unexplained_voxels = 8;
  /// With unexplained_hazards, opt-in: the lying columns (a voxel in the band free only by lying
  /// beams, outside the start area) of a group that touches unexplored space or the map's edge
  /// are hazards too, not merely unknown: the robot keeps its radius + unexplained_margin from
  /// them wherever they lie, whether an occupied column is near or not. Their zone does not hide
  /// the frontier (MapHazards::open): a reachable cell at its edge is a border, so the space
  /// behind is still explored from there. Such a group is no lying region (the frontier rule
  /// handles it). Off (the default), an open group's columns are unknown and narrow the map only
  /// within the robot's radius of an occupied column (thesis Table 3.2), so a view may stand
  /// with its body over a mirror's phantom columns where the mirror itself was not yet seen
  /// (docs/planning.md, "Open lying groups"; "Which options, as measured over 40 seeds" compares
  /// it with the other options over 40 seeds).
  bool open_group_hazards = false;
  /// MobilePlanner, opt-in: the map's update_analysis() (before every plan: the episode runner calls
  /// it; map_options() sets ExplainedMapOptions::find_mirrors) revises the channel
  /// (ExplainedSpace::revise()) and tells it of the mirrors the region analysis finds
  /// (find_lying_surfaces() with `lying`, then resolve_mirrors(); analysis/lying_surfaces.hpp):
  /// every beam through a found mirror is suspect from then on and its patch explained occupied.
  /// Costs about one analysis per plan (about 1.2 s at 5 cm in the lab room, docs/concepts.md).
  /// Over 40 seeds of the lab room it met the mirror closet in 4 runs and ended 17 with less than
  /// 90 % of the floor known; in the runs traced, a false mirror beside the start hid floor
  /// (docs/notes/open-lying-groups-study.md, "find_mirrors over 40 seeds").
  bool find_mirrors = false;
  /// The region analysis' thresholds for find_mirrors (its `threads` is the planner's).
  LyingSurfaceParams lying{};
  /// MobilePlanner, opt-in: the map's update_analysis() finds the gaps of seen walls in the channel
  /// as it stands, without revising it (find_wall_gaps() with `wall_gaps`; analysis/wall_gaps.hpp;
  /// map_options() sets ExplainedMapOptions::find_wall_gaps), and each plan closes every gap that is
  /// not an opening: its
  /// footprint (the gap's patch from end to end along the floor) counts as an occupied column of
  /// the exploration map, so no pose and no path passes it and what lies behind it is reached only
  /// another way. A gap opens as soon as something seen through it contradicts a mirror's
  /// reflection; nothing is told to the channel. What it guards against: a mirror hung on a wall,
  /// whose phantom the channel trusts because its beams cross the wall only where the mirror
  /// hides it, so that no lying region forms (the candidate safe planner drives through such a
  /// mirror in an unbounded grid: docs/planning.md, "Gaps in a wall", measures it with and
  /// without). What it costs: a doorway stays closed until the view through it contradicts a
  /// reflection (a doorway between mirror-symmetric rooms, or into an empty room deeper than the
  /// sensor's range, stays closed). The gaps of each plan are in MobilePlan::wall_gaps.
  bool close_wall_gaps = false;
  /// The thresholds of close_wall_gaps (its `threads` is the planner's).
  WallGapParams wall_gaps{};
  /// Opaque surfaces the user knows: mirrors, glass, black panels, or the walls of a floor plan
  /// (each rectangle as given: walls on both sides of a doorway stay apart). The map's channel is
  /// told of each when the map is made (map_options(); ExplainedSpace::add_mirror() with MirrorMerge::Keep):
  /// every beam through one, more than crossing_tolerance before its end, is suspect (what lies
  /// behind an opaque surface was not seen through it), and its voxels are explained occupied, so
  /// neither planner plans into it, seen or not. Leave a doorway or window the robot may use out
  /// of the list. Empty by default: the planner knows only what its beams tell it.
  std::vector<PlanePatch> known_surfaces{};

  /// \throws InvalidArgument naming the first invalid parameter.
  void validate() const {
    explain.validate();
    lying.validate();
    wall_gaps.validate();
    const ParamCheck check("intervox::ExplainedPlanningParams");
    check.nonnegative("unexplained_margin", unexplained_margin);
    check.at_least("min_unexplained_voxels", min_unexplained_voxels, 1);
    for (const PlanePatch& p : known_surfaces) p.validate();
  }
};

/// True if no voxel whose centre lies within \p clearance of \p p is occupied in \p grid, or
/// explained occupied or unexplained in \p space: the collision test of planning on explained
/// free space. Voxels without any evidence (never observed) do not block.
/// \tparam Grid a VoxelGrid of \p space's geometry
/// Thread safety: reads both only.
template <OccupancyGrid Grid>
bool outside_explained_collision_space(const Grid& grid, const ExplainedSpace& space, const Point3& p,
                                       double clearance) {
  return no_voxel_within(grid.geometry(), p, clearance, [&](const Key& k) {
    if (grid.occupancy(k) == Occupancy::Occupied) return true;
    const ExplainedState s = space.state(k);
    return s == ExplainedState::Occupied || s == ExplainedState::Unexplained;
  });
}

}  // namespace intervox
