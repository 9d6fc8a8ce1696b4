// Quick start: two grids chosen at compile time, fed the same measurements of one voxel.
// A wall voxel is hit by most beams, but one beam in four passes through (a noisy surface).
#include <intervox/intervox.hpp>

#include "common/guarded_main.hpp"

#include <cstdio>
#include <string_view>

namespace iv = intervox;

template <class Grid>
void report(const char* name, const Grid& g, const Eigen::Vector3d& p) {
  const iv::Interval i = g.interval(p);
  std::printf("%-28s state %.3f  interval [%.3f, %.3f]  %-8s  utility %.3f\n", name, g.probability(p), i.lower, i.upper,
              std::string(iv::to_string(g.occupancy(p))).c_str(), g.utility(p));
}

namespace {
int quick_start_main() {
  iv::VoxelGrid<iv::BayesLogOdds, iv::Entropy> bayes(0.05);  // sparse, unbounded
  const iv::Bounds room{{0, 0, 0}, {6, 5, 3}};
  iv::VoxelGrid<iv::IntervalUpdate<iv::MeanState>, iv::MaxEntropy, iv::DenseStorage> interval(0.05, room);

  const Eigen::Vector3d wall(2.0, 1.0, 1.0);
  std::printf("step  configuration                 result\n");
  for (int step = 1; step <= 8; ++step) {
    const auto o = (step % 4 == 0) ? iv::Observation::Miss : iv::Observation::Hit;
    bayes.update(wall, o);
    interval.update(wall, o);
    std::printf("%d (%s)\n", step, std::string(iv::to_string(o)).c_str());
    report("  bayes + entropy", bayes, wall);
    report("  interval-mean + max-entropy", interval, wall);
  }
  std::printf("observed voxels: bayes %zu, interval %zu; memory: bayes %zu B (sparse), interval %zu B (dense)\n",
              bayes.observed_count(), interval.observed_count(), bayes.memory_bytes(), interval.memory_bytes());
  return 0;
}
}  // namespace

// quick_start takes no arguments: --help (or -h) prints what it does, anything else is a usage error.
int main(int argc, char** argv) {
  return examples::main_without_arguments(argc, argv, "quick_start",
                                          "two grids fed the same measurements of one voxel, printed step by step",
                                          [] { return quick_start_main(); });
}
