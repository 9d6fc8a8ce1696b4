// End-to-end mobile exploration of the ideal lab room (coarse voxels, subsampled gain rays).
#include <catch2/catch.hpp>
#include <intervox/intervox.hpp>
#include <intervox/plan/mobile_explorer.hpp>
#include <intervox/raycast/raycast.hpp>
#include <intervox/sim/sim.hpp>

namespace iv = intervox;

namespace {
template <class Grid>
struct Episode {
  iv::sim::LabRoom lab = iv::sim::make_lab_room();
  Grid grid{0.1};
  iv::MobileExplorer<Grid> explorer;
  explicit Episode(std::uint64_t seed, unsigned threads = 2)
      : explorer(grid, lab.scene, iv::sim::SensorRig::mobile_base(), iv::planar_pose(lab.start, 0.0), params(seed, threads)) {}
  static iv::MobileExplorerParams params(std::uint64_t seed, unsigned threads) {
    iv::MobileExplorerParams p;
    p.seed = seed;
    p.threads = threads;
    p.max_steps = 25;
    return p;
  }
};
}  // namespace

TEMPLATE_TEST_CASE("an episode in the ideal lab room ends with at least 95% of the reachable free floor known",
                   "[plan][episode]", iv::BayesGrid, iv::IntervalGrid) {
  // Seed 7 once trapped the interval robot in the maybe-collision space of its cameras' blind zone
  // (fixed by the escape zone of ExplorationMap).
  Episode<TestType> e(7);
  const iv::Termination t = e.explorer.run();
  INFO("termination: " << iv::to_string(t) << " after " << e.explorer.steps() << " steps");
  CHECK(t != iv::Termination::Budget);
  CHECK(t != iv::Termination::Blocked);
  const double known = e.explorer.reachable_area_known();
  INFO("reachable area known " << known << " of " << e.explorer.reachable_area() << " m2");
  CHECK(known >= 0.95);
  CHECK(e.explorer.steps() >= 2);
  for (const auto& r : e.explorer.reports())
    if (r.selected) CHECK(r.gains[*r.selected].gain >= e.explorer.params().min_gain);
}

TEST_CASE("two episodes with the same seed give identical results, whatever the thread count", "[plan][episode]") {
  Episode<iv::IntervalGrid> a(3, 1), b(3, 2);
  for (int i = 0; i < 4; ++i) {
    const auto ra = a.explorer.step();
    const auto rb = b.explorer.step();
    CHECK(ra.pose.matrix() == rb.pose.matrix());
    CHECK(ra.frontier == rb.frontier);
    REQUIRE(ra.gains.size() == rb.gains.size());
    for (std::size_t k = 0; k < ra.gains.size(); ++k) CHECK(ra.gains[k].gain == rb.gains[k].gain);
  }
  CHECK(a.grid.counts().free == b.grid.counts().free);
  CHECK(a.grid.counts().occupied == b.grid.counts().occupied);
}
