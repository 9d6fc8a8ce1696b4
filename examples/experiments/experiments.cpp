// Runs the thesis' chapter 5 comparisons as a seeded sweep and writes machine-readable results,
// the tables of docs/experiments.md and the figures (see docs/experiments.md).
//
//   ./build/examples/experiments/experiments --out docs/experiments
#include "sweep.hpp"

#include "common/cli.hpp"

#include <chrono>
#include <cstdio>

int main(int argc, char** argv) {
  experiments::SweepOptions o;
  CLI::App app{"Intervox experiments: Bayes vs. interval updates and entropy vs. max-entropy on the thesis' "
               "platforms and surfaces (thesis ch. 5), over several seeds. Writes results.csv, results.json, "
               "tables.md and figures/ into the output folder."};
  app.add_option("--out", o.out, "output folder (created as needed)")->capture_default_str();
  app.add_option("--seeds", o.seeds, "seeds per configuration (1..N)")->check(examples::integer_in(1, 1000))->capture_default_str();
  app.add_option("--surfaces", o.mobile_surfaces, "closet surfaces of the mobile runs")
      ->check(examples::one_of(intervox::sim::kMaterialNames))->capture_default_str();
  app.add_option("--updates", o.mobile_updates, "update policies of the mobile runs")
      ->check(CLI::IsMember({"bayes", "interval-lower", "interval-mean", "interval-upper"}))->capture_default_str();
  app.add_option("--arm-objects", o.arm_objects, "objects of the arm runs (part: polished-metal ring; bottle: glass)")
      ->check(CLI::IsMember({"part", "bottle"}))->capture_default_str();
  app.add_option("--arm-updates", o.arm_updates, "update policies of the arm runs")
      ->check(CLI::IsMember({"bayes", "interval-mean"}))->capture_default_str();
  app.add_option("--arm-resolution", o.arm_resolution, "voxel edge length of the arm runs, m")
      ->check(examples::number_in(0.005, 0.05))->capture_default_str();
  app.add_option("--arm-max-views", o.arm_max_views, "arm view budget (initial view included)")
      ->check(examples::integer_in(1, 100))->capture_default_str();
  app.add_flag("--arm-first-edition-materials", o.arm_first_edition_materials,
               "arm runs with the first edition's materials (random-range part, glass without Fresnel)");
  bool no_mobile = false, no_arm = false;
  app.add_flag("--no-mobile", no_mobile, "skip the mobile runs");
  app.add_flag("--no-arm", no_arm, "skip the arm runs");
  app.add_option("--utilities", o.utilities, "NBV criteria")
      ->check(CLI::IsMember({"entropy", "max-entropy"}))->capture_default_str();
  app.add_option("--resolution", o.resolution, "voxel edge length of the mobile runs, m")
      ->check(examples::number_in(0.02, 0.5))->capture_default_str();
  app.add_option("--max-steps", o.max_steps, "exploration step budget")
      ->check(examples::integer_in<int>(0))->capture_default_str();
  app.add_option("--gain-stride", o.gain_stride, "cast every n-th pixel row and column for the gain")
      ->check(examples::integer_in(1, 64))->capture_default_str();
  app.add_option("--workers", o.workers, "runs in parallel (0: all cores)")
      ->check(examples::integer_in<unsigned>())->capture_default_str();
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
    if (!merge.empty()) {
      std::vector<experiments::RunResult> all;
      for (const auto& path : merge) {
        auto part = experiments::read_csv(path);
        all.insert(all.end(), part.begin(), part.end());
      }
      experiments::write_results(o, all);
      std::printf("merged %zu runs into %s/results.csv, results.json, tables.md\n", all.size(), o.out.c_str());
      return 0;
    }
    const auto t0 = std::chrono::steady_clock::now();
    const auto configs = experiments::sweep_configs(o);
    std::printf("intervox experiments: %zu runs -> %s/\n", configs.size(), o.out.c_str());
    experiments::run_and_write(o);
    std::printf("done in %.0f s: %s/results.csv, results.json, tables.md%s\n",
                std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), o.out.c_str(),
                o.figures ? ", figures/" : "");
    return 0;
  });
}
