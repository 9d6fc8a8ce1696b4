/// \file
/// The planners (decide-only API: MobilePlanner, ArmPlanner) with numpy poses, and the episode
/// runner with a Python callable as the sensor source, for every grid type.

#include "planners_bind.hpp"

#include <intervox/plan/arm_planner.hpp>
#include <intervox/plan/episode.hpp>
#include <intervox/plan/mobile_planner.hpp>

#include <memory>

namespace intervox::python {

using namespace bind;

void bind_planners(py::module_& m) {
  py::enum_<Termination>(m, "Termination", "Why an episode ended.")
      .value("RUNNING", Termination::Running)
      .value("EXPLORED", Termination::Explored)
      .value("NO_REACHABLE_FRONTIER", Termination::NoReachableFrontier)
      .value("BLOCKED", Termination::Blocked)
      .value("BUDGET", Termination::Budget);
  py::enum_<ViewReason>(m, "ViewReason", "Why a view was chosen.")
      .value("NONE", ViewReason::None)
      .value("INITIAL", ViewReason::Initial)
      .value("FRONTIER", ViewReason::Frontier)
      .value("GAIN", ViewReason::Gain)
      .value("CONFLICT", ViewReason::Conflict)
      .value("NORMALS", ViewReason::Normals)
      .value("PASSAGE", ViewReason::Passage);

  py::class_<ViewPlan>(m, "ViewPlan", "The decision of one planning call.")
      .def_readonly("termination", &ViewPlan::termination, "RUNNING if the plan holds a view")
      .def_readonly("reason", &ViewPlan::reason)
      .def_property_readonly(
          "path", [](const ViewPlan& p) { return from_poses(p.path); },
          "(N, 4, 4) body poses to drive through to the view")
      .def_property_readonly(
          "scans", [](const ViewPlan& p) { return from_poses(p.scans); }, "(N, 4, 4) body poses to sense at, in order")
      .def_readonly("path_length", &ViewPlan::path_length)
      .def_readonly("gain", &ViewPlan::gain)
      .def_readonly("relative_gain", &ViewPlan::relative_gain)
      .def_readonly("considered", &ViewPlan::considered)
      .def_readonly("seconds", &ViewPlan::seconds);
  const auto gains = [](const std::vector<ViewGain>& g) {
    py::array_t<double> a(static_cast<py::ssize_t>(g.size()));
    for (std::size_t i = 0; i < g.size(); ++i) a.mutable_at(static_cast<py::ssize_t>(i)) = g[i].gain;
    return a;
  };
  py::class_<MobilePlan, ViewPlan>(m, "MobilePlan", "One decision of the mobile planner.")
      .def_readonly("region", &MobilePlan::region)
      .def_property_readonly("frontier",
                             [](const MobilePlan& p) -> py::object {
                               if (!p.frontier) return py::none();
                               return py::make_tuple(p.frontier->x, p.frontier->y);
                             })
      .def_property_readonly(
          "candidates",
          [](const MobilePlan& p) {
            py::array_t<double> a({static_cast<py::ssize_t>(p.candidates.size()), py::ssize_t{3}});
            auto w = a.mutable_unchecked<2>();
            for (std::size_t i = 0; i < p.candidates.size(); ++i) {
              const auto k = static_cast<py::ssize_t>(i);
              w(k, 0) = p.candidates[i].position.x();
              w(k, 1) = p.candidates[i].position.y();
              w(k, 2) = p.candidates[i].yaw;
            }
            return a;
          },
          "(K, 3) sampled candidates (x, y, yaw)")
      .def_property_readonly(
          "gains", [gains](const MobilePlan& p) { return gains(p.gains); }, "(K,) their gains")
      .def_readonly("selected", &MobilePlan::selected, "index into candidates, or None")
      .def_property_readonly("view", [](const MobilePlan& p) { return from_pose(p.view); })
      .def_readonly("retired", &MobilePlan::retired, "frontiers and regions given up as unresolvable in this call")
      .def_property_readonly(
          "refused",
          [](const MobilePlan& p) {
            py::list out;
            for (const RefusedFrontier& f : p.refused) {
              py::dict ring;
              for (std::size_t i = 0; i < kMapLabelCount; ++i)
                if (f.ring_refused[i])
                  ring[py::str(std::string(to_string(static_cast<MapLabel>(i))))] = f.ring_refused[i];
              py::dict d;
              d["frontier"] = py::make_tuple(f.frontier.x, f.frontier.y);
              d["reason"] = std::string(to_string(f.reason));
              d["relative_gain"] = f.relative_gain;
              d["ring_refused"] = ring;
              out.append(d);
            }
            return out;
          },
          "The frontiers tried in this call that did not give the view, closest first: a list of dicts with\n"
          "'frontier' (map cell), 'reason' ('unresolvable', 'no new direction', 'no candidate', 'low gain',\n"
          "'visit budget', 'unexplained'), 'relative_gain' and 'ring_refused' (the ring's cells that could hold no "
          "candidate,\n"
          "counted by exploration-map label, e.g. {'collision space': 12, 'maybe collision': 30}).")
      .def_readonly("skipped", &MobilePlan::skipped,
                    "border cells skipped near a frontier tried in this call or given up before")
      .def_property_readonly(
          "regions",
          [](const MobilePlan& p) {
            py::list out;
            for (const PlannedRegion& r : p.regions) {
              py::dict d;
              d["centroid"] = py::make_tuple(r.region.centroid.x(), r.region.centroid.y(), r.region.centroid.z());
              d["voxels"] = r.region.voxels.size();
              d["views"] = r.region.views.size();
              d["directions"] = r.directions;
              d["unresolvable"] = r.unresolvable;
              d["unexplained"] = r.unexplained;
              out.append(d);
            }
            return out;
          },
          "The lying regions of this call (conflict regions with conflict-aware planning, then the enclosed\n"
          "unexplained groups with explained planning and unexplained_hazards): a list of dicts with 'centroid'\n"
          "(x, y, z), 'voxels', 'views' (scan origins that saw it), 'directions' (distinct ones), 'unresolvable'\n"
          "(given up: its frontiers are retired) and 'unexplained' (an unexplained group, not a conflict region).")
      .def_readonly("conflict_region", &MobilePlan::conflict_region,
                    "index into regions of the region the view aims at (reason CONFLICT), or None");
  py::class_<ArmPlan, ViewPlan>(m, "ArmPlan",
                                "One decision of the arm planner; scans are the flange poses of the sweep.")
      .def_readonly("sampled", &ArmPlan::sampled)
      .def_property_readonly(
          "candidates", [](const ArmPlan& p) { return from_poses(p.candidates); },
          "(K, 4, 4) striper poses at the middle of each accepted sweep")
      .def_property_readonly("gains", [gains](const ArmPlan& p) { return gains(p.gains); })
      .def_readonly("selected", &ArmPlan::selected)
      .def_property_readonly("view", [](const ArmPlan& p) { return from_pose(p.view); })
      .def_property_readonly(
          "refused",
          [](const ArmPlan& p) {
            py::dict d;
            for (std::size_t i = 0; i < kSweepRefusalCount; ++i)
              d[py::str(std::string(to_string(static_cast<SweepRefusal>(i))))] = p.refused[i];
            return d;
          },
          "sampled sweeps refused, by reason: {'table', 'occupied', 'unexplained', 'conflict margin'} -> count\n"
          "(sampled = len(candidates) + their sum; arm_planner.hpp's safety contract)")
      .def_readonly("glint", &ArmPlan::glint,
                    "seeking normals: each candidate's glint score (glint_score, parallel to candidates); else empty")
      .def_readonly("glint_targets", &ArmPlan::glint_targets,
                    "seeking normals: the undecided hit voxels with a normal the glint scores counted");

  py::class_<MobilePlannerParams> mp(m, "MobilePlannerParams",
                                     "Parameters of the mobile planner (see mobile_planner.hpp).");
  mp.def(py::init<>())
      .def_property(
          "region", [](const MobilePlannerParams& p) { return p.region; },
          [](MobilePlannerParams& p, const py::object& b) { p.region = optional_bounds(b); },
          "floor area explored (Bounds) or None (derived from the map)")
      .def_readwrite("floor_clearance", &MobilePlannerParams::floor_clearance)
      .def_readwrite("obstacle_height", &MobilePlannerParams::obstacle_height)
      .def_readwrite("region_margin", &MobilePlannerParams::region_margin)
      .def_property(
          "robot_radius", [](const MobilePlannerParams& p) { return p.map.robot_radius; },
          [](MobilePlannerParams& p, double v) { p.map.robot_radius = v; })
      .def_readwrite("footprint_radius", &MobilePlannerParams::footprint_radius)
      .def_readwrite("start_free_radius", &MobilePlannerParams::start_free_radius,
                     "m around the start counted free unless seen occupied, or None (the rig's blind zone)")
      .def_property(
          "ring_inner_radius", [](const MobilePlannerParams& p) { return p.ring.inner_radius; },
          [](MobilePlannerParams& p, double v) { p.ring.inner_radius = v; })
      .def_property(
          "ring_outer_radius", [](const MobilePlannerParams& p) { return p.ring.outer_radius; },
          [](MobilePlannerParams& p, double v) { p.ring.outer_radius = v; })
      .def_property(
          "ring_positions", [](const MobilePlannerParams& p) { return p.ring.positions; },
          [](MobilePlannerParams& p, int v) { p.ring.positions = v; })
      .def_property(
          "ring_orientations", [](const MobilePlannerParams& p) { return p.ring.orientations; },
          [](MobilePlannerParams& p, int v) { p.ring.orientations = v; })
      .def_property(
          "gain_max_range", [](const MobilePlannerParams& p) { return p.gain.max_range; },
          [](MobilePlannerParams& p, double v) { p.gain.max_range = v; })
      .def_property(
          "gain_bounds", [](const MobilePlannerParams& p) { return p.gain.bounds; },
          [](MobilePlannerParams& p, const py::object& b) { p.gain.bounds = optional_bounds(b); })
      .def_readwrite("gain_height", &MobilePlannerParams::gain_height)
      .def_readwrite("gain_stride", &MobilePlannerParams::gain_stride)
      .def_readwrite("min_relative_gain", &MobilePlannerParams::min_relative_gain)
      .def_readwrite("max_visits_per_frontier", &MobilePlannerParams::max_visits_per_frontier)
      .def_readwrite("frontier_radius", &MobilePlannerParams::frontier_radius)
      .def_readwrite("frontier_attempts", &MobilePlannerParams::frontier_attempts)
      .def_readwrite("max_steps", &MobilePlannerParams::max_steps)
      .def_readwrite("look_around_scans", &MobilePlannerParams::look_around_scans)
      .def_readwrite("look_around_span", &MobilePlannerParams::look_around_span,
                     "rad from the first to the last look-around scan, or None (what covers the full circle)")
      .def_readwrite("hits_block", &MobilePlannerParams::hits_block,
                     "voxels with net hit evidence but not yet occupied are obstacles of the exploration map")
      .def_readwrite("exact_blind_zone", &MobilePlannerParams::exact_blind_zone,
                     "the start rule walks every beam of the look-around through the grid (exact blind voxels; for "
                     "one-camera rigs)")
      .def_readwrite("start_free_columns", &MobilePlannerParams::start_free_columns,
                     "the thesis' start rule: whole columns within start_free_radius count as free")
      .def_readwrite("face_along_path", &MobilePlannerParams::face_along_path,
                     "turn on the spot and drive forward only (differential drive)")
      .def_readwrite("scans_per_view", &MobilePlannerParams::scans_per_view)
      .def_readwrite(
          "frames_per_scan", &MobilePlannerParams::frames_per_scan,
          "frames at every scan pose (>= 1): each pose is listed this many times in plan.scans, so a rig that\n"
          "sees each direction once per look-around (one camera) gives a voxel enough consistent misses")
      .def_readwrite("threads", &MobilePlannerParams::threads, "candidate evaluation threads (0: all cores)")
      .def_readwrite("seed", &MobilePlannerParams::seed)
      .def_property(
          "explained", [](const MobilePlannerParams& p) { return p.explained.enabled; },
          [](MobilePlannerParams& p, bool v) { p.explained.enabled = v; },
          "plan on explained free space: drive only where the beams explain the space as free (docs/planning.md, "
          "\"Planning on explained free space\"; the classing options are ExplainedSpace's defaults)")
      .def_property(
          "unexplained_hazards", [](const MobilePlannerParams& p) { return p.explained.unexplained_hazards; },
          [](MobilePlannerParams& p, bool v) { p.explained.unexplained_hazards = v; },
          "explained planning, opt-in (False by default): keep the robot radius (+ unexplained_margin) from enclosed "
          "groups\n"
          "of columns that only lying beams made free, which stay frontiers to look at (a black obstacle standing "
          "free;\n"
          "in the lab room more runs then use the step budget: docs/planning.md)")
      .def_property(
          "unexplained_margin", [](const MobilePlannerParams& p) { return p.explained.unexplained_margin; },
          [](MobilePlannerParams& p, double v) { p.explained.unexplained_margin = v; },
          "m beyond the robot radius kept from those columns, >= 0 (checked by validate() and the planner)")
      .def_property(
          "min_unexplained_voxels", [](const MobilePlannerParams& p) { return p.explained.min_unexplained_voxels; },
          [](MobilePlannerParams& p, std::size_t v) { p.explained.min_unexplained_voxels = v; },
          "with unexplained_hazards: groups with fewer voxels in the band are no hazard (8 by default, >= 1)")
      .def_property(
          "open_group_hazards", [](const MobilePlannerParams& p) { return p.explained.open_group_hazards; },
          [](MobilePlannerParams& p, bool v) { p.explained.open_group_hazards = v; },
          "with unexplained_hazards, opt-in (False by default): the lying columns of a group open to unexplored space\n"
          "keep the robot off too (radius + unexplained_margin), wherever they lie; the frontier stays at their zone's "
          "edge")
      .def_property(
          "find_mirrors", [](const MobilePlannerParams& p) { return p.explained.find_mirrors; },
          [](MobilePlannerParams& p, bool v) { p.explained.find_mirrors = v; },
          "explained planning, opt-in (False by default): before every plan, revise the channel and tell it of the\n"
          "mirrors find_lying_surfaces finds (their beams suspect, their patches explained occupied; about one\n"
          "analysis per plan: docs/planning.md)")
      .def_property(
          "close_wall_gaps", [](const MobilePlannerParams& p) { return p.explained.close_wall_gaps; },
          [](MobilePlannerParams& p, bool v) { p.explained.close_wall_gaps = v; },
          "explained planning, opt-in (False by default): before every plan, find the gaps of seen walls\n"
          "(find_wall_gaps) and close every one that is not an opening for that plan (a mirror hung on a wall, whose\n"
          "phantom the channel trusts; a doorway opens once what is seen through it contradicts a reflection:\n"
          "docs/planning.md, \"Gaps in a wall\")")
      .def_property(
          "max_inconsistent_share",
          [](const MobilePlannerParams& p) { return p.explained.lying.max_inconsistent_share; },
          [](MobilePlannerParams& p, double v) { p.explained.lying.max_inconsistent_share = v; },
          "with find_mirrors: the region analysis' opacity test (LyingSurfaceParams::max_inconsistent_share, in [0, "
          "1];\n"
          "1, the default, turns it off; checked by validate() and the planner)")
      .def_property(
          "known_surfaces", [](const MobilePlannerParams& p) { return p.explained.known_surfaces; },
          [](MobilePlannerParams& p, std::vector<PlanePatch> v) { p.explained.known_surfaces = std::move(v); },
          "explained planning: opaque surfaces you know (a list of PlanePatch: mirrors, glass, the walls of a floor\n"
          "plan; each kept as given), told to the planner's channel when it makes it: beams through one are suspect\n"
          "and its voxels explained occupied, seen or not. Leave doorways the robot may use out. Empty by default\n"
          "(ExplainedPlanningParams::known_surfaces; docs/planning.md, \"Surfaces you know\")")
      .def_property(
          "min_lying_misses", [](const MobilePlannerParams& p) { return p.explained.explain.min_lying_misses; },
          [](MobilePlannerParams& p, int v) { p.explained.explain.min_lying_misses = v; },
          "explained planning: suspect misses that make a voxel lying (ExplainOptions::min_lying_misses, 1 by default)")
      .def_property(
          "returned_crossing_inside",
          [](const MobilePlannerParams& p) { return p.explained.explain.returned_crossing_inside; },
          [](MobilePlannerParams& p, bool v) { p.explained.explain.returned_crossing_inside = v; },
          "explained planning: a returned beam's crossing counts only at a surface's inside met steeply\n"
          "(ExplainOptions::returned_crossing_inside, False by default)")
      .def_property(
          "passage_views", [](const MobilePlannerParams& p) { return p.passage_views.enabled; },
          [](MobilePlannerParams& p, bool v) { p.passage_views.enabled = v; },
          "opt-in (False by default): when no frontier gives a view, views that open passages such as a doorway whose\n"
          "far side was seen by too few scans (PassageViewParams; docs/planning.md, \"Doors and passages\")")
      .def_property(
          "passage_min_hidden_area", [](const MobilePlannerParams& p) { return p.passage_views.min_hidden_area; },
          [](MobilePlannerParams& p, double v) { p.passage_views.min_hidden_area = v; },
          "m^2 of unknown floor a passage must hide (0.25 by default, >= 0)")
      .def_property(
          "passage_frames", [](const MobilePlannerParams& p) { return p.passage_views.frames; },
          [](MobilePlannerParams& p, int v) { p.passage_views.frames = v; },
          "times each scan pose of a passage view is listed (2 by default, >= 1)")
      .def_property(
          "passage_reach", [](const MobilePlannerParams& p) { return p.passage_views.reach; },
          [](MobilePlannerParams& p, double v) { p.passage_views.reach = v; },
          "m; half the side of the box around the passage whose gain scores its views (1.0 by default, > 0)")
      .def_property(
          "passage_ring_inner_radius", [](const MobilePlannerParams& p) { return p.passage_views.ring.inner_radius; },
          [](MobilePlannerParams& p, double v) { p.passage_views.ring.inner_radius = v; })
      .def_property(
          "passage_ring_outer_radius", [](const MobilePlannerParams& p) { return p.passage_views.ring.outer_radius; },
          [](MobilePlannerParams& p, double v) { p.passage_views.ring.outer_radius = v; })
      .def_readwrite(
          "driven_paths", &MobilePlannerParams::driven_paths,
          "opt-in (False by default): the way back; free cells the robot's centre passed on the paths it drove stay\n"
          "passable while no obstacle comes within its radius (docs/planning.md, \"The way back\")")
      .def("validate", &MobilePlannerParams::validate);

  py::class_<ArmPlannerParams> ap(m, "ArmPlannerParams", "Parameters of the arm planner (see arm_planner.hpp).");
  ap.def(py::init<>())
      .def_property(
          "object_region", [](const ArmPlannerParams& p) { return p.object_region; },
          [](ArmPlannerParams& p, const py::object& b) { p.object_region = to_bounds(b); })
      .def_readwrite("center", &ArmPlannerParams::center,
                     "centre of the sphere of views, or None (the region's centre)")
      .def_readwrite("sphere_radius", &ArmPlannerParams::sphere_radius)
      .def_readwrite("candidates", &ArmPlannerParams::candidates)
      .def_readwrite("min_elevation", &ArmPlannerParams::min_elevation)
      .def_readwrite("max_elevation", &ArmPlannerParams::max_elevation)
      .def_readwrite("sweep_length", &ArmPlannerParams::sweep_length)
      .def_readwrite("profiles", &ArmPlannerParams::profiles)
      .def_readwrite("collision_margin", &ArmPlannerParams::collision_margin)
      .def_readwrite("support_height", &ArmPlannerParams::support_height)
      .def_readwrite("initial_elevation", &ArmPlannerParams::initial_elevation)
      .def_readwrite("initial_azimuth", &ArmPlannerParams::initial_azimuth)
      .def_property(
          "gain_max_range", [](const ArmPlannerParams& p) { return p.gain.max_range; },
          [](ArmPlannerParams& p, double v) { p.gain.max_range = v; })
      .def_property(
          "gain_bounds", [](const ArmPlannerParams& p) { return p.gain.bounds; },
          [](ArmPlannerParams& p, const py::object& b) { p.gain.bounds = optional_bounds(b); })
      .def_readwrite("gain_stride", &ArmPlannerParams::gain_stride)
      .def_readwrite("gain_profile_stride", &ArmPlannerParams::gain_profile_stride)
      .def_readwrite("min_relative_gain", &ArmPlannerParams::min_relative_gain)
      .def_readwrite("max_views", &ArmPlannerParams::max_views)
      .def_readwrite("threads", &ArmPlannerParams::threads)
      .def_readwrite("seed", &ArmPlannerParams::seed)
      .def_property(
          "explained", [](const ArmPlannerParams& p) { return p.explained.enabled; },
          [](ArmPlannerParams& p, bool v) { p.explained.enabled = v; },
          "plan on explained free space: no sweep within collision_margin of space only suspect beams or beams\n"
          "without a return crossed (docs/planning.md, \"Arm object modelling\"; needs an Episode, whose map keeps\n"
          "the evidence)")
      .def_property(
          "known_surfaces", [](const ArmPlannerParams& p) { return p.explained.known_surfaces; },
          [](ArmPlannerParams& p, std::vector<PlanePatch> v) { p.explained.known_surfaces = std::move(v); },
          "explained planning: opaque surfaces you know (a list of PlanePatch, each kept as given), told to the\n"
          "planner's channel when it makes it: beams through one are suspect and its voxels explained occupied\n"
          "(ExplainedPlanningParams::known_surfaces)")
      .def_property(
          "seek_normals", [](const ArmPlannerParams& p) { return p.normals.enabled; },
          [](ArmPlannerParams& p, bool v) { p.normals.enabled = v; },
          "views that seek normals: sweeps scored also by how close to the striper's specular condition they would\n"
          "see surfaces with hits but no decided state (docs/planning.md, \"Views that seek normals\"; needs an\n"
          "Episode, whose map keeps the hits)")
      .def_property(
          "normals_weight", [](const ArmPlannerParams& p) { return p.normals.weight; },
          [](ArmPlannerParams& p, double v) { p.normals.weight = v; },
          "weight of the glint score against the gain (score = gain / max gain + weight * glint / max glint)")
      .def("validate", &ArmPlannerParams::validate);

  // (N, 3) float64 copy of a list of points.
  const auto points = [](const std::vector<Point3>& v) {
    py::array_t<double> a({static_cast<py::ssize_t>(v.size()), py::ssize_t{3}});
    auto w = a.mutable_unchecked<2>();
    for (std::size_t i = 0; i < v.size(); ++i)
      for (py::ssize_t j = 0; j < 3; ++j) w(static_cast<py::ssize_t>(i), j) = v[i][j];
    return a;
  };
  guarded_class<MobilePlanner> mobile(
      m, "MobilePlanner",
      "Decides the next view of a mobile base from the map alone (frontiers, ring candidates, information gain).\n"
      "It neither moves the robot nor senses. Not thread-safe; copy it to branch an episode.");
  mobile
      .def(py::init([](const py::object& rig, const py::object& params) {
             return MobilePlanner(rig.is_none() ? SensorRig::mobile_base() : py::cast<SensorRig>(rig),
                                  params.is_none() ? MobilePlannerParams{} : py::cast<MobilePlannerParams>(params));
           }),
           py::arg("rig") = py::none(), py::arg("params") = py::none(),
           "rig: the base's SensorRig (default SensorRig.mobile_base()); params: MobilePlannerParams.")
      .def_property_readonly("max_range", &MobilePlanner::max_range)
      .def_property_readonly("params", &MobilePlanner::params)
      .def_property_readonly("steps", &MobilePlanner::steps)
      .def_property_readonly("look_around_yaws", &MobilePlanner::look_around_yaws,
                             "yaws (rad) of the look-around, relative to the start heading")
      .def_property_readonly("start_free_radius", &MobilePlanner::start_free_radius,
                             "the start-free radius in use (params' or the rig's blind zone) [m]")
      .def_property_readonly(
          "visited", [points](const MobilePlanner& p) { return points(p.visited()); },
          "(N, 3) positions plan() was given, in order (a copy)")
      .def_property_readonly(
          "scan_origins", [points](const MobilePlanner& p) { return points(p.scan_origins()); },
          "(M, 3) sensor origins of the scans planned so far, in order: the rig's mean mount position at\n"
          "each scan pose (conflict-aware and explained planning count a region's view directions with them; a copy)")
      .def("copy", [](const MobilePlanner& p) { return MobilePlanner(p); });
  guarded_class<ArmPlanner> arm(
      m, "ArmPlanner",
      "Decides the next striper sweep of an arm from the map alone (views on a sphere, collision\n"
      "checks, information gain). Not thread-safe.");
  arm.def(py::init([](const py::object& rig, const py::object& params) {
            return ArmPlanner(rig.is_none() ? SensorRig::arm() : py::cast<SensorRig>(rig),
                              params.is_none() ? ArmPlannerParams{} : py::cast<ArmPlannerParams>(params));
          }),
          py::arg("rig") = py::none(), py::arg("params") = py::none(),
          "rig: the arm's SensorRig, sensor 0 a LaserStriper (default SensorRig.arm()); params: ArmPlannerParams.")
      .def_property_readonly("max_range", &ArmPlanner::max_range)
      .def_property_readonly("params", &ArmPlanner::params)
      .def_property_readonly("views", &ArmPlanner::views)
      .def("copy", [](const ArmPlanner& p) { return ArmPlanner(p); });

  py::class_<PyStep>(m, "EpisodeStep", "What one step of an episode did.")
      .def_readonly("step", &PyStep::step, "0 for the planner's initial view")
      .def_readonly("plan", &PyStep::plan, "the decision (MobilePlan or ArmPlan)")
      .def_property_readonly(
          "pose", [](const PyStep& s) { return from_pose(s.pose); }, "body pose after the step")
      .def_readonly("beams", &PyStep::beams, "beams inserted")
      .def_readonly("seconds_planning", &PyStep::seconds_planning)
      .def_readonly("seconds_sensing", &PyStep::seconds_sensing)
      .def_readonly("seconds_inserting", &PyStep::seconds_inserting)
      .def_readonly("seconds_total", &PyStep::seconds_total);
  guarded_class<PyEpisode> episode(
      m, "Episode",
      "Runs a planner against a sensor source on one grid: plan, drive the path, sense at the scan poses, insert,\n"
      "until the planner ends the episode. The episode's map is the grid and the evidence the planner reads\n"
      "(explained planning: the explained channel, explained_space; the planner only reads it). source(body) gets the "
      "(4, 4) body pose and returns the beams measured\n"
      "there as (origins, ends) or (origins, ends, hits) in world coordinates (a SimulatedRig is such a source).\n"
      "max_range: insertion max range, None (default: the planner's) or > 0; threads: insertion threads.\n"
      "Exceptions raised by the source propagate out of step()/run().");
  episode
      .def(
          "step",
          [](PyEpisode& e) {
            const PyEpisode::Hold hold(e);
            return e.impl->step();
          },
          "Plans, drives, senses and inserts once (EpisodeStep).")
      .def(
          "run",
          [](PyEpisode& e) {
            const PyEpisode::Hold hold(e);
            return e.impl->run();
          },
          "Steps until the planner ends the episode; returns why.")
      .def(
          "sense",
          [](PyEpisode& e, const py::object& scans) {
            const std::vector<Pose> poses = to_poses(scans, "scans");
            const PyEpisode::Hold hold(e);
            return e.impl->sense(poses);
          },
          py::arg("scans"), "Senses and inserts at scripted (N, 4, 4) body poses; returns the beams inserted.")
      .def_property_readonly("termination", [](const PyEpisode& e) { return e.impl->termination(); })
      .def_property_readonly("pose", [](const PyEpisode& e) { return from_pose(e.impl->pose()); })
      .def_property_readonly(
          "trajectory", [](const PyEpisode& e) { return from_poses(e.impl->trajectory()); },
          "(N, 4, 4) every body pose passed through")
      .def_property_readonly("steps", [](const PyEpisode& e) { return e.impl->steps(); })
      .def("distance_driven", [](const PyEpisode& e) { return e.impl->distance_driven(); })
      .def_property_readonly(
          "explained_space", [](const PyEpisode& e) { return e.impl->explained_space(); },
          "a copy of the ExplainedSpace the episode's map keeps for a planner that plans on explained free space (the\n"
          "beam classes, the evidence, the ledger and, with find_mirrors, the mirrors it told), or None for a planner\n"
          "that reads the grid alone. A snapshot: later steps do not change it.");

  for_each_grid([&]<class G>() { add_planning<G>(mobile, arm, episode); });
}

}  // namespace intervox::python
