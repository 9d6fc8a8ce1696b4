// The 3D page coloured by explained state (view/explained_page_options.hpp): on a planted wall with
// phantom beams through it and beams without a return (no simulator), the packed voxels against
// a brute-force pass over the grid and the channel, on every grid type; the page's legend and
// switch names; a channel of another geometry refused.
#include <intervox/explain/explained_space.hpp>
#include <intervox/raycast/insert.hpp>
#include <intervox/view/explained_page_options.hpp>
#include <intervox/view/html_view.hpp>

#include "../common/grid_types.hpp"

#include <catch2/catch.hpp>

#include <array>
#include <map>
#include <string>
#include <tuple>
#include <vector>

namespace iv = intervox;

namespace {

using ViewKey = std::tuple<int, int, int>;

/// What the page holds per voxel: its class (0 occupied, 1 unknown, 2 free) and colour.
using PageVoxels = std::map<ViewKey, std::pair<int, std::array<std::uint8_t, 3>>>;

/// The packed voxels (level 0) by grid key; \p geometry maps offsets back to keys.
PageVoxels page_voxels(const iv::GridGeometry& geometry, const iv::ViewVoxels& v) {
  PageVoxels out;
  std::size_t i = 0;
  for (int cls = 0; cls < 3; ++cls)
    for (std::size_t n = 0; n < v.per_class[static_cast<std::size_t>(cls)]; ++n, ++i) {
      const iv::Key k =
          geometry.key(v.base + iv::Point3(v.offsets[3 * i], v.offsets[3 * i + 1], v.offsets[3 * i + 2]) * v.size);
      out[{k.x, k.y, k.z}] = {cls, {v.rgb[3 * i], v.rgb[3 * i + 1], v.rgb[3 * i + 2]}};
    }
  return out;
}

/// A wall at x = 1.5 m seen straight on from four origins (trusted, so explained occupied and the
/// space before it explained free), then six scans of phantom returns at x = 2.6 m through it
/// (suspect: they cross the supported wall), then beams without a return towards -x.
template <class Grid>
void planted_scans(Grid& grid, iv::ExplainedSpace& space) {
  iv::InsertOptions io;
  io.max_range = 3.0;
  iv::ScanInserter inserter(io);
  const auto scan = [&](const iv::Point3& o, double x, bool hit) {
    std::vector<iv::Beam> beams;
    for (double y = -0.6; y <= 0.6; y += 0.03)
      for (double z = -0.3; z <= 0.3; z += 0.05) beams.push_back({o, iv::Point3(x, y, z), hit});
    space.insert_beams(inserter, grid, std::span<const iv::Beam>(beams));
  };
  for (const double oy : {-0.2, -0.07, 0.07, 0.2})
    for (int round = 0; round < 3; ++round) scan(iv::Point3(0.0, oy, 0.0), 1.5, true);
  for (int round = 0; round < 6; ++round) scan(iv::Point3(0.0, 0.01 * round, 0.0), 2.6, true);
  for (int round = 0; round < 3; ++round) scan(iv::Point3(0.0, 0.0, 0.0), -2.0, false);
}

}  // namespace

TEMPLATE_TEST_CASE("the explained page colours each voxel by its explained state and keeps only unexplained free space",
                   "[view][explained]", INTERVOX_TEST_GRIDS) {
  TestType grid = test::make_grid_for<TestType>(0.1, iv::Bounds{{-4.0, -4.0, -4.0}, {4.0, 4.0, 4.0}});
  iv::ExplainedSpace space(grid.geometry());
  planted_scans(grid, space);

  const iv::HtmlViewOptions o = iv::explained_view_options(grid, space);
  CHECK(o.voxels == iv::HtmlViewOptions::Voxels::Observed);
  CHECK(o.shown == std::array<bool, 3>{true, true, true});
  const iv::ViewVoxels v = iv::pack_view_voxels(grid, o);
  REQUIRE(v.level == 0);
  REQUIRE_FALSE(v.surface_only);

  // Brute force: every observed voxel but the free ones the channel explains free, in its
  // grid class, with the colour of its explained state.
  PageVoxels want;
  std::array<std::size_t, 4> states{};
  std::size_t unexplained_free = 0;
  const auto& u = grid.update_policy();
  grid.for_each_observed([&](const iv::Key& k, const auto& c) {
    const iv::Occupancy occ = u.occupancy(c);
    const iv::ExplainedState st = space.state(k);
    if (occ == iv::Occupancy::Free && st == iv::ExplainedState::Free) return;
    const int cls = occ == iv::Occupancy::Occupied ? 0 : occ == iv::Occupancy::Unknown ? 1 : 2;
    const iv::Rgb rgb = iv::kExplainedStateColours[static_cast<std::size_t>(st)];
    want[{k.x, k.y, k.z}] = {cls, {rgb.r, rgb.g, rgb.b}};
    ++states[static_cast<std::size_t>(st)];
    unexplained_free += cls == 2 ? 1 : 0;
  });
  // The scene has what the page is for: the explained wall and the space lying beams carved.
  REQUIRE(states[static_cast<std::size_t>(iv::ExplainedState::Occupied)] > 0);
  REQUIRE(states[static_cast<std::size_t>(iv::ExplainedState::Unexplained)] > 0);
  CHECK(page_voxels(grid.geometry(), v) == want);
  CHECK(v.per_class[2] == unexplained_free);
  CHECK(v.selected == want.size());

  // A page too small for all: the surface rule and the merges keep the explained colours.
  iv::HtmlViewOptions small = o;
  small.max_voxels = 50;
  const iv::ViewVoxels s = iv::pack_view_voxels(grid, small);
  CHECK(s.size_drawn() <= 50);
  for (std::size_t i = 0; i < s.rgb.size(); i += 3) {
    bool known = false;
    for (const iv::Rgb& c : iv::kExplainedStateColours)
      known = known || (s.rgb[i] == c.r && s.rgb[i + 1] == c.g && s.rgb[i + 2] == c.b);
    CHECK(known);
  }
}

TEST_CASE("the explained page carries its legend and switch names, escaped, and refuses another geometry",
          "[view][explained][errors]") {
  using Grid = test::BayesSparse;
  Grid grid(0.1);
  iv::ExplainedSpace space(grid.geometry());
  planted_scans(grid, space);
  const iv::HtmlViewOptions o = iv::explained_view_options(grid, space);
  const std::string page = iv::html_view_to_string(grid, o, iv::ViewScene{}, "var THREE={};", "");
  for (const char* name : iv::kExplainedStateLegendNames) CHECK(page.find(name) != std::string::npos);
  CHECK(page.find("free in the grid, not explained (") != std::string::npos);
  CHECK(page.find("background:#e67800") != std::string::npos);                // the orange of unexplained
  CHECK(page.find("state (probability of occupancy)") == std::string::npos);  // not the grid's legend

  CHECK(iv::html_swatch_legend("a<b", {{iv::Rgb{1, 2, 255}, "x & y"}}) ==
        "<div class=\"lt\">a&lt;b</div><div><span class=\"sw\" style=\"background:#0102ff\"></span>x &amp; y</div>");

  Grid coarser(0.2);
  CHECK_THROWS_WITH(iv::explained_view_options(coarser, space),
                    Catch::Contains("explained_view_options") && Catch::Contains("geometry"));
}
