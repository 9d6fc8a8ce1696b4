#pragma once
/// \file
/// The mobile planner's parameters and decisions: MobilePlannerParams (with PassageViewParams)
/// and MobilePlan (with the refused frontiers and why). The planner itself is
/// plan/mobile_planner.hpp.

#include <intervox/analysis/wall_gaps.hpp>
#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/plan/conflict_planning.hpp>
#include <intervox/plan/explained_planning.hpp>
#include <intervox/plan/exploration_map.hpp>
#include <intervox/plan/information_gain.hpp>
#include <intervox/plan/planner.hpp>
#include <intervox/plan/view_sampling.hpp>

#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

namespace intervox {

/// Views that open passages (MobilePlannerParams::passage_views; docs/planning.md, "Doors and
/// passages"). A passage is a reachable cell beside maybe-collision space that hides unknown space
/// (ExplorationMap::passages()): a doorway whose far side, right behind the jambs, was crossed by
/// too few scans to be free closes this way, and no frontier opens it. When no frontier (and no
/// lying region) gives a view, the planner tries the passages like frontiers: by path distance,
/// at most frontier_attempts per call, skipping those within frontier_radius of one tried or given
/// up; candidates on `ring` around the passage cell (candidate_random, CandidateStream::Passage),
/// scored by the gain inside the box of half-side `reach` around it (x, y; the region's height
/// band in z), which holds the unknown columns that close it. The view's scans are listed
/// `frames` times as often as a frontier view's (every turn frames_per_scan x frames times), so
/// that the voxels it crosses collect the misses that make them free (five for interval-mean at
/// the library's defaults). A passage is given up like a frontier: min_relative_gain,
/// max_visits_per_frontier (visits counted with the frontiers within frontier_radius).
struct PassageViewParams {
  bool enabled = false;                     ///< off by default (the thesis' planner has no such views)
  RingSamplerParams ring{1.0, 2.0, 12, 2};  ///< candidate positions around the passage cell
  double reach = 1.0;                       ///< m; half the side of the gain box, finite and > 0
  int frames = 2;                           ///< times each scan pose is listed, >= 1
  /// m²; the least unknown floor a passage must hide (ExplorationMapParams::passage_min_hidden_area),
  /// so that pockets beside furniture get no views of their own. Finite, >= 0. (Chosen from 1.0,
  /// 0.5 and 0.25 on the lab room's annex, seeds 1-10: docs/planning.md, "Doors and passages".)
  double min_hidden_area = 0.25;
  /// \throws InvalidArgument naming the first invalid parameter.
  void validate() const {
    const ParamCheck check("intervox::PassageViewParams");
    ring.validate();
    check.positive("reach", reach);
    check.at_least("frames", frames, 1);
    check.nonnegative("min_hidden_area", min_hidden_area);
  }
};

/// Parameters of the mobile planner. Defaults fit the thesis' mobile base (SensorRig::mobile_base)
/// in a room such as the built-in lab room.
struct MobilePlannerParams {
  /// The floor area explored (x, y) and the heights projected onto the exploration map (z). If
  /// unset, derived from the map at every call (see MobilePlanner::region_for): the grid's bounds
  /// (bounded grids) or the observed voxels' extent grown by `region_margin` (unbounded grids) in
  /// x and y, and [floor_clearance, obstacle_height] above the robot's body frame in z.
  std::optional<Bounds> region;
  /// m above the body frame (the floor): columns are projected from here up, so the floor itself
  /// is not an obstacle. The cameras at knee height (0.5 m, +-15 deg) see the layers 0.2-0.8 m of
  /// a column only from about 0.9 m on: obstacles lower than this are not mapped.
  double floor_clearance = 0.2;
  double obstacle_height = 0.8;    ///< m above the body frame: the robot's height
  double region_margin = 0.5;      ///< m around the observed voxels for the derived region, >= 0
  ExplorationMapParams map{0.36};  ///< robot radius: the base's 0.6 x 0.4 m footprint turns in 0.36 m
  double footprint_radius = 0.2;   ///< m; cells within this radius of a position the robot stood on count as free
  /// m; the operator starts the robot in a clear spot, and within this radius of the start the
  /// planner takes that on trust as far as the measurements allow. An unknown voxel there counts
  /// as free if no beam of the look-around could cross it (BlindZone of plan/look_around.hpp:
  /// below the lowest or above the highest beam at its distance) or if beams crossed it and none
  /// ended in it (its probability is still at or below the prior's: misses only, too few to
  /// classify it; any beams, suspect and no-return ones too: beams that never return from the
  /// start area, e.g. towards walls beyond the cameras' range, are the rule, not the exception);
  /// a voxel with any hit on it (probability above the prior), or one the rig could see but never
  /// reached (occluded), stays unknown. The promise is the operator's: a black obstacle within the
  /// radius, seen only as beams without a return, is taken as free. Unset (the default): the rig's blind zone,
  /// blind_radius(rig, look-around yaws, floor_clearance, obstacle_height), the least radius
  /// outside which the rig sees every column's whole height band (1.50 m for
  /// SensorRig::mobile_base). See start_free_columns for the thesis' rule.
  std::optional<double> start_free_radius;
  /// Voxels with net hit evidence that the update does not yet classify as occupied (probability
  /// above the prior's: more hits than the misses offset, e.g. a wall one camera saw twice, where
  /// interval-mean needs five hits) are obstacles of the exploration map, so the robot keeps its
  /// radius from them. Off: such voxels are unknown and, outside collision space, do not narrow
  /// the map (the thesis' rule, which the experiments keep).
  bool hits_block = true;
  /// The thesis' start rule instead: whole columns within start_free_radius count as free unless
  /// seen occupied, whatever the rig could see there (the experiments replicate the thesis with it
  /// and a radius of 1.0 m). A table top at the edge of the cameras' view then counts as free.
  bool start_free_columns = false;
  /// The start rule's "could not see it" exactly (BlindZone::trace): at the look-around every beam
  /// of the rig is walked through the grid within the start-free radius, and a voxel counts as
  /// blind only if no beam crosses it. Off: BlindZone::blind(), which takes the hull of the
  /// heights crossed over the neighbouring azimuths and rings, so that a voxel between a single
  /// camera's turns counts as seen and stays unknown (one forward camera then cannot leave its
  /// start: docs/planning.md, "One camera, one frame per heading"). Measured there ("The exact
  /// start rule").
  bool exact_blind_zone = false;
  RingSamplerParams ring{1.4, 2.4, 12, 2};
  /// Gain options. If bounds are unset, the region (x, y) from the floor to `gain_height` above
  /// the region's top, so that unobserved space outside it does not attract the planner.
  GainOptions gain{4.0, GainCount::PerBeam, std::nullopt};
  double gain_height = 2.5;  ///< m above the region's top for the default gain bounds, >= 0
  int gain_stride = 4;       ///< pixel stride of the rays cast for the gain (1/16 of them)
  /// A frontier whose best view gains less than this fraction of the same view's gain in an
  /// unobserved world (ViewPlan::relative_gain) is given up; the same for every sensor and stride.
  double min_relative_gain = 1e-5;
  int max_visits_per_frontier = 3;  ///< a frontier selected this often is given up
  double frontier_radius = 0.5;     ///< m; frontiers closer than this count as the same one
  int frontier_attempts = 6;        ///< frontiers tried per call before the episode ends
  int max_steps = 40;               ///< views planned after the look-around (then Budget)
  /// Scans at the start, turning on the spot (see look_around_span).
  int look_around_scans = 4;
  /// rad; the turn from the first to the last scan of the look-around (scans evenly spread).
  /// Unset (the default): what makes the rig's fields of view cover the full circle
  /// (look_around_yaws() of plan/look_around.hpp): the thesis' 45° / look_around_scans steps for
  /// rigs that already see all round (SensorRig::mobile_base), else as many scans as closing the
  /// largest gap takes (one 40° camera mounted 0.3 m forward: 15 scans over about 335°).
  std::optional<double> look_around_span;
  /// Robots that must face along their path (differential drive): the plan's path turns on the
  /// spot at each waypoint to face the next one and only drives forward; off, the body keeps its
  /// heading while it translates (a holonomic base such as the thesis' omniRob).
  bool face_along_path = false;
  /// Scans at each view, turning by 45° / n between them (the cameras deliver frames while the
  /// base turns on the spot; see docs/planning.md for how many misses make a voxel free).
  int scans_per_view = 3;
  /// Frames at every scan pose (look-around and views), >= 1: each pose is listed this many times
  /// in a row in ViewPlan::scans, so the sensors deliver that many frames from it and each voxel
  /// they cross gets that many consistent misses (a scan updates a voxel at most once). The
  /// thesis' eight cameras see most directions from several scans, so 1 (the default) suffices
  /// there; a rig that sees each direction once per look-around (one camera) leaves an
  /// interval-mean map unknown, which needs 5 misses per voxel (docs/planning.md, "One camera, one
  /// frame per heading"): give it 5 (3 for Bayes).
  int frames_per_scan = 1;
  unsigned threads = 0;    ///< candidate evaluation threads (0: all cores)
  std::uint64_t seed = 1;  ///< candidate sampling
  /// Conflict-aware planning (docs/planning.md, "Conflict-aware planning"); disabled by default.
  /// Its observation range defaults to the gain's max range when left at its default.
  ConflictPlanningParams conflicts{};
  /// Planning on explained free space; disabled by default. Reads the evidence of an ExplainedMap
  /// (plan(map, pose); make_map() gives one with what these parameters read).
  ExplainedPlanningParams explained{};
  /// Views that open passages (PassageViewParams); disabled by default.
  PassageViewParams passage_views{};
  /// The way back (docs/planning.md, "The way back"), off by default: when plan() is given a pose
  /// within footprint_radius of the previous plan's view, the planner takes that plan's path as
  /// driven, and the cells the robot's centre passed on it stay passable in every later exploration
  /// map while their column is free and no occupied column comes within the robot radius of them
  /// (ExplorationMap's `driven` cells: paths run through them, views never stand on them).
  /// Evidence gathered since that puts them in maybe-collision or hazard zones (a column beside
  /// the path that turned unknown, a lying region beside it) then cannot shut the robot into the
  /// pocket it drove to. Paths are taken as driven only for a
  /// holonomic base (face_along_path off): a differential-drive robot turning on a driven cell
  /// would sweep more than its drive there did.
  bool driven_paths = false;

  /// \throws InvalidArgument naming the first invalid parameter.
  void validate() const {
    const ParamCheck check("intervox::MobilePlannerParams");
    conflicts.validate();
    explained.validate();
    passage_views.validate();
    if (region) check.valid_bounds("region", *region);
    if (!(std::isfinite(floor_clearance) && std::isfinite(obstacle_height) && floor_clearance <= obstacle_height))
      check.fail("need finite floor_clearance <= obstacle_height");
    check.nonnegative("region_margin", region_margin);
    if (start_free_radius) check.nonnegative("start_free_radius", *start_free_radius);
    check.nonnegative("footprint_radius", footprint_radius);
    if (look_around_span) check.nonnegative("look_around_span", *look_around_span);
    check.nonnegative("map.robot_radius", map.robot_radius);
    check.nonnegative("map.clearance", map.clearance);
    ring.validate();
    gain.validate();
    check.nonnegative("gain_height", gain_height);
    check.at_least("gain_stride", gain_stride, 1);
    check.at_least("look_around_scans", look_around_scans, 1);
    check.at_least("scans_per_view", scans_per_view, 1);
    check.at_least("frames_per_scan", frames_per_scan, 1);
    check.nonnegative("min_relative_gain", min_relative_gain);
    check.at_least("max_visits_per_frontier", max_visits_per_frontier, 1);
    check.at_least("frontier_attempts", frontier_attempts, 1);
    check.nonnegative("frontier_radius", frontier_radius);
    check.at_least("max_steps", max_steps, 0);
  }
};

/// One decision of the mobile planner.
/// Why a frontier the planner tried did not give the view (MobilePlan::refused).
enum class FrontierRefusal : std::uint8_t {
  Unresolvable,    ///< it opens onto a conflict region given up (seen from enough directions): retired
  NoNewDirection,  ///< its conflict region has no candidate view from a direction not used yet: retired
  NoCandidate,     ///< no cell of its ring is reachable free space (RefusedFrontier::ring_refused says what they are)
  LowGain,         ///< its best candidate gains less than min_relative_gain of an unknown world's gain: given up
  VisitBudget,     ///< it was selected max_visits_per_frontier times already: given up
  /// It opens onto an enclosed unexplained group (explained planning with unexplained_hazards)
  /// that stayed unexplained from resolve_directions distinct directions, or was given up: retired.
  Unexplained,
};

/// Name of a refusal, for reports.
constexpr std::string_view to_string(FrontierRefusal r) noexcept {
  switch (r) {
    case FrontierRefusal::Unresolvable:
      return "unresolvable";
    case FrontierRefusal::NoNewDirection:
      return "no new direction";
    case FrontierRefusal::NoCandidate:
      return "no candidate";
    case FrontierRefusal::LowGain:
      return "low gain";
    case FrontierRefusal::VisitBudget:
      return "visit budget";
    case FrontierRefusal::Unexplained:
      return "unexplained";
  }
  return "?";
}

/// A frontier tried in one planning call that did not give the view, and why.
struct RefusedFrontier {
  Cell2 frontier;  ///< the border cell of the exploration map
  FrontierRefusal reason = FrontierRefusal::NoCandidate;
  /// LowGain and VisitBudget: the best candidate's gain relative to an unknown world's (0 if no
  /// candidate gained anything).
  double relative_gain = 0;
  /// Where a candidate could have stood and why it could not: the cells of the frontier's ring
  /// (centre distance in [ring.inner_radius, ring.outer_radius]) that are not reachable free
  /// space, counted by their exploration-map label (index: MapLabel; cells outside the map count
  /// as Unknown). Filled for every reason but Unresolvable and Unexplained (whose ring is not sampled).
  std::array<std::uint32_t, kMapLabelCount> ring_refused{};
};

struct MobilePlan : ViewPlan {
  Bounds region;                            ///< the region the map was projected from
  std::optional<ExplorationMap> map;        ///< the exploration map planned on (unset for the look-around)
  std::optional<Cell2> frontier;            ///< the selected frontier (a map cell)
  std::vector<PlanarCandidate> candidates;  ///< poses sampled at the selected frontier
  std::vector<ViewGain> gains;              ///< their gains
  std::optional<std::size_t> selected;      ///< index into candidates
  Pose view = Pose::Identity();             ///< the body pose at the view (the first scan pose)
  /// The lying regions found, with their views and state, and the index of the region the view
  /// aims at (reason Conflict): with conflict-aware planning the conflict regions (detection
  /// limited to the gain bounds), then, with explained planning and unexplained_hazards, the
  /// enclosed unexplained groups (PlannedRegion::unexplained).
  std::vector<PlannedRegion> regions;
  std::optional<std::size_t> conflict_region;
  std::size_t retired = 0;  ///< frontiers and regions given up as unresolvable in this call
  /// The frontiers tried in this call, closest first, that did not give the view, each with its
  /// reason; with Termination::Blocked every one says NoCandidate, with Explored LowGain,
  /// VisitBudget or a conflict reason. Border cells skipped because they lie within
  /// frontier_radius of one tried or given up are not listed (see `skipped`).
  std::vector<RefusedFrontier> refused;
  std::size_t skipped = 0;  ///< border cells skipped near a frontier tried in this call or given up before
  /// With ExplainedPlanningParams::close_wall_gaps: the gaps of seen walls found before this plan
  /// (find_wall_gaps()); every one that is not an opening was closed in the map.
  std::vector<WallGap> wall_gaps;
};

}  // namespace intervox
