#pragma once
/// \file
/// Internal: what the apartment generator's stages share: the draws from its one generator, lists
/// of free intervals, and the scene objects it plans (ObjectSpec) before they are added to a Scene.
/// Not public API.

#include <intervox/core/key.hpp>
#include <intervox/core/random.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/sim/material.hpp>
#include <intervox/sim/scene.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace intervox::sim::detail {

/// Wall thickness [m] of the apartments.
inline constexpr double kWall = 0.1;
/// The smallest side of a room between wall centre lines [m].
inline constexpr double kMinRoomSide = 2.4;

/// Intervals [lo, hi] along a line.
using Intervals = std::vector<std::pair<double, double>>;

/// Removes [a, b] from \p list.
inline void subtract(Intervals& list, double a, double b) {
  Intervals out;
  for (const auto& [lo, hi] : list) {
    if (b <= lo || a >= hi) {
      out.push_back({lo, hi});
      continue;
    }
    if (a > lo) out.push_back({lo, a});
    if (b < hi) out.push_back({b, hi});
  }
  list = std::move(out);
}

/// \p v rounded to 5 cm.
inline double snap(double v) { return std::round(v / 0.05) * 0.05; }

/// The draws of one apartment, all from one SeededRandom (so a seed gives the same world everywhere).
class Draws {
 public:
  explicit Draws(SeededRandom& random) : random_(random) {}
  double uniform() { return random_.uniform(); }
  double uniform(double a, double b) { return a + (b - a) * random_.uniform(); }
  /// Uniform in [a, b] (whole numbers).
  int integer(int a, int b) { return a + static_cast<int>(random_.below(static_cast<std::size_t>(b - a + 1))); }
  std::size_t below(std::size_t n) { return random_.below(n); }
  bool chance(double p) { return random_.uniform() < p; }

  /// The start of a random stretch of \p width within \p list (uniform over where it fits), or
  /// nothing if none fits.
  std::optional<double> pick(const Intervals& list, double width) {
    double room = 0;
    Intervals fits;
    for (const auto& [lo, hi] : list)
      if (hi - lo >= width) {
        fits.push_back({lo, hi});
        room += hi - lo - width;
      }
    if (fits.empty()) return std::nullopt;
    if (room <= 1e-9) return fits[below(fits.size())].first;
    double u = uniform(0.0, room);
    for (const auto& [lo, hi] : fits) {
      const double slack = hi - lo - width;
      if (u <= slack) return lo + u;
      u -= slack;
    }
    return fits.back().first;
  }

 private:
  SeededRandom& random_;
};

/// A scene object to add: what the generator plans, added to the Scene at the end.
struct ObjectSpec {
  enum class Shape : std::uint8_t { Box, OrientedBox, Quad, Cylinder };
  Shape shape = Shape::Box;
  std::string name;
  Material material = Material::diffuse();
  Bounds box{};                  ///< Box
  Pose pose = Pose::Identity();  ///< OrientedBox: centre and rotation
  Point3 half = Point3::Zero();  ///< OrientedBox: half extents
  Point3 corner = Point3::Zero(), edge_u = Point3::Zero(), edge_v = Point3::Zero();  ///< Quad
  Point3 base = Point3::Zero(), top = Point3::Zero();                                ///< Cylinder
  double radius = 0;                                                                 ///< Cylinder
  int fixture = -1;           ///< the fixture whose surface (or body) this is, or -1
  bool fixture_body = false;  ///< the fixture's furniture body, not its lying surface
  int doorway = -1;           ///< the doorway whose leaf or pane this is, or -1
};

/// Adds \p s to \p scene.
inline ObjectId add_object(Scene& scene, const ObjectSpec& s) {
  switch (s.shape) {
    case ObjectSpec::Shape::OrientedBox:
      return scene.add_oriented_box(s.pose, s.half, s.material, s.name);
    case ObjectSpec::Shape::Quad:
      return scene.add_quad(s.corner, s.edge_u, s.edge_v, s.material, s.name);
    case ObjectSpec::Shape::Cylinder:
      return scene.add_cylinder(s.base, s.top, s.radius, s.material, s.name);
    case ObjectSpec::Shape::Box:
      break;
  }
  return scene.add_box(s.box, s.material, s.name);
}

/// A box object named \p name.
inline ObjectSpec box_spec(std::string name, const Bounds& box, const Material& m = Material::diffuse()) {
  ObjectSpec s;
  s.name = std::move(name);
  s.box = box;
  s.material = m;
  return s;
}

}  // namespace intervox::sim::detail
