// A grid whose update policy has no grid-file codec (here the hit-and-miss count policy without
// io/codec/hit_miss_count.hpp) handed to save_grid must be rejected by the GridFilePolicy concept
// at the call.
// expect: required for the satisfaction of .*GridFilePolicy<U>.* \[with U = intervox::HitMissCount\]
#include <intervox/io/grid_file.hpp>
#include <intervox/update/hit_miss_count.hpp>

int main() {
  intervox::VoxelGrid<intervox::HitMissCount, intervox::Entropy, intervox::SparseStorage> grid(0.1);
  return intervox::save_grid_to_memory(grid).empty() ? 1 : 0;
}
