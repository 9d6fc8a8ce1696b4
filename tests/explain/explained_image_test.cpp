// The explained-state picture: one pixel block per voxel column, the worst state of the column
// drawn, north up; bad bands refused.
#include <intervox/explain/explained_space.hpp>
#include <intervox/update/bayes_log_odds.hpp>
#include <intervox/view/explained_image.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

namespace iv = intervox;

namespace {
iv::Rgb pixel(const iv::RgbImage& im, int x, int y) {
  const std::size_t i =
      3 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(im.width) + static_cast<std::size_t>(x));
  return {im.rgb[i], im.rgb[i + 1], im.rgb[i + 2]};
}
}  // namespace

TEST_CASE("the explained-state picture draws each column's worst state, north up", "[explain][image]") {
  iv::VoxelGrid<iv::BayesLogOdds> grid(0.1, iv::BayesLogOdds::octomap());  // one miss: free
  iv::ExplainedSpace space(grid.geometry());
  iv::InsertOptions io;
  io.max_range = 2.0;
  iv::ScanInserter inserter(io);
  // A trusted return along +x at y = 0.05 (free columns x 0..9, occupied column x = 10), and a
  // no-return beam along +y at x = -0.45 (unexplained columns y 0..19).
  const std::vector<iv::Beam> beams = {{{0.05, 0.05, 0.05}, {1.05, 0.05, 0.05}, true},
                                       {{-0.45, 0.05, 0.05}, {-0.45, 1.0, 0.05}, false}};
  space.insert_beams(inserter, grid, std::span<const iv::Beam>(beams));
  const iv::Bounds band{{-0.95, -0.95, 0.0}, {1.95, 1.95, 0.09}};  // keys x, y in [-10, 19], z = 0
  const iv::RgbImage im = iv::render_explained_band(space, band, 2);
  REQUIRE(im.width == 60);
  REQUIRE(im.height == 60);
  const auto at = [&](int kx, int ky) { return pixel(im, 2 * (kx + 10), 2 * (19 - ky)); };  // north up
  CHECK(at(0, 0) == iv::kExplainedStateColours[1]);                                         // free
  CHECK(at(9, 0) == iv::kExplainedStateColours[1]);
  CHECK(at(10, 0) == iv::kExplainedStateColours[2]);  // the return: occupied
  CHECK(at(-5, 5) == iv::kExplainedStateColours[3]);  // no-return only: unexplained
  CHECK(at(5, 10) == iv::kExplainedStateColours[0]);  // nothing: unknown
  // The plain map calls the no-return column free.
  const iv::RgbImage plain = iv::render_occupancy_band(grid, band, 2);
  CHECK(pixel(plain, 2 * (-5 + 10), 2 * (19 - 5)) == iv::kExplainedStateColours[1]);
  CHECK(iv::explained_legend().swatches.size() == 4);
}

TEST_CASE("a picture of a bad band is refused with a reason", "[explain][image][errors]") {
  iv::ExplainedSpace space(iv::GridGeometry(0.05));
  const double nan = std::nan("");
  CHECK_THROWS_WITH(iv::render_explained_band(space, iv::Bounds{{0, 0, 0}, {nan, 1, 1}}), Catch::Contains("finite"));
  CHECK_THROWS_WITH(iv::render_explained_band(space, iv::Bounds{{0, 0, 0}, {1, 1, 1}}, 0),
                    Catch::Contains("pixels_per_voxel"));
  CHECK_THROWS_WITH(iv::render_explained_band(space, iv::Bounds{{0, 0, 0}, {1000, 1000, 1}}, 4),
                    Catch::Contains("2^26"));
  CHECK_THROWS_WITH(
      iv::render_truth_band(space.geometry(), iv::Bounds{{0, 0, 0}, {1e30, 1, 1}}, [](const iv::Key&) { return true; }),
      Catch::Contains("key range"));
}
