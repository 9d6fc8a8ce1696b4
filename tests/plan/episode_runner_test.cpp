// The episode runner with a user's sensor callback: what it asks the source, what it inserts and
// what it records.
#include <catch2/catch.hpp>
#include <intervox/grid/named_grids.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/plan/episode.hpp>
#include <intervox/plan/mobile_planner.hpp>
#include <intervox/sim/scenes.hpp>
#include <intervox/sim/source.hpp>

#include <functional>
#include <optional>
#include <vector>

namespace iv = intervox;

namespace {
// Grid configurations: unbounded sparse, bounded sparse, dense.
struct Sparse {
  using Grid = iv::BayesGrid;
  static std::optional<iv::Bounds> bounds() { return std::nullopt; }
};
struct BoundedSparse {
  using Grid = iv::BayesGrid;
  static std::optional<iv::Bounds> bounds() { return iv::Bounds{{-0.5, -0.5, -0.5}, {8.5, 6.5, 3.0}}; }
};
struct Dense {
  using Grid = iv::DenseBayesGrid;
  static std::optional<iv::Bounds> bounds() { return iv::Bounds{{-0.5, -0.5, -0.5}, {8.5, 6.5, 3.0}}; }
};
}  // namespace

static_assert(iv::SensorSource<iv::sim::SimulatedRig>);
static_assert(iv::SensorSource<std::function<std::vector<iv::Beam>(const iv::Pose&)>>);
static_assert(!iv::SensorSource<int>);
static_assert(iv::EpisodePlanner<iv::MobilePlanner, iv::BayesGrid>);

TEMPLATE_TEST_CASE("the runner senses at exactly the plan's scan poses and inserts what a user callback returns",
                   "[plan][runner]", Sparse, BoundedSparse, Dense) {
  const iv::sim::LabRoom lab = iv::sim::make_lab_room();
  typename TestType::Grid grid(iv::GridGeometry(0.1), TestType::bounds());
  typename TestType::Grid reference(iv::GridGeometry(0.1), TestType::bounds());
  iv::MobilePlannerParams p;
  p.region = iv::Bounds{{0.0, 0.0, 0.2}, {8.0, 6.0, 0.8}};
  p.threads = 1;
  iv::MobilePlanner planner(iv::SensorRig::mobile_base(), p);
  // The user's robot: a callback that records where it was asked to sense; here it renders with
  // the simulator, a real robot would drive there and convert its depth images.
  iv::sim::SimulatedRig camera(lab.scene, iv::SensorRig::mobile_base(), 9);
  std::vector<iv::Pose> asked;
  std::size_t returned = 0;
  auto robot = [&](const iv::Pose& body) {
    asked.push_back(body);
    std::vector<iv::Beam> beams = camera(body);
    returned += beams.size();
    return beams;
  };
  iv::Episode episode(grid, planner, robot, iv::planar_pose(lab.start, 0.0));
  std::vector<iv::Pose> expected;
  std::size_t inserted = 0;
  for (int i = 0; i < 3; ++i) {
    const auto& s = episode.step();
    REQUIRE(s.plan.termination == iv::Termination::Running);
    expected.insert(expected.end(), s.plan.scans.begin(), s.plan.scans.end());
    inserted += s.beams;
    CHECK(s.pose.matrix() == s.plan.scans.back().matrix());
  }
  REQUIRE(asked.size() == expected.size());
  for (std::size_t k = 0; k < asked.size(); ++k) CHECK(asked[k].matrix() == expected[k].matrix());
  CHECK(inserted == returned);
  // The map is what inserting the same scans by hand gives, with the planner's max range.
  iv::sim::SimulatedRig again(lab.scene, iv::SensorRig::mobile_base(), 9);
  iv::InsertOptions io;
  io.max_range = planner.max_range();
  for (const iv::Pose& body : expected) {
    const std::vector<iv::Beam> beams = again(body);
    iv::insert_beams(reference, std::span<const iv::Beam>(beams), io);
  }
  CHECK(grid.counts().free == reference.counts().free);
  CHECK(grid.counts().occupied == reference.counts().occupied);
  CHECK(grid.counts().unknown == reference.counts().unknown);
  // Every pose driven through is recorded: the start, the path poses, the scan poses.
  for (const auto& s : episode.steps())
    for (const iv::Pose& q : s.plan.path) {
      bool found = false;
      for (const iv::Pose& t : episode.trajectory()) found = found || t.matrix() == q.matrix();
      CHECK(found);
    }
}

TEST_CASE("a source that throws stops the step and leaves the runner usable", "[plan][runner]") {
  iv::BayesGrid grid(0.1);
  iv::MobilePlanner planner;
  int calls = 0;
  auto failing = [&](const iv::Pose&) -> std::vector<iv::Beam> {
    if (++calls == 2) throw iv::IoError("camera disconnected");
    return {};
  };
  iv::Episode episode(grid, planner, failing, iv::Pose::Identity());
  CHECK_THROWS_AS(episode.step(), iv::IoError);
  CHECK(episode.termination() == iv::Termination::Running);
  iv::Pose nan_pose = iv::Pose::Identity();
  nan_pose.translation().x() = NAN;
  CHECK_THROWS_AS(iv::Episode(grid, planner, failing, nan_pose), iv::InvalidArgument);
}
