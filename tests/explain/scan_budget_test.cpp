// The explained channel's per-scan scratch (its copies of the scan's beams, their classes, the
// ledger's record and the count grids' prepared rays) is bounded by the insertion budget, as the
// plain insertion bounds what a scan adds to the map: a scan over it is refused before anything
// is allocated or changed, with a message that names the budget.
#include <intervox/core/sensors.hpp>
#include <intervox/explain/explain.hpp>
#include <intervox/raycast/insert.hpp>
#include <intervox/update/bayes_log_odds.hpp>

#include "../common/explained_evidence.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

namespace iv = intervox;

namespace scan_budget_test {

// n returns within half a metre of the origin: the plain insertion's block bound is a few blocks
// (the rays' key box), far below any budget, whatever n.
std::vector<iv::Point3> short_returns(std::size_t n) {
  std::vector<iv::Point3> out;
  out.reserve(n);
  for (std::size_t i = 0; i < n; ++i)
    out.emplace_back(0.3 + 0.1 * static_cast<double>(i % 3), 0.1 * static_cast<double>(i % 5) - 0.2,
                     0.1 * static_cast<double>(i % 7) - 0.3);
  return out;
}

}  // namespace scan_budget_test

using namespace scan_budget_test;

TEST_CASE(
    "a scan whose explained scratch exceeds the insertion budget is refused before the grid or the channel changes",
    "[explain][budget][errors]") {
  const std::size_t n = 20000;
  const std::vector<iv::Point3> points = short_returns(n);
  iv::InsertOptions io;
  io.max_range = 5.0;
  // A budget the plain insertion of these rays meets (a few blocks) and the channel's scratch
  // for 20,000 beams does not.
  io.max_grid_bytes = std::uint64_t{1} << 20;
  REQUIRE(n * iv::ExplainedSpace::kScratchBytesPerBeam > io.max_grid_bytes);
  {
    iv::VoxelGrid<iv::BayesLogOdds> plain(0.05);
    CHECK(iv::ScanInserter(io).insert_point_cloud(plain, iv::Point3::Zero(), points).rays == n);
  }
  iv::VoxelGrid<iv::BayesLogOdds> grid(0.05);
  iv::ExplainedSpace space(grid.geometry());
  iv::ScanInserter inserter(io);
  std::vector<iv::Beam> beams;
  for (const iv::Point3& p : points) beams.push_back({iv::Point3::Zero(), p, true});
  const std::vector<iv::BeamClass> classes(n, iv::BeamClass::Trusted);
  CHECK_THROWS_WITH(
      space.insert_point_cloud(inserter, grid, iv::Point3::Zero(), points),
      Catch::Contains("20000 beams") && Catch::Contains("max_grid_bytes") && Catch::Contains("budget of 1.0 MiB"));
  CHECK_THROWS_WITH(space.insert_beams(inserter, grid, std::span<const iv::Beam>(beams)),
                    Catch::Contains("max_grid_bytes"));
  CHECK_THROWS_WITH(space.add(std::span<const iv::Beam>(beams), classes, io), Catch::Contains("max_grid_bytes"));
  iv::DepthFrame frame;
  frame.intrinsics = iv::PinholeIntrinsics::from_fov(200, 100, iv::deg(60), iv::deg(45));
  frame.image = iv::DepthImage(200, 100);
  std::fill(frame.image.depth.begin(), frame.image.depth.end(), 1.0f);
  frame.pose = iv::Pose::Identity();
  frame.max_range = 5.0;
  CHECK_THROWS_WITH(space.insert_depth_image(inserter, grid, frame), Catch::Contains("20000 beams"));
  CHECK(grid.observed_count() == 0);
  CHECK(space.size() == 0);
  CHECK(space.ledger().scans().empty());
  // Within the budget (or with the budget off) the same scan goes in.
  io.max_grid_bytes = iv::kUnlimitedInsertBudget;
  inserter.set_options(io);
  CHECK(space.insert_point_cloud(inserter, grid, iv::Point3::Zero(), points).beams_trusted == n);
  CHECK(space.size() > 0);
}
