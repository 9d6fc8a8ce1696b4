#pragma once
/// \file
/// Simulated measurements: the noise model applied along beams through a scene, for depth
/// cameras (depth images or beams) and laser striper sweeps.
///
/// Depth cameras are time-of-flight sensors: the receiver sits at the beam's origin, and
/// Material's model applies with the angle between the beam and the surface normal.
///
/// Laser stripers measure by triangulation (LaserStriper): a camera at the world position
/// C = pose * LaserStriper::camera_position() watches the laser line. Along a striper beam's
/// straight path from the laser (before any reflection; passes through glass do not bend it), at
/// the surface that answers the beam at the point p:
///  - **Half-vector lobe**: a specular surface (SpecularModel::Reflect) returns directly with
///    probability Material::direct_return_probability(cos θ_h), cos θ_h = max(0, n · h),
///    h = normalize(l + v), where l = −beam is the unit vector from p towards the laser, v the
///    unit vector from p towards C, and n the surface normal facing the incoming beam: a polished
///    surface shows the line where its normal bisects the directions to the laser and to the
///    camera. Glass keeps the beam's angle for its Fresnel reflectance.
///  - **Triangulation shadow**: a return there (BeamPath::Direct, or Passed behind glass) counts
///    only if the camera sees p: the camera lies in front of the surface (n · v > 0) and the
///    segment from p, nudged 1 µm towards C, to C meets no surface other than glass (which the
///    camera sees through, without a random draw; a view through more than 64 glass surfaces
///    counts as blocked). Otherwise the beam gives BeamPath::NoReturn. The segment is tested
///    through the scene's BVH (Scene::intersect()).
/// After a reflection the folded-path model holds as for cameras (the camera is assumed to see
/// the spot along the path the beam came: the beam angle for the lobe, no shadow test). The
/// camera's field of view is not modelled. A coaxial striper (baseline 0: C is the beam's origin)
/// is treated as a time-of-flight sensor, exactly as trace() (bit for bit). The shadow test draws
/// no random numbers and the lobe changes only a probability, so every beam draws in the same
/// order as before, and results stay independent of the thread count.
///
/// Every beam's result is that of trace() (a triangulating striper's: trace_striper()) along its
/// ray with its own random stream. Camera beams are traced in tiles of 8 x 8 pixels, striper beams
/// in runs of 64 samples: the primitives a tile's (run's) rays can meet are listed once
/// (Scene::cone_primitives()) and each beam tests only those (Scene::intersect_among()), which
/// gives the same hits as the BVH, bit for bit.
/// Two mirror conditions of a real time-of-flight camera are options, off by default (and then
/// without any effect, draw for draw): the near-normal glint (SimOptions::glint: within
/// SimOptions::glint_angle of a specular surface's normal the sensor measures the surface itself)
/// and the robot's own body (SimOptions::body, RobotBody: placed at the body pose by the rig calls,
/// met by beams only after their first reflection, so it appears in mirrors).
///
/// Thread safety: simulation reads the scene only; concurrent simulations of one scene are safe.

#include <intervox/core/error.hpp>
#include <intervox/core/parallel.hpp>
#include <intervox/core/ray.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/sim/beam_rng.hpp>
#include <intervox/sim/material.hpp>
#include <intervox/sim/scene.hpp>
#include <intervox/sim/sensor_aliases.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace intervox::sim {

/// The default bounce limit of a simulated beam (SimOptions::max_bounces).
inline constexpr int kDefaultMaxBounces = 3;

/// The default half-angle of the near-normal glint (SimOptions::glint_angle): 3° [rad].
inline constexpr double kDefaultGlintAngle = deg(3.0);

/// The default height of RobotBody::mobile_base() [m]: 0.1 m above the default cameras (0.5 m).
inline constexpr double kDefaultBodyHeight = 0.6;

/// The robot's own body as the simulator sees it (SimOptions::body): a box fixed in the body frame
/// with a material. The rig calls (simulate(rig, ...), simulate_path(), simulate_images(),
/// SimulatedRig) place it at each body pose for that pose's scans, so that it appears in mirrors.
///
/// **Rule of the first segment.** A beam ignores the body along its path up to its first
/// reflection (through glass passes too) and meets it like any other solid afterwards: the cameras
/// sit on the body's surface, where their own direct rays would otherwise meet it at range 0. So
/// the body never changes a beam that is not reflected (a scene without mirrors, polished metal or
/// glass reflections gives the same scan, bit for bit, with or without it), and a beam reflected
/// back onto the body returns from it at the folded range (BeamPath::Reflected). Of the body and a
/// scene surface met at the same range, the scene's wins. The body is not part of the Scene:
/// Scene::intersect(), inside(), ground_truth() and a striper camera's line of sight (which is
/// tested before the first reflection) do not see it.
///
/// Thread safety: a value type.
struct RobotBody {
  /// The body's box in the body frame (for the mobile base: x forward, z up, the floor at z = 0).
  Bounds box{{-0.3, -0.2, 0.0}, {0.3, 0.2, kDefaultBodyHeight}};
  /// Its surface.
  Material material = Material::diffuse();

  /// The body of SensorRig::mobile_base(\p o): the footprint \p o.length x \p o.width centred on
  /// the body origin, from the floor (z = 0) up to \p height, where the eight cameras sit on its
  /// faces and corners (at camera_height).
  /// \throws InvalidArgument for a footprint or height that is not finite and > 0, or a material
  /// that does not validate.
  static RobotBody mobile_base(const MobileBaseOptions& o = {}, double height = kDefaultBodyHeight,
                               const Material& material = Material::diffuse()) {
    const ParamCheck check("intervox::sim::RobotBody::mobile_base");
    check.positive("length", o.length);
    check.positive("width", o.width);
    check.positive("height", height);
    RobotBody b;
    b.box = Bounds{{-0.5 * o.length, -0.5 * o.width, 0.0}, {0.5 * o.length, 0.5 * o.width, height}};
    b.material = material;
    b.validate();
    return b;
  }

  /// \throws InvalidArgument unless the box is finite with min < max on every axis and the
  /// material validates.
  void validate() const {
    const ParamCheck check("intervox::sim::RobotBody");
    check.valid_bounds("box", box);
    if (!(box.min.array() < box.max.array()).all()) check.fail("box needs min < max on every axis");
    material.validate();
  }
};

/// Options of a simulation call. Every option beyond threads and max_bounces is off by default;
/// off, it changes nothing (the same beams, bit for bit, and the same random draws).
struct SimOptions {
  /// Worker threads (0: std::thread::hardware_concurrency(); more are capped at it). Results are
  /// identical for every thread count: each beam draws from its own stream BeamRng(seed, sensor, beam).
  unsigned threads = 1;
  /// Reflections a beam may undergo (at mirrors, polished metal and glass); a beam that would
  /// reflect once more is lost (no return). In [0, 255].
  int max_bounces = kDefaultMaxBounces;
  /// **Near-normal glint** of a time-of-flight sensor at a specular surface (off by default): a
  /// beam that meets a specular surface (Surface::Specular with SpecularModel::Reflect: a mirror or
  /// polished metal) within `glint_angle` of its normal (θ <= glint_angle, θ the angle between the
  /// beam and the normal) sends the sensor's own light straight back, so the sensor measures the
  /// surface itself: a diffuse return with the material's σ at the path length so far, without
  /// the lobe's random draw. Before any reflection that is the mirror's own range
  /// (BeamPath::Direct) instead of the folded phantom; after a reflection, the folded range to the
  /// glinting surface (BeamPath::Reflected). Beyond the angle the material's model applies
  /// unchanged. A triangulating striper's beam before its first reflection keeps its half-vector
  /// lobe (its camera is not at the laser); glass keeps Fresnel.
  bool glint = false;
  /// Half-angle of the glint cone around the normal [rad], in [0, pi/2] (default 3°; 0: exact
  /// normal incidence only). Used only with `glint`.
  double glint_angle = kDefaultGlintAngle;
  /// The robot's own body (see RobotBody for the rule of the first segment); none by default.
  /// Only the rig calls place it (they know the body pose): simulate(camera, ...) and
  /// simulate_sweep() throw InvalidArgument if it is set.
  std::optional<RobotBody> body{};

  /// \throws InvalidArgument if max_bounces lies outside [0, 255], glint_angle outside
  /// [0, pi/2] (or NaN), or the body does not validate.
  void validate() const {
    const ParamCheck check("intervox::sim::SimOptions");
    check.in_range("max_bounces", max_bounces, 0, 255);
    check.in_range("glint_angle", glint_angle, 0.0, 0.5 * std::numbers::pi);
    if (body) body->validate();
  }
};

/// How a simulated beam ended: the simulator's ground truth of every beam, for metrics (e.g.
/// which voxels received phantom evidence).
enum class BeamPath : std::uint8_t {
  Direct = 0,     ///< returned by the first surface it met (diffuse, absorbing, a direct polished return)
  Reflected = 1,  ///< returned after one or more reflections: the range is the folded path (a phantom point)
  Passed = 2,     ///< returned after passing through glass, without reflection
  /// Nothing came back (out of range, absorbed, beyond the bounce limit, or, for a striper, a
  /// spot its camera cannot see: the triangulation shadow): max range.
  NoReturn = 3,
  Invalid = 4,  ///< the path to the first surface (or the return) is shorter than min_range: no measurement
};

/// Name of a beam path ("direct", "reflected", "passed", "no-return", "invalid").
constexpr std::string_view to_string(BeamPath p) noexcept {
  switch (p) {
    case BeamPath::Reflected:
      return "reflected";
    case BeamPath::Passed:
      return "passed";
    case BeamPath::NoReturn:
      return "no-return";
    case BeamPath::Invalid:
      return "invalid";
    case BeamPath::Direct:
      break;
  }
  return "direct";
}

/// The outcome of one simulated beam.
struct TraceResult {
  BeamPath path = BeamPath::NoReturn;
  /// The measured range (along the original beam) for a return; +inf for NoReturn, NaN for Invalid.
  double range = std::numeric_limits<double>::infinity();
  /// Reflections the beam underwent before it returned or was lost.
  std::uint8_t bounces = 0;
  /// For a return: the true point on the surface that returned the beam (noise-free). After a
  /// reflection it differs from origin + range * direction, which is the phantom the sensor sees.
  Point3 surface = Point3::Constant(std::numeric_limits<double>::quiet_NaN());

  /// True if the sensor measured a range (Direct, Reflected or Passed).
  bool returned() const noexcept {
    return path == BeamPath::Direct || path == BeamPath::Reflected || path == BeamPath::Passed;
  }
};

/// Follows one beam from \p origin along the unit direction \p dir through \p scene, applying
/// each surface's Material (see Material for the model) until a return, a loss, or max_range.
///
/// Rules: a reflected beam continues from the hit point along r = b − 2 (b · n) n, with the path
/// length so far added to its range; the reported range is the whole folded path, along the
/// original direction. A path longer than \p max_range gives no return; a beam that would reflect
/// for the (\p max_bounces + 1)-th time is lost (no return), so a beam trapped between parallel
/// mirrors terminates. A surface met (or a return measured) closer than \p min_range along the
/// path gives Invalid. Transparent passes continue 1 µm beyond the surface, reflections 1 µm off
/// the surface; after 64 passes the beam counts as lost. \p max_bounces is clamped to [0, 255].
/// This is a time-of-flight beam (a depth camera's, or a coaxial striper's); trace_striper()
/// follows a triangulating striper's.
inline TraceResult trace(const Scene& scene, const Point3& origin, const Point3& dir, double min_range,
                         double max_range, BeamRng& rng, int max_bounces = kDefaultMaxBounces) noexcept;

/// Follows one beam of a laser striper from the laser at \p origin along the unit direction
/// \p dir, its camera at \p camera (world frame, pose * LaserStriper::camera_position()): trace()
/// with the triangulation rules of the file comment (the half-vector lobe of polished surfaces and
/// the triangulation shadow, along the beam's path before its first reflection). A camera at
/// \p origin (baseline 0) gives trace()'s result exactly. Draws the same random numbers in the
/// same order as trace().
inline TraceResult trace_striper(const Scene& scene, const Point3& origin, const Point3& dir, const Point3& camera,
                                 double min_range, double max_range, BeamRng& rng,
                                 int max_bounces = kDefaultMaxBounces) noexcept;

namespace detail {
/// The distance by which beams and lines of sight start off a surface [m].
inline constexpr double kSurfaceNudge = 1e-6;

/// True if a striper's camera at \p camera sees the spot \p p on a surface with unit normal \p n
/// (facing the incoming beam): \p camera lies in front of the surface (n · v > 0, v the unit
/// vector from p towards the camera) and the segment from p + 1 µm v to the camera meets no
/// surface but glass (Surface::Transparent, seen through; more than 64 of them block). Uses the
/// scene's BVH; draws nothing.
inline bool camera_sees(const Scene& scene, const Point3& p, const Point3& n, const Point3& camera) noexcept {
  const Point3 to = camera - p;
  const double distance = to.norm();
  if (!(distance > kSurfaceNudge)) return true;  // the spot at the camera itself
  const Point3 v = to / distance;
  if (!(n.dot(v) > 0)) return false;  // the camera looks at the surface's back
  const Point3 start = p + kSurfaceNudge * v;
  const double reach = distance - kSurfaceNudge;
  double from = 0.0;
  for (int glass = 0; glass <= 64; ++glass) {
    const auto hit = scene.intersect(start, v, from, reach);
    if (!hit) return true;
    if (scene.material(hit->object).surface != Surface::Transparent) return false;
    from = hit->t + kSurfaceNudge;
  }
  return false;
}

/// The cosine of the half-vector lobe: max(0, n · h), h = normalize(l + v), l = −\p dir (towards
/// the laser, \p dir the beam's unit direction), v the unit vector from \p p towards \p camera,
/// \p n the unit normal facing the beam.
inline double half_vector_cos(const Point3& dir, const Point3& p, const Point3& n, const Point3& camera) noexcept {
  const Point3 h = (camera - p).normalized() - dir;
  const double length = h.norm();
  if (!(length > 0)) return 0.0;
  return std::max(0.0, n.dot(h) / length);
}

/// The robot's body placed at a body pose (SimOptions::body, RobotBody): an oriented box and its
/// material.
struct PlacedBody {
  Prim prim;
  Material material;
};

/// The body \p b at the body pose \p body.
inline PlacedBody place_body(const RobotBody& b, const Pose& body) {
  PlacedBody p;
  p.prim.kind = PrimKind::OrientedBox;
  p.prim.a = body * Point3(0.5 * (b.box.min + b.box.max));
  p.prim.b = 0.5 * (b.box.max - b.box.min);
  p.prim.rot = body.linear();
  prepare(p.prim);
  p.material = b.material;
  return p;
}

/// What tracing a beam needs beside its ray and stream: the bounce limit, the glint (as the
/// cosine of its angle; above 1: off) and the placed body (null: none).
struct BeamModel {
  int max_bounces = kDefaultMaxBounces;
  double glint_cos = 2.0;
  const PlacedBody* body = nullptr;
};

/// The BeamModel of \p options with the body \p body (null: none).
inline BeamModel beam_model(const SimOptions& options, const PlacedBody* body = nullptr) noexcept {
  BeamModel m;
  m.max_bounces = options.max_bounces;
  m.glint_cos = options.glint ? std::cos(options.glint_angle) : 2.0;
  m.body = body;
  return m;
}

/// trace(), or, with a \p camera other than \p origin, trace_striper() with that camera, under
/// \p model (SimOptions::glint and body; off in the defaults, then exactly the plain trace). If
/// \p use_candidates, the hits along the beam up to its first reflection are looked up among
/// \p candidates, which must be Scene::cone_primitives() of a cone with apex \p origin that holds
/// \p dir: intersect_among() then gives the same hits as intersect(), so the result is trace()'s
/// (trace_striper()'s) bit for bit. Reflected parts of the beam and the camera's lines of sight
/// always go through the scene's BVH. The body is tested only after the first reflection
/// (RobotBody's rule of the first segment).
inline TraceResult trace_among(const Scene& scene, const Point3& origin, const Point3& dir, double min_range,
                               double max_range, BeamRng& rng, const BeamModel& model,
                               std::span<const ConeCandidate> candidates, bool use_candidates,
                               const Point3* camera = nullptr) noexcept {
  constexpr double kNudge = kSurfaceNudge;
  const int max_bounces = std::clamp(model.max_bounces, 0, 255);
  if (camera && *camera == origin) camera = nullptr;  // coaxial: a time-of-flight beam
  TraceResult out;
  Point3 o = origin, d = dir;
  double travelled = 0.0, from = 0.0;
  bool passed = false;
  for (int passes = 0; passes <= 64;) {
    const auto hit = use_candidates && out.bounces == 0
                         ? scene.intersect_among(candidates, o, d, from, max_range - travelled)
                         : scene.intersect(o, d, from, max_range - travelled);
    // The body, after the first reflection only, if nearer than the scene's surface.
    double t = hit ? hit->t : kInf;
    bool on_body = false;
    if (model.body && out.bounces > 0) {
      const double tb = intersect(model.body->prim, o, d, from, hit ? hit->t : max_range - travelled);
      if (tb < t) {
        t = tb;
        on_body = true;
      }
    }
    if (!hit && !on_body) return out;
    const double length = travelled + t;
    if (length < min_range) {
      out.path = BeamPath::Invalid;
      out.range = std::numeric_limits<double>::quiet_NaN();
      return out;
    }
    const Material& m = on_body ? model.body->material : scene.material(hit->object);
    // A triangulating striper's beam before its first reflection: the camera's rules apply.
    const bool triangulated = camera && out.bounces == 0;
    Point3 n = Point3::Zero();
    double cos_theta = 1.0;
    if (m.needs_normal() || triangulated) {
      n = on_body ? normal(model.body->prim, o + t * d, d) : scene.normal(*hit, o, d);
      cos_theta = -n.dot(d);
      if (triangulated && m.surface == Surface::Specular) cos_theta = half_vector_cos(d, o + t * d, n, *camera);
    }
    double range = 0;
    // The near-normal glint (SimOptions::glint): the sensor's own light straight back.
    const bool glint = m.surface == Surface::Specular && m.specular_model == SpecularModel::Reflect && !triangulated &&
                       cos_theta >= model.glint_cos;
    switch (glint ? respond_direct(m, length, min_range, rng, range)
                  : respond(m, length, cos_theta, min_range, max_range, rng, range)) {
      case Response::Return:
        if (triangulated && !camera_sees(scene, o + t * d, n, *camera)) return out;  // the triangulation shadow
        out.path = out.bounces > 0 ? BeamPath::Reflected : passed ? BeamPath::Passed : BeamPath::Direct;
        out.range = range;
        out.surface = o + t * d;
        return out;
      case Response::NoReturn:
        return out;
      case Response::Pass:
        from = t + kNudge;
        passed = true;
        ++passes;
        break;
      case Response::Reflect:
        if (out.bounces >= max_bounces) return out;
        ++out.bounces;
        o = o + t * d;
        d = (d - 2.0 * d.dot(n) * n).normalized();
        travelled = length;
        from = kNudge;
        break;
    }
  }
  return out;
}
}  // namespace detail

inline TraceResult trace(const Scene& scene, const Point3& origin, const Point3& dir, double min_range,
                         double max_range, BeamRng& rng, int max_bounces) noexcept {
  detail::BeamModel model;
  model.max_bounces = max_bounces;
  return detail::trace_among(scene, origin, dir, min_range, max_range, rng, model, {}, false);
}

inline TraceResult trace_striper(const Scene& scene, const Point3& origin, const Point3& dir, const Point3& camera,
                                 double min_range, double max_range, BeamRng& rng, int max_bounces) noexcept {
  detail::BeamModel model;
  model.max_bounces = max_bounces;
  return detail::trace_among(scene, origin, dir, min_range, max_range, rng, model, {}, false, &camera);
}

namespace detail {
/// Side of the square tiles of pixels whose beams are traced together: one
/// Scene::cone_primitives() per tile, then intersect_among() per beam.
inline constexpr int kTileSize = 8;

/// The cone of the rays of pixels [u0, u1] x [v0, v1] (inclusive) of a camera with intrinsics \p k
/// at \p pose, widened by 1/100 pixel on every side so that rounding in a ray's direction never
/// leaves it.
inline RayCone pixel_cone(const PinholeIntrinsics& k, const Pose& pose, int u0, int v0, int u1, int v1) {
  constexpr double m = 0.01;
  const Point3 c[4] = {k.ray(u0 - m, v0 - m), k.ray(u1 + m, v0 - m), k.ray(u1 + m, v1 + m), k.ray(u0 - m, v1 + m)};
  const Point3 mid = k.ray(0.5 * (u0 + u1), 0.5 * (v0 + v1));
  RayCone cone;
  cone.apex = pose.translation();
  cone.planes = 4;
  for (std::size_t i = 0; i < 4; ++i) {
    Point3 n = c[i].cross(c[(i + 1) % 4]);
    if (n.dot(mid) < 0) n = -n;
    cone.normals[i] = (pose.linear() * n).normalized();
  }
  return cone;
}

/// Samples of a striper profile whose beams are traced together (one cone per run).
inline constexpr int kFanRun = 64;

/// The cone of the rays of samples [i0, i1] (inclusive) of striper \p st at \p pose: a wedge
/// around the fan's plane, widened by 1/100 of the sample spacing at its edges and by 1e-6 rad on
/// both sides of the plane, so that rounding in a ray's direction never leaves it.
inline RayCone fan_cone(const LaserStriper& st, const Pose& pose, int i0, int i1) {
  const double step = st.opening / (st.samples - 1);
  const double a0 = -0.5 * st.opening + i0 * step - 0.01 * step, a1 = -0.5 * st.opening + i1 * step + 0.01 * step;
  const double am = 0.5 * (a0 + a1);
  const Point3 mid(std::sin(am), 0.0, std::cos(am));
  constexpr double eps = 1e-6;
  const Point3 n[4] = {{std::cos(a0), 0.0, -std::sin(a0)},
                       {-std::cos(a1), 0.0, std::sin(a1)},
                       Point3(Point3::UnitY() + eps * mid),
                       Point3(-Point3::UnitY() + eps * mid)};
  RayCone cone;
  cone.apex = pose.translation();
  cone.planes = 4;
  for (std::size_t i = 0; i < 4; ++i) cone.normals[i] = (pose.linear() * n[i]).normalized();
  return cone;
}

/// Traces the beams of the pixels of the tile with top-left pixel (u0, v0) of \p cam at \p pose:
/// pixel (u, v) draws from BeamRng(seed, sensor, first_beam + v * width + u) and is handed to
/// emit(pixel index, camera-frame unit direction, world direction, TraceResult). \p directions,
/// if given, holds cam.direction(u, v) of every pixel (row-major; shared by cameras with equal
/// intrinsics), else they are computed here. \p candidates is scratch space.
template <class Emit>
void trace_pixel_tile(const Scene& scene, const DepthCamera& cam, const Pose& pose, int u0, int v0, std::uint64_t seed,
                      std::uint64_t sensor, std::uint64_t first_beam, const BeamModel& model, const Point3* directions,
                      std::vector<ConeCandidate>& candidates, Emit&& emit) {
  const int w = cam.intrinsics.width, h = cam.intrinsics.height;
  const int u1 = std::min(w, u0 + kTileSize) - 1, v1 = std::min(h, v0 + kTileSize) - 1;
  scene.cone_primitives(pixel_cone(cam.intrinsics, pose, u0, v0, u1, v1), candidates);
  const Point3 origin = pose.translation();
  for (int v = v0; v <= v1; ++v)
    for (int u = u0; u <= u1; ++u) {
      const std::size_t pixel = static_cast<std::size_t>(v) * static_cast<std::size_t>(w) + static_cast<std::size_t>(u);
      // As pixel_ray() and DepthCamera::direction().
      const Point3 dc = directions ? directions[pixel] : cam.intrinsics.ray(u, v).normalized();
      const Point3 dir = pose.linear() * dc;
      BeamRng rng(seed, sensor, first_beam + pixel);
      emit(pixel, dc, dir, trace_among(scene, origin, dir, cam.min_range, cam.max_range, rng, model, candidates, true));
    }
}

/// The Beam measured along \p ray with the trace result \p r: a return at r.range, or no return
/// ending at ray.range (Invalid results are for the caller to drop).
inline Beam to_beam(const Ray& ray, const TraceResult& r) {
  if (r.returned()) return {ray.origin, ray.at(r.range), true};
  return {ray.origin, ray.at(ray.range), false};
}
}  // namespace detail

/// A simulated depth-camera view: a DepthFrame (image: z-depth, +inf = no return, NaN = invalid,
/// i.e. closer than min_range; the camera's intrinsics, pose and max range), ready for
/// `insert_depth_image(grid, measurement, options)`, plus the simulator's ground truth.
struct CameraMeasurement : DepthFrame {
  /// The simulator's ground truth: how each pixel's beam ended (row-major, one per pixel).
  /// Empty for a measurement that did not come from the simulator.
  std::vector<BeamPath> paths;
};

namespace detail {
/// simulate() of a camera, with its pixel directions (DepthCamera::direction(), row-major) given
/// in \p directions, or computed per pixel if null, and the robot's body placed in \p body (null:
/// none; SimOptions::body is not read here).
inline CameraMeasurement simulate_camera(const DepthCamera& camera, const Scene& scene, const Pose& pose,
                                         std::uint64_t seed, const SimOptions& options, std::uint64_t sensor,
                                         const Point3* directions, const PlacedBody* body = nullptr) {
  camera.validate();
  options.validate();
  detail::validate_pose(pose, "camera pose");
  const BeamModel model = beam_model(options, body);
  CameraMeasurement m;
  m.intrinsics = camera.intrinsics;
  m.pose = pose;
  m.max_range = camera.max_range;
  const int w = camera.intrinsics.width, h = camera.intrinsics.height;
  m.image = DepthImage(w, h);
  m.paths.assign(camera.beam_count(), BeamPath::NoReturn);
  const int tiles_u = (w + detail::kTileSize - 1) / detail::kTileSize,
            tiles_v = (h + detail::kTileSize - 1) / detail::kTileSize;
  const auto tiles = static_cast<std::size_t>(tiles_u) * static_cast<std::size_t>(tiles_v);
  intervox::parallel_for_chunks(
      tiles, options.threads,
      [&](std::size_t b, std::size_t e) {
        std::vector<ConeCandidate> candidates;
        for (std::size_t t = b; t < e; ++t) {
          const int u0 = static_cast<int>(t % static_cast<std::size_t>(tiles_u)) * detail::kTileSize;
          const int v0 = static_cast<int>(t / static_cast<std::size_t>(tiles_u)) * detail::kTileSize;
          detail::trace_pixel_tile(scene, camera, pose, u0, v0, seed, sensor, 0, model, directions, candidates,
                                   [&](std::size_t i, const Point3& dc, const Point3&, const TraceResult& r) {
                                     float& px = m.image.depth[i];
                                     m.paths[i] = r.path;
                                     if (r.returned())
                                       px = static_cast<float>(r.range * dc.z());  // range to z-depth
                                     else if (r.path == BeamPath::NoReturn)
                                       px = std::numeric_limits<float>::infinity();
                                     else
                                       px = std::numeric_limits<float>::quiet_NaN();
                                   });
        }
      },
      1);
  return m;
}
}  // namespace detail

namespace detail {
/// \throws InvalidArgument if \p options carries a body (the single-sensor calls know no body pose).
inline void require_no_body(const SimOptions& options, const char* where) {
  if (options.body)
    ParamCheck(where).fail("SimOptions::body needs a body pose; use the rig calls (simulate(rig, ...), simulate_path, "
                           "simulate_images, SimulatedRig)");
}
}  // namespace detail

/// Simulates one view of \p camera at \p pose (optical frame to world). Pixel (u, v) draws from
/// BeamRng(seed, \p sensor, v * width + u). SimOptions::glint applies; SimOptions::body must be
/// unset (a lone camera has no body pose; put the camera in a rig for it).
/// \throws InvalidArgument for an invalid camera, a non-rigid / non-finite pose, invalid options, or
/// options with a body.
inline CameraMeasurement simulate(const DepthCamera& camera, const Scene& scene, const Pose& pose, std::uint64_t seed,
                                  const SimOptions& options = {}, std::uint64_t sensor = 0) {
  detail::require_no_body(options, "intervox::sim::simulate(camera)");
  return detail::simulate_camera(camera, scene, pose, seed, options, sensor, nullptr);
}

/// The beams of a depth frame (e.g. a CameraMeasurement), row-major, invalid pixels dropped: a
/// return at z-depth d ends at pixel_point(intrinsics, pose, u, v, d) (as depth-image insertion
/// reads it); a no-return pixel becomes a Beam with hit = false ending at max_range along
/// pixel_ray() (1 m along it if the frame's max_range is +inf: insertion then cuts it at its own).
/// \throws InvalidArgument for an invalid frame (DepthFrame::validate()).
inline std::vector<Beam> to_beams(const DepthFrame& m) {
  m.validate();
  const double no_return = std::isfinite(m.max_range) ? m.max_range : 1.0;
  std::vector<Beam> beams;
  beams.reserve(m.image.depth.size());
  for (int v = 0; v < m.image.height; ++v)
    for (int u = 0; u < m.image.width; ++u) {
      const double z = m.image.at(u, v);
      if (std::isfinite(z) && z > 0)
        beams.push_back({m.pose.translation(), pixel_point(m.intrinsics, m.pose, u, v, z), true});
      else if (z == std::numeric_limits<double>::infinity())
        beams.push_back({m.pose.translation(), pixel_ray(m.intrinsics, m.pose, u, v).at(no_return), false});
    }
  return beams;
}

/// A simulated striper sweep.
struct SweepMeasurement {
  /// Every valid sample as a Beam with its own profile's origin (profile-major); invalid samples
  /// (closer than min_range) are dropped.
  std::vector<Beam> beams;
  /// The simulator's ground truth: how each beam of `beams` ended (parallel to it).
  std::vector<BeamPath> paths;
  /// Profile image: width = samples, height = profiles; z-depth in each profile's own sensor
  /// frame (+inf = no return, NaN = invalid). Not a pinhole image: use `beams` for insertion.
  DepthImage image;
};

/// Simulates \p striper along \p path (sensor poses, one per profile). Sample i of profile k
/// draws from BeamRng(seed, \p sensor, k * samples + i) and is trace_striper() along its beam with
/// the camera at path[k] * striper.camera_position(): the triangulation rules of the file comment
/// (the half-vector lobe of polished surfaces, the triangulation shadow, the folded path after a
/// reflection). A striper with baseline 0 is a time-of-flight sensor: every sample is trace()'s.
/// SimOptions::glint applies (see there for a triangulating striper); SimOptions::body must be
/// unset (use simulate_path() with a rig for it).
/// \throws InvalidArgument for an invalid striper, any bad pose in the path, invalid options, or
/// options with a body.
inline SweepMeasurement simulate_sweep(const LaserStriper& striper, const Scene& scene, const std::vector<Pose>& path,
                                       std::uint64_t seed, const SimOptions& options = {}, std::uint64_t sensor = 0) {
  striper.validate();
  options.validate();
  detail::require_no_body(options, "intervox::sim::simulate_sweep");
  const detail::BeamModel model = detail::beam_model(options);
  for (const Pose& p : path) detail::validate_pose(p, "striper pose");
  const std::size_t n = striper.beam_count();
  SweepMeasurement m;
  m.image = DepthImage(striper.samples, static_cast<int>(path.size()));
  std::vector<Point3> dirs(n);
  for (std::size_t i = 0; i < n; ++i) dirs[i] = striper.direction(static_cast<int>(i));
  std::vector<TraceResult> results(n * path.size());
  // Runs of kFanRun samples of one profile, each traced through its cone's candidates.
  const std::size_t runs = (n + detail::kFanRun - 1) / detail::kFanRun;
  intervox::parallel_for_chunks(
      runs * path.size(), options.threads,
      [&](std::size_t b, std::size_t e) {
        std::vector<ConeCandidate> candidates;
        for (std::size_t item = b; item < e; ++item) {
          const Pose& pose = path[item / runs];
          const Point3 camera = pose * striper.camera_position();
          const std::size_t i0 = item % runs * detail::kFanRun, i1 = std::min(n, i0 + detail::kFanRun);
          scene.cone_primitives(detail::fan_cone(striper, pose, static_cast<int>(i0), static_cast<int>(i1) - 1),
                                candidates);
          for (std::size_t i = i0; i < i1; ++i) {
            const std::size_t j = item / runs * n + i;
            BeamRng rng(seed, sensor, j);
            results[j] = detail::trace_among(scene, pose.translation(), pose.linear() * dirs[i], striper.min_range,
                                             striper.max_range, rng, model, candidates, true, &camera);
          }
        }
      },
      1);
  m.beams.reserve(results.size());
  m.paths.reserve(results.size());
  for (std::size_t j = 0; j < results.size(); ++j) {
    const Pose& pose = path[j / n];
    const Point3& dc = dirs[j % n];
    const auto& r = results[j];
    float& px = m.image.depth[j];
    if (r.path == BeamPath::Invalid) continue;  // px stays NaN
    px = r.returned() ? static_cast<float>(r.range * dc.z()) : std::numeric_limits<float>::infinity();
    m.beams.push_back(detail::to_beam({pose.translation(), pose.linear() * dc, striper.max_range}, r));
    m.paths.push_back(r.path);
  }
  return m;
}

}  // namespace intervox::sim
