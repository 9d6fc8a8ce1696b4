#pragma once
/// \file
/// The exploration map as an image with the colour code of the thesis' Table 3.2 (in io/, not
/// plan/, so that the planning layer needs no libpng). Needs the CMake target `intervox::png`
/// (for write_png).

#include <intervox/core/validate.hpp>
#include <intervox/io/png.hpp>
#include <intervox/plan/exploration_map.hpp>
#include <intervox/plan/view_sampling.hpp>
#include <intervox/view/image_annotation.hpp>

#include <array>
#include <cmath>
#include <cstdlib>
#include <cstdint>
#include <numbers>
#include <optional>
#include <vector>

namespace intervox {

/// What a planning step adds on top of the map's labels.
struct MapOverlay {
  std::optional<Cell2> frontier;          ///< selected frontier (light yellow)
  std::optional<RingSamplerParams> ring;  ///< scan area around the frontier (purple, reachable cells)
  std::vector<Cell2> sampled;             ///< sampled robot positions (orange)
  std::optional<Cell2> selected;          ///< selected robot position (yellow)
  std::vector<Cell2> path;                ///< the robot's path so far, drawn as a line (dark green)
  std::vector<Cell2> views;               ///< positions of the views taken (orange rings)
};

/// Table 3.2 colours, indexed by MapLabel, extended by teal for lying regions given up as
/// unresolvable (conflict regions or unexplained groups seen from enough directions, see
/// docs/planning.md).
inline constexpr std::array<std::array<std::uint8_t, 3>, 9> kMapLabelColours{{
    {255, 255, 255},  // Unknown: blank
    {0, 0, 0},        // Occupied: black
    {128, 128, 128},  // CollisionSpace: gray
    {70, 110, 230},   // ReachableFree: blue
    {139, 0, 0},      // UnknownInCollision: dark red
    {150, 238, 150},  // MaybeCollision: light green
    {0, 100, 0},      // Unreachable: dark green
    {255, 140, 140},  // Border: light red
    {0, 160, 160},    // Unresolvable: teal (not in the thesis)
}};
inline constexpr std::array<std::uint8_t, 3> kFrontierColour{255, 255, 170};  ///< light yellow
inline constexpr std::array<std::uint8_t, 3> kScanAreaColour{160, 60, 200};   ///< purple
inline constexpr std::array<std::uint8_t, 3> kSampledColour{255, 150, 0};     ///< orange
inline constexpr std::array<std::uint8_t, 3> kSelectedColour{255, 225, 0};    ///< yellow
inline constexpr std::array<std::uint8_t, 3> kPathColour{0, 150, 60};         ///< green
inline constexpr std::array<std::uint8_t, 3> kViewColour{230, 90, 0};         ///< dark orange
/// Passage cells (ExplorationMap::passages(), with MobilePlannerParams::passage_views).
inline constexpr std::array<std::uint8_t, 3> kPassageColour{200, 0, 150};  ///< magenta
/// Cells passable only as the way back (ExplorationMap::passable() but not reachable(), with
/// MobilePlannerParams::driven_paths).
inline constexpr std::array<std::uint8_t, 3> kWayBackColour{30, 190, 255};  ///< sky blue

/// The legend of the exploration map's colours (Table 3.2 and the overlay).
inline Legend exploration_legend() {
  Legend l;
  l.title = "exploration map (table 3.2)";
  for (std::size_t i = 0; i <= static_cast<std::size_t>(MapLabel::Border); ++i)  // the labels of Table 3.2
    l.swatches.push_back({{kMapLabelColours[i][0], kMapLabelColours[i][1], kMapLabelColours[i][2]},
                          std::string(to_string(static_cast<MapLabel>(i)))});
  auto rgb = [](const std::array<std::uint8_t, 3>& c) { return Rgb{c[0], c[1], c[2]}; };
  l.swatches.push_back(
      {rgb(kMapLabelColours[static_cast<std::size_t>(MapLabel::Unresolvable)]), "lying region given up"});
  l.swatches.push_back({rgb(kPassageColour), "passage (beside space hiding unknown floor)"});
  l.swatches.push_back({rgb(kWayBackColour), "way back (driven path, passable only)"});
  l.swatches.push_back({rgb(kFrontierColour), "frontier"});
  l.swatches.push_back({rgb(kScanAreaColour), "scan area"});
  l.swatches.push_back({rgb(kSampledColour), "sampled positions"});
  l.swatches.push_back({rgb(kSelectedColour), "selected position"});
  l.swatches.push_back({rgb(kPathColour), "path"});
  l.swatches.push_back({rgb(kViewColour), "views taken"});
  return l;
}

/// Renders \p map with \p overlay, \p scale pixels per cell, north (+y) up; with \p labels, framed
/// by annotate_image (title, exploration_legend(), scale bar).
/// \throws InvalidArgument if scale < 1 or the image would exceed 2^28 pixels; as annotate_image.
/// Thread safety: reentrant.
inline RgbImage render_exploration_map(const ExplorationMap& map, const MapOverlay& overlay = {}, int scale = 4,
                                       const ImageLabels& labels = {}) {
  ParamCheck("intervox::render_exploration_map").at_least("scale", scale, 1);
  RgbImage img = RgbImage::filled(map.width() * scale, map.height() * scale, 255, 255, 255);
  auto paint = [&](const Cell2& c, const std::array<std::uint8_t, 3>& col, int shrink = 0) {
    if (c.x < 0 || c.y < 0 || c.x >= map.width() || c.y >= map.height()) return;
    const int y0 = (map.height() - 1 - c.y) * scale;
    for (int dy = shrink; dy < scale - shrink; ++dy)
      for (int dx = shrink; dx < scale - shrink; ++dx) img.set(c.x * scale + dx, y0 + dy, col[0], col[1], col[2]);
  };
  for (int y = 0; y < map.height(); ++y)
    for (int x = 0; x < map.width(); ++x) paint({x, y}, kMapLabelColours[static_cast<std::size_t>(map.label({x, y}))]);
  for (const Cell2& c : map.passages()) paint(c, kPassageColour);
  for (int y = 0; y < map.height(); ++y)
    for (int x = 0; x < map.width(); ++x)
      if (map.passable({x, y}) && !map.reachable({x, y})) paint({x, y}, kWayBackColour);
  if (overlay.frontier && overlay.ring) {
    for (const Cell2& c : ring_cells(map, *overlay.frontier, *overlay.ring)) paint(c, kScanAreaColour);
  }
  // Markers: a few cells wide so that they are visible at any scale.
  auto mark = [&](const Cell2& c, const std::array<std::uint8_t, 3>& col, int r) {
    for (int dy = -r; dy <= r; ++dy)
      for (int dx = -r; dx <= r; ++dx) paint({c.x + dx, c.y + dy}, col);
  };
  if (overlay.frontier) mark(*overlay.frontier, kFrontierColour, 1);
  for (const Cell2& c : overlay.sampled) mark(c, kSampledColour, 1);
  if (overlay.selected) mark(*overlay.selected, kSelectedColour, 2);
  // The path: straight lines between consecutive cells, one pixel per step at the cells' centres.
  auto plot = [&](double fx, double fy, const std::array<std::uint8_t, 3>& col) {
    const int px = static_cast<int>(std::floor(fx * scale)),
              py = static_cast<int>(std::floor((map.height() - fy) * scale));
    for (int dy = -(scale / 4); dy <= scale / 4; ++dy)
      for (int dx = -(scale / 4); dx <= scale / 4; ++dx) img.set(px + dx, py + dy, col[0], col[1], col[2]);
  };
  for (std::size_t i = 1; i < overlay.path.size(); ++i) {
    const Cell2 a = overlay.path[i - 1], b = overlay.path[i];
    const int steps = std::max(1, std::max(std::abs(b.x - a.x), std::abs(b.y - a.y)) * scale);
    for (int s = 0; s <= steps; ++s) {
      const double t = static_cast<double>(s) / steps;
      plot(a.x + 0.5 + t * (b.x - a.x), a.y + 0.5 + t * (b.y - a.y), kPathColour);
    }
  }
  // Views: a ring of radius 2 cells around each position.
  for (const Cell2& c : overlay.views) {
    const int n = 16 * scale;
    for (int s = 0; s < n; ++s) {
      const double a = 2.0 * std::numbers::pi * s / n;
      plot(c.x + 0.5 + 2.0 * std::cos(a), c.y + 0.5 + 2.0 * std::sin(a), kViewColour);
    }
  }
  if (!labels.any()) return img;
  const Legend legend = exploration_legend();
  return annotate_image(img, labels, &legend, map.resolution() / scale);
}

}  // namespace intervox
