// A utility whose value() takes the wrong arguments must be rejected by the UtilityPolicy concept.
// expect: satisfaction of .*UtilityPolicy<H>.* \[with H = WrongUtility\]
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/update/bayes_log_odds.hpp>

struct WrongUtility {
  static constexpr std::string_view kName = "wrong";
  double value(int) const { return 0.0; }
};

intervox::VoxelGrid<intervox::BayesLogOdds, WrongUtility> grid(0.1);
int main() { return 0; }
