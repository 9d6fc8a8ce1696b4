#pragma once
/// \file
/// The lying regions the mobile planner plans around, found anew in every plan (docs/planning.md,
/// "Conflicts" and "Unexplained hazards and lying regions"): the conflict regions of an interval
/// grid (conflict-aware planning) and the enclosed unexplained groups of the explained evidence
/// (explained planning with unexplained_hazards), each with the directions it was seen from and
/// whether it is resolvable, and the hazard columns they give the exploration map. MobilePlanner
/// calls them; they read the map and the planner's memory (LyingRegionContext) and change nothing
/// but their outputs.

#include <intervox/analysis/conflicts.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/explain/explained_space.hpp>
#include <intervox/grid/occupancy_grid.hpp>
#include <intervox/plan/column_map.hpp>
#include <intervox/plan/conflict_planning.hpp>
#include <intervox/plan/exploration_map.hpp>
#include <intervox/plan/information_gain.hpp>
#include <intervox/plan/look_around.hpp>
#include <intervox/plan/mobile_plan.hpp>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

namespace intervox {

/// The lying regions of one plan: each region's columns (map cells, any height; columns[i] of
/// MobilePlan::regions[i]), and the hazard columns of the exploration map (robot band).
struct LyingRegions {
  std::vector<std::vector<Cell2>> columns;
  MapHazards hazards;
};

/// The start area of the planner: the operator's promise of a clear spot (start_free_radius),
/// where beams that never return are the rule and voxels are no hazard.
struct StartArea {
  const BlindZone* blind = nullptr;  ///< the look-around's blind zone (the voxel start rule), or null (whole columns)
  Pose to_start = Pose::Identity();  ///< world to the start's body frame
  std::optional<Point3> first;       ///< the first position the planner was given
  double radius = 0;                 ///< start_free_radius (whole columns)

  /// True if the voxel centred at \p c (half size \p half) lies in the start area.
  bool contains(const Point3& c, double half) const {
    if (blind) return blind->contains(to_start * c, half);
    return first && (c - *first).head<2>().norm() <= radius;
  }
};

/// What the lying-region analysis reads of the planner.
struct LyingRegionContext {
  const MobilePlannerParams& params;
  std::span<const Point3> origins;  ///< the sensor origins of every scan planned so far
  const RegionMemory& given_up;     ///< the regions given up
  StartArea start;
};

/// Conflict-aware planning: the conflict regions of \p grid inside the \p gain bounds, the
/// directions they were seen from, appended to r.regions; their columns and hazards (r.region's
/// columns and height band). Empty for a grid without an interval policy or with conflict-aware
/// planning off.
/// \tparam Grid a VoxelGrid
template <OccupancyGrid Grid>
LyingRegions conflict_regions(const Grid& grid, [[maybe_unused]] const GainOptions& gain, MobilePlan& r,
                              const LyingRegionContext& ctx) {
  LyingRegions out;
  const ConflictPlanningParams& cp = ctx.params.conflicts;
  out.hazards.margin = cp.safety_margin;
  if constexpr (IntervalPolicy<typename Grid::UpdateType>) {
    if (!cp.enabled) return out;
    const KeyBox region_box = grid.geometry().key_box(r.region);
    ConflictReport rep = detect_conflicts(grid, cp.detect, gain.bounds);
    observe_regions(grid, ctx.origins, rep.regions, cp.observe);
    for (ConflictRegion& reg : rep.regions) {
      PlannedRegion pr;
      pr.directions = distinct_directions(reg.views, cp.min_angle);
      pr.unresolvable = pr.directions >= cp.resolve_directions || ctx.given_up.given_up(reg);
      std::vector<Cell2> cols;
      for (const Key& k : reg.voxels) {
        const Cell2 c{k.x - region_box.min.x, k.y - region_box.min.y};
        cols.push_back(c);
        const double z = grid.geometry().center(k).z();
        if (z >= r.region.min.z() && z <= r.region.max.z())
          (pr.unresolvable ? out.hazards.unresolvable : out.hazards.cells).push_back(c);
      }
      std::sort(cols.begin(), cols.end());
      cols.erase(std::unique(cols.begin(), cols.end()), cols.end());
      out.columns.push_back(std::move(cols));
      pr.region = std::move(reg);
      r.regions.push_back(std::move(pr));
    }
    for (auto* v : {&out.hazards.cells, &out.hazards.unresolvable}) {
      std::sort(v->begin(), v->end());
      v->erase(std::unique(v->begin(), v->end()), v->end());
    }
  }
  return out;
}

namespace detail {

/// The parts of the columns of \p cols for the unexplained groups: per voxel of the band (the
/// region's keys \p box), 2 lying (free only by lying beams, outside the start area), 1 unexplained
/// (its column unknown in the map, beams without a return crossed it), 0 none (a column the map
/// holds occupied takes no part: an obstacle already, e.g. the space under a table top).
struct UnexplainedParts {
  const ExplainedSpace& explained;
  const ColumnMap& cols;
  const GridGeometry& g;
  const StartArea& start;

  std::uint8_t voxel(const Cell2& c, const Key& k) const {
    if (cols.at(c) == Occupancy::Occupied) return 0;
    if (explained.free_only_by_lying_beams(k) && !start.contains(g.center(k), 0.5 * g.resolution())) return 2;
    return cols.at(c) == Occupancy::Unknown && explained.state(k) == ExplainedState::Unexplained ? 1 : 0;
  }
  /// Per column of \p cols: the largest part of its band voxels.
  std::vector<std::uint8_t> columns(const KeyBox& box) const {
    std::vector<std::uint8_t> out(cols.size(), 0);
    for (std::int32_t y = box.min.y; y <= box.max.y; ++y)
      for (std::int32_t x = box.min.x; x <= box.max.x; ++x) {
        const Cell2 c = cols.cell_of_key(Key{x, y, box.min.z});
        if (!cols.contains(c)) continue;
        std::uint8_t& l = out[cols.index(c)];
        for (std::int32_t z = box.min.z; z <= box.max.z && l < 2; ++z) l = std::max(l, voxel(c, Key{x, y, z}));
      }
    return out;
  }
};

/// True if a cell of \p group (indices into \p cols) lies at the map's edge or next to an
/// unexplored column (unknown, no part in a group).
inline bool group_is_open(const ColumnMap& cols, std::span<const std::size_t> group,
                          const std::vector<std::uint8_t>& part) {
  for (const std::size_t i : group) {
    const Cell2 c = cols.cell_of(i);
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const Cell2 q{c.x + dx, c.y + dy};
        if (!cols.contains(q) || (!part[cols.index(q)] && cols.at(q) == Occupancy::Unknown)) return true;
      }
  }
  return false;
}

/// An enclosed group's region: its lying columns and the unexplained ones within \p zone (offsets
/// around a lying column) of one, with their lying and unexplained voxels in the band (\p box);
/// \p near and \p marked are scratch kept between groups. Columns in \p cells.
inline ConflictRegion enclosed_group_region(const UnexplainedParts& parts, const KeyBox& box,
                                            std::vector<std::size_t>& group, const std::vector<std::uint8_t>& part,
                                            std::span<const Cell2> zone, std::vector<std::uint8_t>& near,
                                            std::vector<std::size_t>& marked, std::vector<Cell2>& cells) {
  const ColumnMap& cols = parts.cols;
  for (const std::size_t i : marked) near[i] = 0;
  marked.clear();
  for (const std::size_t i : group) {
    if (part[i] != 2) continue;
    const Cell2 c = cols.cell_of(i);
    for (const Cell2& d : zone) {
      const Cell2 q{c.x + d.x, c.y + d.y};
      if (!cols.contains(q) || near[cols.index(q)]) continue;
      near[cols.index(q)] = 1;
      marked.push_back(cols.index(q));
    }
  }
  std::sort(group.begin(), group.end());
  ConflictRegion reg;
  cells.clear();
  for (const std::size_t i : group) {
    if (!near[i]) continue;
    const Cell2 c = cols.cell_of(i);
    cells.push_back(c);
    const Key base = cols.key_of(c);
    for (std::int32_t z = box.min.z; z <= box.max.z; ++z)
      if (const Key k{base.x, base.y, z}; parts.voxel(c, k)) reg.voxels.push_back(k);
  }
  return reg;
}

}  // namespace detail

/// Explained planning with unexplained_hazards: the columns of \p cols (the exploration map's
/// columns of \p region) holding a voxel free only by lying beams
/// (ExplainedSpace::free_only_by_lying_beams()) within the robot's height band (the region's z
/// range), outside the start area, grouped by 8-connectivity together with the unknown columns
/// joined to them that beams without a return crossed in the band (unexplained: a black object's
/// columns that no lying beam reached). A group that no unexplored column (unknown, no evidence)
/// and not the map's edge touches is enclosed by space the robot has explained (a black object
/// standing free, a phantom pocket): it is a lying region of its own (PlannedRegion::unexplained;
/// its columns are the group's lying columns and its unexplained ones within the hazard zone's
/// radius, robot radius + clearance + margin, of a lying one: farther ones are where beams ran
/// out of range, which the frontier rule handles; its voxels are their lying and unexplained
/// voxels in the band; columns the map holds occupied take no part), observed from the scan
/// origins like a conflict region (observe_regions with ConflictPlanningParams::observe). An
/// open one (seen from fewer than resolve_directions distinct directions, not given up) gives
/// hazards whose zone does not hide the frontier (MapHazards::open): the robot keeps its
/// radius + unexplained_margin (or the conflict-aware safety margin if larger) from them and
/// looks at them from new directions. An unresolvable one gives hazards labelled Unresolvable
/// whose zone hides the frontier: the group is retired. A group open to unexplored space is where
/// beams ran out of range at the border of what was seen: it stays unknown, as without the option
/// (with open_group_hazards its lying columns are open hazards). Appends the groups to \p lying's
/// columns and \p plan's regions when given.
/// \tparam Grid a VoxelGrid
template <OccupancyGrid Grid>
void unexplained_regions(const Grid& grid, const ExplainedSpace& explained, const ColumnMap& cols, const Bounds& region,
                         MapHazards& hazards, LyingRegions* lying, MobilePlan* plan, const LyingRegionContext& ctx) {
  const MobilePlannerParams& p = ctx.params;
  const GridGeometry& g = grid.geometry();
  const KeyBox box = g.key_box(region);
  const detail::UnexplainedParts parts{explained, cols, g, ctx.start};
  const std::vector<std::uint8_t> part = parts.columns(box);
  std::vector<std::uint8_t> seen(cols.size(), 0), near(cols.size(), 0);
  std::vector<std::size_t> group, marked;
  std::vector<ConflictRegion> regions;
  std::vector<std::vector<Cell2>> columns;
  // The hazard zone around a lying column (offsets within robot radius + clearance + margin):
  // unexplained columns of a group outside every lying column's zone are where beams ran out of
  // range, not the lying surface's footprint.
  const std::vector<Cell2> zone =
      disk_offsets((p.map.keep_out() + std::max(hazards.margin, p.explained.unexplained_margin)) / cols.resolution());
  std::vector<Cell2> cells;
  for (std::size_t s = 0; s < cols.size(); ++s) {
    if (part[s] != 2 || seen[s]) continue;
    group.clear();
    cols.flood_fill(
        s, seen, [&](const Cell2&, std::size_t qi, std::size_t) { return part[qi] != 0; },
        [&](std::size_t i) { group.push_back(i); });
    if (detail::group_is_open(cols, group, part)) {
      // open_group_hazards: its lying columns keep the robot off, the frontier stays at the zone's edge.
      if (p.explained.open_group_hazards)
        for (const std::size_t i : group)
          if (part[i] == 2) hazards.open.push_back(cols.cell_of(i));
      continue;
    }
    ConflictRegion reg = detail::enclosed_group_region(parts, box, group, part, zone, near, marked, cells);
    if (reg.voxels.size() < p.explained.min_unexplained_voxels) continue;
    set_region_extent(reg, g);
    regions.push_back(std::move(reg));
    columns.push_back(cells);
  }
  hazards.margin = std::max(hazards.margin, p.explained.unexplained_margin);
  if (regions.empty()) return;
  observe_regions(grid, ctx.origins, regions, p.conflicts.observe);
  for (std::size_t i = 0; i < regions.size(); ++i) {
    PlannedRegion pr;
    pr.unexplained = true;
    pr.directions = distinct_directions(regions[i].views, p.conflicts.min_angle);
    pr.unresolvable = pr.directions >= p.conflicts.resolve_directions || ctx.given_up.given_up(regions[i]);
    std::vector<Cell2>& h = pr.unresolvable ? hazards.unresolvable : hazards.open;
    h.insert(h.end(), columns[i].begin(), columns[i].end());
    pr.region = std::move(regions[i]);
    if (lying) lying->columns.push_back(std::move(columns[i]));
    if (plan) plan->regions.push_back(std::move(pr));
  }
}

}  // namespace intervox
