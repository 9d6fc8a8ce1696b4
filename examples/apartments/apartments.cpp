// The apartments benchmark: the plain planner, the safe configuration and the oracle (the plain
// planner whose sensor knows every lying surface) in random apartments (sim::make_apartment) and
// their honest twins, with eight cameras and with one camera on a differential drive, with the
// interval-mean and the Bayes update; each run scored against the true world (docs/experiments.md,
// "Random apartments"). Writes results.csv (the same for any number of workers and threads),
// timings.csv and figures/ (top views) into --out; scripts/apartments_report.py turns the rows into
// the report with intervals. Shards and --resume as the experiments program
// (scripts/experiments_dask.py --program build/examples/apartments/apartments runs it on Dask).
//
//   ./build/examples/apartments/apartments --first-seed 1 --worlds 8 --out out/apartments
//   ./build/examples/apartments/apartments --tables-from a/results.csv b/results.csv --out merged
//
// A run found in more than one merged file (a resumed copy) is kept once when its results agree;
// when they differ the merge is refused, naming the run and both files.
#include "benchmark.hpp"

#include "common/cli.hpp"

#include <intervox/raycast/vector_walks.hpp>

#include <cstdio>
#include <map>
#include <string>
#include <vector>

namespace {

/// One line per configuration: runs, runs with a collision, completed runs, floor known.
void print_summary(const std::vector<apartments::Result>& rows) {
  struct Sum {
    int runs = 0, collided = 0, completed = 0;
    double known = 0;
  };
  std::map<std::string, Sum> by;
  for (const apartments::Result& r : rows) {
    Sum& s = by[r.run.group()];
    ++s.runs;
    s.collided += r.collision_poses > 0 || r.collision_segments > 0;
    s.completed += r.completed;
    s.known += r.known;
  }
  std::printf("%-36s %5s %10s %10s %8s\n", "configuration", "runs", "collided", "completed", "known%");
  for (const auto& [group, s] : by)
    std::printf("%-36s %5d %10d %10d %8.1f\n", group.c_str(), s.runs, s.collided, s.completed,
                100.0 * s.known / s.runs);
}

}  // namespace

int main(int argc, char** argv) {
  intervox::use_vector_walks();
  apartments::Options o;
  std::vector<std::string> merge;
  bool quiet = false;
  std::string shard;
  CLI::App app{
      "Intervox apartments: the plain, safe and oracle planners in random apartments and their honest twins, "
      "scored against the true world. Seeds below 10001 are for development; reports use seeds from 10001 on."};
  app.add_option("--first-seed", o.first_seed, "the first world's seed")
      ->check(examples::integer_in<std::uint64_t>(1, 1000000000))
      ->capture_default_str();
  app.add_option("--worlds", o.worlds, "worlds: seeds first-seed .. first-seed + worlds - 1")
      ->check(examples::integer_in(1, 100000))
      ->capture_default_str();
  app.add_option("--planners", o.planners,
                 "planners: plain, safe (the safe configuration), oracle (plain, told every lying surface)")
      ->check(CLI::IsMember(apartments::names(apartments::kPlanners)))
      ->delimiter(',')
      ->capture_default_str();
  app.add_option("--rigs", o.rigs,
                 "rigs: eight (the thesis' eight cameras), one (one forward camera, differential drive)")
      ->check(CLI::IsMember(apartments::names(apartments::kRigs)))
      ->delimiter(',')
      ->capture_default_str();
  app.add_option("--updates", o.updates, "updates: interval-mean, bayes")
      ->check(CLI::IsMember(apartments::names(apartments::kUpdates)))
      ->delimiter(',')
      ->capture_default_str();
  bool no_twins = false;
  app.add_flag("--no-twins", no_twins, "skip the honest twins (every surface diffuse)");
  app.add_option("--resolution", o.resolution, "voxel edge length, m")
      ->check(examples::number_in(0.02, 0.5))
      ->capture_default_str();
  app.add_option("--max-steps", o.max_steps, "views planned after the look-around")
      ->check(examples::integer_in(0, 1000))
      ->capture_default_str();
  app.add_option("--threads", o.threads, "threads of each run's planner and simulator (results do not depend on it)")
      ->check(examples::integer_in(1u, 256u))
      ->capture_default_str();
  app.add_option("--workers", o.workers, "runs in parallel (0: every core)")
      ->check(examples::integer_in(0u, 256u))
      ->capture_default_str();
  app.add_option("--figure-worlds", o.figure_worlds,
                 "top views of every run of the first N worlds and of every run with a collision (0: none)")
      ->check(examples::integer_in(0, 100000))
      ->capture_default_str();
  app.add_option("--out", o.out, "output folder")->capture_default_str();
  app.add_flag("--resume", o.resume, "keep the runs already in OUT/results.csv and run the others");
  app.add_option("--shard", shard, "run shard K/N of the run list (run i belongs to shard i mod N + 1)");
  app.add_flag("--quiet", quiet, "no line per run");
  app.add_option(
      "--tables-from", merge,
      "merge these results.csv (each with its timings.csv beside it) into OUT, run nothing; a run in several files "
      "is kept once if they agree, refused if not");
  return examples::cli_main("apartments", app, argc, argv, [&] {
    o.twins = !no_twins;
    o.progress = !quiet;
    if (!shard.empty()) apartments::parse_shard(shard, o.shard_index, o.shard_count);
    if (!merge.empty()) {
      std::vector<apartments::Result> rows;
      std::map<std::string, std::pair<std::string, std::string>> seen;  // run key -> its results.csv row, its file
      std::size_t duplicates = 0;
      for (const std::string& csv : merge) {
        const std::string timings = std::filesystem::path(csv).replace_filename("timings.csv").string();
        for (apartments::Result& r : apartments::read_results(csv, timings)) {
          // A run in two files (a resumed copy) is kept once if its results agree, refused if not.
          const std::string row = apartments::results_row(r);
          const auto [it, inserted] = seen.emplace(r.run.key(), std::pair(row, csv));
          if (inserted) {
            rows.push_back(std::move(r));
          } else if (it->second.first == row) {
            ++duplicates;
          } else {
            throw intervox::IoError("run " + r.run.key() + " is in more than one merged file with different results: " +
                                    it->second.second + " and " + csv);
          }
        }
      }
      if (duplicates > 0)
        std::printf("apartments: %zu runs found in more than one file, with the same results, kept once\n", duplicates);
      apartments::sort_runs(rows);
      std::filesystem::create_directories(o.out);
      apartments::write_results(o.out, rows);
      print_summary(rows);
      return 0;
    }
    const apartments::Report report = apartments::run_benchmark(o);
    std::printf("apartments: %zu runs, %zu resumed, %zu failed; results in %s\n", report.ran, report.resumed,
                report.failed.size(), o.out.c_str());
    print_summary(report.results);
    return report.failed.empty() ? 0 : 1;
  });
}
