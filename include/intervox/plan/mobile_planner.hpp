#pragma once
/// \file
/// The next view of the mobile base (thesis 3.3.3–3.5), decided from the map alone: project the
/// grid to the exploration map, pick the closest reachable frontier, sample candidate poses in a
/// ring around it, return the candidate of highest information gain with the drivable path to
/// it, or the reason the exploration ends. The planner neither moves the robot nor senses: an
/// episode runner (plan/episode.hpp) or the user's loop does, and calls plan() again.

#include <intervox/analysis/no_return_evidence.hpp>
#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/sensors.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/explain/explained_space.hpp>
#include <intervox/grid/occupancy_grid.hpp>
#include <intervox/plan/candidate_scoring.hpp>
#include <intervox/plan/column_map.hpp>
#include <intervox/plan/conflict_planning.hpp>
#include <intervox/plan/exploration_map.hpp>
#include <intervox/plan/frontier_memory.hpp>
#include <intervox/plan/frontier_views.hpp>
#include <intervox/map/explained_map.hpp>
#include <intervox/plan/explained_planning.hpp>
#include <intervox/plan/information_gain.hpp>
#include <intervox/plan/look_around.hpp>
#include <intervox/plan/lying_region_analysis.hpp>
#include <intervox/plan/lying_region_views.hpp>
#include <intervox/plan/path_driving.hpp>
#include <intervox/plan/mobile_plan.hpp>
#include <intervox/plan/mobile_step.hpp>
#include <intervox/plan/planner.hpp>
#include <intervox/plan/planner_maps.hpp>
#include <intervox/plan/planning_views.hpp>
#include <intervox/plan/rig_rays.hpp>
#include <intervox/plan/view_sampling.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

namespace intervox {

/// Decides the next view of a mobile base with a rig of depth cameras.
///
/// The first call returns the look-around at the current pose (reason Initial): the base turns on
/// the spot and scans at look_around_yaws(). Every later call projects the grid to the
/// exploration map, with the cells around every position the robot was given at (footprint_radius)
/// and the voxels around the first that the look-around could not see (start_free_radius, BlindZone)
/// counting as free, and voxels with hit evidence as obstacles (hits_block), tries the reachable
/// frontiers by path
/// distance (at most `frontier_attempts`, skipping frontiers near one tried or given up), samples
/// ring candidates around each, and returns the first whose best candidate gains enough. A frontier
/// is given up when its best view gains less than `min_relative_gain` or it was selected
/// `max_visits_per_frontier` times. The plan's path runs over the map's reachable cells (and,
/// with `driven_paths`, the way back's passable ones) from the robot's cell to the view; its
/// scans turn on the spot at the view. In code, plan() is the frontier strategy followed
/// (conflict-aware planning, no view yet) by the lying-region strategy below and
/// (`passage_views`, no view yet) by the passage strategy (PassageViewParams: views that open a
/// doorway whose far side was seen by too few scans, reason Passage, refusals listed in
/// `refused` like a frontier's); all score candidates with the step ArmPlanner shares
/// (plan/candidate_scoring.hpp: one seed rule, gains, the best candidate and its relative gain).
///
/// Termination: NoReachableFrontier when the map has no border cell (with passage views: and no
/// passage); Explored when frontiers (or passages) remain but none is worth a view; Blocked when
/// none had a candidate position at all; Budget after `max_steps` views. The state kept between
/// calls: the positions given, the step count, the frontiers (and passages) given up and their
/// visit counts, and (`driven_paths`) the cells of the paths driven; copy the planner to branch an
/// episode.
///
/// Conflict-aware planning (`params.conflicts.enabled`, interval grids only): the planner records
/// the sensor origin of every scan it plans (the rig's mean mount position at each scan pose; it
/// assumes every plan is carried out, as the episode runner does). Each call detects the conflict
/// regions inside the gain bounds (detect_conflicts) and which recorded origins saw them
/// (observe_regions). A region seen from `resolve_directions` distinct directions is unresolvable.
/// The columns of regions' voxels within the robot's height band are hazards of the exploration
/// map (MapHazards with `safety_margin`): never driven into or planned at. Free voxels that only
/// beams without a return crossed (an ExplainedMap's no-return evidence, thesis 5.5: an absorbing
/// surface and what lies behind it) count as unknown in the exploration map (`no_return_unknown`,
/// plan(map, pose)). A frontier with a
/// region column within `region_reach` is retired if the region is unresolvable; if the region is
/// open, the planner instead samples the ring around the region, keeps candidates whose direction
/// to it is new, and returns the best by conflict_view_score() (reason Conflict). A region with no
/// such candidate, or aimed at `max_region_views` times, is given up (unresolvable from then on).
/// When no frontier gave a view, the open regions whose centroid lies in the robot's band are
/// tried the same way, closest first (their safety margin hides the unknown columns at them from
/// the frontier rule). Termination Explored when regions remain but none gives a view.
/// Explained planning with ExplainedPlanningParams::unexplained_hazards plans the same way around
/// the enclosed unexplained groups (PlannedRegion::unexplained; see unexplained_regions() in the
/// code), with the same parameters, whether conflict-aware planning is on or not: a group seen from
/// `resolve_directions` directions, or aimed at that many times, is retired
/// (FrontierRefusal::Unexplained), an open one is viewed from new directions; groups below
/// ExplainedPlanningParams::min_unexplained_voxels are left out. Unlike a conflict region, an open
/// group without a candidate from a new direction at a frontier is not given up there: the
/// frontier is planned like any other (the group's zone keeps the robot off it), and the group is
/// given up only when no frontier gives a view and it still has no such candidate.
///
/// What a plan promises (the safety contract as built; docs/planning.md, "Planning on explained
/// free space" measures where it holds): every pose of the path and the view lies on a reachable
/// cell of the exploration map, so the robot's centre stays on free columns at least the robot
/// radius (+ `map.clearance`) from every occupied column and from unknown columns in reach, and a
/// path never cuts a corner between cells. A column is free only if every voxel of the robot's
/// height band is: free in the grid; with `hits_block`, without net hit evidence; with explained
/// planning, free on explained evidence too (space that only suspect beams or beams without a
/// return crossed is unknown; with ExplainedPlanningParams::unexplained_hazards, enclosed groups
/// of such columns are hazards the robot keeps its radius from, and with
/// ExplainedPlanningParams::open_group_hazards the lying columns of open groups too); with conflict-aware planning,
/// not a conflict region or its margin.
/// Exceptions, each the user's to accept: the footprint of every pose given and the start area
/// (`start_free_radius`, the operator's promise of a clear spot) count as free; unknown columns
/// outside collision space do not narrow the map (thesis Table 3.2), so the body may overlap a
/// column no beam reached, or one only lying beams crossed (a black obstacle standing free; a
/// mirror's phantom columns open to unexplored space) unless `explained.unexplained_hazards`
/// (and for open groups `explained.open_group_hazards`) is on; a robot standing in maybe-collision space may leave it
/// over free cells of its escape zone (ExplorationMap); and a mirror whose phantom crosses no surface the map supports
/// is explained free (no per-beam rule sees it: the robot can drive into a mirror-fronted closet, and in an unbounded
/// grid through a wall mirror into its phantom room unless `explained.close_wall_gaps` closes the gap it leaves in the
/// wall; docs/planning.md, "Gaps in a wall").
///
/// Thread safety: not thread-safe (plan() updates the state above); the grid must not be modified
/// during plan(). Candidate evaluation inside plan() uses `params.threads` threads, with results
/// independent of that number.
class MobilePlanner : public detail::PlannerMapMaking<MobilePlanner> {
 public:
  /// \param rig the sensors on the base (its rays are cast for the gain; copied)
  /// \throws InvalidArgument for invalid parameters, a rig without sensors, or (with the defaults
  ///         left unset) a rig whose look-around or blind zone cannot be derived: no beam with a
  ///         horizontal component, or a band height never seen in some direction (give
  ///         look_around_span or start_free_radius).
  explicit MobilePlanner(const SensorRig& rig = SensorRig::mobile_base(), MobilePlannerParams params = {})
      : params_(std::move(params)) {
    params_.validate();
    if (rig.size() == 0) ParamCheck("intervox::MobilePlanner").fail("the rig has no sensor");
    look_yaws_ = intervox::look_around_yaws(rig, params_.look_around_scans, params_.look_around_span);
    if (params_.start_free_radius) {
      start_free_ = *params_.start_free_radius;
    } else {
      const std::optional<double> blind =
          intervox::blind_radius(rig, look_yaws_, params_.floor_clearance, params_.obstacle_height);
      if (!blind)
        ParamCheck("intervox::MobilePlanner")
            .fail("the rig does not see the band [floor_clearance, obstacle_height] "
                  "in every direction around the base during the look-around; set start_free_radius");
      start_free_ = *blind;
    }
    if (!params_.start_free_columns) blind_ = BlindZone(rig, look_yaws_, start_free_);
    rays_ = rig_bundle(rig, params_.gain_stride);
    if (params_.conflicts.observe.max_range == ObservationParams{}.max_range)
      params_.conflicts.observe.max_range = params_.gain.max_range;
    for (const auto& s : rig.sensors()) sensor_centre_ += s.mount.translation();
    sensor_centre_ /= double(rig.size());
  }

  /// The next view for the robot at \p pose on the plain grid \p grid (the thesis' planner and
  /// conflict-aware planning on the grid alone; see the class comment). Records \p pose as a
  /// position the robot stood on.
  /// \tparam Grid a VoxelGrid (any update, utility and storage; an interval policy for
  ///         conflict-aware planning)
  /// \throws InvalidArgument for a non-finite pose, a pose outside a given region, conflict-aware
  ///         planning on a grid without an interval policy, or explained planning
  ///         (params().explained.enabled), which reads the evidence of an ExplainedMap: plan(map, pose).
  template <OccupancyGrid Grid>
  MobilePlan plan(const Grid& grid, const Pose& pose) {
    if (params_.explained.enabled)
      ParamCheck("intervox::MobilePlanner::plan")
          .fail("planning on explained free space reads the evidence of an "
                "ExplainedMap (planner.make_map(grid)), not a plain grid");
    return plan_on(grid, pose, Evidence{}, {});
  }

  /// The next view for the robot at \p pose on \p map: its grid and, as the parameters ask, its
  /// explained channel (explained planning), its no-return evidence (conflict-aware planning with
  /// no_return_unknown) and the wall gaps of its last update_analysis() (close_wall_gaps). The
  /// planner only reads the map: update it (ExplainedMap::insert(), update_analysis()) before
  /// planning; the episode runner does. make_map() gives a map with what this planner reads.
  /// \tparam Grid a VoxelGrid
  /// \throws InvalidArgument as plan(grid, pose), or if the map lacks what the parameters read (a
  ///         channel for explained planning, wall gaps for close_wall_gaps).
  template <class Grid>
  MobilePlan plan(const ExplainedMap<Grid>& map, const Pose& pose) {
    return plan_on(map.grid(), pose, evidence_of(map),
                   params_.explained.close_wall_gaps ? map.wall_gaps() : std::vector<WallGap>{});
  }

  /// What an ExplainedMap for this planner keeps and analyses: the explained channel with the
  /// classing options and known surfaces of params().explained if explained planning is on, the
  /// no-return evidence for conflict-aware planning with no_return_unknown, the mirror analysis
  /// with params().explained.find_mirrors, the wall gaps with close_wall_gaps.
  ExplainedMapOptions map_options() const {
    ExplainedMapOptions o = explained_map_options(params_.explained);
    o.no_return_evidence = params_.conflicts.enabled && params_.conflicts.no_return_unknown;
    o.find_mirrors = params_.explained.enabled && params_.explained.find_mirrors;
    o.lying = params_.explained.lying;
    o.find_wall_gaps = params_.explained.enabled && params_.explained.close_wall_gaps;
    o.wall_gaps = params_.explained.wall_gaps;
    return o;
  }
  // insert_options() and make_map(grid) come from detail::PlannerMapMaking (plan/planner_maps.hpp).

  /// The region plan() projects for the robot at \p pose: params().region if set, else derived
  /// from the map (see MobilePlannerParams::region). The robot's position is always inside in x, y.
  /// \tparam Grid a VoxelGrid
  template <OccupancyGrid Grid>
  Bounds region_for(const Grid& grid, const Pose& pose) const {
    return region_for(grid, pose, nullptr);
  }
  /// region_for() on \p map: with explained planning, an unbounded grid's region follows the
  /// channel's trusted extent (phantom voxels do not widen it).
  template <class Grid>
  Bounds region_for(const ExplainedMap<Grid>& map, const Pose& pose) const {
    return region_for(map.grid(), pose, params_.explained.enabled ? map.explained() : nullptr);
  }

  /// region_for() of \p grid, following \p explained's trusted extent if given.
  template <OccupancyGrid Grid>
  Bounds region_for(const Grid& grid, const Pose& pose, const ExplainedSpace* explained) const {
    if (params_.region) return *params_.region;
    const GridGeometry& g = grid.geometry();
    const Point3 p = pose.translation();
    Bounds b;
    b.min = Point3(p.x() - start_free_, p.y() - start_free_, 0.0);
    b.max = Point3(p.x() + start_free_, p.y() + start_free_, 0.0);
    if (const auto& box = grid.key_box()) {
      const Point3 lo = g.corner(box->min), hi = g.corner(Key{box->max.x + 1, box->max.y + 1, box->max.z + 1});
      b.min = b.min.cwiseMin(lo);
      b.max = b.max.cwiseMax(hi);
    } else if (explained && explained->trusted_extent()) {
      // Explained planning: what trusted beams walked, not what phantoms added to the grid.
      const KeyBox& t = *explained->trusted_extent();
      b.min = b.min.cwiseMin(g.center(t.min) - Point3::Constant(params_.region_margin));
      b.max = b.max.cwiseMax(g.center(t.max) + Point3::Constant(params_.region_margin));
    } else {
      grid.for_each_observed([&](const Key& k, const auto&) {
        const Point3 c = g.center(k);
        b.min = b.min.cwiseMin(c - Point3::Constant(params_.region_margin));
        b.max = b.max.cwiseMax(c + Point3::Constant(params_.region_margin));
      });
    }
    b.min.z() = p.z() + params_.floor_clearance;
    b.max.z() = p.z() + params_.obstacle_height;
    return b;
  }

  /// The exploration map of \p grid inside \p region for the robot at \p pose, with the footprint
  /// rule applied to every position plan() was given, and \p hazards (conflict-aware planning;
  /// the footprint does not clear hazard columns), and with explained planning the unexplained
  /// columns as hazards too (ExplainedPlanningParams::unexplained_hazards) and the wall gaps the
  /// last plan() closed (ExplainedPlanningParams::close_wall_gaps) occupied.
  /// \tparam Grid a VoxelGrid
  /// \throws InvalidArgument if the robot lies outside the region.
  template <OccupancyGrid Grid>
  ExplorationMap exploration_map(const Grid& grid, const Pose& pose, const Bounds& region,
                                 const MapHazards& given = {}) const {
    return build_map(grid, pose, region, given, nullptr, nullptr, Evidence{});
  }
  /// exploration_map() of \p map's grid with the map's evidence as plan(map, pose) reads it (the
  /// wall gaps of its last update_analysis() closed with close_wall_gaps).
  template <class Grid>
  ExplorationMap exploration_map(const ExplainedMap<Grid>& map, const Pose& pose, const Bounds& region,
                                 const MapHazards& given = {}) const {
    return build_map(map.grid(), pose, region, given, nullptr, nullptr, evidence_of(map));
  }
  /// The exploration map for the robot at \p pose on \p map in the region plan() would use.
  template <class Grid>
  ExplorationMap exploration_map(const ExplainedMap<Grid>& map, const Pose& pose) const {
    return exploration_map(map, pose, region_for(map, pose));
  }
  /// The exploration map for the robot at \p pose in the region plan() would use.
  template <OccupancyGrid Grid>
  ExplorationMap exploration_map(const Grid& grid, const Pose& pose) const {
    return exploration_map(grid, pose, region_for(grid, pose));
  }

  /// The map cell of the robot at \p pose in a map projected from \p region.
  static Cell2 robot_cell(const GridGeometry& g, const Pose& pose, const Bounds& region) {
    const Key k = g.key(Point3(pose.translation().x(), pose.translation().y(), region.min.z()));
    const KeyBox box = g.key_box(region);
    return {k.x - box.min.x, k.y - box.min.y};
  }

  /// The gain options plan() uses for \p region (bounds filled in if unset).
  GainOptions gain_options(const Bounds& region) const {
    GainOptions o = params_.gain;
    if (!o.bounds) {
      Bounds b = region;
      b.min.z() = region.min.z() - params_.floor_clearance - 1e-6;
      b.max.z() = region.max.z() + params_.gain_height;
      o.bounds = b;
    }
    return o;
  }

  /// The gain rays' reach: the range up to which the planner expects the sensors to observe,
  /// and so the insertion's max range for beams without a return.
  double max_range() const noexcept { return params_.gain.max_range; }
  const MobilePlannerParams& params() const noexcept { return params_; }
  /// The yaws of the look-around (rad, relative to the start heading; look_around_yaws() of the
  /// rig, or params().look_around_span evenly).
  const std::vector<double>& look_around_yaws() const noexcept { return look_yaws_; }
  /// The start-free radius in use: params().start_free_radius, or the rig's blind zone.
  double start_free_radius() const noexcept { return start_free_; }
  const RayBundle& rays() const noexcept { return rays_; }
  /// Views planned so far, the look-around included.
  int steps() const noexcept { return steps_; }
  /// Positions plan() was given, in order.
  const std::vector<Point3>& visited() const noexcept { return visited_; }
  /// Sensor origins of the scans planned so far (conflict-aware planning counts the directions a
  /// region was seen from with them): the rig's mean mount position at each scan pose.
  const std::vector<Point3>& scan_origins() const noexcept { return origins_; }

 private:
  /// What a plan reads of a map besides its grid (null and empty for a plain grid).
  struct Evidence {
    const ExplainedSpace* explained = nullptr;     ///< explained planning: the map's channel
    const NoReturnEvidence* no_returns = nullptr;  ///< conflict-aware planning with no_return_unknown
    std::vector<PlanePatch> closed_gaps;           ///< close_wall_gaps: the gaps closed for this plan
  };

  /// What plan(map, pose) reads of \p map. \throws InvalidArgument if the map lacks what the
  /// parameters read.
  template <class Grid>
  Evidence evidence_of(const ExplainedMap<Grid>& map) const {
    Evidence e;
    if (params_.explained.enabled) {
      if (!map.explained())
        ParamCheck("intervox::MobilePlanner")
            .fail("planning on explained free space needs a map with the explained "
                  "channel (ExplainedMapOptions::explained; planner.make_map(grid) makes one)");
      e.explained = map.explained();
      if (params_.explained.close_wall_gaps) {
        if (!map.options().find_wall_gaps)
          ParamCheck("intervox::MobilePlanner")
              .fail("close_wall_gaps needs a map that finds wall gaps "
                    "(ExplainedMapOptions::find_wall_gaps; planner.make_map(grid) makes one)");
        for (const WallGap& gp : map.wall_gaps())
          if (!gp.opening) e.closed_gaps.push_back(gp.surface);
      }
    }
    if (params_.conflicts.enabled && params_.conflicts.no_return_unknown) e.no_returns = map.no_returns();
    return e;
  }

  /// plan() on \p grid with \p ev read; \p gaps the wall gaps the plan reports.
  template <OccupancyGrid Grid>
  MobilePlan plan_on(const Grid& grid, const Pose& pose, const Evidence& ev, std::vector<WallGap> gaps) {
    const auto t0 = std::chrono::steady_clock::now();
    if (!pose.matrix().allFinite()) ParamCheck("intervox::MobilePlanner::plan").fail("pose is not finite");
    if constexpr (!IntervalPolicy<typename Grid::UpdateType>) {
      if (params_.conflicts.enabled)
        ParamCheck("intervox::MobilePlanner::plan")
            .fail("conflict-aware planning needs an interval grid "
                  "(a Bayes grid cannot tell conflicts from ignorance)");
    }
    MobilePlan r;
    r.wall_gaps = std::move(gaps);
    if (steps_ == 0) {
      look_around(grid, pose, r, ev.explained);
    } else if (steps_ > params_.max_steps) {
      r.termination = Termination::Budget;
    } else {
      paths_.take(pose, params_.footprint_radius);
      visited_.push_back(pose.translation());
      r.region = region_for(grid, pose, ev.explained);
      const GainOptions gain = gain_options(r.region);
      LyingRegions lying = conflict_regions(grid, gain, r, lying_context());
      ExplorationMap map = build_map(grid, pose, r.region, lying.hazards, &lying, &r, ev);
      const detail::MobileStepContext step = step_context();
      detail::FrontierSearch search = detail::frontier_strategy(grid, map, gain, pose, lying.columns, r, step);
      if (plans_lying_regions() && !r.selected) detail::lying_region_strategy(grid, map, gain, pose, r, step);
      if (params_.passage_views.enabled && !r.selected) detail::passage_strategy(grid, map, gain, search, r, step);
      if (r.selected) {
        go_to_view(grid, map, pose, r);
        paths_.hold(grid.geometry(), params_.driven_paths && !params_.face_along_path ? r.path : std::vector<Pose>{});
      } else {
        detail::end_exploration(map, search, r, params_);
      }
      r.map.emplace(std::move(map));
    }
    r.seconds = seconds_since(t0);
    return r;
  }

  static double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  /// What the strategies of this step read of the planner and the memories they update
  /// (plan/mobile_step.hpp).
  detail::MobileStepContext step_context() { return {params_, rays_, sensor_centre_, steps_, frontiers_, regions_}; }
  /// What the lying-region analysis reads of the planner (plan/lying_region_analysis.hpp).
  LyingRegionContext lying_context() const {
    StartArea start;
    if (!params_.start_free_columns) start.blind = &blind_;
    start.to_start = to_start_;
    if (!visited_.empty()) start.first = visited_.front();
    start.radius = start_free_;
    return {params_, origins_, regions_, start};
  }
  /// n scans turning on the spot by 45° / n between them, each frames_per_scan times.
  std::vector<Pose> turns(const Pose& at, int n, int frames = 1) const {
    std::vector<Pose> out;
    for (int i = 0; i < n; ++i) {
      const double yaw = std::numbers::pi / 4 * i / n;
      out.insert(out.end(), static_cast<std::size_t>(params_.frames_per_scan) * static_cast<std::size_t>(frames),
                 at * Pose(Eigen::AngleAxisd(yaw, Point3::UnitZ())));
    }
    return out;
  }
  void record_scans(const std::vector<Pose>& scans) {
    for (const Pose& p : scans) origins_.push_back(p * sensor_centre_);
  }
  /// The first call: the look-around at \p pose (reason Initial).
  template <OccupancyGrid Grid>
  void look_around(const Grid& grid, const Pose& pose, MobilePlan& r, const ExplainedSpace* explained) {
    visited_.push_back(pose.translation());
    to_start_ = planar_pose(pose.translation(), std::atan2(pose.linear()(1, 0), pose.linear()(0, 0))).inverse();
    if (!params_.start_free_columns && params_.exact_blind_zone) blind_.trace(grid.geometry(), pose);
    r.reason = ViewReason::Initial;
    r.view = pose;
    for (const double yaw : look_yaws_)
      r.scans.insert(r.scans.end(), static_cast<std::size_t>(params_.frames_per_scan),
                     pose * Pose(Eigen::AngleAxisd(yaw, Point3::UnitZ())));
    record_scans(r.scans);
    r.region = region_for(grid, pose, explained);
    ++steps_;
  }

  /// exploration_map() with the unexplained groups (explained planning with unexplained_hazards)
  /// also appended to \p lying's columns and \p plan's regions when given.
  template <OccupancyGrid Grid>
  ExplorationMap build_map(const Grid& grid, const Pose& pose, const Bounds& region, MapHazards hazards,
                           LyingRegions* lying, MobilePlan* plan, const Evidence& ev) const {
    // The start rule on voxels (start_free_columns off) and hits as obstacles (hits_block) wrap
    // whichever view is in use.
    const bool blind_start = !params_.start_free_columns && !visited_.empty();
    const auto project = [&](const auto& view) {
      using View = std::decay_t<decltype(view)>;
      if (!blind_start && !params_.hits_block) return project_columns(view, region);
      return project_columns(PlanningRulesView<View, Grid>{view, grid, blind_start ? &blind_ : nullptr, to_start_,
                                                           prior_probability(grid), params_.hits_block},
                             region);
    };
    ColumnMap cols = ev.explained    ? project(ExplainedOccupancyView<Grid>{grid, *ev.explained})
                     : ev.no_returns ? project(ConfirmedView<Grid>{grid, *ev.no_returns})
                                     : project(grid);
    close_gaps(grid.geometry(), cols, region, ev.closed_gaps);
    if (ev.explained && params_.explained.unexplained_hazards)
      unexplained_regions(grid, *ev.explained, cols, region, hazards, lying, plan, lying_context());
    std::vector<Cell2> footprint;
    for (std::size_t i = 0; i < visited_.size(); ++i) {
      const Point3& v = visited_[i];
      const double radius = i == 0 && params_.start_free_columns ? std::max(start_free_, params_.footprint_radius)
                                                                 : params_.footprint_radius;
      const int rc = static_cast<int>(std::floor(radius / cols.resolution()));
      const Cell2 c = cols.cell_of_key(grid.geometry().key(Point3(v.x(), v.y(), region.min.z())));
      for (const Cell2& d : disk_offsets(rc)) footprint.push_back({c.x + d.x, c.y + d.y});
    }
    std::vector<Cell2> driven;  // the columns of the paths driven (driven_paths)
    driven.reserve(paths_.driven().size());
    for (const Key& k : paths_.driven()) driven.push_back(cols.cell_of_key(k));
    ExplorationMapParams mp = params_.map;
    if (params_.passage_views.enabled) {
      mp.passages = true;
      mp.passage_min_hidden_area = params_.passage_views.min_hidden_area;
    }
    if (params_.conflicts.enabled && params_.conflicts.cell_clearance)
      mp.clearance = std::max(mp.clearance, std::numbers::sqrt2 / 2 * grid.geometry().resolution());
    return ExplorationMap(std::move(cols), robot_cell(grid.geometry(), pose, region), mp, footprint, hazards, driven);
  }

  /// close_wall_gaps: the columns of \p cols that the footprint of a closed gap (\p closed:
  /// its patch's line along the floor, end to end, and the same line half a voxel towards the
  /// side it was seen from, where a mirror hangs before the wall) passes are occupied.
  static void close_gaps(const GridGeometry& g, ColumnMap& cols, const Bounds& region,
                         std::span<const PlanePatch> closed) {
    const double step = 0.5 * g.resolution();
    for (const PlanePatch& p : closed) {
      const Point3 along(p.axis_u.x(), p.axis_u.y(), 0.0), front(p.normal.x(), p.normal.y(), 0.0);
      const int steps = static_cast<int>(std::ceil(2.0 * p.half_u / step));
      for (const double off : {0.0, step})
        for (int i = 0; i <= steps; ++i) {
          const Point3 q = Point3(p.center.x(), p.center.y(), region.min.z()) + front * off +
                           along * (-p.half_u + 2.0 * p.half_u * i / std::max(steps, 1));
          const std::optional<Key> k = g.try_key(q);
          if (!k) continue;
          const Cell2 c = cols.cell_of_key(*k);
          if (cols.contains(c)) cols.set(c, Occupancy::Occupied);
        }
    }
  }

  /// True if plan() looks for lying regions and views them from new directions: conflict-aware
  /// planning, or explained planning with unexplained_hazards.
  bool plans_lying_regions() const noexcept {
    return params_.conflicts.enabled || (params_.explained.enabled && params_.explained.unexplained_hazards);
  }

  /// The plan's view is chosen (r.selected): the body pose there, the drivable path to it and the
  /// scans; records the scans and counts the step.
  template <OccupancyGrid Grid>
  void go_to_view(const Grid& grid, const ExplorationMap& map, const Pose& pose, MobilePlan& r) {
    const PlanarCandidate& c = r.candidates[*r.selected];
    if (r.reason != ViewReason::Conflict && r.reason != ViewReason::Passage) r.reason = ViewReason::Frontier;
    r.view = detail::candidate_pose(c, pose.translation().z());
    r.path = drive_path(map, grid.geometry(), pose, r.view, c.cell, params_.face_along_path);
    for (std::size_t k = 1; k < r.path.size(); ++k)
      r.path_length += (r.path[k].translation() - r.path[k - 1].translation()).norm();
    r.scans = turns(r.view, params_.scans_per_view, r.reason == ViewReason::Passage ? params_.passage_views.frames : 1);
    record_scans(r.scans);
    ++steps_;
  }

  MobilePlannerParams params_;
  std::vector<double> look_yaws_;
  double start_free_ = 0;
  BlindZone blind_;                   ///< what the look-around cannot see (blind start rule)
  Pose to_start_ = Pose::Identity();  ///< world to the start's body frame
  RayBundle rays_;
  int steps_ = 0;
  std::vector<Point3> visited_;
  DrivenPaths paths_;         ///< driven_paths: the way back
  FrontierMemory frontiers_;  ///< the frontiers given up and their visit counts
  Point3 sensor_centre_ = Point3::Zero();
  std::vector<Point3> origins_;
  RegionMemory regions_{params_.frontier_radius};  ///< regions are recognised within frontier_radius
};

}  // namespace intervox
