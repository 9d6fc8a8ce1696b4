#pragma once
/// \file
/// Explained free space as a picture: a horizontal band of the map seen from above, each column
/// of voxels coloured by what the explained-free-space channel (explain/) says of it, with the
/// legend; and the same band of any grid by its own occupancy, for side-by-side figures. Writes
/// nothing itself (write_png() in io/png.hpp does, with the target intervox::png).

#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/explain/explained_space.hpp>
#include <intervox/grid/occupancy_grid.hpp>
#include <intervox/io/color.hpp>
#include <intervox/io/rgb_image.hpp>
#include <intervox/view/image_annotation.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <string>

namespace intervox {

/// The colours of the explained states, indexed by ExplainedState (Unknown, Free, Occupied,
/// Unexplained); the occupancy and truth pictures use the first three for unknown, free and
/// occupied.
inline constexpr std::array<Rgb, 4> kExplainedStateColours{{
    {200, 200, 200},  // unknown: light gray
    {255, 255, 255},  // free: white
    {0, 0, 0},        // occupied: black
    {230, 120, 0},    // unexplained: orange
}};

/// The legend of the explained-state picture.
inline Legend explained_legend() {
  Legend l;
  l.title = "explained state (worst voxel of the column)";
  static constexpr std::array<const char*, 4> kNames{"unknown", "explained free", "explained occupied",
                                                     "unexplained (suspect or no-return evidence only, or conflict)"};
  for (std::size_t i = 0; i < kNames.size(); ++i) l.swatches.push_back({kExplainedStateColours[i], kNames[i]});
  return l;
}

/// The legend of the occupancy picture (render_occupancy_band()).
inline Legend occupancy_legend() {
  Legend l;
  l.title = "occupancy (worst voxel of the column)";
  l.swatches = {{kExplainedStateColours[0], "unknown"},
                {kExplainedStateColours[1], "free"},
                {kExplainedStateColours[2], "occupied"}};
  return l;
}

namespace detail {

/// Checks a band and returns its key range; \p what names the caller in messages.
inline KeyBox band_keys(const GridGeometry& g, const Bounds& band, int pixels_per_voxel, const char* what) {
  const std::string where = std::string("intervox::") + what;
  const ParamCheck check(where.c_str());
  check.valid_bounds("band", band);
  check.in_range("pixels_per_voxel", pixels_per_voxel, 1, 16);
  const auto lo = g.try_key(band.min), hi = g.try_key(band.max);
  if (!lo || !hi) check.fail("the band leaves the key range");
  const KeyBox box{*lo, *hi};
  const std::int64_t w = box.extent(0) * pixels_per_voxel, h = box.extent(1) * pixels_per_voxel;
  if (w * h > (std::int64_t{1} << 26))
    check.fail("the picture would have " + std::to_string(w) + " x " + std::to_string(h) +
               " pixels (more than 2^26); choose a smaller band or coarser pixels");
  return box;
}

/// Draws each (x, y) column of \p box in the colour kExplainedStateColours[r], r the highest
/// rank(key) among its voxels (the worst state wins). North (max y) is up.
template <class Rank>
RgbImage render_columns(const KeyBox& box, int ppv, Rank&& rank) {
  const int w = static_cast<int>(box.extent(0)), h = static_cast<int>(box.extent(1));
  RgbImage im = RgbImage::filled(w * ppv, h * ppv, 0, 0, 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      int best = 0;
      for (std::int32_t z = box.min.z; z <= box.max.z; ++z)
        best = std::max(best, rank(Key{box.min.x + x, box.min.y + y, z}));
      const Rgb c = kExplainedStateColours[static_cast<std::size_t>(best)];
      for (int dy = 0; dy < ppv; ++dy)
        for (int dx = 0; dx < ppv; ++dx) im.set(x * ppv + dx, (h - 1 - y) * ppv + dy, c.r, c.g, c.b);
    }
  return im;
}

}  // namespace detail

/// The voxels of \p band seen from above, each (x, y) column coloured by the worst explained
/// state among its voxels (unexplained > occupied > free > unknown: a column is drawn orange if
/// any voxel in it is unexplained), \p pixels_per_voxel pixels a voxel, north up.
/// \throws InvalidArgument for an invalid band, pixels_per_voxel outside 1..16, or a picture of
///         more than 2^26 pixels.
inline RgbImage render_explained_band(const ExplainedSpace& space, const Bounds& band, int pixels_per_voxel = 2) {
  const KeyBox box = detail::band_keys(space.geometry(), band, pixels_per_voxel, "render_explained_band");
  // The rank is the state's value: unknown 0 < free 1 < occupied 2 < unexplained 3.
  return detail::render_columns(box, pixels_per_voxel, [&](const Key& k) { return static_cast<int>(space.state(k)); });
}

/// The same band of any grid, each column coloured by the worst occupancy among its voxels
/// (occupied > free > unknown), for a figure beside render_explained_band().
/// \tparam G an OccupancyGrid
/// \throws as render_explained_band().
template <OccupancyGrid G>
RgbImage render_occupancy_band(const G& grid, const Bounds& band, int pixels_per_voxel = 2) {
  const KeyBox box = detail::band_keys(grid.geometry(), band, pixels_per_voxel, "render_occupancy_band");
  // The rank is the class's value, as in the colour table: unknown 0 < free 1 < occupied 2.
  return detail::render_columns(box, pixels_per_voxel,
                                [&](const Key& k) { return static_cast<int>(grid.occupancy(k)); });
}

/// The same band of any truth, each column black where \p occupied(key) holds for one of its
/// voxels, white elsewhere (e.g. the simulator's Scene::occupied).
/// \throws as render_explained_band().
inline RgbImage render_truth_band(const GridGeometry& g, const Bounds& band,
                                  const std::function<bool(const Key&)>& occupied, int pixels_per_voxel = 2) {
  const KeyBox box = detail::band_keys(g, band, pixels_per_voxel, "render_truth_band");
  return detail::render_columns(box, pixels_per_voxel, [&](const Key& k) { return occupied(k) ? 2 : 1; });
}

}  // namespace intervox
