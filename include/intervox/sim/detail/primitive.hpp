#pragma once
/// \file
/// Internal: the flat primitive record of the simulator's scene, its ray intersection, signed
/// distance and box overlap tests. Users go through intervox::sim::Scene.

#include <intervox/core/key.hpp>
#include <intervox/core/point.hpp>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

namespace intervox::sim::detail {

inline constexpr double kInf = std::numeric_limits<double>::infinity();

enum class PrimKind : std::uint8_t { Box, OrientedBox, Quad, Sphere, Cylinder, Triangle };

/// One primitive. Meaning of the fields per kind:
///  Box: a = min, b = max.   OrientedBox: a = centre, b = half extents, rot = local-to-world.
///  Quad: a = corner, b = edge u, c = edge v.   Sphere: a = centre, r = radius.
///  Cylinder: a = base centre, b = top centre, r = radius.   Triangle: a, b, c = vertices.
/// Derived per kind by prepare() (computed once, with the same expressions as on the fly, so
/// results are the same bit for bit):
///  Cylinder: w = unit axis (b - a) / len, len = |b - a|.
struct Prim {
  PrimKind kind = PrimKind::Box;
  bool solid = true;  ///< part of a solid (ground truth uses open-set semantics)
  std::uint32_t object = 0;
  Point3 a = Point3::Zero(), b = Point3::Zero(), c = Point3::Zero();
  Eigen::Matrix3d rot = Eigen::Matrix3d::Identity();
  double r = 0;
  Point3 w = Point3::Zero();
  double len = 0;
};

/// Fills the derived fields of \p p (see Prim).
inline void prepare(Prim& p) noexcept {
  if (p.kind == PrimKind::Cylinder) {
    const Point3 axis = p.b - p.a;
    p.len = axis.norm();
    p.w = axis / p.len;
  }
}

/// slab() with the ray's component-wise inverse direction \p inv = d.cwiseInverse() given (the
/// same arithmetic, so the same result bit for bit).
inline bool slab_inv(const Point3& lo, const Point3& hi, const Point3& o, const Point3& d, const Point3& inv,
                     double& t0, double& t1) noexcept {
  t0 = -kInf;
  t1 = kInf;
  for (int i = 0; i < 3; ++i) {
    if (d[i] == 0.0) {
      if (o[i] < lo[i] || o[i] > hi[i]) return false;
      continue;
    }
    double ta = (lo[i] - o[i]) * inv[i], tb = (hi[i] - o[i]) * inv[i];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  return true;
}

/// Slab test of a ray against [lo, hi]; on success [t0, t1] is the parameter interval inside.
inline bool slab(const Point3& lo, const Point3& hi, const Point3& o, const Point3& d, double& t0,
                 double& t1) noexcept {
  return slab_inv(lo, hi, o, d, d.cwiseInverse(), t0, t1);
}

/// The first parameter in (tmin, tmax] where the ray meets a solid box's boundary.
inline double hit_box(const Point3& lo, const Point3& hi, const Point3& o, const Point3& d, double tmin,
                      double tmax) noexcept {
  double t0, t1;
  if (!slab(lo, hi, o, d, t0, t1)) return kInf;
  const double t = t0 > tmin ? t0 : t1;
  return (t > tmin && t <= tmax) ? t : kInf;
}

/// slab_inv() for a ray whose \p inv has only finite components (no zero or subnormal direction
/// component): without branches, and then the same result bit for bit (min/max of finite values
/// in place of the swap, and the empty test once at the end, since t0 only grows and t1 only
/// shrinks).
inline bool slab_finite_inv(const Point3& lo, const Point3& hi, const Point3& o, const Point3& inv, double& t0,
                            double& t1) noexcept {
  const double ax = (lo.x() - o.x()) * inv.x(), bx = (hi.x() - o.x()) * inv.x();
  const double ay = (lo.y() - o.y()) * inv.y(), by = (hi.y() - o.y()) * inv.y();
  const double az = (lo.z() - o.z()) * inv.z(), bz = (hi.z() - o.z()) * inv.z();
  t0 = std::max(std::max(std::max(-kInf, std::min(ax, bx)), std::min(ay, by)), std::min(az, bz));
  t1 = std::min(std::min(std::min(kInf, std::max(ax, bx)), std::max(ay, by)), std::max(az, bz));
  return t0 <= t1;
}

inline double hit_triangle(const Point3& v0, const Point3& v1, const Point3& v2, const Point3& o, const Point3& d,
                           double tmin, double tmax) noexcept {
  const Point3 e1 = v1 - v0, e2 = v2 - v0;
  const Point3 p = d.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-300) return kInf;
  const double inv = 1.0 / det;
  const Point3 s = o - v0;
  const double u = s.dot(p) * inv;
  if (u < 0.0 || u > 1.0) return kInf;
  const Point3 q = s.cross(e1);
  const double v = d.dot(q) * inv;
  if (v < 0.0 || u + v > 1.0) return kInf;
  const double t = e2.dot(q) * inv;
  return (t > tmin && t <= tmax) ? t : kInf;
}

inline double hit_quad(const Prim& q, const Point3& o, const Point3& d, double tmin, double tmax) noexcept {
  const Point3 n = q.b.cross(q.c);
  const double denom = n.dot(d);
  if (denom == 0.0) return kInf;
  const double t = n.dot(q.a - o) / denom;
  if (!(t > tmin && t <= tmax)) return kInf;
  const Point3 p = o + t * d - q.a;
  const double nn = n.squaredNorm();
  const double al = p.cross(q.c).dot(n) / nn;
  const double be = q.b.cross(p).dot(n) / nn;
  return (al >= 0 && al <= 1 && be >= 0 && be <= 1) ? t : kInf;
}

inline double hit_sphere(const Prim& s, const Point3& o, const Point3& d, double tmin, double tmax) noexcept {
  const Point3 oc = o - s.a;
  const double a = d.squaredNorm(), b = oc.dot(d), c = oc.squaredNorm() - s.r * s.r;
  const double disc = b * b - a * c;
  if (disc < 0) return kInf;
  const double sq = std::sqrt(disc);
  double t = (-b - sq) / a;
  if (!(t > tmin)) t = (-b + sq) / a;
  return (t > tmin && t <= tmax) ? t : kInf;
}

inline double hit_cylinder(const Prim& cy, const Point3& o, const Point3& d, double tmin, double tmax) noexcept {
  const Point3& w = cy.w;  // prepare(): (b - a) / |b - a|
  const double len = cy.len;
  const Point3 oc = o - cy.a;
  const double dw = d.dot(w), ow = oc.dot(w);
  const Point3 dp = d - dw * w, op = oc - ow * w;
  double best = kInf;
  const auto consider = [&](double t) {
    if (t > tmin && t <= tmax && t < best) best = t;
  };
  const double A = dp.squaredNorm();
  if (A > 0) {
    const double B = op.dot(dp), C = op.squaredNorm() - cy.r * cy.r;
    const double disc = B * B - A * C;
    if (disc >= 0) {
      const double sq = std::sqrt(disc);
      for (const double t : {(-B - sq) / A, (-B + sq) / A}) {
        const double s = ow + t * dw;
        if (s >= 0 && s <= len) consider(t);
      }
    }
  }
  if (dw != 0) {
    for (const double s : {0.0, len}) {
      const double t = (s - ow) / dw;
      if ((op + t * dp).squaredNorm() <= cy.r * cy.r) consider(t);
    }
  }
  return best;
}

/// The first ray parameter in (tmin, tmax] at which the ray meets the primitive, or +inf.
inline double intersect(const Prim& p, const Point3& o, const Point3& d, double tmin, double tmax) noexcept {
  switch (p.kind) {
    case PrimKind::Box:
      return hit_box(p.a, p.b, o, d, tmin, tmax);
    case PrimKind::OrientedBox: {
      const Point3 lo = p.rot.transpose() * (o - p.a), ld = p.rot.transpose() * d;
      return hit_box(-p.b, p.b, lo, ld, tmin, tmax);
    }
    case PrimKind::Quad:
      return hit_quad(p, o, d, tmin, tmax);
    case PrimKind::Sphere:
      return hit_sphere(p, o, d, tmin, tmax);
    case PrimKind::Cylinder:
      return hit_cylinder(p, o, d, tmin, tmax);
    case PrimKind::Triangle:
      return hit_triangle(p.a, p.b, p.c, o, d, tmin, tmax);
  }
  return kInf;
}

inline Bounds prim_bounds(const Prim& p) noexcept;

/// A ray's component-wise inverse direction for repeated primitive tests (intersect_fast()).
struct RayInverse {
  Point3 inv;   ///< d.cwiseInverse()
  bool finite;  ///< no zero or subnormal component: the branch-free slab applies
  explicit RayInverse(const Point3& d) noexcept : inv(d.cwiseInverse()), finite(is_finite(inv)) {}
};

/// The slab test of [lo, hi] for a ray with its RayInverse: the same result as slab() bit for bit.
inline bool slab_fast(const Point3& lo, const Point3& hi, const Point3& o, const Point3& d, const RayInverse& ri,
                      double& t0, double& t1) noexcept {
  return ri.finite ? slab_finite_inv(lo, hi, o, ri.inv, t0, t1) : slab_inv(lo, hi, o, d, ri.inv, t0, t1);
}

/// The bounds of a primitive grown by 1e-9 (1 + its largest absolute coordinate) m: a margin that
/// rounding in a ray's hit cannot bridge, so a ray that misses them misses the primitive.
inline Bounds loose_bounds(const Prim& p) noexcept {
  const Bounds b = prim_bounds(p);
  const double slack = 1e-9 * (1.0 + std::max(b.min.cwiseAbs().maxCoeff(), b.max.cwiseAbs().maxCoeff()));
  return {b.min.array() - slack, b.max.array() + slack};
}

/// intersect(), the same result bit for bit, faster for repeated tests of one ray: a box by the
/// slab test with the ray's inverse direction, any other kind only if the ray meets \p loose
/// (loose_bounds(p)) within (tmin, tmax].
inline double intersect_fast(const Prim& p, const Bounds& loose, const Point3& o, const Point3& d, const RayInverse& ri,
                             double tmin, double tmax) noexcept {
  double t0, t1;
  if (p.kind == PrimKind::Box) {  // hit_box()
    if (!slab_fast(p.a, p.b, o, d, ri, t0, t1)) return kInf;
    const double t = t0 > tmin ? t0 : t1;
    return (t > tmin && t <= tmax) ? t : kInf;
  }
  if (!slab_fast(loose.min, loose.max, o, d, ri, t0, t1) || t1 <= tmin || t0 > tmax) return kInf;
  return intersect(p, o, d, tmin, tmax);
}

/// The unit normal of primitive \p p at the surface point \p x (a point where a ray met it),
/// oriented against the ray direction \p d (n . d <= 0), as mirror reflection needs.
///  Box, OrientedBox: the normal of the face \p x lies closest to (at an edge or corner the first
///  of the tied faces in x, y, z order). Sphere: (x - centre) / r. Cylinder: the cap normal if
///  \p x lies closer to a cap plane than to the mantle, else the radial direction. Quad,
///  Triangle: the plane normal.
inline Point3 normal(const Prim& p, const Point3& x, const Point3& d) noexcept {
  Point3 n = Point3::UnitZ();
  const auto box_normal = [](const Point3& lo, const Point3& hi, const Point3& q) {
    int axis = 0;
    double sign = -1.0, best = kInf;
    for (int i = 0; i < 3; ++i) {
      const double dl = std::abs(q[i] - lo[i]), dh = std::abs(q[i] - hi[i]);
      if (dl < best) best = dl, axis = i, sign = -1.0;
      if (dh < best) best = dh, axis = i, sign = 1.0;
    }
    return Point3(sign * Point3::Unit(axis));
  };
  switch (p.kind) {
    case PrimKind::Box:
      n = box_normal(p.a, p.b, x);
      break;
    case PrimKind::OrientedBox:
      n = p.rot * box_normal(-p.b, p.b, p.rot.transpose() * (x - p.a));
      break;
    case PrimKind::Quad:
      n = p.b.cross(p.c).normalized();
      break;
    case PrimKind::Sphere:
      n = (x - p.a).normalized();
      break;
    case PrimKind::Cylinder: {
      const Point3 axis = p.b - p.a;
      const double len = axis.norm();
      const Point3 w = axis / len;
      const double s = (x - p.a).dot(w);
      const Point3 radial = (x - p.a) - s * w;
      const double to_mantle = std::abs(radial.norm() - p.r), to_cap = std::min(std::abs(s), std::abs(s - len));
      if (to_cap < to_mantle || radial.squaredNorm() == 0)
        n = s < 0.5 * len ? Point3(-w) : w;
      else
        n = radial.normalized();
      break;
    }
    case PrimKind::Triangle:
      n = (p.b - p.a).cross(p.c - p.a).normalized();
      break;
  }
  return n.dot(d) > 0 ? Point3(-n) : n;
}

/// Exact signed distance for the solid kinds (Box, OrientedBox, Sphere, Cylinder); +inf otherwise.
inline double sdf(const Prim& p, const Point3& x) noexcept {
  const auto box_sdf = [](const Point3& q) {
    const Point3 qq = q.cwiseMax(Point3::Zero());
    return qq.norm() + std::min(q.maxCoeff(), 0.0);
  };
  switch (p.kind) {
    case PrimKind::Box: {
      const Point3 c = 0.5 * (p.a + p.b), h = 0.5 * (p.b - p.a);
      return box_sdf((x - c).cwiseAbs() - h);
    }
    case PrimKind::OrientedBox:
      return box_sdf((p.rot.transpose() * (x - p.a)).cwiseAbs() - p.b);
    case PrimKind::Sphere:
      return (x - p.a).norm() - p.r;
    case PrimKind::Cylinder: {
      const Point3 axis = p.b - p.a;
      const double len = axis.norm();
      const Point3 w = axis / len;
      const double s = (x - p.a).dot(w);
      const double radial = ((x - p.a) - s * w).norm();
      const double dx = radial - p.r, dy = std::abs(s - 0.5 * len) - 0.5 * len;
      return std::min(std::max(dx, dy), 0.0) + std::hypot(std::max(dx, 0.0), std::max(dy, 0.0));
    }
    case PrimKind::Quad:
    case PrimKind::Triangle:
      break;
  }
  return kInf;
}

/// Triangle / closed box overlap by the separating axis theorem (Akenine-Möller).
inline bool triangle_box_overlap(const Point3& v0w, const Point3& v1w, const Point3& v2w, const Point3& lo,
                                 const Point3& hi) noexcept {
  const Point3 c = 0.5 * (lo + hi), e = 0.5 * (hi - lo);
  const Point3 v[3] = {v0w - c, v1w - c, v2w - c};
  for (int i = 0; i < 3; ++i) {
    const double mn = std::min({v[0][i], v[1][i], v[2][i]}), mx = std::max({v[0][i], v[1][i], v[2][i]});
    if (mn > e[i] || mx < -e[i]) return false;
  }
  const Point3 f[3] = {v[1] - v[0], v[2] - v[1], v[0] - v[2]};
  const auto separated = [&](const Point3& ax) {
    const double p0 = v[0].dot(ax), p1 = v[1].dot(ax), p2 = v[2].dot(ax);
    const double rad = e.dot(ax.cwiseAbs());
    return std::min({p0, p1, p2}) > rad || std::max({p0, p1, p2}) < -rad;
  };
  const Point3 n = f[0].cross(f[1]);
  if (separated(n)) return false;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      const Point3 ax = Point3::Unit(i).cross(f[j]);
      if (ax.squaredNorm() > 0 && separated(ax)) return false;
    }
  }
  return true;
}

/// True if a solid primitive given by its SDF meets the box [lo, hi]; resolved by subdivision to
/// 1/2^depth of the box size, conservative below that.
inline bool sdf_box_overlap(const Prim& p, const Point3& lo, const Point3& hi, int depth) noexcept {
  const Point3 c = 0.5 * (lo + hi);
  const double half_diag = 0.5 * (hi - lo).norm();
  const double s = sdf(p, c);
  if (s <= 0) return true;
  if (s > half_diag) return false;
  if (depth == 0) return true;
  for (int k = 0; k < 8; ++k) {
    Point3 l, h;
    for (int i = 0; i < 3; ++i) {
      const bool upper = (k >> i) & 1;
      l[i] = upper ? c[i] : lo[i];
      h[i] = upper ? hi[i] : c[i];
    }
    if (sdf_box_overlap(p, l, h, depth - 1)) return true;
  }
  return false;
}

/// True if the primitive meets the closed box [lo, hi] (see Scene::ground_truth for the rules).
inline bool overlaps(const Prim& p, const Point3& lo, const Point3& hi) noexcept {
  switch (p.kind) {
    case PrimKind::Box:
      return (p.a.array() <= hi.array()).all() && (lo.array() <= p.b.array()).all();
    case PrimKind::Sphere: {
      const Point3 q = p.a.cwiseMax(lo).cwiseMin(hi);
      return (q - p.a).squaredNorm() <= p.r * p.r;
    }
    case PrimKind::OrientedBox:
    case PrimKind::Cylinder:
      return sdf_box_overlap(p, lo, hi, 4);
    case PrimKind::Quad:
      return triangle_box_overlap(p.a, p.a + p.b, p.a + p.b + p.c, lo, hi) ||
             triangle_box_overlap(p.a, p.a + p.b + p.c, p.a + p.c, lo, hi);
    case PrimKind::Triangle:
      return triangle_box_overlap(p.a, p.b, p.c, lo, hi);
  }
  return false;
}

/// Axis-aligned bounds of a primitive.
inline Bounds prim_bounds(const Prim& p) noexcept {
  switch (p.kind) {
    case PrimKind::Box:
      return {p.a, p.b};
    case PrimKind::OrientedBox: {
      const Point3 ext = p.rot.cwiseAbs() * p.b;
      return {p.a - ext, p.a + ext};
    }
    case PrimKind::Quad: {
      Point3 lo = p.a, hi = p.a;
      for (const Point3& q : {Point3(p.a + p.b), Point3(p.a + p.c), Point3(p.a + p.b + p.c)}) {
        lo = lo.cwiseMin(q);
        hi = hi.cwiseMax(q);
      }
      return {lo, hi};
    }
    case PrimKind::Sphere:
      return {p.a.array() - p.r, p.a.array() + p.r};
    case PrimKind::Cylinder: {
      const Point3 w = (p.b - p.a).normalized();
      Point3 ext;
      for (int i = 0; i < 3; ++i) ext[i] = p.r * std::sqrt(std::max(0.0, 1.0 - w[i] * w[i]));
      return {p.a.cwiseMin(p.b) - ext, p.a.cwiseMax(p.b) + ext};
    }
    case PrimKind::Triangle:
      return {p.a.cwiseMin(p.b).cwiseMin(p.c), p.a.cwiseMax(p.b).cwiseMax(p.c)};
  }
  return {};
}

}  // namespace intervox::sim::detail
