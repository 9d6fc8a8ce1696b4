// The lab room under the thesis' map rules and the library's (docs/notes/lab-room-library-defaults.md, "The lab room at
// the library's defaults"): for each seed, the plain planner with the thesis' start rule (whole
// columns within 1 m free) and unknown voxels whatever their hits, the plain planner at the
// library's defaults (the rig's start rule, hits_block), the explained planner at the library's
// defaults, and the explained planner with enclosed unexplained columns as hazards
// (ExplainedPlanningParams::unexplained_hazards, opt-in); --planners picks them (the first three
// by default).
// Interval-mean + max-entropy, 5 cm, the thesis' eight cameras (or one forward camera, --rig one).
// Prints one
// row per run (termination, steps, reachable floor known, distance, collisions by object at the
// robot's radius) and a summary per configuration (mean ± sd).
//
// With --annex the room has an open doorway in its east wall to an annex (the region takes it in;
// its reachable floor known is printed apart), with --front-only only the closet's front has
// the material (its body is wood); --passage-views turns on the views that open passages
// (MobilePlannerParams::passage_views) and --driven-paths the way back (MobilePlannerParams::
// driven_paths) for every planner; --known-surfaces tells the explained planners the room's floor
// plan (walls, openings left out), the closet's surfaces and/or the floor under the whole region
// (ExplainedPlanningParams::known_surfaces: what a user who knows the building can tell); --open-group-hazards keeps
// the "explained hazards" planner off lying columns open to unexplored space too
// (ExplainedPlanningParams::open_group_hazards); --glint simulates the near-normal glint a real
// time-of-flight camera sees at a mirror (sim::SimOptions::glint); --inside-crossings counts a returned
// beam's crossing only at a surface's inside (ExplainOptions::returned_crossing_inside);
// --close-wall-gaps closes the gaps of seen walls that nothing seen through them shows to be an
// opening (ExplainedPlanningParams::close_wall_gaps).
// --condition thesis runs every planner under the thesis condition of docs/experiments.md: the
// interval update's thesis preset (IntervalUpdate::thesis(), latching), floor returns cut out of
// each scan before insertion (given to the map's evidence, ExplainedMap::add_evidence, as the experiments program does)
// and the gain over unknown voxels, and every planner with the thesis' start and map rules (the
// rig's start rule leaves the start area unknown once the floor returns are cut: the look-around
// carves the band only with beams that end on something else).
//
//   ./build/examples/experiments/map_rules --material mirror --seeds 10 [--first-seed 1] [--rig one] [--frames-per-scan
//   5] [--resolution 0.1]
//       [--planners "explained,explained hazards"] [--annex] [--front-only] [--min-lying-misses 2] [--find-mirrors]
//       [--max-inconsistent-share 0.2] [--inside-crossings]
//       [--exact-blind-zone] [--clearance 0.035] [--passage-views [--passage-min-area 0.25]] [--driven-paths]
//       [--known-surfaces walls,closet,floor] [--open-group-hazards] [--close-wall-gaps] [--glint] [--condition thesis]
#include "common/cli.hpp"
#include "common/rigs.hpp"
#include "floor_cut_source.hpp"

#include <intervox/eval/ground_truth.hpp>
#include <intervox/grid/named_grids.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/plan/episode.hpp>
#include <intervox/plan/mobile_planner.hpp>
#include <intervox/raycast/vector_walks.hpp>
#include <intervox/sim/scenes.hpp>
#include <intervox/sim/source.hpp>
#include <intervox/update/interval_update.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <map>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace {

namespace iv = intervox;

struct Options {
  std::string material = "diffuse";
  std::string rig = "eight";
  /// "defaults": the library's update and gain, every return inserted; "thesis": the thesis
  /// condition of docs/experiments.md (IntervalUpdate::thesis(), floor returns cut at 5 cm, the gain
  /// over unknown voxels, the thesis' start and map rules for every planner).
  std::string condition = "defaults";
  int seeds = 10;
  int first_seed = 1;  ///< the runs take seeds first_seed .. first_seed + seeds - 1
  int max_steps = 30;
  int frames_per_scan = 1;
  double resolution = 0.05;
  bool annex = false, front_only = false;                        ///< LabRoomOptions::annex, closet_front_only
  int min_lying_misses = iv::ExplainOptions{}.min_lying_misses;  ///< the explained planners' channel
  bool inside_crossings = false;  ///< ExplainOptions::returned_crossing_inside for the explained planners' channel
  bool find_mirrors = false;      ///< ExplainedPlanningParams::find_mirrors for the explained planners
  bool open_groups = false;       ///< ExplainedPlanningParams::open_group_hazards for "explained hazards"
  bool close_gaps = false;        ///< ExplainedPlanningParams::close_wall_gaps for the explained planners
  bool glint = false;             ///< sim::SimOptions::glint: the near-normal glint of a ToF camera at the mirror
  double max_inconsistent_share = iv::LyingSurfaceParams{}.max_inconsistent_share;  ///< ... its opacity test
  bool exact_blind = false;  ///< MobilePlannerParams::exact_blind_zone for every planner
  double clearance = -1;     ///< ExplorationMapParams::clearance for every planner (< 0: each planner's own)
  bool passages = false;     ///< MobilePlannerParams::passage_views for every planner
  bool driven = false;       ///< MobilePlannerParams::driven_paths for every planner
  double passage_min_area = iv::PassageViewParams{}.min_hidden_area;          ///< ... its min_hidden_area
  std::vector<std::string> planners{"thesis rules", "library", "explained"};  ///< "explained hazards" on request
  /// Surfaces the explained planners are told (ExplainedPlanningParams::known_surfaces): "walls"
  /// (the floor plan, sim::lab_floor_plan()), "closet" (sim::lab_closet_surfaces()) and/or "floor"
  /// (the plane z = 0 under the whole region: a beam that would have met it within range but
  /// returned nothing is suspect).
  std::vector<std::string> known;
};

struct Row {
  std::string termination;
  int steps = 0;
  double known = 0, distance = 0;
  double annex_known = 0;  ///< with --annex: the annex's reachable floor known (floor_coverage over its part)
  std::map<std::string, std::size_t> met;      // object -> poses within the robot radius
  std::size_t mirrors = 0;                     ///< with --find-mirrors: mirrors the planner's channel knows at the end
  std::vector<iv::PlanePatch> mirror_patches;  ///< ... and their patches
};

iv::sim::SimOptions sim_options(const Options& o) {
  iv::sim::SimOptions so;
  so.glint = o.glint;
  return so;
}

Row run_once(const Options& o, const std::string& config, std::uint64_t seed) {
  iv::sim::LabRoomOptions ro;
  ro.closet_material = iv::sim::material_from_string(o.material);
  ro.annex = o.annex;
  ro.closet_front_only = o.front_only;
  const iv::sim::LabRoom lab = iv::sim::make_lab_room(ro);
  const bool thesis = o.condition == "thesis";
  using Update = iv::IntervalGrid::UpdateType;
  iv::IntervalGrid empty(o.resolution, thesis ? Update::thesis() : Update{});
  iv::MobilePlannerParams p;
  p.region = iv::Bounds{{0.0, 0.0, 0.2}, {8.0, 6.0, 0.8}};  // the lab room's floor
  if (lab.annex_interior)                                   // and the annex's, behind the doorway
    p.region = iv::Bounds{{0.0, 0.0, 0.2}, {lab.annex_interior->max.x(), lab.annex_interior->max.y(), 0.8}};
  p.seed = seed;
  p.threads = 1;
  p.max_steps = o.max_steps;
  p.frames_per_scan = o.frames_per_scan;
  if (thesis) p.gain.voxels = iv::GainVoxels::Unknown;
  // The thesis' start rule and map (whole columns within 1 m free, hits not blocking): the "thesis
  // rules" planner's, and under the thesis condition every planner's, as in the experiments
  // program. With the floor returns cut, the rig's own start rule leaves the start area unknown.
  if (config == "thesis rules" || thesis) {
    p.start_free_radius = 1.0;
    p.start_free_columns = true;
    p.hits_block = false;
  }
  p.explained.enabled = config == "explained" || config == "explained hazards";
  p.explained.unexplained_hazards = config == "explained hazards";
  p.explained.explain.min_lying_misses = o.min_lying_misses;
  p.explained.explain.returned_crossing_inside = o.inside_crossings;
  p.explained.find_mirrors = o.find_mirrors;
  p.explained.open_group_hazards = o.open_groups;
  p.explained.close_wall_gaps = o.close_gaps;
  p.explained.lying.max_inconsistent_share = o.max_inconsistent_share;
  for (const std::string& k : o.known) {
    if (k == "floor") {  // the plane the robot drives on, under the whole region
      p.explained.known_surfaces.push_back(iv::sim::box_face(*p.region, 2, lab.interior.min.z()));
      continue;
    }
    for (const iv::PlanePatch& s : k == "walls" ? iv::sim::lab_floor_plan(lab) : iv::sim::lab_closet_surfaces(lab))
      p.explained.known_surfaces.push_back(s);
  }
  p.exact_blind_zone = o.exact_blind;
  if (o.clearance >= 0) p.map.clearance = o.clearance;
  p.passage_views.enabled = o.passages;
  p.driven_paths = o.driven;
  p.passage_views.min_hidden_area = o.passage_min_area;
  const iv::SensorRig rig = o.rig == "one" ? examples::front_camera_rig() : iv::SensorRig::mobile_base();
  iv::MobilePlanner planner(rig, p);
  auto map = planner.make_map(std::move(empty));
  const iv::IntervalGrid& grid = map.grid();
  // Under the thesis condition the floor returns (at or below 5 cm) never reach the grid; the
  // map's evidence is told they returned (ExplainedMap::add_evidence), as in the experiments program.
  iv::Episode episode(
      map, planner,
      experiments::FloorCutSource{iv::sim::SimulatedRig(lab.scene, rig, seed, sim_options(o)), thesis, 0.05, nullptr,
                                  [&](std::span<const iv::Beam> cut) { map.add_evidence(cut); }},
      iv::planar_pose(lab.start, 0.0));
  Row r;
  r.termination = std::string(iv::to_string(episode.run()));
  r.steps = planner.steps() - 1;
  r.known = iv::floor_coverage(grid, lab.scene, *p.region, p.map, lab.start).known;
  if (lab.annex_interior) {
    const iv::Bounds annex{{lab.annex_doorway->min.x(), lab.annex_interior->min.y(), 0.0}, lab.annex_interior->max};
    r.annex_known = iv::floor_coverage(grid, lab.scene, *p.region, p.map, lab.start, annex).known;
  }
  r.distance = episode.distance_driven();
  if (map.explained()) {  // the mirrors found (the known surfaces come first)
    const std::vector<iv::PlanePatch>& m = map.explained()->mirrors();
    r.mirror_patches.assign(m.begin() + static_cast<std::ptrdiff_t>(p.explained.known_surfaces.size()), m.end());
    r.mirrors = r.mirror_patches.size();
  }
  for (const iv::ObjectCollisions& c : iv::collisions_by_object(
           lab.scene, grid.geometry(), episode.trajectory(), p.map.robot_radius, p.floor_clearance, p.obstacle_height))
    r.met[c.name] = c.poses;
  return r;
}

double mean(const std::vector<double>& v) {
  double s = 0;
  for (const double x : v) s += x;
  return v.empty() ? 0.0 : s / double(v.size());
}
double sd(const std::vector<double>& v) {
  if (v.size() < 2) return 0.0;
  const double m = mean(v);
  double s = 0;
  for (const double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / double(v.size() - 1));
}

int run(const Options& o) {
  const std::vector<std::string>& configs = o.planners;
  std::printf("%s condition: ", o.condition.c_str());
  std::printf(
      "lab room%s, closet %s%s, %s camera(s), interval-mean + max-entropy, %.3f m, %d steps at most, %d frame(s) per "
      "scan, "
      "seeds %d-%d%s%s%s%s%s%s\n",
      o.annex ? " with the annex" : "", o.material.c_str(), o.front_only ? " (front only)" : "", o.rig.c_str(),
      o.resolution, o.max_steps, o.frames_per_scan, o.first_seed, o.first_seed + o.seeds - 1,
      o.passages ? (", passage views (hiding at least " + std::to_string(o.passage_min_area) + " m²)").c_str() : "",
      o.driven ? ", the way back (driven paths)" : "",
      o.known.empty() ? "" : (", known surfaces: " + CLI::detail::join(o.known, ",")).c_str(),
      o.open_groups ? ", open group hazards" : "", o.close_gaps ? ", closed wall gaps" : "",
      o.glint ? ", near-normal glint" : "");
  if (o.clearance >= 0)
    std::printf("every planner keeps %.3f m beyond the robot radius (ExplorationMapParams::clearance)\n", o.clearance);
  std::printf("%-13s %4s  %-22s %5s %7s %8s %7s  %s\n", "planner", "seed", "termination", "steps", "known%", "dist_m",
              o.annex ? "annex%" : "", "met (poses)");
  std::map<std::string, std::vector<Row>> rows;
  for (const std::string& c : configs)
    for (int s = o.first_seed; s < o.first_seed + o.seeds; ++s) {
      const Row r = run_once(o, c, static_cast<std::uint64_t>(s));
      std::string met;
      for (const auto& [name, n] : r.met) met += name + ":" + std::to_string(n) + " ";
      const std::string annex = o.annex ? std::to_string(static_cast<int>(std::lround(100 * r.annex_known))) : "";
      std::printf("%-13s %4d  %-22s %5d %7.1f %8.1f %7s  %s%s\n", c.c_str(), s, r.termination.c_str(), r.steps,
                  100 * r.known, r.distance, annex.c_str(), met.empty() ? "-" : met.c_str(),
                  o.find_mirrors ? ("  (mirrors told: " + std::to_string(r.mirrors) + ")").c_str() : "");
      for (const iv::PlanePatch& m : r.mirror_patches)
        std::printf("    mirror at (%.2f, %.2f, %.2f), normal (%.2f, %.2f, %.2f), %.2f m x %.2f m\n", m.center.x(),
                    m.center.y(), m.center.z(), m.normal.x(), m.normal.y(), m.normal.z(), 2 * m.half_u, 2 * m.half_v);
      rows[c].push_back(r);
    }
  std::printf("\n| planner | runs with a collision | objects met (runs) | steps | floor known %% | m driven | ended "
              "before the budget |%s\n",
              o.annex ? " annex floor known % | runs with ≥ 90 % of the annex known |" : "");
  std::printf("|---|---:|---|---:|---:|---:|---:|%s\n", o.annex ? "---:|---:|" : "");
  for (const std::string& c : configs) {
    std::vector<double> steps, known, dist, annex;
    std::map<std::string, int> objects;
    int colliding = 0, ended = 0, annex_known = 0;
    for (const Row& r : rows[c]) {
      steps.push_back(r.steps);
      known.push_back(100 * r.known);
      dist.push_back(r.distance);
      annex.push_back(100 * r.annex_known);
      annex_known += r.annex_known >= 0.9 ? 1 : 0;
      colliding += r.met.empty() ? 0 : 1;
      ended += r.termination == "budget" ? 0 : 1;
      for (const auto& [name, n] : r.met) ++objects[name];
    }
    std::string met;
    for (const auto& [name, n] : objects) met += (met.empty() ? "" : ", ") + name + " " + std::to_string(n);
    std::printf("| %s | %d of %zu | %s | %.1f ± %.1f | %.1f ± %.1f | %.1f ± %.1f | %d |", c.c_str(), colliding,
                rows[c].size(), met.empty() ? "-" : met.c_str(), mean(steps), sd(steps), mean(known), sd(known),
                mean(dist), sd(dist), ended);
    if (o.annex) std::printf(" %.1f ± %.1f | %d |", mean(annex), sd(annex), annex_known);
    std::printf("\n");
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  intervox::use_vector_walks();  // the AVX-512 / AVX2 walks where the processor has them
  Options o;
  CLI::App app{"Intervox map_rules: the lab room with the thesis' map rules and the library's, plain and explained "
               "planners, per seed and summarised (docs/planning.md)."};
  app.add_option("--material", o.material, "closet material")
      ->check(examples::one_of(intervox::sim::kMaterialNames))
      ->capture_default_str();
  app.add_option(
         "--condition", o.condition,
         "defaults: the library's update and gain; thesis: IntervalUpdate::thesis(), floor returns cut at 5 cm, "
         "the gain over unknown voxels, the thesis' start and map rules for every planner (docs/experiments.md, "
         "\"Conditions\")")
      ->check(CLI::IsMember({"defaults", "thesis"}))
      ->capture_default_str();
  app.add_option("--rig", o.rig, "eight: the thesis' base; one: one forward camera")
      ->check(CLI::IsMember({"eight", "one"}))
      ->capture_default_str();
  app.add_option("--seeds", o.seeds, "how many seeds: first-seed .. first-seed + n - 1")
      ->check(examples::integer_in(1, 1000))
      ->capture_default_str();
  app.add_option("--first-seed", o.first_seed, "the first seed (1 by default)")
      ->check(examples::integer_in(1, 1000000))
      ->capture_default_str();
  app.add_option("--max-steps", o.max_steps, "step budget")
      ->check(examples::integer_in(1, 1000))
      ->capture_default_str();
  app.add_option("--frames-per-scan", o.frames_per_scan,
                 "frames at every scan pose (MobilePlannerParams::frames_per_scan; one camera with interval-mean: 5)")
      ->check(examples::integer_in(1, 20))
      ->capture_default_str();
  app.add_flag("--annex", o.annex,
               "an open doorway in the east wall to an annex room (LabRoomOptions::annex; its floor scored apart)");
  app.add_flag("--front-only", o.front_only,
               "the closet's material on its front only, its body wood (LabRoomOptions::closet_front_only)");
  app.add_option("--max-inconsistent-share", o.max_inconsistent_share,
                 "with --find-mirrors: the region analysis' opacity test (LyingSurfaceParams::max_inconsistent_share; "
                 "1: off, the default)")
      ->check(CLI::Range(0.0, 1.0));
  app.add_flag("--find-mirrors", o.find_mirrors,
               "the explained planners find mirrors before every plan and tell the channel "
               "(ExplainedPlanningParams::find_mirrors)");
  app.add_flag("--open-group-hazards", o.open_groups,
               "with explained hazards: the lying columns of groups open to unexplored space keep the robot off too "
               "(ExplainedPlanningParams::open_group_hazards)");
  app.add_flag("--close-wall-gaps", o.close_gaps,
               "the explained planners close the gaps of seen walls that are no opening "
               "(ExplainedPlanningParams::close_wall_gaps)");
  app.add_flag(
      "--glint", o.glint,
      "the simulated cameras see the near-normal glint of specular surfaces (sim::SimOptions::glint, default angle)");
  app.add_option("--clearance", o.clearance,
                 "m kept beyond the robot radius by every planner (ExplorationMapParams::clearance; default: each "
                 "planner's own, 0)")
      ->check(examples::number_in(0.0, 1.0));
  app.add_flag("--exact-blind-zone", o.exact_blind,
               "the start rule walks the look-around's beams through the grid, for every planner "
               "(MobilePlannerParams::exact_blind_zone)");
  app.add_flag("--passage-views", o.passages,
               "views that open passages closed by unknown columns seen too few times, for every planner "
               "(MobilePlannerParams::passage_views)");
  app.add_flag("--driven-paths", o.driven,
               "the way back: cells of the paths the robot drove stay passable, for every planner "
               "(MobilePlannerParams::driven_paths)");
  app.add_option(
         "--passage-min-area", o.passage_min_area,
         "with --passage-views: the least unknown floor a passage hides [m²] (PassageViewParams::min_hidden_area)")
      ->check(examples::number_in(0.0, 1e6))
      ->capture_default_str();
  app.add_option(
         "--min-lying-misses", o.min_lying_misses,
         "suspect misses that make a voxel lying, for the explained planners (ExplainOptions::min_lying_misses)")
      ->check(examples::integer_in(1, 65535))
      ->capture_default_str();
  app.add_flag("--inside-crossings", o.inside_crossings,
               "a returned beam's crossing counts only at a surface's inside, for the explained planners' channel "
               "(ExplainOptions::returned_crossing_inside)");
  app.add_option("--resolution", o.resolution, "voxel edge length [m]")
      ->check(examples::number_in(0.02, 0.5))
      ->capture_default_str();
  app.add_option(
         "--known-surfaces", o.known,
         "surfaces the explained planners are told (ExplainedPlanningParams::known_surfaces): walls (the floor plan, "
         "openings left out), closet (its surfaces of --material) and/or floor (z = 0 under the region), "
         "comma-separated")
      ->delimiter(',')
      ->check(CLI::IsMember({"walls", "closet", "floor"}));
  app.add_option("--planners", o.planners, "configurations to run, in this order (comma-separated)")
      ->delimiter(',')
      ->check(CLI::IsMember({"thesis rules", "library", "explained", "explained hazards"}))
      ->capture_default_str();
  return examples::cli_main("map_rules", app, argc, argv, [&] { return run(o); });
}
