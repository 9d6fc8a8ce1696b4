#pragma once
// One run of the sweep: an episode of the mobile base in the lab room or of the arm in the
// workcell, under the run's conditions, measured against the scene's ground truth; and the
// compile-time configurations offered. run_one() (run_one.cpp) instantiates them.
#include "run_one.hpp"
#include "summary.hpp"

#include "common/policies.hpp"
#include "common/rigs.hpp"
#include "floor_cut_source.hpp"

#include <intervox/analysis/conflicts.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/eval/conflict_scoring.hpp>
#include <intervox/eval/ground_truth.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/io/png.hpp>
#include <intervox/plan/arm_planner.hpp>
#include <intervox/plan/episode.hpp>
#include <intervox/plan/mobile_planner.hpp>
#include <intervox/sim/sim.hpp>
#include <intervox/update/bayes_log_odds.hpp>
#include <intervox/update/interval_update.hpp>
#include <intervox/view/exploration_image.hpp>
#include <intervox/view/slice.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <functional>
#include <optional>
#include <span>
#include <tuple>
#include <type_traits>
#include <string>
#include <utility>
#include <vector>

namespace experiments {

namespace detail {

template <class Grid>
long long count_conflicts(const Grid& grid) {
  const auto& u = grid.update_policy();
  if (u.interval(u.unobserved()).width() < kConflictWidth) return -1;  // no ignorance to tell apart
  long long n = 0;
  grid.for_each_observed([&](const iv::Key&, const typename Grid::Cell& c) {
    n += u.occupancy(c) == iv::Occupancy::Unknown && u.interval(c).width() < kConflictWidth;
  });
  return n;
}

/// The update policy of a run: the thesis' preset (`U::thesis()`, latching) for "thesis" where the
/// policy has one, the library's defaults otherwise; with \p unobserved "by-rule" (interval
/// policies) never-observed voxels are classified by the state rule (IntervalParams::classify_unobserved).
template <class U>
U make_policy(const std::string& preset, const std::string& unobserved) {
  U u{};
  if constexpr (requires { U::thesis(); }) {
    if (preset == "thesis") u = U::thesis();
  }
  if constexpr (requires { u.params().classify_unobserved; }) {
    if (unobserved == "by-rule") {
      auto p = u.params();
      p.classify_unobserved = true;
      return U(p);
    }
  }
  return u;
}

/// Voxels in the box of keys that \p region covers.
inline std::size_t voxels_in(const iv::GridGeometry& g, const iv::Bounds& region) {
  const iv::KeyBox b = g.key_box(region);
  return std::size_t(b.max.x - b.min.x + 1) * std::size_t(b.max.y - b.min.y + 1) * std::size_t(b.max.z - b.min.z + 1);
}

/// A figure's title (the run's configuration and \p what it shows), legend and scale bar.
inline iv::ImageLabels figure_labels(const RunConfig& c, const std::string& what) {
  std::string t = c.platform == "mobile" ? c.surface + " closet" : c.surface;
  t += ", " + c.update + " + " + c.utility;
  if (c.planner != "plain") t += ", " + c.planner;
  if (c.policies != "thesis") t += ", " + c.policies;
  if (c.unobserved != "unknown") t += ", unobserved " + c.unobserved;
  if (c.room != "lab") t += ", room " + c.room;
  if (c.rules != "thesis") t += ", " + c.rules + " rules";
  if (c.sensor != "plain") t += ", " + c.sensor;
  return {t + ", seed " + std::to_string(c.seed) + ": " + what, true, true, 0};
}

/// The voxel-space pictures of a finished run, as the thesis' Fig. 5.8 / 5.9: a horizontal slice
/// at knee height coloured by state (gray), interval width (blue narrow .. red broad) and the
/// combined code of Table 5.2.
template <class Grid>
void write_voxel_figures(const Grid& grid, const iv::Bounds& region, double z, const std::string& stem,
                         const RunConfig& c) {
  const iv::KeyBox box = grid.geometry().key_box(region);
  iv::SliceOptions o;
  o.window = box;
  o.z = grid.geometry().key(iv::Point3(region.min.x(), region.min.y(), z)).z;
  o.pixels_per_voxel = std::max(1, static_cast<int>(std::lround(0.02 / grid.resolution() * 4)));
  const std::string at = "slice at " + std::to_string(static_cast<int>(std::lround(z * 100))) + " cm";
  for (auto [color, name, what] : {std::tuple{iv::ColorBy::State, "_state.png", "state"},
                                   std::tuple{iv::ColorBy::IntervalWidth, "_width.png", "interval width"},
                                   std::tuple{iv::ColorBy::Table52, "_table52.png", "table 5.2 code"}}) {
    o.color = color;
    o.labels = figure_labels(c, std::string(what) + ", " + at);
    iv::write_png(stem + name, iv::render_slice(grid, o));
  }
}

/// The lab room's conflict band: the closet's extent along y, from 1 m behind the closet's back
/// (through the west wall, where a mirror's phantom surfaces appear) to 0.5 m in front of it (+x),
/// from above the floor layer (one voxel of \p resolution) to the closet's top.
inline iv::Bounds conflict_band(const iv::Bounds& closet, double resolution) {
  return {{closet.min.x() - 1.0, closet.min.y(), resolution * 1.000001},
          {closet.max.x() + 0.5, closet.max.y(), closet.max.z()}};
}

/// The gain rule of a run ("unknown": the thesis' voxels of unknown state; "all").
inline iv::GainVoxels gain_voxels(const std::string& gain) {
  return gain == "unknown" ? iv::GainVoxels::Unknown : iv::GainVoxels::All;
}

/// The mobile planner's parameters of a run: the lab room's floor as the region (and the annex's
/// with \p annex_interior), one thread, the sweep's step budget and gain stride, the run's gain
/// rule, start and map rules and planner.
inline iv::MobilePlannerParams mobile_params(const RunConfig& c, const SweepOptions& o,
                                             const std::optional<iv::Bounds>& annex_interior = std::nullopt) {
  iv::MobilePlannerParams p;
  p.region = iv::Bounds{{0.0, 0.0, 0.2}, {8.0, 6.0, 0.8}};  // the lab room's floor
  if (annex_interior)                                       // and the annex's, behind the doorway
    p.region = iv::Bounds{{0.0, 0.0, 0.2}, {annex_interior->max.x(), annex_interior->max.y(), 0.8}};
  if (c.rules == "thesis") {
    p.start_free_radius =
        1.0;  // the thesis' start rule, which both earlier editions ran with: whole columns within 1 m
    p.start_free_columns = true;
    p.hits_block = false;  // the thesis' map: unclassified voxels are unknown, whatever their hits
  }                        // "library": the rig's start rule and hits_block, the library's defaults
  p.seed = c.seed;
  p.threads = 1;
  p.max_steps = o.max_steps;
  p.gain_stride = o.gain_stride;
  p.gain.voxels = gain_voxels(c.gain);
  p.conflicts.enabled = c.planner == "conflict-aware";
  if (c.planner == "safe") {  // docs/planning.md, "Planning on explained free space"
    p.explained.enabled = true;
    p.explained.unexplained_hazards = true;
    p.explained.open_group_hazards = true;
    p.explained.close_wall_gaps = true;
  }
  if (c.sensor == "one-camera") {  // docs/planning.md, "Any rig": the exact start rule, the misses a policy needs
    p.exact_blind_zone = true;
    p.frames_per_scan = c.update == "bayes" ? 3 : 5;
  }
  return p;
}

/// The run's rig: the thesis' eight cameras, or with the "one-camera" condition one forward camera.
inline iv::SensorRig mobile_rig(const RunConfig& c) {
  return c.sensor == "one-camera" ? examples::front_camera_rig() : iv::SensorRig::mobile_base();
}

/// The share of \p keys that \p grid classifies free and, with a channel, that \p explained also
/// explains free (RunResult::closet_free_curve); 0 for no keys.
template <class Grid>
double free_share(const Grid& grid, const iv::ExplainedSpace* explained, const std::vector<iv::Key>& keys) {
  std::size_t free = 0;
  for (const iv::Key& k : keys)
    free += grid.occupancy(k) == iv::Occupancy::Free && (!explained || explained->explained_free(k));
  return keys.empty() ? 0.0 : static_cast<double>(free) / static_cast<double>(keys.size());
}

/// Of the voxels of \p box that \p grid classifies free, the share \p explained also explains free
/// (RunResult::explained_free_share); -1 if none is free.
template <class Grid>
double explained_free_share(const Grid& grid, const iv::ExplainedSpace& explained, const iv::Bounds& box) {
  const iv::KeyBox b = grid.geometry().key_box(box);
  std::size_t free = 0, both = 0;
  for (std::int32_t x = b.min.x; x <= b.max.x; ++x)
    for (std::int32_t y = b.min.y; y <= b.max.y; ++y)
      for (std::int32_t z = b.min.z; z <= b.max.z; ++z) {
        const iv::Key k{x, y, z};
        if (grid.occupancy(k) != iv::Occupancy::Free) continue;
        ++free;
        both += explained.explained_free(k);
      }
  return free == 0 ? -1.0 : static_cast<double>(both) / static_cast<double>(free);
}

/// True if \p gap's floor segment (its patch's centre ± half_u along axis_u, projected on the
/// floor) comes within \p slack of \p doorway's footprint: the gap is the doorway's.
inline bool gap_at(const iv::WallGap& gap, const iv::Bounds& doorway, double slack = 0.25) {
  const iv::PlanePatch& s = gap.surface;
  constexpr int kSamples = 32;
  for (int i = 0; i <= kSamples; ++i) {
    const iv::Point3 p = s.center + (2.0 * i / kSamples - 1.0) * s.half_u * s.axis_u;
    if (p.x() >= doorway.min.x() - slack && p.x() <= doorway.max.x() + slack && p.y() >= doorway.min.y() - slack &&
        p.y() <= doorway.max.y() + slack)
      return true;
  }
  return false;
}

template <class Grid>
RunResult run_mobile(const RunConfig& c, const SweepOptions& o, const std::string& figure_stem) {
  iv::sim::LabRoomOptions room;
  room.closet_material = iv::sim::material_from_string(c.surface);
  room.annex = c.room == "annex";
  room.closet_front_only = c.room == "front-only";
  const iv::sim::LabRoom lab = iv::sim::make_lab_room(room);
  const iv::MobilePlannerParams p = mobile_params(c, o, lab.annex_interior);
  constexpr bool interval = iv::IntervalPolicy<typename Grid::UpdateType>;
  if (p.conflicts.enabled && !interval)
    throw iv::InvalidArgument("experiments: the conflict-aware planner needs an interval update, not " + c.update);
  const iv::SensorRig rig = mobile_rig(c);
  const iv::Pose start = iv::planar_pose(lab.start, 0.0);
  iv::MobilePlanner planner(rig, p);
  auto map = planner.make_map(Grid(o.resolution, make_policy<typename Grid::UpdateType>(c.policies, c.unobserved)));
  const Grid& grid = map.grid();
  // The simulator's label of every beam: the ground truth of conflict voxels (eval/conflict_scoring.hpp).
  iv::ConflictEvidence evidence(grid.geometry(), lab.scene, lab.scene.bounds(), planner.max_range());
  iv::sim::SimOptions sensing;
  sensing.glint = c.sensor == "glint";
  if (c.sensor == "body") sensing.body = iv::sim::RobotBody::mobile_base();  // the robot, seen in a mirror
  // With an explained channel, the batches the map's channel classes, with their true paths, for
  // the beam classes' scores (the newest few more than its ledger keeps).
  std::deque<LabelledBatch> batches;
  const bool explained = p.explained.enabled;
  iv::Episode ex(map, planner,
                 FloorCutSource{iv::sim::SimulatedRig(lab.scene, rig, c.seed, sensing), c.floor == "removed",
                                o.floor_cut, &evidence, [&](std::span<const iv::Beam> cut) { map.add_evidence(cut); },
                                explained ? &batches : nullptr},
                 start);
  // The evaluated region: the room above the floor layer (its voxels take the noisy floor
  // returns); the closet band: the closet (its box, also with the material on its front only)
  // and 0.5 m in front of it (towards +x) within it; the closet's own voxels there, which the
  // scene occupies: any the planner may treat as free is space a lying beam made look free.
  iv::Bounds region = *planner.gain_options(*p.region).bounds;
  region.min.z() = std::max(region.min.z(), o.resolution * 1.000001);
  const iv::Bounds closet = lab.scene.object_bounds(lab.closet_body);
  const iv::Bounds band{{closet.min.x(), closet.min.y(), region.min.z()},
                        {closet.max.x() + 0.5, closet.max.y(), std::min(closet.max.z(), region.max.z())}};
  const std::vector<iv::Key> closet_voxels =
      lab.scene.ground_truth(grid.geometry(), iv::Bounds{band.min, {closet.max.x(), band.max.y(), band.max.z()}});
  RunResult r;
  const auto t0 = std::chrono::steady_clock::now();
  double drawing = 0;  // the pictures and the closet's share are kept out of the timing
  const auto record_closet = [&] {
    const auto d0 = std::chrono::steady_clock::now();
    r.closet_free_curve.push_back(free_share(grid, map.explained(), closet_voxels));
    if (explained && map.explained())
      while (batches.size() > map.explained()->ledger().scans().size() + 16) batches.pop_front();
    drawing += std::chrono::duration<double>(std::chrono::steady_clock::now() - d0).count();
  };
  ex.step();  // step 0: the look-around
  record_closet();
  if (!figure_stem.empty()) {
    const auto d0 = std::chrono::steady_clock::now();
    // The map after the look-around, as the thesis' Fig. 5.3.
    iv::write_png(figure_stem + "_lookaround_map.png",
                  iv::render_exploration_map(planner.exploration_map(map, ex.pose(), *p.region), {}, 4,
                                             figure_labels(c, "map after the look-around")));
    drawing += std::chrono::duration<double>(std::chrono::steady_clock::now() - d0).count();
  }
  // The doorway's gap in the wall gaps of every plan (room annex, planners that close gaps).
  const bool door = lab.annex_doorway && p.explained.enabled && p.explained.close_wall_gaps;
  if (door) r.door_plans = r.door_opening_plans = 0;
  while (ex.termination() == iv::Termination::Running) {
    const auto& s = ex.step();
    if (door) {
      const auto at_door = [&](const iv::WallGap& g) { return gap_at(g, *lab.annex_doorway); };
      if (std::ranges::any_of(s.plan.wall_gaps, at_door)) {
        const bool opening =
            std::ranges::any_of(s.plan.wall_gaps, [&](const iv::WallGap& g) { return at_door(g) && g.opening; });
        ++r.door_plans;
        r.door_opening_plans += opening;
        r.door_last_opening = opening;
      }
    }
    if (!s.plan.scans.empty()) record_closet();
  }
  const iv::Termination t = ex.termination();
  r.config = c;
  r.seconds_total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() - drawing;
  r.steps = std::max(0, planner.steps() - 1);  // the look-around is step 0
  r.termination = std::string(iv::to_string(t));
  r.distance = ex.distance_driven();
  const iv::FloorCoverage floor = iv::floor_coverage(grid, lab.scene, *p.region, p.map, start.translation());
  r.known = floor.known;
  r.area = floor.area;
  r.completed =
      (t == iv::Termination::NoReachableFrontier || t == iv::Termination::Explored) && r.known >= kCompleteFraction;
  if (lab.annex_interior) {  // the annex's reachable floor, from the doorway on
    const iv::Bounds annex{{lab.annex_doorway->min.x(), lab.annex_interior->min.y(), 0.0}, lab.annex_interior->max};
    r.annex_known = iv::floor_coverage(grid, lab.scene, *p.region, p.map, start.translation(), annex).known;
  }
  if (explained && map.explained()) {
    const BeamClassScore score = score_beam_classes(map.explained()->ledger().scans(), batches);
    r.direct_suspect = score.direct_share();
    r.reflected_suspect = score.reflected_share();
    r.suspect_precision = score.precision();
    r.suspect_recall = score.recall();
    r.explained_free_share = explained_free_share(grid, *map.explained(), region);
    if (lab.annex_interior)
      r.annex_explained_free_share =
          explained_free_share(grid, *map.explained(),
                               iv::Bounds{{lab.annex_doorway->min.x(), lab.annex_interior->min.y(), region.min.z()},
                                          {lab.annex_interior->max.x(), lab.annex_interior->max.y(), region.max.z()}});
  }
  // Errors above the floor layer, split into the closet band and the rest.
  const iv::VoxelErrors e = iv::evaluate_voxels(grid, lab.scene, region);
  const iv::VoxelErrors b = iv::evaluate_voxels(grid, lab.scene, band);
  r.wrongly_occupied = e.wrongly_occupied;
  r.wrongly_free = e.wrongly_free;
  r.true_occupied = e.true_occupied;
  r.region_voxels = voxels_in(grid.geometry(), region);
  r.band_wrongly_occupied = b.wrongly_occupied;
  r.band_wrongly_free = b.wrongly_free;
  r.band_voxels = voxels_in(grid.geometry(), band);
  // Collisions of the robot's footprint (a disk of the map's robot radius, from the floor
  // clearance to the robot's height) with the true scene, at every pose and along every segment.
  const iv::PathCollisions col = iv::count_path_collisions(lab.scene, grid.geometry(), ex.trajectory(),
                                                           p.map.robot_radius, p.region->min.z(), p.region->max.z());
  r.collision_poses = col.poses;
  r.collision_segments = col.segments;
  for (const iv::ObjectCollisions& met : iv::collisions_by_object(
           lab.scene, grid.geometry(), ex.trajectory(), p.map.robot_radius, p.region->min.z(), p.region->max.z()))
    r.collision_objects.push_back({met.name, met.poses, met.segments});
  r.conflicts = count_conflicts(grid);
  if constexpr (interval) {
    const iv::ConflictReport report = iv::detect_conflicts(grid);
    const iv::ConflictScore score = iv::score_conflicts(grid, report, evidence);
    r.conflict_precision = score.precision();
    r.conflict_recall = score.recall();
    r.conflict_truth = static_cast<long long>(score.truth);
    // Where the signature, the detector and the ground truth put their voxels: inside the
    // conflict band (behind and in front of the closet) or elsewhere.
    const iv::KeyBox cband = grid.geometry().key_box(conflict_band(closet, o.resolution));
    const auto& u = grid.update_policy();
    r.signature_voxels = r.signature_band = 0;
    grid.for_each_observed([&](const iv::Key& k, const typename Grid::Cell& cell) {
      if (!iv::conflict_signature(u, cell)) return;
      ++r.signature_voxels;
      r.signature_band += cband.contains(k);
    });
    r.flagged_voxels = report.conflict_voxels();
    r.flagged_band = 0;
    for (const auto& region : report.regions)
      for (const iv::Key& k : region.voxels) r.flagged_band += cband.contains(k);
    r.truth_band = 0;
    for (const iv::Key& k : evidence.conflict_voxels()) r.truth_band += cband.contains(k);
  }
  r.seconds_per_step = planner.steps() > 0 ? r.seconds_total / planner.steps() : 0.0;
  if (!figure_stem.empty()) {
    iv::write_png(figure_stem + "_map.png",
                  iv::render_exploration_map(planner.exploration_map(map, ex.pose(), *p.region), {}, 4,
                                             figure_labels(c, "final map")));
    write_voxel_figures(grid, *p.region, 0.5, figure_stem, c);
  }
  return r;
}

/// An arm run: the object keeps its workcell material (the part polished metal, the bottle glass;
/// or the first edition's materials, see SweepOptions::arm_first_edition_materials).
template <class Grid>
RunResult run_arm(const RunConfig& c, const SweepOptions& o, const std::string& figure_stem) {
  iv::sim::WorkcellOptions wo;
  if (o.arm_first_edition_materials) {
    wo.part_material = iv::sim::Material::specular_random_range();
    wo.bottle_material = iv::sim::Material::transparent_without_fresnel();
  }
  const iv::sim::Workcell cell = iv::sim::make_workcell(wo);
  Grid grid(o.arm_resolution, iv::Bounds{{0, 0, 0}, {1.5, 1.5, 1.5}},
            make_policy<typename Grid::UpdateType>(c.policies, c.unobserved));
  iv::ArmPlannerParams p;
  p.object_region = cell.object_region(c.surface, o.arm_resolution);
  p.support_height = cell.table_center.z();
  p.max_views = o.arm_max_views;
  p.threads = 1;
  p.seed = c.seed;
  p.gain.voxels = gain_voxels(c.gain);
  p.conflicts.enabled = c.planner == "conflict-aware";
  if (p.conflicts.enabled && !iv::IntervalPolicy<typename Grid::UpdateType>)
    throw iv::InvalidArgument("experiments: the conflict-aware planner needs an interval update, not " + c.update);
  iv::ArmPlanner m(iv::SensorRig::arm(), p);
  iv::Episode episode(grid, m, iv::sim::SimulatedRig(cell.scene, m.rig(), c.seed), iv::Pose::Identity());
  RunResult r;
  r.config = c;
  const auto t0 = std::chrono::steady_clock::now();
  double evaluating = 0;  // coverage after every view is measured, not planned: kept out of the timing
  while (episode.termination() == iv::Termination::Running) {
    const auto& s = episode.step();
    if (s.plan.scans.empty()) continue;
    const auto e0 = std::chrono::steady_clock::now();
    const double k = iv::surface_coverage(grid, cell.scene, p.object_region, p.support_height).known;
    r.coverage_curve.push_back(k);
    if (k >= 0.8 && r.views_to_80 < 0) r.views_to_80 = m.views();
    evaluating += std::chrono::duration<double>(std::chrono::steady_clock::now() - e0).count();
  }
  const iv::Termination t = episode.termination();
  r.seconds_total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() - evaluating;
  r.steps = m.views();
  r.termination = std::string(iv::to_string(t));
  r.distance = episode.distance_driven();
  r.known = iv::surface_coverage(grid, cell.scene, p.object_region, p.support_height).known;
  r.completed = t != iv::Termination::Blocked && r.known >= kCompleteFraction;
  const iv::VoxelErrors e = iv::evaluate_voxels(grid, cell.scene, p.object_region);
  r.wrongly_occupied = e.wrongly_occupied;
  r.wrongly_free = e.wrongly_free;
  r.true_occupied = e.true_occupied;
  r.region_voxels = voxels_in(grid.geometry(), p.object_region);
  r.conflicts = count_conflicts(grid);
  r.seconds_per_step = m.views() > 0 ? r.seconds_total / m.views() : 0.0;
  if (!figure_stem.empty()) {
    // Top view of the object region (maximum along z, without the table-top layer).
    iv::SliceOptions so;
    so.mode = iv::SliceMode::MaxProjection;
    iv::Bounds around = p.object_region;
    around.min -= iv::Point3(0.05, 0.05, 0.0);
    around.max += iv::Point3(0.05, 0.05, 0.0);
    so.window = grid.geometry().key_box(around);
    so.window->min.z = std::min(so.window->min.z + 1, so.window->max.z);
    so.pixels_per_voxel = 4;
    for (auto [color, name, what] : {std::tuple{iv::ColorBy::State, "_state.png", "state"},
                                     std::tuple{iv::ColorBy::IntervalWidth, "_width.png", "interval width"},
                                     std::tuple{iv::ColorBy::Table52, "_table52.png", "table 5.2 code"}}) {
      so.color = color;
      so.labels = figure_labels(c, std::string(what) + ", top view");
      iv::write_png(figure_stem + name, iv::render_slice(grid, so));
    }
  }
  return r;
}

template <class U, class H>
using MobileGrid = iv::VoxelGrid<U, H, iv::SparseStorage>;
template <class U, class H>
using ArmGrid = iv::VoxelGrid<U, H, iv::DenseStorage>;

using Runner = RunResult (*)(const RunConfig&, const SweepOptions&, const std::string&);

/// The mobile runs: every update but the compact interval, with entropy and max-entropy.
struct MobileOffer {
  template <class U, class H>
  static constexpr bool offers() {
    return !std::is_same_v<U, iv::CompactIntervalUpdate<iv::MeanState>> && !std::is_same_v<H, iv::TotalUncertainty>;
  }
};

/// The arm runs: Bayes, the mean-state interval and the two credal cells, with entropy and max-entropy.
struct ArmOffer {
  template <class U, class H>
  static constexpr bool offers() {
    return (std::is_same_v<U, iv::BayesLogOdds> || std::is_same_v<U, iv::IntervalUpdate<iv::MeanState>> ||
            examples::kCredalUpdate<U>)&&!std::is_same_v<H, iv::TotalUncertainty>;
  }
};

}  // namespace detail

}  // namespace experiments
