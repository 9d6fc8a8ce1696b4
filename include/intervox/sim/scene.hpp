#pragma once
/// \file
/// A scene for the built-in raycaster: primitives with materials, a BVH for fast ray queries,
/// inside tests and ground-truth occupancy of a voxel grid.

#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/point.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/core/sensors.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/sim/detail/bvh.hpp>
#include <intervox/sim/detail/primitive.hpp>
#include <intervox/sim/material.hpp>
#include <intervox/sim/mesh.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace intervox::sim {

/// Index of an object in a Scene (in the order of adding, from 0).
using ObjectId = std::uint32_t;

/// The kind of shape of a scene object.
enum class ShapeKind : std::uint8_t { Box, OrientedBox, Quad, Sphere, Cylinder, Mesh };

/// A convex cone of ray directions from one apex, bounded by up to four planes through the apex,
/// each given by a normal pointing into the cone: the rays of a tile of a camera's pixels
/// (the simulator builds one per tile, and one per run of striper samples). Scene::cone_primitives()
/// lists what such rays can meet.
struct RayCone {
  Point3 apex = Point3::Zero();
  std::array<Point3, 4> normals{};  ///< inward normals of the bounding planes (any length > 0)
  int planes = 0;                   ///< how many of `normals` are used, in [0, 4]
};

/// A primitive that rays of a RayCone may meet (Scene::cone_primitives()).
struct ConeCandidate {
  std::uint32_t primitive = 0;  ///< index of the primitive in the scene
  double distance = 0;          ///< a lower bound of its distance from the cone's apex [m]
};

/// Where a ray meets the scene first.
struct RayHit {
  double t = 0;                 ///< ray parameter (the range, for a unit direction)
  ObjectId object = 0;          ///< the object met
  std::uint32_t primitive = 0;  ///< the primitive met (a mesh triangle, or the object's one shape)
};

namespace detail {
using intervox::detail::require_finite;
using intervox::detail::validate_pose;
inline void require_positive(double v, const char* what) { ParamCheck("intervox::sim::Scene").positive(what, v); }
}  // namespace detail

/// A static scene of objects, each with a material.
///
/// Shapes: axis-aligned boxes, oriented boxes, quads (finite planar parallelograms; an infinite
/// plane is not offered because a scene must be bounded), spheres, capped cylinders with any
/// axis, and triangle meshes. Boxes, spheres, cylinders and closed meshes are *solids*; quads and
/// open meshes are *surfaces*. Every `add_*` validates its input and rebuilds the BVH (cheap for
/// the scenes here: about 30 ms for a mesh of ten thousand triangles).
///
/// Thread safety: const member functions may be called concurrently; adding objects or changing
/// materials must not overlap any other call.
class Scene {
 public:
  /// An axis-aligned box [box.min, box.max]. \throws InvalidArgument unless finite with min < max.
  ObjectId add_box(const Bounds& box, const Material& material = {}, std::string name = {}) {
    detail::require_finite(box.min, "box corner");
    detail::require_finite(box.max, "box corner");
    if (!(box.min.array() < box.max.array()).all())
      ParamCheck("intervox::sim::Scene::add_box").fail("box '" + name + "' needs min < max on every axis");
    detail::Prim p;
    p.kind = detail::PrimKind::Box;
    p.a = box.min;
    p.b = box.max;
    return add_object(ShapeKind::Box, {p}, true, material, std::move(name));
  }

  /// A box of half extents \p half_extents centred at pose.translation(), rotated by pose.
  /// \throws InvalidArgument for a non-rigid or non-finite pose, or a half extent <= 0.
  ObjectId add_oriented_box(const Pose& pose, const Point3& half_extents, const Material& material = {},
                            std::string name = {}) {
    detail::validate_pose(pose, "oriented box pose");
    detail::require_finite(half_extents, "oriented box half extents");
    if (!(half_extents.array() > 0).all())
      ParamCheck("intervox::sim::Scene::add_oriented_box").fail("half extents of '" + name + "' must be > 0");
    detail::Prim p;
    p.kind = detail::PrimKind::OrientedBox;
    p.a = pose.translation();
    p.b = half_extents;
    p.rot = pose.linear();
    return add_object(ShapeKind::OrientedBox, {p}, true, material, std::move(name));
  }

  /// A quad (planar parallelogram) corner + s * edge_u + t * edge_v, s, t in [0, 1]; seen from
  /// both sides. \throws InvalidArgument for non-finite input or parallel/zero edges.
  ObjectId add_quad(const Point3& corner, const Point3& edge_u, const Point3& edge_v, const Material& material = {},
                    std::string name = {}) {
    detail::require_finite(corner, "quad corner");
    detail::require_finite(edge_u, "quad edge");
    detail::require_finite(edge_v, "quad edge");
    if (!(edge_u.cross(edge_v).norm() > 1e-12))
      ParamCheck("intervox::sim::Scene::add_quad").fail("edges of '" + name + "' are zero or parallel");
    detail::Prim p;
    p.kind = detail::PrimKind::Quad;
    p.solid = false;
    p.a = corner;
    p.b = edge_u;
    p.c = edge_v;
    return add_object(ShapeKind::Quad, {p}, false, material, std::move(name));
  }

  /// A sphere. \throws InvalidArgument for a non-finite centre or a radius that is not > 0.
  ObjectId add_sphere(const Point3& center, double radius, const Material& material = {}, std::string name = {}) {
    detail::require_finite(center, "sphere centre");
    detail::require_positive(radius, "sphere radius");
    detail::Prim p;
    p.kind = detail::PrimKind::Sphere;
    p.a = center;
    p.r = radius;
    return add_object(ShapeKind::Sphere, {p}, true, material, std::move(name));
  }

  /// A capped cylinder from the centre of its base disk \p base to that of its top disk \p top.
  /// \throws InvalidArgument for non-finite input, base == top, or a radius that is not > 0.
  ObjectId add_cylinder(const Point3& base, const Point3& top, double radius, const Material& material = {},
                        std::string name = {}) {
    detail::require_finite(base, "cylinder base");
    detail::require_finite(top, "cylinder top");
    detail::require_positive(radius, "cylinder radius");
    if (!((top - base).norm() > 1e-12))
      ParamCheck("intervox::sim::Scene::add_cylinder").fail("cylinder '" + name + "' has zero length");
    detail::Prim p;
    p.kind = detail::PrimKind::Cylinder;
    p.a = base;
    p.b = top;
    p.r = radius;
    return add_object(ShapeKind::Cylinder, {p}, true, material, std::move(name));
  }

  /// A triangle mesh (a solid if closed, see TriangleMesh). \throws InvalidArgument if the mesh
  /// does not validate.
  ObjectId add_mesh(const TriangleMesh& mesh, const Material& material = {}, std::string name = {}) {
    mesh.validate();
    const bool solid = mesh.closed();
    std::vector<detail::Prim> prims;
    prims.reserve(mesh.triangles.size());
    for (const auto& t : mesh.triangles) {
      detail::Prim p;
      p.kind = detail::PrimKind::Triangle;
      p.solid = solid;
      p.a = mesh.vertices[t[0]];
      p.b = mesh.vertices[t[1]];
      p.c = mesh.vertices[t[2]];
      prims.push_back(p);
    }
    return add_object(ShapeKind::Mesh, std::move(prims), solid, material, std::move(name));
  }

  /// Number of objects.
  std::size_t size() const noexcept { return objects_.size(); }
  /// Number of primitives (a mesh counts its triangles).
  std::size_t primitive_count() const noexcept { return prims_.size(); }

  /// The material of object \p id. \throws OutOfRange for an unknown id.
  const Material& material(ObjectId id) const { return object(id).material; }
  /// Replaces the material of object \p id. \throws OutOfRange, InvalidArgument (bad material).
  void set_material(ObjectId id, const Material& m) {
    m.validate();
    object(id).material = m;
  }
  /// The name given when adding object \p id. \throws OutOfRange for an unknown id.
  const std::string& name(ObjectId id) const { return object(id).name; }
  /// The shape kind of object \p id. \throws OutOfRange for an unknown id.
  ShapeKind shape(ObjectId id) const { return object(id).shape; }
  /// True if object \p id is a solid. \throws OutOfRange for an unknown id.
  bool solid(ObjectId id) const { return object(id).solid; }
  /// Axis-aligned bounds of object \p id. \throws OutOfRange for an unknown id.
  const Bounds& object_bounds(ObjectId id) const { return object(id).bounds; }
  /// The first object named \p name, if any.
  std::optional<ObjectId> find(std::string_view name) const {
    for (std::size_t i = 0; i < objects_.size(); ++i)
      if (objects_[i].name == name) return static_cast<ObjectId>(i);
    return std::nullopt;
  }

  /// Axis-aligned bounds of the whole scene; a zero box at the origin for an empty scene.
  const Bounds& bounds() const noexcept { return bounds_; }

  /// The first surface met by the ray o + t d for t in (tmin, tmax], if any. \p d need not be
  /// unit (t is then in units of |d|). Non-finite input gives no hit. Of surfaces met at the same
  /// t, the primitive added first wins (as in intersect_brute_force()): e.g. a room's floor, added
  /// before the furniture standing on it, against a furniture's bottom face.
  std::optional<RayHit> intersect(const Point3& o, const Point3& d, double tmin = 0.0,
                                  double tmax = detail::kInf) const noexcept {
    if (!is_finite(o) || !is_finite(d) || d.squaredNorm() == 0 || std::isnan(tmin) || std::isnan(tmax))
      return std::nullopt;
    double t = 0;
    const std::int64_t i = bvh_.closest(prims_, o, d, tmin, tmax, t);
    if (i < 0) return std::nullopt;
    return RayHit{t, prims_[static_cast<std::size_t>(i)].object, static_cast<std::uint32_t>(i)};
  }

  /// The unit surface normal where the ray o + t d met the scene (\p hit from intersect() with
  /// the same \p o and \p d), oriented against the ray (n . d <= 0): the exact normal of the
  /// primitive met (a box's face, the sphere's radius, a cylinder's mantle or cap, a quad's or
  /// triangle's plane). \throws OutOfRange if \p hit names no primitive of this scene.
  Point3 normal(const RayHit& hit, const Point3& o, const Point3& d) const {
    if (hit.primitive >= prims_.size())
      throw OutOfRange("intervox::sim::Scene::normal: unknown primitive " + std::to_string(hit.primitive));
    return detail::normal(prims_[hit.primitive], o + hit.t * d, d);
  }

  /// The same as intersect() by testing every primitive (the reference for tests and benchmarks);
  /// of primitives met at the same t, the one added first.
  std::optional<RayHit> intersect_brute_force(const Point3& o, const Point3& d, double tmin = 0.0,
                                              double tmax = detail::kInf) const noexcept {
    if (!is_finite(o) || !is_finite(d) || d.squaredNorm() == 0 || std::isnan(tmin) || std::isnan(tmax))
      return std::nullopt;
    std::optional<RayHit> best;
    double bt = tmax;
    for (std::size_t i = 0; i < prims_.size(); ++i) {
      const double t = detail::intersect(prims_[i], o, d, tmin, bt);
      if (t < detail::kInf && (t < bt || !best)) {
        bt = t;
        best = RayHit{t, prims_[i].object, static_cast<std::uint32_t>(i)};
      }
    }
    return best;
  }

  /// The primitives that a ray from \p cone's apex with its direction inside the cone may meet,
  /// for intersect_among(), nearest first: every primitive whose bounds are not entirely outside
  /// one of the cone's planes (with a slack of 1e-9 (1 + |apex|) m, so that rounding never drops a
  /// primitive a ray of the cone meets), with a lower bound of its distance from the apex. \p out
  /// is cleared first.
  /// \throws InvalidArgument for a non-finite apex, a zero or non-finite normal, or planes outside
  /// [0, 4].
  void cone_primitives(const RayCone& cone, std::vector<ConeCandidate>& out) const {
    detail::require_finite(cone.apex, "cone apex");
    ParamCheck("intervox::sim::Scene::cone_primitives").in_range("planes", cone.planes, 0, 4);
    std::array<Point3, 4> normals{};
    for (std::size_t i = 0; i < static_cast<std::size_t>(cone.planes); ++i) {
      detail::require_finite(cone.normals[i], "cone normal");
      const double length = cone.normals[i].norm();
      if (!(length > 0 && std::isfinite(length)))
        ParamCheck("intervox::sim::Scene::cone_primitives").fail("a cone normal is zero or too long");
      normals[i] = cone.normals[i] / length;
    }
    out.clear();
    const double slack = 1e-9 * (1.0 + cone.apex.cwiseAbs().maxCoeff());
    const auto keep = [&](const Point3& lo, const Point3& hi) {
      for (std::size_t i = 0; i < static_cast<std::size_t>(cone.planes); ++i) {
        const Point3& n = normals[i];
        // The corner of the box farthest along n: if even it lies outside the plane, all do.
        const Point3 far((n.x() >= 0 ? hi.x() : lo.x()) - cone.apex.x(), (n.y() >= 0 ? hi.y() : lo.y()) - cone.apex.y(),
                         (n.z() >= 0 ? hi.z() : lo.z()) - cone.apex.z());
        if (n.dot(far) < -slack) return false;
      }
      return true;
    };
    bvh_.for_each_kept(keep, [&](std::uint32_t i) {
      // Distance from the apex to the grown bounds, shrunk by a relative 1e-9 against rounding.
      const Bounds& lb = bvh_.loose(i);
      const double dist = (cone.apex.cwiseMax(lb.min).cwiseMin(lb.max) - cone.apex).norm();
      out.push_back({i, dist * (1.0 - 1e-9)});
    });
    std::sort(out.begin(), out.end(), [](const ConeCandidate& x, const ConeCandidate& y) {
      return x.distance < y.distance || (x.distance == y.distance && x.primitive < y.primitive);
    });
  }

  /// The first hit of the ray o + t d, t in (tmin, tmax], among \p candidates, for a ray from the
  /// apex of the cone they were listed for by cone_primitives() (o = apex, d in the cone): then
  /// the same answer as intersect() and intersect_brute_force() (of hits at the same t the lowest
  /// primitive index wins, as in both). Stops at the first candidate farther than the best hit.
  /// Indices beyond the scene are ignored.
  std::optional<RayHit> intersect_among(std::span<const ConeCandidate> candidates, const Point3& o, const Point3& d,
                                        double tmin = 0.0, double tmax = detail::kInf) const noexcept {
    if (!is_finite(o) || !is_finite(d) || d.squaredNorm() == 0 || std::isnan(tmin) || std::isnan(tmax))
      return std::nullopt;
    double bt = tmax;
    std::int64_t best = -1;
    const double dd = d.squaredNorm();
    const detail::RayInverse ri(d);
    for (const ConeCandidate& c : candidates) {
      // A hit at t lies t |d| from the apex: none closer than c.distance.
      if (c.distance * c.distance > bt * bt * dd) break;
      const std::uint32_t i = c.primitive;
      if (i >= prims_.size()) continue;
      const double t = detail::intersect_fast(prims_[i], bvh_.loose(i), o, d, ri, tmin, bt);
      if (t < detail::kInf && (t < bt || (t == bt && (best < 0 || static_cast<std::int64_t>(i) < best)))) {
        bt = t;
        best = i;
      }
    }
    if (best < 0) return std::nullopt;
    return RayHit{bt, prims_[static_cast<std::size_t>(best)].object, static_cast<std::uint32_t>(best)};
  }

  /// True if \p p lies inside (or on) a solid object. Surfaces never contain points.
  bool inside(const Point3& p) const {
    if (!is_finite(p)) ParamCheck("intervox::sim::Scene::inside").fail("point is not finite");
    return bvh_.any_in_box(p, p, [&](std::uint32_t i) {
      const auto& q = prims_[i];
      if (q.kind == detail::PrimKind::Triangle || q.kind == detail::PrimKind::Quad) return false;
      return detail::sdf(q, p) <= 0;
    }) || inside_closed_mesh(p, nullptr);
  }

  /// True if any object (solid or surface) meets the closed box \p box; e.g. a robot's footprint.
  /// Oriented boxes and cylinders are resolved to 1/16 of the box size (conservative below).
  /// \throws InvalidArgument if the box is not valid.
  bool overlaps(const Bounds& box) const {
    ParamCheck("intervox::sim::Scene::overlaps").valid_bounds("box", box);
    return bvh_.any_in_box(box.min, box.max, [&](std::uint32_t i) {
      return detail::overlaps(prims_[i], box.min, box.max);
    }) || inside_closed_mesh(0.5 * (box.min + box.max), nullptr);
  }

  /// True if the voxel \p key of \p geometry is occupied by the scene (rules at ground_truth()).
  bool occupied(const GridGeometry& geometry, const Key& key) const {
    // Plain variables, not structured bindings: Clang before 16 cannot capture those.
    const std::pair<Point3, Point3> box = voxel_box(geometry, key);
    const Point3 &lo = box.first, &hi = box.second;
    const std::pair<Point3, Point3> inner = shrink(lo, hi, geometry.resolution());
    const Point3 &slo = inner.first, &shi = inner.second;
    return bvh_.any_in_box(lo, hi, [&](std::uint32_t i) {
      const auto& p = prims_[i];
      return p.solid ? detail::overlaps(p, slo, shi) : detail::overlaps(p, lo, hi);
    }) || inside_closed_mesh(geometry.center(key), nullptr);
  }

  /// The objects that occupy the voxel \p key of \p geometry (rules at ground_truth()), in id
  /// order without duplicates; empty if the voxel is free. occupied() is true exactly when this is
  /// not empty.
  std::vector<ObjectId> occupants(const GridGeometry& geometry, const Key& key) const {
    const std::pair<Point3, Point3> box = voxel_box(geometry, key);
    const Point3 &lo = box.first, &hi = box.second;
    const std::pair<Point3, Point3> inner = shrink(lo, hi, geometry.resolution());
    const Point3 &slo = inner.first, &shi = inner.second;
    std::vector<ObjectId> out;
    bvh_.any_in_box(lo, hi, [&](std::uint32_t i) {
      const auto& p = prims_[i];
      if (p.solid ? detail::overlaps(p, slo, shi) : detail::overlaps(p, lo, hi))
        out.push_back(static_cast<ObjectId>(p.object));
      return false;  // visit every primitive in the box
    });
    for (std::size_t i = 0; i < objects_.size(); ++i) {
      const auto& ob = objects_[i];
      if (ob.shape == ShapeKind::Mesh && ob.solid && inside_mesh(ob, geometry.center(key)))
        out.push_back(static_cast<ObjectId>(i));
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  }

  /// The voxels of \p geometry within \p region that the scene occupies, sorted (Key order)
  /// without duplicates.
  ///
  /// A voxel is occupied if it shares volume with a solid (boxes, oriented boxes, spheres,
  /// cylinders, closed meshes; a solid merely touching a voxel's face does not occupy it), or
  /// if a surface (quad, open mesh) touches the closed voxel. Exact for boxes, spheres, quads and
  /// meshes; oriented boxes and cylinders are resolved to 1/16 of a voxel (conservative below).
  /// \throws InvalidArgument if region is not valid; OutOfRange if it leaves the key range.
  std::vector<Key> ground_truth(const GridGeometry& geometry, const Bounds& region) const {
    const KeyBox all = geometry.key_box(region);
    std::vector<Key> keys;
    const double res = geometry.resolution();
    const auto scan = [&](const Bounds& b, auto&& test) {
      Bounds cut{b.min.cwiseMax(region.min), b.max.cwiseMin(region.max)};
      if (!(cut.min.array() <= cut.max.array()).all()) return;
      KeyBox kb = geometry.key_box(cut);
      // key_box steps back from a max on a voxel face; a surface there still touches that voxel.
      for (int a = 0; a < 3; ++a) kb.max[a] = std::min(all.max[a], kb.max[a] + 1);
      for (int a = 0; a < 3; ++a) kb.min[a] = std::max(all.min[a], kb.min[a] - 1);
      Key k;
      for (k.x = kb.min.x; k.x <= kb.max.x; ++k.x)
        for (k.y = kb.min.y; k.y <= kb.max.y; ++k.y)
          for (k.z = kb.min.z; k.z <= kb.max.z; ++k.z)
            if (test(k)) keys.push_back(k);
    };
    for (const auto& p : prims_) {
      scan(detail::prim_bounds(p), [&](const Key& k) {
        const auto [lo, hi] = voxel_box(geometry, k);
        if (!p.solid) return detail::overlaps(p, lo, hi);
        const auto [slo, shi] = shrink(lo, hi, res);
        return detail::overlaps(p, slo, shi);
      });
    }
    for (std::size_t i = 0; i < objects_.size(); ++i) {
      const auto& ob = objects_[i];
      if (ob.shape != ShapeKind::Mesh || !ob.solid) continue;
      scan(ob.bounds, [&](const Key& k) { return inside_mesh(ob, geometry.center(k)); });
    }
    std::sort(keys.begin(), keys.end());
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    return keys;
  }

 private:
  struct Object {
    std::string name;
    Material material;
    ShapeKind shape = ShapeKind::Box;
    bool solid = true;
    Bounds bounds;
    std::uint32_t first = 0, count = 0;
  };

  static std::pair<Point3, Point3> voxel_box(const GridGeometry& g, const Key& k) {
    const Point3 lo = g.corner(k);
    return {lo, lo + Point3::Constant(g.resolution())};
  }
  static std::pair<Point3, Point3> shrink(const Point3& lo, const Point3& hi, double res) {
    const double e = 1e-6 * res;
    return {lo.array() + e, hi.array() - e};
  }

  Object& object(ObjectId id) {
    if (id >= objects_.size()) throw OutOfRange("intervox::sim::Scene: unknown object id " + std::to_string(id));
    return objects_[id];
  }
  const Object& object(ObjectId id) const {
    if (id >= objects_.size()) throw OutOfRange("intervox::sim::Scene: unknown object id " + std::to_string(id));
    return objects_[id];
  }

  ObjectId add_object(ShapeKind shape, std::vector<detail::Prim> prims, bool solid, const Material& material,
                      std::string name) {
    material.validate();
    const auto id = static_cast<ObjectId>(objects_.size());
    Object ob;
    ob.name = std::move(name);
    ob.material = material;
    ob.shape = shape;
    ob.solid = solid;
    ob.first = static_cast<std::uint32_t>(prims_.size());
    ob.count = static_cast<std::uint32_t>(prims.size());
    ob.bounds = detail::prim_bounds(prims.front());
    for (auto& p : prims) {
      p.object = id;
      detail::prepare(p);
      const Bounds b = detail::prim_bounds(p);
      ob.bounds.min = ob.bounds.min.cwiseMin(b.min);
      ob.bounds.max = ob.bounds.max.cwiseMax(b.max);
      prims_.push_back(p);
    }
    if (objects_.empty()) {
      bounds_ = ob.bounds;
    } else {
      bounds_.min = bounds_.min.cwiseMin(ob.bounds.min);
      bounds_.max = bounds_.max.cwiseMax(ob.bounds.max);
    }
    objects_.push_back(std::move(ob));
    bvh_.build(prims_);
    return id;
  }

  /// Parity test along a fixed, deliberately skew direction.
  bool inside_mesh(const Object& ob, const Point3& p) const noexcept {
    if (!ob.bounds.contains(p)) return false;
    const Point3 d = Point3(1.0, 0.7548776662466927, 0.5698402909980532).normalized();
    int crossings = 0;
    for (std::uint32_t k = ob.first; k < ob.first + ob.count; ++k) {
      const auto& t = prims_[k];
      if (detail::hit_triangle(t.a, t.b, t.c, p, d, 0.0, detail::kInf) < detail::kInf) ++crossings;
    }
    return (crossings & 1) != 0;
  }
  bool inside_closed_mesh(const Point3& p, const void*) const noexcept {
    for (const auto& ob : objects_)
      if (ob.shape == ShapeKind::Mesh && ob.solid && inside_mesh(ob, p)) return true;
    return false;
  }

  std::vector<Object> objects_;
  std::vector<detail::Prim> prims_;
  detail::Bvh bvh_;
  Bounds bounds_;
};

}  // namespace intervox::sim
