#pragma once
/// \file
/// A rectangle in a plane: the surface a lying region is found on (analysis/lying_surfaces.hpp)
/// and the mirror an explained channel is told of (ExplainedSpace::add_mirror()).
///
/// Thread safety: a plain value type.

#include <intervox/core/error.hpp>
#include <intervox/core/point.hpp>
#include <intervox/core/validate.hpp>

#include <cmath>
#include <optional>
#include <string>

namespace intervox {

/// The rectangle through `center` with unit `normal`, spanned by the unit `axis_u` (orthogonal to
/// the normal) and axis_v() = normal x axis_u, reaching `half_u` and `half_v` from the centre
/// along them (metres). Both faces count: a beam crosses it from either side.
struct PlanePatch {
  Point3 center = Point3::Zero();
  Point3 normal = Point3::UnitX();
  Point3 axis_u = Point3::UnitY();
  double half_u = 0.0;
  double half_v = 0.0;

  /// The second in-plane axis, normal x axis_u.
  Point3 axis_v() const noexcept { return normal.cross(axis_u); }

  /// The patch's in-plane axis along the floor for \p normal: the horizontal direction in the
  /// plane (normal x z), or x for a horizontal plane.
  static Point3 floor_axis(const Point3& normal) noexcept {
    const Point3 u = normal.cross(Point3::UnitZ());
    return u.norm() > 1e-9 ? Point3(u.normalized()) : Point3(Point3::UnitX());
  }

  /// \throws InvalidArgument unless every field is finite, the normal and axis_u are unit vectors
  ///         (within 1e-6) orthogonal to each other (within 1e-6), and the half extents are >= 0.
  void validate() const {
    const ParamCheck check("intervox::PlanePatch");
    if (!is_finite(center) || !is_finite(normal) || !is_finite(axis_u) || !std::isfinite(half_u) ||
        !std::isfinite(half_v))
      check.fail("every field must be finite");
    if (std::abs(normal.norm() - 1.0) > 1e-6) check.fail("the normal must be a unit vector");
    if (std::abs(axis_u.norm() - 1.0) > 1e-6) check.fail("axis_u must be a unit vector");
    if (std::abs(normal.dot(axis_u)) > 1e-6) check.fail("axis_u must be orthogonal to the normal");
    check.nonnegative("half_u", half_u);
    check.nonnegative("half_v", half_v);
  }

  /// Where the segment \p a -> \p b crosses the patch, as the fraction t in (0, 1) of the way,
  /// or nothing: the two ends strictly on opposite sides of the plane and the crossing point
  /// within the rectangle.
  std::optional<double> crossing(const Point3& a, const Point3& b) const noexcept {
    const double sa = normal.dot(a - center), sb = normal.dot(b - center);
    if (!((sa > 0.0 && sb < 0.0) || (sa < 0.0 && sb > 0.0))) return std::nullopt;
    const double t = sa / (sa - sb);
    const Point3 m = a + t * (b - a) - center;
    if (std::abs(m.dot(axis_u)) > half_u || std::abs(m.dot(axis_v())) > half_v) return std::nullopt;
    return t;
  }

  /// True if \p p lies within \p half_thickness of the plane and within the rectangle's extent
  /// (measured in the plane).
  bool contains(const Point3& p, double half_thickness) const noexcept {
    const Point3 d = p - center;
    return std::abs(d.dot(normal)) <= half_thickness && std::abs(d.dot(axis_u)) <= half_u &&
           std::abs(d.dot(axis_v())) <= half_v;
  }
};

}  // namespace intervox
