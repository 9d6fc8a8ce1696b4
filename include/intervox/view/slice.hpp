#pragma once
/// \file
/// Images of a grid: a z-slice, or a maximum / mean projection along z, coloured by state,
/// interval width, utility or the thesis' Table 5.2 code. Needs no library; write the result with
/// io/png.hpp (target intervox::png).

#include <intervox/core/checked_math.hpp>
#include <intervox/core/error.hpp>
#include <intervox/core/interval.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/grid/occupancy_grid.hpp>
#include <intervox/io/color.hpp>
#include <intervox/io/rgb_image.hpp>
#include <intervox/view/image_annotation.hpp>

#include <algorithm>
#include <cstdint>
#include <optional>
#include <vector>

namespace intervox {

/// What a slice image shows along z.
enum class SliceMode : std::uint8_t {
  Slice,           ///< the voxels of one z layer (SliceOptions::z)
  MaxProjection,   ///< per column, the maximum of state, width and utility over the z range
  MeanProjection,  ///< per column, the mean of state, width and utility over the observed voxels
};

/// Options of render_slice.
struct SliceOptions {
  ColorBy color = ColorBy::State;
  SliceMode mode = SliceMode::Slice;
  std::int32_t z = 0;  ///< the key z of the layer (SliceMode::Slice)
  /// The keys drawn (x, y) and, for projections, the z range. Default: the grid's key box, or the
  /// smallest box around the observed voxels of an unbounded grid.
  std::optional<KeyBox> window;
  int pixels_per_voxel = 1;           ///< each voxel becomes a square of this many pixels, 1..64
  Rgb unobserved = kUnobservedColor;  ///< colour of columns without an observed voxel
  /// Title, legend of the colour code and scale bar around the image (annotate_image); none by
  /// default, so that pixel (0, 0) is the window's corner.
  ImageLabels labels;
};

/// Renders a slice or projection of \p grid. Pixel (0, 0) is the top-left corner: x grows to the
/// right and y upwards (the row of window.max.y is the top row). Columns without any observed voxel
/// in range get options.unobserved.
/// \tparam Grid any VoxelGrid
/// With options.labels set, the image is annotate_image's: the slice framed, title above, legend
/// (legend_for(options.color)) and scale bar below.
/// \throws InvalidArgument if pixels_per_voxel is outside 1..64, the window is empty, the image would
///         exceed 2^28 pixels, or there is no window (unbounded grid without observations); as
///         annotate_image for bad labels.
/// Thread safety: reads the grid only.
template <OccupancyGrid Grid>
RgbImage render_slice(const Grid& grid, const SliceOptions& options = {}) {
  ParamCheck("intervox::render_slice").in_range("pixels_per_voxel", options.pixels_per_voxel, 1, 64);
  std::optional<KeyBox> window = options.window ? options.window : grid.key_box();
  if (!window) {
    grid.for_each_observed([&](const Key& k, const typename Grid::Cell&) {
      if (!window) window = KeyBox{k, k};
      for (int a = 0; a < 3; ++a) {
        window->min[a] = std::min(window->min[a], k[a]);
        window->max[a] = std::max(window->max[a], k[a]);
      }
    });
    if (!window) ParamCheck("intervox::render_slice").fail("an unbounded grid without observations needs a window");
  }
  const KeyBox w = *window;
  if (w.extent(0) <= 0 || w.extent(1) <= 0 || w.extent(2) <= 0)
    ParamCheck("intervox::render_slice").fail("empty window");
  const std::int64_t ppv = options.pixels_per_voxel;
  // The window may come from a file's key box (extents up to 2^32): a product that cannot wrap.
  if (saturating_mul(saturating_mul(w.extent(0), ppv), saturating_mul(w.extent(1), ppv)) > (std::int64_t{1} << 28)) {
    ParamCheck("intervox::render_slice").fail("the image would exceed 2^28 pixels");
  }
  const auto nx = static_cast<std::size_t>(w.extent(0));
  const auto ny = static_cast<std::size_t>(w.extent(1));
  struct Column {
    double state = 0, width = 0, utility = 0;
    int count = 0;
  };
  std::vector<Column> columns(nx * ny);
  const auto& u = grid.update_policy();
  grid.for_each_observed([&](const Key& k, const typename Grid::Cell& c) {
    if (k.x < w.min.x || k.x > w.max.x || k.y < w.min.y || k.y > w.max.y) return;
    if (options.mode == SliceMode::Slice ? k.z != options.z : (k.z < w.min.z || k.z > w.max.z)) return;
    Column& col = columns[static_cast<std::size_t>(k.y - w.min.y) * nx + static_cast<std::size_t>(k.x - w.min.x)];
    const Interval i = u.interval(c);
    const double s = u.state(c), wd = i.upper - i.lower, ut = grid.utility_of(c);
    if (options.mode == SliceMode::MaxProjection && col.count > 0) {
      col.state = std::max(col.state, s);
      col.width = std::max(col.width, wd);
      col.utility = std::max(col.utility, ut);
    } else if (options.mode == SliceMode::MaxProjection) {
      col = {s, wd, ut, 0};
    } else {
      col.state += s;
      col.width += wd;
      col.utility += ut;
    }
    ++col.count;
  });
  RgbImage image = RgbImage::filled(static_cast<int>(static_cast<std::int64_t>(nx) * ppv),
                                    static_cast<int>(static_cast<std::int64_t>(ny) * ppv), options.unobserved.r,
                                    options.unobserved.g, options.unobserved.b);
  for (std::size_t y = 0; y < ny; ++y) {
    for (std::size_t x = 0; x < nx; ++x) {
      const Column& col = columns[y * nx + x];
      if (col.count == 0) continue;
      const double n = options.mode == SliceMode::MaxProjection ? 1.0 : col.count;
      const Rgb rgb = voxel_color(options.color, col.state / n, col.width / n, col.utility / n);
      const auto top = static_cast<int>((static_cast<std::int64_t>(ny) - 1 - static_cast<std::int64_t>(y)) * ppv);
      for (int py = 0; py < ppv; ++py)
        for (int px = 0; px < ppv; ++px) image.set(static_cast<int>(x * ppv) + px, top + py, rgb.r, rgb.g, rgb.b);
    }
  }
  if (!options.labels.any()) return image;
  Legend legend = legend_for(options.color);
  legend.swatches.push_back({options.unobserved, "unobserved"});
  return annotate_image(image, options.labels, &legend, grid.geometry().resolution() / static_cast<double>(ppv));
}

}  // namespace intervox
