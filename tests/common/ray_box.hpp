// The slab test of a ray against an axis-aligned box, shared by the hand-built rooms of the tests
// (tests/common/planar_walls.hpp in x and y, tests/common/planted_mirror_room.hpp in 3D).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <utility>

namespace test {

/// The interval [t0, t1] of the parameter t in [0, \p t_max] over which o + t d lies in the closed
/// box lo..hi along its N axes (t0 = 0 if o lies inside), or nothing if the ray misses the box
/// within it. An axis along which d is (nearly) zero holds the ray only if o lies in its slab.
template <std::size_t N>
std::optional<std::pair<double, double>> ray_box(const std::array<double, N>& o, const std::array<double, N>& d,
                                                 const std::array<double, N>& lo, const std::array<double, N>& hi,
                                                 double t_max) {
  double t0 = 0.0, t1 = t_max;
  for (std::size_t a = 0; a < N; ++a) {
    if (std::abs(d[a]) < 1e-12) {
      if (o[a] < lo[a] || o[a] > hi[a]) return std::nullopt;
      continue;
    }
    double ta = (lo[a] - o[a]) / d[a], tb = (hi[a] - o[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return std::nullopt;
  }
  return std::pair{t0, t1};
}

}  // namespace test
