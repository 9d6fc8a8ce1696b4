// A storage tag without a Container template must be rejected by the Storage concept.
// expect: satisfaction of .*Storage<S>.* \[with S = NoContainer\]
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/update/bayes_log_odds.hpp>

struct NoContainer {
  static constexpr bool kBounded = false;
  static constexpr std::string_view kName = "none";
};

intervox::VoxelGrid<intervox::BayesLogOdds, intervox::Entropy, NoContainer> grid(0.1);
int main() { return 0; }
