// Hand-built rooms for the planner tests that run without the simulator: walls as boxes in x and y
// (as high as the band), and horizontal beam fans that end just inside the first wall they meet.
#pragma once

#include <intervox/core/point.hpp>
#include <intervox/core/sensor_data.hpp>

#include "ray_box.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <span>
#include <utility>
#include <vector>

namespace test {

/// A wall (or any box) in x and y: x0 <= x <= x1, y0 <= y <= y1.
struct WallBox {
  double x0, y0, x1, y1;
};

/// The parameter t >= 0 (in units of \p d) at which the ray o + t d in x and y enters \p w (slab
/// test; 0 if o lies inside), or infinity if it never does within t <= \p t_max.
inline double wall_entry(double ox, double oy, double dx, double dy, const WallBox& w,
                         double t_max = std::numeric_limits<double>::infinity()) {
  const auto t = ray_box<2>({ox, oy}, {dx, dy}, {w.x0, w.y0}, {w.x1, w.y1}, t_max);
  return t ? t->first : std::numeric_limits<double>::infinity();
}

/// Whether the segment a -> b meets \p w in x and y.
inline bool segment_meets(const intervox::Point3& a, const intervox::Point3& b, const WallBox& w) {
  return std::isfinite(wall_entry(a.x(), a.y(), b.x() - a.x(), b.y() - a.y(), w, 1.0));
}

/// The distance along the unit direction (dx, dy) from (x, y) to the first of \p walls, or
/// infinity if it meets none.
inline double distance_to_walls(std::span<const WallBox> walls, double x, double y, double dx, double dy) {
  double best = std::numeric_limits<double>::infinity();
  for (const WallBox& w : walls) best = std::min(best, wall_entry(x, y, dx, dy, w, best));
  return best;
}

/// Beams from (x, y) in 0.5° steps, in the six 0.1 m voxel layers of the band (z 0.25 to 0.75),
/// each ending 0.02 m inside the first of \p walls it meets, of those \p keep accepts (given both
/// ends). \p walls must enclose (x, y).
inline std::vector<intervox::Beam> planar_fan(
    std::span<const WallBox> walls, double x, double y,
    const std::function<bool(const intervox::Point3&, const intervox::Point3&)>& keep) {
  std::vector<intervox::Beam> beams;
  for (int layer = 0; layer < 6; ++layer) {
    const intervox::Point3 origin(x, y, 0.25 + 0.1 * layer);
    for (int a = 0; a < 720; ++a) {
      const double angle = a * std::numbers::pi / 360.0;
      const double dx = std::cos(angle), dy = std::sin(angle);
      const intervox::Point3 end =
          origin + intervox::Point3(dx, dy, 0.0) * (distance_to_walls(walls, x, y, dx, dy) + 0.02);
      if (keep(origin, end)) beams.push_back({origin, end, true});
    }
  }
  return beams;
}

}  // namespace test
