// Autonomous object modelling in the simulated workcell with the arm's laser striper (thesis
// chapters 3.4, 4.3.2, 5.1, 5.5). Writes a top-down projection of the object's voxels after every
// view as a PNG, the model as PLY (the grid's occupied voxels and the explained-occupied ones) and a
// summary.
//
// The update x utility combination is a compile-time choice: every offered combination is
// instantiated (examples/common/policies.hpp) and --update / --utility pick one at run time.
#include <intervox/analysis/conflicts.hpp>
#include <intervox/core/key_set.hpp>
#include <intervox/eval/ground_truth.hpp>
#include <intervox/explain/explained_space.hpp>
#include <intervox/intervox.hpp>
#include <intervox/view/html_view.hpp>
#include <intervox/io/ply_writer.hpp>
#include <intervox/io/png.hpp>
#include <intervox/view/slice.hpp>
#include <intervox/plan/arm_planner.hpp>
#include <intervox/plan/episode.hpp>
#include <intervox/plan/explained_planning.hpp>
#include <intervox/raycast/raycast.hpp>
#include <intervox/sim/sim.hpp>
#include <intervox/raycast/vector_walks.hpp>

#include "common/cli.hpp"
#include "common/policies.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

namespace iv = intervox;

namespace {

struct Options {
  std::string update = "interval-mean";
  std::string utility = "max-entropy";
  std::string object = "part";
  std::string material = "diffuse";
  std::string planner = "plain";
  std::uint64_t seed = 1;
  std::string out = "out/arm_modelling";
  int max_views = 12;
  int candidates = 16;
  double min_relative_gain = 0.002;
  double resolution = 0.01;
  double sphere_radius = 0.45;
  unsigned threads = 0;
  int scale = 0;
  bool seek_normals = false;
  double striper_baseline = iv::LaserStriper::kDefaultBaseline;
  double normals_weight = 1.0;
};

template <class Grid>
int run(const Options& o) {
  iv::sim::WorkcellOptions wo;
  const iv::sim::Material m = iv::sim::material_from_string(o.material);
  if (o.object == "part") wo.part_material = m;
  if (o.object == "bottle") wo.bottle_material = m;
  if (o.object == "box") wo.box_material = m;
  const iv::sim::Workcell cell = iv::sim::make_workcell(wo);
  iv::ArmPlannerParams p;
  p.object_region = cell.object_region(o.object, o.resolution);
  p.support_height = cell.table_center.z();
  p.sphere_radius = o.sphere_radius;
  p.candidates = o.candidates;
  p.min_relative_gain = o.min_relative_gain;
  p.max_views = o.max_views;
  p.threads = o.threads;
  p.seed = o.seed;
  constexpr bool interval = iv::IntervalPolicy<typename Grid::UpdateType>;
  p.conflicts.enabled = o.planner == "conflict-aware";
  p.explained.enabled = o.planner == "explained";
  p.normals.enabled = o.seek_normals;
  p.normals.weight = o.normals_weight;
  if (p.conflicts.enabled && !interval)
    throw iv::InvalidArgument(
        "--planner conflict-aware needs an interval update (a Bayes grid cannot tell conflicts from ignorance)");
  iv::ArmOptions arm;
  arm.striper.baseline = o.striper_baseline;
  iv::ArmPlanner planner(iv::SensorRig::arm(arm), p);
  // The explained model (docs/planning.md, "The arm's explained model"): every sweep's beams classed as trusted,
  // suspect (folded returns that end under the table, behind the backdrop or inside the part cross
  // surfaces other beams saw) or no return, their evidence kept beside the grid; the part's model
  // is its explained-occupied voxels, which suspect misses do not erase. The map keeps that
  // evidence whatever the planner reads of it (the explained planner reads it, the others only
  // read the grid).
  iv::ExplainedMapOptions kept = planner.map_options();
  kept.explained = true;
  iv::ExplainedMap<Grid> map(Grid(o.resolution, iv::Bounds{{0, 0, 0}, {1.5, 1.5, 1.5}}), kept,
                             planner.insert_options());
  const Grid& grid = map.grid();
  iv::Episode episode(map, planner, iv::sim::SimulatedRig(cell.scene, planner.rig(), o.seed), iv::Pose::Identity());
  auto coverage = [&] { return iv::surface_coverage(grid, cell.scene, p.object_region, p.support_height); };
  const iv::KeyBox region_keys = grid.geometry().key_box(p.object_region);
  // The explained model: the explained-occupied voxels of the object region.
  auto explained_model = [&] {
    std::vector<iv::Key> model;
    const iv::ExplainedSpace* space = map.explained();
    space->for_each([&](const iv::Key& k, const iv::EvidenceCell&) {
      if (region_keys.contains(k) && space->state(k) == iv::ExplainedState::Occupied) model.push_back(k);
    });
    std::sort(model.begin(), model.end());
    return model;
  };
  auto model_evaluation = [&] {
    return iv::evaluate_model(grid.geometry(), cell.scene, p.object_region, p.support_height, explained_model());
  };

  // Pictures: the object region and 5 cm around it, seen from above (maximum along z), leaving out
  // the voxel layer on the table top (where noisy hits on the table blacken the whole picture).
  iv::Bounds around = p.object_region;
  around.min -= iv::Point3(0.05, 0.05, 0.0);
  around.max += iv::Point3(0.05, 0.05, 0.0);
  iv::SliceOptions so;
  so.mode = iv::SliceMode::MaxProjection;
  so.window = grid.geometry().key_box(around);
  so.window->min.z = std::min(so.window->min.z + 1, so.window->max.z);
  // --scale 0: at least 480 pixels on the long side.
  so.pixels_per_voxel =
      o.scale > 0 ? o.scale
                  : std::clamp(static_cast<int>((480 + std::max(so.window->extent(0), so.window->extent(1)) - 1) /
                                                std::max(so.window->extent(0), so.window->extent(1))),
                               1, 64);

  std::filesystem::create_directories(o.out);
  std::printf("arm modelling: %s + %s, %s planner%s, %s %s, seed %llu, %.3f m voxels -> %s/\n",
              std::string(Grid::UpdateType::kName).c_str(), std::string(Grid::UtilityType::kName).c_str(),
              o.planner.c_str(), o.seek_normals ? " seeking normals" : "", o.material.c_str(), o.object.c_str(),
              static_cast<unsigned long long>(o.seed), o.resolution, o.out.c_str());
  // coverage %: the visible surface the grid holds occupied; model %: the share the explained model holds.
  std::printf("%4s %5s %-9s %10s %10s %9s %9s %10s %8s %9s\n", "step", "views", "reason", "gain", "candidates",
              "plan s", "total s", "coverage %", "model %", p.explained.enabled ? "refused u" : "regions");
  double total_time = 0;
  for (;;) {
    const auto& s = episode.step();
    const iv::ArmPlan& r = s.plan;
    total_time += s.seconds_total;
    // Why the view was chosen (initial, gain), or why the episode ended.
    const std::string reason = r.termination == iv::Termination::Running ? std::string(iv::to_string(r.reason))
                                                                         : std::string(iv::to_string(r.termination));
    // Conflict-aware: regions given up as unresolvable / regions found.
    std::size_t given_up = 0;
    for (const auto& pr : r.regions) given_up += pr.unresolvable;
    // Explained: sweeps refused for unexplained (or explained-occupied) space near them.
    const std::string regions =
        p.conflicts.enabled   ? std::to_string(given_up) + "/" + std::to_string(r.regions.size())
        : p.explained.enabled ? "u" + std::to_string(r.refused[static_cast<std::size_t>(iv::SweepRefusal::Unexplained)])
                              : "-";
    std::printf("%4d %5d %-9s %10.1f %7zu/%-2zu %9.3f %9.3f %10.1f %8.1f %9s\n", s.step, planner.views(),
                reason.c_str(), r.gain, r.candidates.size(), r.sampled, s.seconds_planning, s.seconds_total,
                100.0 * coverage().known, 100.0 * model_evaluation().coverage.known, regions.c_str());
    if (r.termination != iv::Termination::Running) break;
    char name[64];
    std::snprintf(name, sizeof name, "/view_%03d.png", planner.views());
    so.labels = {"view " + std::to_string(planner.views()) + ", from above", true, true, 0};
    iv::write_png(o.out + name, iv::render_slice(grid, so));
  }
  so.color = iv::ColorBy::Table52;
  so.labels.title = "final model, table 5.2 code";
  iv::write_png(o.out + "/final_table52.png", iv::render_slice(grid, so));
  // The 3D page of the final model with the flange path and the striper's sweeps (needs libjs-three).
  iv::ViewScene scene{episode.trajectory(), {}, planner.rig(), 0.3, {}};
  for (const auto& s : episode.steps()) {  // each sweep by its first and last profile
    if (s.plan.scans.empty()) continue;
    scene.scans.push_back(s.plan.scans.front());
    if (s.plan.scans.size() > 1) scene.scans.push_back(s.plan.scans.back());
  }
  iv::HtmlViewOptions view;
  view.color = iv::ColorBy::Table52;
  view.shown = {true, false, false};  // occupied first; unknown and free voxels behind their switches
  view.title =
      "arm modelling: " + o.object + ", " + std::string(Grid::UpdateType::kName) + ", seed " + std::to_string(o.seed);
  iv::write_html_view(o.out + "/final.html", grid, view, scene);
  const iv::VoxelErrors e = iv::evaluate_voxels(grid, cell.scene, p.object_region);
  const iv::SurfaceCoverage cov = coverage();
  std::printf("\nsummary\n");
  std::printf("  termination              %s after %d views\n",
              std::string(iv::to_string(episode.termination())).c_str(), planner.views());
  std::printf("  surface known occupied   %.1f %% of %zu visible surface voxels\n", 100.0 * cov.known, cov.voxels);
  std::printf("  voxels wrongly occupied  %zu\n", e.wrongly_occupied);
  std::printf("  voxels wrongly free      %zu (of %zu occupied in the object region)\n", e.wrongly_free,
              e.true_occupied);
  std::printf("  time per step            %.3f s (total %.2f s)\n",
              total_time / std::max<std::size_t>(1, episode.steps().size()), total_time);
  if constexpr (interval) {
    // Thesis ch. 6, "discard before meshing": the model without the conflict regions' voxels and
    // the occupied voxels next to them (model_voxels, distance 1).
    const iv::ConflictReport rep = iv::detect_conflicts(grid, {}, p.object_region);
    const std::vector<iv::Key> model = iv::model_voxels(grid, rep, 1, p.object_region);
    std::size_t occupied = 0;
    grid.for_each_observed([&](const iv::Key& k, const auto& c) {
      if (p.object_region.contains(grid.center(k)) && grid.update_policy().occupancy(c) == iv::Occupancy::Occupied)
        ++occupied;
    });
    std::printf("  conflict regions         %zu (%zu voxels) in the object region\n", rep.regions.size(),
                rep.conflict_voxels());
    std::printf("  model voxels             %zu of %zu occupied kept after discarding conflicts\n", model.size(),
                occupied);
  }
  // The explained model: what lying beams cannot erase (docs/planning.md, "The arm's explained model").
  const std::vector<iv::Key> model_keys = explained_model();
  const iv::ModelEvaluation em =
      iv::evaluate_model(grid.geometry(), cell.scene, p.object_region, p.support_height, model_keys);
  std::printf("  explained model          %zu voxels, %.1f %% of the visible surface, %zu wrongly occupied\n",
              em.voxels, 100.0 * em.coverage.known, em.wrongly_occupied);
  // The models as PLY points: the grid's occupied voxels of the object region, and the explained model.
  iv::PlyExportOptions ply;
  ply.keep = [&](const iv::Key& k) { return region_keys.contains(k); };
  iv::write_ply(o.out + "/model.ply", grid, ply);
  iv::KeySet model_set;
  for (const iv::Key& k : model_keys) model_set.insert(k);
  ply.voxels = iv::PlyExportOptions::Voxels::Observed;
  ply.keep = [&](const iv::Key& k) { return model_set.contains(k); };
  iv::write_ply(o.out + "/model_explained.ply", grid, ply);
  std::printf("  models (PLY points)      %s/model.ply (grid, occupied), %s/model_explained.ply (explained occupied)\n",
              o.out.c_str(), o.out.c_str());
  std::printf("  pictures                 %s/view_*.png, %s/final_table52.png, 3D: %s/final.html\n", o.out.c_str(),
              o.out.c_str(), o.out.c_str());
  return 0;
}

/// Every update with entropy and max-entropy, except the credal cells, built with max-entropy only.
struct Offer {
  template <class U, class H>
  static constexpr bool offers() {
    if constexpr (examples::kCredalUpdate<U>)
      return std::is_same_v<H, iv::MaxEntropy>;
    else
      return !std::is_same_v<H, iv::TotalUncertainty>;
  }
};

}  // namespace

int main(int argc, char** argv) {
  intervox::use_vector_walks();  // the AVX-512 / AVX2 walks where the processor has them
  Options o;
  CLI::App app{"Intervox: autonomous modelling of an object of the simulated workcell by the arm's laser striper\n"
               "(thesis ch. 5.1, 5.5). Scan paths are sampled on a sphere around the object, outside the\n"
               "collision space around occupied voxels; the path of highest information gain is scanned until\n"
               "no path gains --min-relative-gain or --max-views views are used. Writes a top-down projection of the\n"
               "object's voxels after every view (white free, black occupied, teal unobserved) and a summary."};
  app.add_option(
         "--update", o.update,
         "update policy (compact-interval-mean: interval-mean in 4 bytes per voxel; dirichlet-mean, belief-mean: "
         "the credal cells of docs/concepts.md, with max-entropy only)")
      ->check(CLI::IsMember(examples::offered_updates<Offer>()))
      ->capture_default_str();
  app.add_option("--utility", o.utility, "utility policy for the information gain")
      ->check(CLI::IsMember(examples::offered_utilities<Offer>()))
      ->capture_default_str();
  app.add_option("--planner", o.planner,
                 "plain: the thesis' planner; conflict-aware: views of conflict regions near their normal from new "
                 "directions, conflict voxels kept clear (interval updates only); explained: no sweep near space only "
                 "suspect beams or beams without a return crossed (any update; docs/planning.md)")
      ->check(CLI::IsMember({"plain", "conflict-aware", "explained"}))
      ->capture_default_str();
  app.add_flag("--seek-normals", o.seek_normals,
               "score sweeps also by how close to the striper's specular condition (the half-vector of laser and "
               "camera along the surface normal) they would see surfaces with hits but no decided state "
               "(docs/planning.md, \"Views that seek normals\"); with any --planner");
  app.add_option("--normals-weight", o.normals_weight,
                 "weight of that glint score against the gain (with --seek-normals)")
      ->check(examples::number_in(0.0, 1000.0))
      ->capture_default_str();
  app.add_option("--striper-baseline", o.striper_baseline,
                 "the striper's camera offset from the laser along its y axis in metres (docs/platforms.md): positive "
                 "puts the camera below the laser line in the arm's views, negative above it, 0 makes a coaxial sensor")
      ->check(examples::number_in(-0.5, 0.5))
      ->capture_default_str();
  app.add_option("--object", o.object, "object to model: the ring-shaped part, the bottle or the box")
      ->check(CLI::IsMember({"part", "bottle", "box"}))
      ->capture_default_str();
  app.add_option("--material", o.material,
                 "material of the modelled object (the others keep the workcell's defaults: "
                 "polished-metal part, transparent bottle, diffuse box; specular = mirror)")
      ->check(examples::one_of(iv::sim::kMaterialNames))
      ->capture_default_str();
  app.add_option("--seed", o.seed, "seed of sensor noise and candidate sampling")
      ->check(examples::integer_in<std::uint64_t>())
      ->capture_default_str();
  app.add_option("--out", o.out, "output folder (created as needed)")->capture_default_str();
  app.add_option("--max-views", o.max_views, "view budget, the fixed initial view included")
      ->check(examples::integer_in(1, 1000))
      ->capture_default_str();
  app.add_option("--candidates", o.candidates, "scan paths sampled on the sphere per step")
      ->check(examples::integer_in(1, 1000))
      ->capture_default_str();
  app.add_option("--min-relative-gain", o.min_relative_gain,
                 "stop when the best scan path gains less than this fraction of its gain in an unobserved world")
      ->check(examples::number_in(0.0, 1.0))
      ->capture_default_str();
  app.add_option("--resolution", o.resolution, "voxel edge length in metres")
      ->check(examples::number_in(0.005, 0.1))
      ->capture_default_str();
  app.add_option("--sphere-radius", o.sphere_radius, "distance of the striper from the object centre in metres")
      ->check(examples::number_in(0.15, 0.9))
      ->capture_default_str();
  app.add_option("--threads", o.threads, "threads for candidate evaluation (0: all cores)")
      ->check(examples::integer_in<unsigned>())
      ->capture_default_str();
  app.add_option("--scale", o.scale, "pixels per voxel in the pictures (0: at least 480 pixels on the long side)")
      ->check(examples::integer_in(0, 64))
      ->capture_default_str();
  app.callback([&] {
    if (const std::string error = examples::offer_error<Offer>(o.update, o.utility); !error.empty())
      throw CLI::ValidationError("--utility", error);
  });
  // Bad options: "arm_modelling: error: ..." and exit code 2; failures while running (an output
  // folder that cannot be created or written, ...): the same line and exit code 1.
  return examples::cli_main("arm_modelling", app, argc, argv, [&] {
    return examples::with_policies<Offer, int>(
        o.update, o.utility, [&]<class U, class H>() { return run<iv::VoxelGrid<U, H, iv::DenseStorage>>(o); });
  });
}
