#pragma once
// One run of the apartments benchmark: a planner's episode in a random apartment (or its honest
// twin), measured against the true world (docs/experiments.md, "Random apartments").
#include "common/rigs.hpp"
#include "config.hpp"

#include <intervox/eval/ground_truth.hpp>
#include <intervox/grid/named_grids.hpp>
#include <intervox/plan/column_map.hpp>
#include <intervox/plan/episode.hpp>
#include <intervox/plan/mobile_planner.hpp>
#include <intervox/sim/apartment.hpp>
#include <intervox/sim/oracle.hpp>
#include <intervox/sim/source.hpp>

#include <algorithm>
#include <chrono>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace apartments {

/// What one run measured. Timings are kept apart from the rest (timings.csv), so that results.csv
/// is the same on any machine and any number of threads.
struct Result {
  Run run;
  // The world.
  int rooms = 0;
  std::string kinds;      ///< the fixture kinds it holds, ';'-separated in FixtureKind order ("-": none)
  double floor_area = 0;  ///< m², the floor the robot can reach from the start (the truth's map)
  // The episode.
  std::string termination;
  bool completed = false;  ///< ended by itself: explored, or no reachable frontier left (not budget, not blocked)
  int steps = 0;           ///< views planned after the look-around
  double distance = 0;     ///< m driven
  double known = 0;        ///< share of the reachable floor whose column the map holds free
  std::size_t collision_poses = 0;     ///< trajectory poses whose footprint meets the true world
  std::size_t collision_segments = 0;  ///< path segments between poses that meet it
  int first_collision = -1;            ///< index of the first trajectory pose (or segment end) in collision, -1: none
  std::string met;                     ///< objects met, "name:kind" ';'-separated in scene order ("-": none)
  bool met_lying = false;              ///< a lying surface or the furniture it fronts was among them
  // Timings (timings.csv).
  double seconds_per_plan = 0;
  double seconds_per_insert = 0;  ///< sensing excluded: the grid's insertion (and the planner's observe())
  double seconds_total = 0;
};

/// What a run leaves for its top view (top_view.hpp): the poses driven and the final map's columns
/// over the scored band.
struct Capture {
  std::vector<iv::Pose> trajectory;
  std::optional<iv::ColumnMap> columns;
  double resolution = 0;
};

/// What object \p id of \p a is: its fixture kind (as surface or as the furniture body), "wall",
/// "door" or "furniture".
inline std::string kind_of(const iv::sim::Apartment& a, iv::sim::ObjectId id) {
  for (const iv::sim::ApartmentFixture& f : a.fixtures)
    if (f.surface == id || (f.body && *f.body == id)) return std::string(iv::sim::to_string(f.kind));
  const std::string& name = a.scene.name(id);
  if (name.rfind("wall", 0) == 0 || name == "floor" || name == "ceiling") return "wall";
  if (name.rfind("door", 0) == 0) return "door";
  return "furniture";
}

/// The planner's parameters of \p r: an unbounded grid (the region derived from what was seen),
/// the library's start and map rules, the step budget; "safe" adds the safe configuration of
/// docs/experiments.md ("What to choose"); "one" the one-camera rules of docs/planning.md ("Any
/// rig": the exact start rule, several frames per scan, facing along the path).
inline iv::MobilePlannerParams planner_params(const Run& r, const Options& o) {
  iv::MobilePlannerParams p;
  p.seed = r.seed;
  p.threads = o.threads;
  p.max_steps = o.max_steps;
  if (r.planner == "safe") {
    p.explained.enabled = true;
    p.explained.unexplained_hazards = true;
    p.explained.open_group_hazards = true;
    p.explained.close_wall_gaps = true;
  }
  if (r.rig == "one") {
    p.exact_blind_zone = true;
    p.frames_per_scan = r.update == "bayes" ? 3 : 5;
    p.face_along_path = true;
  }
  return p;
}

/// The rig of \p r.
inline iv::SensorRig rig_of(const Run& r) {
  return r.rig == "one" ? examples::front_camera_rig() : iv::SensorRig::mobile_base();
}

/// Collisions of a trajectory with the true world: counts, objects met and the first pose (or
/// segment end) in collision. The robot is the planners' disk (the map's robot radius) from the
/// floor clearance to the robot's height.
inline void score_collisions(const iv::sim::Apartment& a, const iv::sim::Scene& world, const iv::GridGeometry& g,
                             const std::vector<iv::Pose>& trajectory, const iv::MobilePlannerParams& p, Result& out) {
  const double radius = p.map.robot_radius, lo = p.floor_clearance, hi = p.obstacle_height;
  const iv::PathCollisions c = iv::count_path_collisions(world, g, trajectory, radius, lo, hi);
  out.collision_poses = c.poses;
  out.collision_segments = c.segments;
  out.met.clear();
  for (const iv::ObjectCollisions& m : iv::collisions_by_object(world, g, trajectory, radius, lo, hi)) {
    const std::string kind = kind_of(a, m.object);
    out.met += (out.met.empty() ? "" : ";") + m.name + ":" + kind;
    out.met_lying = out.met_lying || (kind != "wall" && kind != "door" && kind != "furniture");
  }
  if (out.met.empty()) out.met = "-";
  out.first_collision = -1;
  if (c.poses == 0 && c.segments == 0) return;
  for (std::size_t i = 0; i < trajectory.size() && out.first_collision < 0; ++i) {
    const std::vector<iv::Pose> upto(trajectory.begin() + static_cast<std::ptrdiff_t>(i > 0 ? i - 1 : 0),
                                     trajectory.begin() + static_cast<std::ptrdiff_t>(i + 1));
    const iv::PathCollisions here = iv::count_path_collisions(world, g, upto, radius, lo, hi);
    if (here.poses > 0 || here.segments > 0) out.first_collision = static_cast<int>(i);
  }
}

/// A run's episode, its grid type chosen by the run's update.
template <class Grid>
Result run_with(const Run& r, const Options& o, const iv::sim::Apartment& a, const iv::sim::Scene& world,
                Capture* capture) {
  const iv::MobilePlannerParams p = planner_params(r, o);
  const iv::SensorRig rig = rig_of(r);
  iv::MobilePlanner planner(rig, p);
  auto map = planner.make_map(Grid(o.resolution));
  const Grid& grid = map.grid();
  const iv::Pose start = iv::planar_pose(a.start, 0.0);
  Result out;
  out.run = r;
  const auto t0 = std::chrono::steady_clock::now();
  const auto episode_of = [&](auto source) {
    iv::Episode ex(map, planner, std::move(source), start);
    ex.run();
    double planning = 0, inserting = 0;
    for (const auto& s : ex.steps()) {
      planning += s.seconds_planning;
      inserting += s.seconds_inserting;
    }
    const double n = static_cast<double>(std::max<std::size_t>(1, ex.steps().size()));
    out.seconds_per_plan = planning / n;
    out.seconds_per_insert = inserting / n;
    out.termination = std::string(iv::to_string(ex.termination()));
    out.completed =
        ex.termination() == iv::Termination::Explored || ex.termination() == iv::Termination::NoReachableFrontier;
    out.distance = ex.distance_driven();
    return ex.trajectory();
  };
  iv::sim::SimOptions sim;
  sim.threads = o.threads;
  const std::vector<iv::Pose> path = r.planner == "oracle" ? episode_of(iv::sim::make_oracle_rig(a, rig, r.seed, sim))
                                                           : episode_of(iv::sim::SimulatedRig(world, rig, r.seed, sim));
  out.seconds_total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  out.steps = std::max(0, planner.steps() - 1);  // the look-around is step 0
  out.known = iv::floor_coverage(grid, world, a.band(p.floor_clearance, p.obstacle_height), p.map, a.start).known;
  score_collisions(a, world, grid.geometry(), path, p, out);
  if (capture) {
    capture->trajectory = path;
    capture->columns = iv::project_columns(grid, a.band(p.floor_clearance, p.obstacle_height));
    capture->resolution = o.resolution;
  }
  return out;
}

/// The world's description in \p out: rooms, fixture kinds, reachable floor.
inline void describe_world(const iv::sim::Apartment& a, const iv::sim::Scene& world, const Options& o, Result& out) {
  out.rooms = static_cast<int>(a.rooms.size());
  out.kinds.clear();
  for (std::size_t k = 0; k < iv::sim::kFixtureKinds; ++k)
    if (a.has(static_cast<iv::sim::FixtureKind>(k)))
      out.kinds +=
          (out.kinds.empty() ? "" : ";") + std::string(iv::sim::to_string(static_cast<iv::sim::FixtureKind>(k)));
  if (out.kinds.empty()) out.kinds = "-";
  const iv::GridGeometry g(o.resolution);
  const iv::TruthMap truth = iv::truth_exploration_map(world, g, a.band(), iv::ExplorationMapParams{}, a.start);
  std::size_t cells = 0;
  for (int y = 0; y < truth.map.height(); ++y)
    for (int x = 0; x < truth.map.width(); ++x) cells += truth.map.reachable({x, y}) ? 1 : 0;
  out.floor_area = static_cast<double>(cells) * o.resolution * o.resolution;
}

/// Runs \p r: builds its apartment (the honest twin for "honest"), runs the episode and scores
/// it. With \p capture, what the top view draws is kept there.
/// \throws iv::InvalidArgument for an unknown planner, rig, update or world.
inline Result run_one(const Run& r, const Options& o, Capture* capture = nullptr) {
  const auto known = [](const std::string& v, const auto& list) {
    return std::ranges::find(list, v) != std::end(list);
  };
  if (!known(r.planner, kPlanners) || !known(r.rig, kRigs) || !known(r.update, kUpdates) || !known(r.world, kWorlds))
    throw iv::InvalidArgument("apartments: unknown run configuration '" + r.group() + "'");
  const iv::sim::Apartment a = iv::sim::make_apartment(r.seed);
  const iv::sim::Scene twin = a.honest_twin();
  const iv::sim::Scene& world = r.world == "honest" ? twin : a.scene;
  Result out = r.update == "bayes" ? run_with<iv::BayesGrid>(r, o, a, world, capture)
                                   : run_with<iv::IntervalGrid>(r, o, a, world, capture);
  describe_world(a, world, o, out);
  return out;
}

}  // namespace apartments
