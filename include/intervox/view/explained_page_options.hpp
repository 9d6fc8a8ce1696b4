#pragma once
/// \file
/// Explained free space on the 3D page (view/html_view.hpp): page options that colour every voxel
/// by what the explained-free-space channel (explain/explained_space.hpp) says of it, and keep
/// in the page's free class only the space that lying beams alone made look free.
///
///     iv::ExplainedSpace space(grid.geometry());
///     // ... space.insert_point_cloud(inserter, grid, origin, points) for every scan ...
///     iv::write_html_view("explained.html", grid, iv::explained_view_options(grid, space));
///
/// The `view` program does the same with `--explained FILE.ivxe` (docs/viewing.md).

#include <intervox/core/error.hpp>
#include <intervox/explain/explained_space.hpp>
#include <intervox/grid/occupancy_grid.hpp>
#include <intervox/view/explained_image.hpp>
#include <intervox/view/html_view.hpp>

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace intervox {

/// The names of the explained states on the page's legend, indexed by ExplainedState.
inline constexpr std::array<const char*, 4> kExplainedStateLegendNames{
    "no evidence (unknown)", "explained free", "explained occupied",
    "unexplained: suspect or no-return evidence only, or conflict"};

/// Page options (a copy of \p options with the changes below) that draw the voxels of \p grid
/// by their explained state in \p space:
///  - each voxel's colour is kExplainedStateColours[space.state(key)]: light gray no evidence,
///    white explained free, black explained occupied, orange unexplained; the legend says so;
///  - the free class holds only the voxels the grid calls free that \p space does not explain
///    free: what the plain map believes free on the word of suspect or no-return beams alone (a
///    mirror's phantom room, the void behind a black surface). Free voxels that are explained
///    free are left out, so that the page shows where the two maps disagree and the surfaces;
///  - options.voxels becomes Observed, all three classes are shown when the page opens, and the
///    free switch is named "free in the grid, not explained". Change them on the returned options
///    if you want otherwise; options.color is not used.
/// \p space is captured by reference: it must outlive every use of the returned options, and must
/// not be modified while a page is being written.
/// \tparam Grid any OccupancyGrid
/// \throws InvalidArgument if the grid's geometry (resolution, origin) differs from the channel's.
/// Thread safety: reads \p grid and \p space only.
template <OccupancyGrid Grid>
HtmlViewOptions explained_view_options(const Grid& grid, const ExplainedSpace& space, HtmlViewOptions options = {}) {
  space.check_geometry(grid.geometry(), "intervox::explained_view_options");
  const ExplainedSpace* s = &space;
  options.voxel_colour = [s](const Key& k, Occupancy o) -> std::optional<Rgb> {
    const ExplainedState state = s->state(k);
    if (o == Occupancy::Free && state == ExplainedState::Free) return std::nullopt;
    return kExplainedStateColours[static_cast<std::size_t>(state)];
  };
  std::vector<std::pair<Rgb, std::string>> swatches;
  for (std::size_t i = 0; i < kExplainedStateLegendNames.size(); ++i)
    swatches.emplace_back(kExplainedStateColours[i], kExplainedStateLegendNames[i]);
  options.legend_html = html_swatch_legend("explained state", swatches);
  options.voxels = HtmlViewOptions::Voxels::Observed;
  options.shown = {true, true, true};
  options.class_names[2] = "free in the grid, not explained";
  return options;
}

}  // namespace intervox
