// A credal policy whose interval() returns a pair of doubles instead of intervox::Interval must be
// rejected by the UpdatePolicy concept with one readable line naming it.
// expect: satisfaction of .*UpdatePolicy<U>.* \[with U = PairIntervalCounts\]
#include <intervox/grid/voxel_grid.hpp>

#include <cstdint>
#include <utility>

struct PairIntervalCounts {
  struct Cell {
    std::uint16_t hits, misses;
  };
  static constexpr std::string_view kName = "pair-counts";
  static Cell unobserved() { return {0, 0}; }
  static bool is_observed(const Cell& c) { return c.hits + c.misses > 0; }
  void update(Cell& c, intervox::Observation o) const { ++(o == intervox::Observation::Hit ? c.hits : c.misses); }
  double state(const Cell& c) const { return (c.hits + 1.0) / (c.hits + c.misses + 2.0); }
  std::pair<double, double> interval(const Cell& c) const { return {c.hits / (c.hits + c.misses + 2.0), 1.0}; }
  intervox::Occupancy occupancy(const Cell&) const { return intervox::Occupancy::Unknown; }
};

intervox::VoxelGrid<PairIntervalCounts> grid(0.1);
int main() { return 0; }
