// A policy without a Cell type and update() must be rejected by the UpdatePolicy concept.
// expect: satisfaction of .*UpdatePolicy<U>.* \[with U = NotAPolicy\]
#include <intervox/grid/voxel_grid.hpp>

struct NotAPolicy {
  static constexpr std::string_view kName = "broken";
  double state(float) const { return 0.5; }
};

intervox::VoxelGrid<NotAPolicy> grid(0.1);
int main() { return 0; }
