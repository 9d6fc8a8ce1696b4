// Runs the thesis' chapter 5 comparisons as a seeded sweep and writes machine-readable results,
// the tables of docs/experiments.md and the figures (see docs/experiments.md).
//
//   ./build/examples/experiments/experiments --out docs/experiments
#include "sweep.hpp"

#include "common/cli.hpp"
#include "common/output_lock.hpp"

#include <chrono>
#include <cstdio>
#include <set>
#include <string>
#include <intervox/raycast/vector_walks.hpp>

int main(int argc, char** argv) {
  intervox::use_vector_walks();  // the AVX-512 / AVX2 walks where the processor has them
  experiments::SweepOptions o;
  CLI::App app{"Intervox experiments: Bayes vs. interval updates and entropy vs. max-entropy on the thesis' "
               "platforms and surfaces (thesis ch. 5), over several seeds. Writes results.csv, results.json, "
               "tables.md and figures/ into the output folder."};
  app.add_option("--out", o.out, "output folder (created as needed)")->capture_default_str();
  app.add_option("--seeds", o.seeds, "seeds per configuration (1..N)")
      ->check(examples::integer_in(1, 1000))
      ->capture_default_str();
  app.add_option("--surfaces", o.mobile_surfaces, "closet surfaces of the mobile runs")
      ->check(examples::one_of(intervox::sim::kMaterialNames))
      ->capture_default_str();
  app.add_option("--updates", o.mobile_updates, "update policies of the mobile runs")
      ->check(CLI::IsMember(examples::offered_updates<experiments::detail::MobileOffer>()))
      ->capture_default_str();
  app.add_option("--arm-objects", o.arm_objects, "objects of the arm runs (part: polished-metal ring; bottle: glass)")
      ->check(CLI::IsMember({"part", "bottle"}))
      ->capture_default_str();
  app.add_option("--arm-updates", o.arm_updates, "update policies of the arm runs")
      ->check(CLI::IsMember(examples::offered_updates<experiments::detail::ArmOffer>()))
      ->capture_default_str();
  app.add_option("--arm-resolution", o.arm_resolution, "voxel edge length of the arm runs, m")
      ->check(examples::number_in(0.005, 0.05))
      ->capture_default_str();
  app.add_option("--arm-max-views", o.arm_max_views, "arm view budget (initial view included)")
      ->check(examples::integer_in(1, 100))
      ->capture_default_str();
  app.add_flag("--arm-first-edition-materials", o.arm_first_edition_materials,
               "arm runs with the first edition's materials (random-range part, glass without Fresnel)");
  app.add_option("--policies", o.policies,
                 "policy presets: thesis (the thesis' parameters with latching, Table 3.1 / 5.3.3), clamped (the "
                 "library's defaults)")
      ->check(CLI::IsMember({"thesis", "clamped"}))
      ->capture_default_str();
  app.add_option("--floors", o.floors,
                 "mobile depth images: floor returns removed before insertion (thesis 3.3.1) or kept")
      ->check(CLI::IsMember({"removed", "kept"}))
      ->capture_default_str();
  app.add_option("--gains", o.gains, "which voxels the gain sums over: unknown (the thesis, 3.4) or all")
      ->check(CLI::IsMember({"unknown", "all"}))
      ->capture_default_str();
  app.add_option(
         "--planners", o.planners,
         "planners: plain (the thesis'), conflict-aware (docs/planning.md; both platforms, interval and credal "
         "updates, skipped for bayes) or safe (the mobile robot: explained free space, lying columns as hazards, "
         "wall gaps closed; skipped for the arm)")
      ->check(CLI::IsMember(experiments::names(experiments::kPlanners)))
      ->capture_default_str();
  app.add_option("--rooms", o.rooms,
                 "mobile rooms: lab (the thesis' lab room), annex (with an open doorway to an annex room, its floor "
                 "scored apart) or front-only (the closet's material on its front only)")
      ->check(CLI::IsMember(experiments::names(experiments::kRooms)))
      ->capture_default_str();
  app.add_option(
         "--rules", o.rules,
         "mobile start and map rules: thesis (whole columns within 1 m of the start free, hits not blocking) or "
         "library (the rig's start rule, hits_block)")
      ->check(CLI::IsMember(experiments::names(experiments::kRules)))
      ->capture_default_str();
  app.add_option("--sensors", o.sensors,
                 "mobile sensing conditions: plain (the thesis' eight cameras), glint (the near-normal glint of a "
                 "time-of-flight camera at a mirror), body (the robot's own body, seen in a mirror) or one-camera (one "
                 "forward camera, the exact start rule, 5 frames per scan, Bayes 3)")
      ->check(CLI::IsMember(experiments::names(experiments::kSensorConditions)))
      ->capture_default_str();
  app.add_option("--unobserved", o.unobserved,
                 "classification of never-observed voxels: unknown (ours) or by-rule (the thesis, 4.1 / 5.3.4: the "
                 "lower rule calls them free, the upper occupied; run for interval-lower and interval-upper only)")
      ->check(CLI::IsMember({"unknown", "by-rule"}))
      ->capture_default_str();
  app.add_option("--floor-cut", o.floor_cut, "height in m at or below which returns count as floor")
      ->check(examples::number_in(-1.0, 1.0))
      ->capture_default_str();
  std::string shard;
  app.add_option("--shard", shard,
                 "run only shard K of N (K/N, 1-based): run i of the sweep belongs to shard (i mod N) + 1; merge the "
                 "shards' results.csv with --tables-from")
      ->check([](const std::string& text) {
        int k = 0, n = 0;
        try {
          experiments::parse_shard(text, k, n);
        } catch (const intervox::InvalidArgument& e) {
          return std::string(e.what());
        }
        return std::string();
      });
  app.add_flag("--resume", o.resume,
               "keep the runs already in OUT/results.csv and run only the others (without it an existing file is "
               "kept as results.csv.previous)");
  bool no_mobile = false, no_arm = false;
  app.add_flag("--no-mobile", no_mobile, "skip the mobile runs");
  app.add_flag("--no-arm", no_arm, "skip the arm runs");
  app.add_option("--utilities", o.utilities, "NBV criteria")
      ->check(CLI::IsMember(examples::offered_utilities<experiments::detail::MobileOffer>()))
      ->capture_default_str();
  app.add_option("--resolution", o.resolution, "voxel edge length of the mobile runs, m")
      ->check(examples::number_in(0.02, 0.5))
      ->capture_default_str();
  app.add_option("--max-steps", o.max_steps, "exploration step budget")
      ->check(examples::integer_in<int>(0))
      ->capture_default_str();
  app.add_option("--gain-stride", o.gain_stride, "cast every n-th pixel row and column for the gain")
      ->check(examples::integer_in(1, 64))
      ->capture_default_str();
  app.add_option("--workers", o.workers, "runs in parallel (0: all cores)")
      ->check(examples::integer_in<unsigned>())
      ->capture_default_str();
  std::vector<std::string> merge;
  app.add_option("--tables-from", merge,
                 "run nothing: read these results.csv files (e.g. of sweeps run separately), merge them and write "
                 "results.csv, results.json and tables.md into --out")
      ->check(CLI::ExistingFile);
  bool no_figures = false, quiet = false;
  app.add_flag("--no-figures", no_figures, "skip the pictures");
  app.add_flag("--quiet", quiet, "no progress lines");
  // Bad options: "experiments: error: ..." and exit code 2; failures while running (a malformed
  // --tables-from file, an output folder that cannot be written, ...): the same line and exit code 1.
  return examples::cli_main("experiments", app, argc, argv, [&] {
    o.figures = !no_figures;
    if (no_mobile) o.mobile_surfaces.clear();
    if (no_arm) o.arm_objects.clear();
    o.progress = !quiet;
    if (!shard.empty()) experiments::parse_shard(shard, o.shard_index, o.shard_count);
    // One run per output folder: two shards (or runs) writing one folder would keep only one's
    // rows, so the second is refused while the first runs.
    const examples::OutputFolderLock lock(o.out);
    if (!merge.empty()) {
      std::vector<experiments::RunResult> all;
      std::set<std::string> keys;
      for (const auto& path : merge) {
        for (auto& r : experiments::read_csv(path)) {
          if (!keys.insert(r.config.key()).second)
            throw intervox::IoError(path + ": run " + r.config.key() + " appears in more than one file");
          all.push_back(std::move(r));
        }
      }
      const std::size_t n = all.size();
      experiments::write_results(o, std::move(all));
      std::printf("merged %zu runs into %s/results.csv, results.json, tables.md\n", n, o.out.c_str());
      return 0;
    }
    const auto t0 = std::chrono::steady_clock::now();
    const auto configs = experiments::shard_configs(o);
    std::printf("intervox experiments: %zu runs (shard %d of %d) -> %s/\n", configs.size(), o.shard_index,
                o.shard_count, o.out.c_str());
    const auto report = experiments::run_and_write(o);
    std::printf("done in %.0f s: %zu runs, %zu resumed, %zu failed: %s/results.csv, results.json, tables.md%s\n",
                std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), report.ran,
                report.resumed, report.failed.size(), o.out.c_str(), o.figures ? ", figures/" : "");
    for (const auto& f : report.failed) std::fprintf(stderr, "experiments: failed: %s\n", f.c_str());
    return report.failed.empty() ? 0 : 1;
  });
}
