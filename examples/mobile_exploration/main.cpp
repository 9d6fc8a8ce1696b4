// Autonomous exploration of the simulated lab room with the mobile base (thesis chapters 3.3-3.5,
// 4.3.2, 5.3-5.4). Writes the exploration map of every step as a PNG and a summary.
//
// The update x utility combination is a compile-time choice: every offered combination is
// instantiated (examples/common/policies.hpp) and --update / --utility pick one at run time.
#include <intervox/analysis/conflicts.hpp>
#include <intervox/eval/conflict_scoring.hpp>
#include <intervox/eval/ground_truth.hpp>
#include <intervox/intervox.hpp>
#include <intervox/view/exploration_image.hpp>
#include <intervox/view/html_view.hpp>
#include <intervox/plan/episode.hpp>
#include <intervox/plan/mobile_planner.hpp>
#include <intervox/raycast/raycast.hpp>
#include <intervox/sim/sim.hpp>
#include <intervox/raycast/vector_walks.hpp>

#include "common/cli.hpp"
#include "common/output_lock.hpp"
#include "common/policies.hpp"

#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace iv = intervox;

namespace {

struct Options {
  std::string update = "interval-mean";
  std::string utility = "max-entropy";
  std::string material = "diffuse";
  std::string planner = "plain";
  std::uint64_t seed = 1;
  std::string out = "out/mobile_exploration";
  int max_steps = 30;
  double resolution = 0.05;
  unsigned threads = 0;
  int gain_stride = 4;
  int scale = 4;
  int ring_positions = iv::RingSamplerParams{}.positions;
  int ring_orientations = iv::RingSamplerParams{}.orientations;
  int frontier_attempts = iv::MobilePlannerParams{}.frontier_attempts;
  double ledger_mb =
      double(iv::ExplainOptions{}.ledger_bytes) / (1024.0 * 1024.0);  ///< explained planner's revision ledger
  int revision_interval = iv::ExplainOptions{}.revision_interval;
  bool unexplained_hazards = false;  ///< explained planner: ExplainedPlanningParams::unexplained_hazards
  bool annex = false;                ///< LabRoomOptions::annex: an open doorway to an annex room
  bool passage_views = false;        ///< MobilePlannerParams::passage_views
  bool driven_paths = false;         ///< MobilePlannerParams::driven_paths
};

template <class Grid>
int run(const Options& o) {
  iv::sim::LabRoomOptions room_options;
  room_options.closet_material = iv::sim::material_from_string(o.material);
  room_options.annex = o.annex;
  const iv::sim::LabRoom lab = iv::sim::make_lab_room(room_options);
  iv::MobilePlannerParams p;
  p.region = iv::Bounds{{0.0, 0.0, 0.2}, {8.0, 6.0, 0.8}};  // the lab room's floor
  if (lab.annex_interior)                                   // and the annex's
    p.region = iv::Bounds{{0.0, 0.0, 0.2}, {lab.annex_interior->max.x(), lab.annex_interior->max.y(), 0.8}};
  p.passage_views.enabled = o.passage_views;
  p.driven_paths = o.driven_paths;
  p.start_free_radius = 1.0;    // the thesis' start rule: whole columns within 1 m (the library's default: the
  p.start_free_columns = true;  // voxels the rig cannot see within its blind zone, 1.50 m)
  p.hits_block = false;         // the thesis' map: unclassified voxels are unknown, whatever their hits
  p.seed = o.seed;
  p.threads = o.threads;
  p.max_steps = o.max_steps;
  p.gain_stride = o.gain_stride;
  p.ring.positions = o.ring_positions;
  p.ring.orientations = o.ring_orientations;
  p.frontier_attempts = o.frontier_attempts;
  p.conflicts.enabled = o.planner == "conflict-aware";
  p.explained.enabled = o.planner == "explained";
  p.explained.explain.ledger_bytes = static_cast<std::size_t>(o.ledger_mb * 1024.0 * 1024.0);
  p.explained.explain.revision_interval = o.revision_interval;
  p.explained.unexplained_hazards = o.unexplained_hazards;
  constexpr bool interval = iv::IntervalPolicy<typename Grid::UpdateType>;
  if (p.conflicts.enabled && !interval)
    throw iv::InvalidArgument(
        "--planner conflict-aware needs an interval update (a Bayes grid cannot tell conflicts from ignorance)");
  const iv::SensorRig rig = iv::SensorRig::mobile_base();
  const iv::Pose start = iv::planar_pose(lab.start, 0.0);
  iv::MobilePlanner planner(rig, p);
  // The map: the grid and, for the explained planner, its evidence (the planner only reads it).
  auto state = planner.make_map(Grid(o.resolution));
  const Grid& grid = state.grid();
  // The simulator labels every beam (direct, reflected, passed, no return): the ground truth of
  // conflict voxels for the detector's precision and recall in the summary.
  const iv::Bounds truth_region{{-0.5, -0.5, -0.2}, {8.5, 6.5, 3.2}};
  iv::ConflictEvidence evidence(grid.geometry(), lab.scene, truth_region, planner.max_range());
  iv::sim::SimulatedRig sim(lab.scene, rig, o.seed);
  auto source = [&](const iv::Pose& body) {
    std::vector<iv::Beam> beams = sim(body);
    evidence.add(beams, sim.last_paths());
    return beams;
  };
  iv::Episode episode(state, planner, std::ref(source), start);
  auto known = [&] { return iv::floor_coverage(grid, lab.scene, *p.region, p.map, start.translation()); };
  // One run per output folder: a second run into it is refused instead of mixing their files.
  const examples::OutputFolderLock lock(o.out);
  std::printf("mobile exploration: %s + %s, %s planner, closet %s, seed %llu, %.3f m voxels -> %s/\n",
              std::string(Grid::UpdateType::kName).c_str(), std::string(Grid::UtilityType::kName).c_str(),
              o.planner.c_str(), o.material.c_str(), static_cast<unsigned long long>(o.seed), o.resolution,
              o.out.c_str());
  std::printf("%4s %-9s %10s %10s %8s %9s %9s %10s %8s %9s\n", "step", "reason", "gain", "candidates", "path m",
              "plan s", "total s", "known %", "regions", "collide");
  double total_time = 0;
  for (;;) {
    const auto& s = episode.step();
    const iv::MobilePlan& r = s.plan;
    total_time += s.seconds_total;
    // The picture of the step: the map it planned on, with frontier, ring, samples and choice.
    const iv::ExplorationMap map = r.map ? *r.map : planner.exploration_map(state, episode.pose());
    iv::MapOverlay ov;
    ov.frontier = r.frontier;
    if (r.frontier) ov.ring = p.ring;
    for (const auto& c : r.candidates) ov.sampled.push_back(c.cell);
    if (r.selected) ov.selected = r.candidates[*r.selected].cell;
    auto cell = [&](const iv::Pose& q) { return map.columns().cell_of_key(grid.key(q.translation())); };
    for (const iv::Pose& q : episode.trajectory()) ov.path.push_back(cell(q));
    for (const auto& done : episode.steps())
      for (const iv::Pose& q : done.plan.scans) ov.views.push_back(cell(q));
    char name[64];
    std::snprintf(name, sizeof name, "/step_%03d.png", s.step);
    iv::ImageLabels labels{"step " + std::to_string(s.step), true, true, 0};
    iv::write_png(o.out + name, iv::render_exploration_map(map, ov, o.scale, labels));
    std::size_t given_up = 0;
    for (const auto& g : r.regions) given_up += g.unresolvable;
    char regions[32];
    std::snprintf(regions, sizeof regions, "%zu/%zu", given_up, r.regions.size());
    const std::string reason = r.termination == iv::Termination::Running ? std::string(iv::to_string(r.reason))
                                                                         : std::string(iv::to_string(r.termination));
    // Poses of this step's path and scans where the robot meets the true scene (the simulator's
    // ground truth; a real robot has none).
    std::vector<iv::Pose> driven = r.path;
    driven.insert(driven.end(), r.scans.begin(), r.scans.end());
    const std::size_t hits = iv::count_collisions(lab.scene, grid.geometry(), driven, p.map.robot_radius,
                                                  p.floor_clearance, p.obstacle_height);
    std::printf("%4d %-9s %10.1f %10zu %8.2f %9.3f %9.3f %10.1f %8s %9zu\n", s.step, reason.c_str(), r.gain,
                r.candidates.size(), r.path_length, s.seconds_planning, s.seconds_total, 100.0 * known().known,
                p.conflicts.enabled ? regions : "-", hits);
    if (r.termination != iv::Termination::Running) break;
  }
  const iv::ExplorationMap final_map = planner.exploration_map(state, episode.pose(), *p.region);
  iv::MapOverlay final_overlay;
  for (const iv::Pose& q : episode.trajectory())
    final_overlay.path.push_back(final_map.columns().cell_of_key(grid.key(q.translation())));
  for (const auto& done : episode.steps())
    for (const iv::Pose& q : done.plan.scans)
      final_overlay.views.push_back(final_map.columns().cell_of_key(grid.key(q.translation())));
  iv::write_png(o.out + "/final.png",
                iv::render_exploration_map(final_map, final_overlay, o.scale, {"final map", true, true, 0}));
  // The 3D page of the final map with the path driven and the views taken (needs libjs-three).
  iv::ViewScene scene{episode.trajectory(), {}, rig, 0.5, {}};
  for (const auto& s : episode.steps()) scene.scans.insert(scene.scans.end(), s.plan.scans.begin(), s.plan.scans.end());
  std::optional<iv::ConflictReport> conflicts;
  if constexpr (interval) {
    conflicts = iv::detect_conflicts(grid);
    for (std::size_t i = 0; i < conflicts->regions.size(); ++i)
      scene.regions.push_back(
          {conflicts->regions[i].bounds,
           "conflict " + std::to_string(i) + " (" + std::to_string(conflicts->regions[i].size()) + " voxels)"});
  }
  iv::HtmlViewOptions view;
  view.color = iv::ColorBy::Table52;
  view.shown = {true, false, false};  // occupied first; unknown and free voxels behind their switches
  view.title = "mobile exploration: " + std::string(Grid::UpdateType::kName) + ", seed " + std::to_string(o.seed);
  iv::write_html_view(o.out + "/final.html", grid, view, scene);
  const iv::VoxelErrors e = iv::evaluate_voxels(grid, lab.scene, *planner.gain_options(*p.region).bounds);
  const iv::FloorCoverage floor = known();
  const std::size_t collisions = iv::count_collisions(lab.scene, grid.geometry(), episode.trajectory(),
                                                      p.map.robot_radius, p.floor_clearance, p.obstacle_height);
  std::printf("\nsummary\n");
  std::printf("  termination              %s after %d steps\n",
              std::string(iv::to_string(episode.termination())).c_str(), planner.steps() - 1);
  std::printf("  reachable area explored  %.1f %% of %.2f m2\n", 100.0 * floor.known, floor.area);
  std::printf("  voxels wrongly occupied  %zu\n", e.wrongly_occupied);
  std::printf("  voxels wrongly free      %zu\n", e.wrongly_free);
  std::printf("  distance driven          %.2f m (%zu poses in collision)\n", episode.distance_driven(), collisions);
  std::printf("  time per step            %.3f s (total %.2f s)\n", total_time / std::max(1, planner.steps()),
              total_time);
  if (const iv::ExplainedSpace* e = state.explained()) {
    const iv::ExplainedSpace::RevisionStats& r = e->revision_stats();
    std::printf(
        "  explained evidence       %.1f MiB, ledger %.1f MiB of %.1f (%zu scans kept, %llu forgotten); revision moved "
        "%llu beams to suspect, %llu to trusted\n",
        double(e->memory_bytes()) / (1024.0 * 1024.0), double(e->ledger().bytes()) / (1024.0 * 1024.0),
        double(e->ledger().budget()) / (1024.0 * 1024.0), e->ledger().scans().size(),
        (unsigned long long)e->ledger().forgotten(), (unsigned long long)r.to_suspect,
        (unsigned long long)r.to_trusted);
  }
  if constexpr (interval) {
    const iv::ConflictScore score = iv::score_conflicts(grid, *conflicts, evidence);
    std::printf("  conflict regions         %zu (%zu voxels; %zu with the signature, %zu of them surface fringe)\n",
                conflicts->regions.size(), score.flagged, conflicts->signature_voxels, conflicts->fringe_voxels);
    std::printf(
        "  conflict detection       precision %.3f (%.3f within one voxel), recall %.3f of %zu true conflict voxels\n",
        score.precision(), score.near_precision(), score.recall(), score.truth);
    std::printf("  surface-edge voxels      %.2f %% flagged (%zu of %zu)\n", 100.0 * score.edge_rate(),
                score.edge_flagged, score.edge_voxels);
  }
  std::printf("  pictures                 %s/step_*.png, %s/final.png, 3D: %s/final.html\n", o.out.c_str(),
              o.out.c_str(), o.out.c_str());
  return 0;
}

/// Every update with entropy and max-entropy, except the credal cells, which take the two criteria
/// that see their interval (max-entropy, total uncertainty).
struct Offer {
  template <class U, class H>
  static constexpr bool offers() {
    if constexpr (examples::kCredalUpdate<U>)
      return !std::is_same_v<H, iv::Entropy>;
    else
      return !std::is_same_v<H, iv::TotalUncertainty>;
  }
};

}  // namespace

int main(int argc, char** argv) {
  intervox::use_vector_walks();  // the AVX-512 / AVX2 walks where the processor has them
  Options o;
  CLI::App app{"Intervox: autonomous exploration of the simulated lab room by the mobile base (thesis ch. 3-5).\n"
               "Writes the exploration map of every step (colours of the thesis' Table 3.2) and a summary."};
  app.add_option(
         "--update", o.update,
         "update policy (compact-interval-mean: interval-mean in 4 bytes per voxel; dirichlet-mean, belief-mean: "
         "the credal cells, with max-entropy or total-uncertainty)")
      ->check(CLI::IsMember(examples::offered_updates<Offer>()))
      ->capture_default_str();
  app.add_option("--utility", o.utility, "utility policy for the information gain")
      ->check(CLI::IsMember(examples::offered_utilities<Offer>()))
      ->capture_default_str();
  app.add_option("--material", o.material,
                 "material of the closet against the west wall (specular = mirror: reflects the beams; "
                 "specular-random: the first edition's random range)")
      ->check(examples::one_of(iv::sim::kMaterialNames))
      ->capture_default_str();
  app.add_option("--planner", o.planner,
                 "plain: the thesis' planner; conflict-aware: plan around conflict regions (interval updates only); "
                 "explained: drive only where the beams explain free space (any update; docs/planning.md)")
      ->check(CLI::IsMember({"plain", "conflict-aware", "explained"}))
      ->capture_default_str();
  app.add_option("--ledger-mb", o.ledger_mb,
                 "explained planner: revision ledger budget [MiB] (0: every beam keeps the class of its arrival)")
      ->check(examples::number_in(0.0, 65536.0))
      ->capture_default_str();
  app.add_option("--revision-interval", o.revision_interval, "explained planner: scans between two revisions")
      ->check(examples::integer_in<int>(1, 1000))
      ->capture_default_str();
  app.add_flag("--unexplained-hazards", o.unexplained_hazards,
               "explained planner: keep the robot radius from enclosed columns only lying beams made free (opt-in;\n"
               "docs/planning.md: in the lab room more runs use the step budget)");
  app.add_flag("--annex", o.annex, "an open doorway in the east wall to an annex room (LabRoomOptions::annex)");
  app.add_flag("--passage-views", o.passage_views,
               "views that open passages such as a doorway whose far side was seen by too few scans\n"
               "(MobilePlannerParams::passage_views; docs/planning.md, \"Doors and passages\")");
  app.add_flag(
      "--driven-paths", o.driven_paths,
      "the way back: cells of the paths the robot drove stay passable, so that evidence gathered since cannot\n"
      "shut it into a pocket (MobilePlannerParams::driven_paths; docs/planning.md, \"The way back\")");
  app.add_option("--seed", o.seed, "seed of sensor noise and candidate sampling")
      ->check(examples::integer_in<std::uint64_t>())
      ->capture_default_str();
  app.add_option("--out", o.out, "output folder (created as needed)")->capture_default_str();
  app.add_option("--max-steps", o.max_steps, "exploration step budget")
      ->check(examples::integer_in<int>(0))
      ->capture_default_str();
  app.add_option("--resolution", o.resolution, "voxel edge length in metres")
      ->check(examples::number_in(0.02, 0.5))
      ->capture_default_str();
  app.add_option("--threads", o.threads, "threads for candidate evaluation (0: all cores)")
      ->check(examples::integer_in<unsigned>())
      ->capture_default_str();
  app.add_option("--gain-stride", o.gain_stride, "cast every n-th pixel row and column for the gain")
      ->check(examples::integer_in(1, 64))
      ->capture_default_str();
  app.add_option("--ring-positions", o.ring_positions, "candidate positions drawn on the ring around a frontier")
      ->check(examples::integer_in(1, 1000))
      ->capture_default_str();
  app.add_option("--ring-orientations", o.ring_orientations, "candidate headings per ring position")
      ->check(examples::integer_in(1, 64))
      ->capture_default_str();
  app.add_option("--frontier-attempts", o.frontier_attempts, "frontiers tried per step before the episode ends")
      ->check(examples::integer_in(1, 1000))
      ->capture_default_str();
  app.add_option("--scale", o.scale, "pixels per map cell in the pictures")
      ->check(examples::integer_in(1, 16))
      ->capture_default_str();
  app.callback([&] {
    if (const std::string error = examples::offer_error<Offer>(o.update, o.utility); !error.empty())
      throw CLI::ValidationError("--utility", error);
  });
  // Bad options: "mobile_exploration: error: ..." and exit code 2; failures while running (an
  // output folder that cannot be created or written, ...): the same line and exit code 1.
  return examples::cli_main("mobile_exploration", app, argc, argv, [&] {
    return examples::with_policies<Offer, int>(o.update, o.utility,
                                               [&]<class U, class H>() { return run<iv::VoxelGrid<U, H>>(o); });
  });
}
