#pragma once
/// \file
/// Triangle meshes for the simulator's scenes, and generators for the shapes the built-in scenes use.

#include <intervox/core/error.hpp>
#include <intervox/core/point.hpp>
#include <intervox/core/validate.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

namespace intervox::sim {

/// An indexed triangle mesh. A mesh whose every edge is shared by exactly two triangles is
/// *closed* and counts as a solid (its inside is occupied); otherwise it is a surface.
///
/// Thread safety: a value type.
struct TriangleMesh {
  std::vector<Point3> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;

  /// \throws InvalidArgument for an empty mesh, a non-finite vertex, an index out of range or a
  /// degenerate (zero-area) triangle.
  void validate() const {
    const ParamCheck check("intervox::sim::TriangleMesh");
    if (triangles.empty()) check.fail("mesh has no triangles");
    for (const Point3& v : vertices)
      if (!is_finite(v)) check.fail("vertex is not finite");
    for (std::size_t i = 0; i < triangles.size(); ++i) {
      for (const auto idx : triangles[i])
        if (idx >= vertices.size()) check.fail("triangle " + std::to_string(i) + " indexes a missing vertex");
      const Point3& a = vertices[triangles[i][0]];
      const Point3 n = (vertices[triangles[i][1]] - a).cross(vertices[triangles[i][2]] - a);
      if (!(n.norm() > 1e-12)) check.fail("triangle " + std::to_string(i) + " is degenerate");
    }
  }

  /// True if every undirected edge belongs to exactly two triangles.
  bool closed() const {
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
    for (const auto& t : triangles)
      for (int k = 0; k < 3; ++k) {
        std::uint32_t a = t[k], b = t[(k + 1) % 3];
        if (a > b) std::swap(a, b);
        ++edges[{a, b}];
      }
    for (const auto& [e, n] : edges)
      if (n != 2) return false;
    return !edges.empty();
  }
};

/// A closed ring (a tube: an annulus extruded along z), e.g. a flange-like mechanical part with a
/// central hole: centre of the bottom face \p base, radii \p inner < \p outer, \p height, and
/// \p segments facets around (>= 3).
/// \throws InvalidArgument unless 0 < inner < outer, height > 0, all finite, segments >= 3.
inline TriangleMesh make_ring(const Point3& base, double inner, double outer, double height, int segments = 48) {
  const ParamCheck check("intervox::sim::make_ring");
  if (!is_finite(base)) check.fail("base must be finite");
  check.positive("inner", inner);
  check.positive("outer", outer);
  if (!(inner < outer)) check.fail("need inner < outer");
  check.positive("height", height);
  check.at_least("segments", segments, 3);
  TriangleMesh m;
  const double two_pi = 2.0 * std::numbers::pi;
  const auto n = static_cast<std::uint32_t>(segments);
  // Vertex layout per segment k: 4k + {inner bottom, outer bottom, inner top, outer top}.
  for (std::uint32_t k = 0; k < n; ++k) {
    const double a = two_pi * k / n, c = std::cos(a), s = std::sin(a);
    m.vertices.push_back(base + Point3(inner * c, inner * s, 0));
    m.vertices.push_back(base + Point3(outer * c, outer * s, 0));
    m.vertices.push_back(base + Point3(inner * c, inner * s, height));
    m.vertices.push_back(base + Point3(outer * c, outer * s, height));
  }
  const auto quad = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d) {
    m.triangles.push_back({a, b, c});
    m.triangles.push_back({a, c, d});
  };
  for (std::uint32_t k = 0; k < n; ++k) {
    const std::uint32_t i = 4 * k, j = 4 * ((k + 1) % n);
    quad(i + 1, j + 1, j + 3, i + 3);  // outer wall
    quad(i + 0, i + 2, j + 2, j + 0);  // inner wall
    quad(i + 2, i + 3, j + 3, j + 2);  // top
    quad(i + 0, j + 0, j + 1, i + 1);  // bottom
  }
  return m;
}

/// A closed box mesh of [lo, hi] (12 triangles). \throws InvalidArgument unless lo < hi, finite.
inline TriangleMesh make_box_mesh(const Point3& lo, const Point3& hi) {
  if (!is_finite(lo) || !is_finite(hi) || !(lo.array() < hi.array()).all())
    ParamCheck("intervox::sim::make_box_mesh").fail("need finite lo < hi on every axis");
  TriangleMesh m;
  for (int k = 0; k < 8; ++k)
    m.vertices.emplace_back((k & 1) ? hi.x() : lo.x(), (k & 2) ? hi.y() : lo.y(), (k & 4) ? hi.z() : lo.z());
  const std::uint32_t f[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : f) {
    m.triangles.push_back({q[0], q[1], q[2]});
    m.triangles.push_back({q[0], q[2], q[3]});
  }
  return m;
}

}  // namespace intervox::sim
