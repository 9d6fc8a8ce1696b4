// The safe-planner candidate in the planted scenes (examples/experiments/planted_scenes.hpp): a wall
// mirror with the room's region, with its wall told, and in an unbounded grid with nothing told; a
// black box before a wall; the doorway between two mirror-symmetric rooms; a doorway into a deeper
// room; a glass window. One row per run (termination, trajectory poses, poses and segments within
// the robot's radius of a true obstacle, poses outside the start room, the objects met, the start
// room's floor known, the wall gaps closed in the last plan) and one summary line per scene (docs/planning.md, "Gaps in
// a wall"). --no-close-wall-gaps runs the candidate without ExplainedPlanningParams::close_wall_gaps;
// --planner plain runs the plain planner instead (the same region, seed and budget), as the
// baseline of docs/experiments.md's third edition.
//
//   ./build/examples/experiments/planted_scenes --seeds 10 [--first-seed 1] [--scenes 2,5] [--planner safe|plain]
//       [--no-close-wall-gaps] [--grid interval|bayes] [--resolution 0.1] [--max-steps 30]
#include "common/cli.hpp"
#include "planted_scenes.hpp"

#include <intervox/grid/named_grids.hpp>
#include <intervox/raycast/vector_walks.hpp>

#include <cmath>
#include <cstddef>
#include <cstdio>
#include <string>
#include <vector>

namespace {

namespace iv = intervox;

struct Options {
  int seeds = 10;
  int first_seed = 1;
  std::vector<int> scenes{};  ///< indices into experiments::planted_scenes() (empty: all)
  bool no_close = false;
  std::string grid = "interval";
  std::string planner = "safe";  ///< "safe": the candidate; "plain": the plain planner
  double resolution = 0.1;
  int max_steps = 30;
};

int run(const Options& o) {
  const std::vector<experiments::Planted> all = experiments::planted_scenes();
  std::vector<int> which = o.scenes;
  if (which.empty())
    for (int i = 0; i < static_cast<int>(all.size()); ++i) which.push_back(i);
  if (o.planner == "plain")
    std::printf("planted scenes: the plain planner, eight cameras, %s grid, %.3f m, %d steps, seeds %d-%d\n",
                o.grid.c_str(), o.resolution, o.max_steps, o.first_seed, o.first_seed + o.seeds - 1);
  else
    std::printf("planted scenes: the candidate (explained hazards, open groups%s), eight cameras, %s grid, %.3f m, %d "
                "steps, seeds %d-%d\n",
                o.no_close ? "" : ", close_wall_gaps", o.grid.c_str(), o.resolution, o.max_steps, o.first_seed,
                o.first_seed + o.seeds - 1);
  std::printf("%-45s %4s  %-22s %6s %8s %9s %7s %6s  %s\n", "scene", "seed", "termination", "poses", "outside",
              "collide", "known%", "closed", "met");
  for (const int i : which) {
    if (i < 0 || i >= static_cast<int>(all.size()))
      throw iv::InvalidArgument("--scenes: no scene " + std::to_string(i));
    const experiments::Planted& planted = all[static_cast<std::size_t>(i)];
    int collided = 0, ended = 0, left = 0;
    std::vector<double> known;
    for (int seed = o.first_seed; seed < o.first_seed + o.seeds; ++seed) {
      const auto s = static_cast<std::uint64_t>(seed);
      iv::MobilePlannerParams p = experiments::safe_params(planted, s, 1, !o.no_close);
      p.max_steps = o.max_steps;
      if (o.planner == "plain") p.explained = iv::ExplainedPlanningParams{};
      const experiments::Outcome r = o.grid == "bayes"
                                         ? experiments::explore<iv::BayesGrid>(planted, p, s, o.resolution)
                                         : experiments::explore<iv::IntervalGrid>(planted, p, s, o.resolution);
      const bool hit = r.collisions.poses > 0 || r.collisions.segments > 0 || !r.met.empty();
      collided += hit ? 1 : 0;
      ended += r.termination != iv::Termination::Budget ? 1 : 0;
      left += r.outside > 0 ? 1 : 0;
      known.push_back(100.0 * r.known);
      std::printf("%-45s %4d  %-22s %6zu %8zu %4zu/%-4zu %7.1f %6zu  %s\n", planted.name.c_str(), seed,
                  std::string(iv::to_string(r.termination)).c_str(), r.trajectory.size(), r.outside,
                  static_cast<std::size_t>(r.collisions.poses), static_cast<std::size_t>(r.collisions.segments),
                  100.0 * r.known, r.gaps_closed, r.met.empty() ? "-" : experiments::met_names(r).c_str());
      std::fflush(stdout);
    }
    double m = 0, v = 0, lo = known.front(), hi = known.front();
    for (const double k : known) {
      m += k / static_cast<double>(known.size());
      lo = std::min(lo, k);
      hi = std::max(hi, k);
    }
    for (const double k : known)
      v += (k - m) * (k - m) / std::max<double>(1.0, static_cast<double>(known.size()) - 1.0);
    std::printf("summary | %s | runs with a collision %d of %d | ended before the budget %d | left the start room %d | "
                "floor known %.1f ± %.1f %% (%.1f-%.1f)\n",
                planted.name.c_str(), collided, o.seeds, ended, left, m, std::sqrt(v), lo, hi);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  intervox::use_vector_walks();
  Options o;
  CLI::App app{
      "Intervox planted_scenes: the safe-planner candidate in the planted scenes of issue 33, against the true "
      "scene (docs/planning.md, \"Gaps in a wall\")."};
  app.add_option("--seeds", o.seeds, "how many seeds: first-seed .. first-seed + n - 1")
      ->check(examples::integer_in(1, 1000))
      ->capture_default_str();
  app.add_option("--first-seed", o.first_seed, "the first seed")
      ->check(examples::integer_in(1, 1000000))
      ->capture_default_str();
  app.add_option(
         "--scenes", o.scenes,
         "scenes to run (comma-separated indices; all by default): 0 mirror wall with the room's region, 1 mirror wall "
         "unbounded with the wall told, 2 mirror wall unbounded with nothing told, 3 black box, 4 doorway between "
         "symmetric rooms, 5 doorway to a deeper room, 6 glass window")
      ->delimiter(',')
      ->check(examples::integer_in(0, 6));
  app.add_flag("--no-close-wall-gaps", o.no_close, "the candidate without ExplainedPlanningParams::close_wall_gaps");
  app.add_option("--planner", o.planner,
                 "safe: the candidate; plain: the plain planner (the same region, seed and budget)")
      ->check(CLI::IsMember({"safe", "plain"}))
      ->capture_default_str();
  app.add_option("--max-steps", o.max_steps, "step budget")
      ->check(examples::integer_in(1, 1000))
      ->capture_default_str();
  app.add_option("--grid", o.grid, "interval: interval-mean; bayes: the Bayes update")
      ->check(CLI::IsMember({"interval", "bayes"}))
      ->capture_default_str();
  app.add_option("--resolution", o.resolution, "voxel edge length [m]")
      ->check(examples::number_in(0.05, 0.5))
      ->capture_default_str();
  return examples::cli_main("planted_scenes", app, argc, argv, [&] { return run(o); });
}
