#pragma once
/// \file
/// Colour schemes for voxels, shared by the PLY export and the slice images.
/// Thread safety: pure functions; safe to call concurrently.

#include <intervox/core/interval.hpp>
#include <intervox/grid/occupancy_grid.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace intervox {

/// An 8-bit colour.
struct Rgb {
  std::uint8_t r = 0, g = 0, b = 0;
  friend constexpr bool operator==(const Rgb&, const Rgb&) = default;
};

/// What a voxel's colour shows.
enum class ColorBy : std::uint8_t {
  State,          ///< grayscale: white = free (state 0), black = occupied (state 1)
  IntervalWidth,  ///< blue = narrow interval (width 0) → red = broad (width 1), thesis Fig. 5.8
  Utility,        ///< black (0) → red → yellow (≥ 1); the utility policies' values lie in [0, 1]
  Table52,        ///< the thesis' combined code of Table 5.2 (see table52_color)
};

/// Colour of unobserved voxels in slices (teal; not used by any scheme for observed voxels).
inline constexpr Rgb kUnobservedColor{0, 150, 150};

namespace detail {
inline std::uint8_t to_byte(double v) noexcept {
  if (!(v > 0.0)) return 0;  // also NaN
  return v >= 1.0 ? 255 : static_cast<std::uint8_t>(std::lround(v * 255.0));
}
}  // namespace detail

/// The thesis' Table 5.2 with state and width quantised to 0..255:
/// red = width > 127 (any state); with width ≤ 127: blue = 75 < state < 180, black = state > 250,
/// white = state ≤ 4, then gray = width ≤ 50, yellow = 50 < width ≤ 127 for all other states.
inline Rgb table52_color(double state, double width) noexcept {
  const int s = detail::to_byte(state);
  const int w = detail::to_byte(width);
  if (w > 127) return {255, 0, 0};
  if (s > 75 && s < 180) return {0, 0, 255};
  if (s > 250) return {0, 0, 0};
  if (s <= 4) return {255, 255, 255};
  if (w <= 50) return {128, 128, 128};
  return {255, 255, 0};
}

/// Colour of an observed voxel from its state, interval width and utility.
inline Rgb voxel_color(ColorBy by, double state, double width, double utility) noexcept {
  switch (by) {
    case ColorBy::State: {
      const std::uint8_t v = detail::to_byte(1.0 - state);
      return {v, v, v};
    }
    case ColorBy::IntervalWidth:
      return {detail::to_byte(width), 0, detail::to_byte(1.0 - width)};
    case ColorBy::Utility:
      return {detail::to_byte(2.0 * utility), detail::to_byte(2.0 * utility - 1.0), 0};
    case ColorBy::Table52:
      return table52_color(state, width);
  }
  return kUnobservedColor;
}

/// Colour of a grid's cell (which must be observed) by \p by.
template <OccupancyGrid Grid>
Rgb cell_color(const Grid& grid, const typename Grid::Cell& c, ColorBy by) {
  const auto& u = grid.update_policy();
  const Interval i = u.interval(c);
  return voxel_color(by, u.state(c), i.upper - i.lower, grid.utility_of(c));
}

}  // namespace intervox
