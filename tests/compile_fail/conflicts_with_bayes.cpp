// Conflict detection on a Bayes grid must not compile: its interval is always degenerate.
// expect: conflict detection needs an interval policy
#include <intervox/analysis/conflicts.hpp>
#include <intervox/grid/named_grids.hpp>
#include <intervox/grid/voxel_grid.hpp>

int main() {
  intervox::BayesGrid grid(0.1);
  return static_cast<int>(intervox::detect_conflicts(grid).regions.size());
}
