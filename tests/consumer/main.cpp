// Exits 0 only if Intervox works from an outside project: a hit makes a voxel likelier occupied.
#include <intervox/intervox.hpp>

#include <cstdio>

int main() {
  namespace iv = intervox;
  iv::VoxelGrid<iv::IntervalUpdate<iv::MeanState>, iv::MaxEntropy> grid(0.1);
  const Eigen::Vector3d p(0.25, 0.25, 0.25);
  const double before = grid.probability(p);
  grid.update(p, iv::Observation::Hit);
  const double after = grid.probability(p);
  std::printf("intervox %d: %.3f -> %.3f\n", iv::kVersion, before, after);
  return after > before ? 0 : 1;
}
