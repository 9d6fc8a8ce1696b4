#pragma once
/// \file
/// Sensor descriptions, below the simulator and the planners: a pinhole depth camera (e.g. a
/// time-of-flight camera), a laser striper, and a rig of sensors mounted on one body, with the
/// presets of the thesis' two platforms (eight ifm O3D-100 cameras on the mobile base, one
/// Micro-Epsilon scanCONTROL striper on the arm). The planners cast the rig's noise-free rays for
/// the information gain; the simulator (sim/) renders the same descriptions into measurements; a
/// real robot describes its own sensors with the same types.
///
/// Sensor frames are optical frames, as for PinholeIntrinsics: x right, y down, z forward.

#include <intervox/core/error.hpp>
#include <intervox/core/point.hpp>
#include <intervox/core/ray.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/core/validate.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <string>
#include <variant>
#include <vector>

namespace intervox {

/// Degrees to radians.
constexpr double deg(double degrees) noexcept { return degrees * std::numbers::pi / 180.0; }

namespace detail {
/// \throws InvalidArgument unless \p p is finite.
inline void require_finite(const Point3& p, const char* what) {
  if (!is_finite(p)) ParamCheck("intervox").fail(std::string(what) + " is not finite");
}
}  // namespace detail

/// A pinhole depth camera (e.g. a time-of-flight camera) with a range window.
///
/// Pixel (u, v) casts one beam through its centre, along PinholeIntrinsics::ray(u, v).
/// Thread safety: a value type.
struct DepthCamera {
  PinholeIntrinsics intrinsics;
  double min_range = 0.1;  ///< surfaces closer than this give an invalid pixel [m]
  double max_range = 4.0;  ///< surfaces farther than this give no return [m]

  /// A camera of \p width x \p height pixels with full opening angles \p fov_x (horizontal, along
  /// the image width) and \p fov_y (vertical), in radians.
  /// \throws InvalidArgument for a non-positive size, an angle outside (0, pi) (e.g. a zero field
  /// of view), or a range window that is not 0 <= min_range < max_range, finite.
  static DepthCamera make(int width, int height, double fov_x, double fov_y, double min_range, double max_range) {
    DepthCamera c;
    c.intrinsics = PinholeIntrinsics::from_fov(width, height, fov_x, fov_y);
    c.min_range = min_range;
    c.max_range = max_range;
    c.validate();
    return c;
  }

  /// The ifm O3D-100 time-of-flight camera of the thesis' mobile platform (Tab. 5.1): 64 x 48
  /// pixels, 40° horizontal (along the 64 pixels) x 30° vertical (along the 48) — the orientation
  /// in which the 30° x 40° opening gives square pixels (0.625° each) — range 0.1 to 4 m.
  static DepthCamera o3d100() { return make(64, 48, deg(40), deg(30), 0.1, 4.0); }

  /// \throws InvalidArgument if the intrinsics or the range window are not valid.
  void validate() const {
    intrinsics.validate();
    const ParamCheck check("intervox::DepthCamera");
    check.nonnegative("min_range", min_range);
    check.finite("max_range", max_range);
    if (!(min_range < max_range)) check.fail("need min_range < max_range");
  }

  /// Number of beams (pixels).
  std::size_t beam_count() const noexcept {
    return static_cast<std::size_t>(intrinsics.width) * static_cast<std::size_t>(intrinsics.height);
  }

  /// Unit direction of pixel (u, v) in the camera frame: pixel_ray(intrinsics, identity, u, v).direction.
  Point3 direction(int u, int v) const noexcept { return intrinsics.ray(u, v).normalized(); }
};

/// A laser striper: one line of samples fanned over an opening angle, measuring by triangulation.
/// Sample i looks along (sin a_i, 0, cos a_i) in the sensor frame, a_i running evenly from
/// -opening/2 (i = 0) to +opening/2 (i = samples - 1): the line lies along the sensor's x axis,
/// and a sweep moves the sensor along its y axis.
///
/// Triangulation: the laser plane is the sensor's x-z plane, with the laser at the origin; a camera
/// sits `baseline` along y from it (a negative baseline: on the -y side), at camera_position() =
/// (0, baseline, 0), and looks towards (0, 0, camera_crossing), where its optical axis crosses the
/// laser plane; the triangulation angle between the laser's z axis and the camera's axis is
/// atan(|baseline| / camera_crossing). The
/// simulator (sim::simulate_sweep) takes from this the direct returns of polished surfaces (where
/// the normal bisects the directions to the laser and to the camera) and the triangulation shadow
/// (a spot the camera cannot see gives no measurement); only the camera's position matters there,
/// its field of view is not modelled. A baseline of 0 describes a coaxial sensor (the camera at
/// the laser origin), which the simulator treats like a time-of-flight sensor. The default
/// LaserStriper{} and make() have the triangulation of scancontrol_2700().
///
/// Thread safety: a value type.
struct LaserStriper {
  /// Default camera baseline [m] (of LaserStriper{}, make() and scancontrol_2700()): a
  /// representative value, not a datasheet one (the thesis gives none).
  static constexpr double kDefaultBaseline = 0.15;
  /// Default range at which the camera's axis crosses the laser plane [m]: with kDefaultBaseline a
  /// triangulation angle of atan(0.15 / 0.45) = 18.4°; representative, not a datasheet value.
  static constexpr double kDefaultCameraCrossing = 0.45;

  int samples = 640;           ///< samples per profile, >= 2
  double opening = deg(14.0);  ///< full opening angle of the line [rad], in (0, pi)
  double min_range = 0.1;      ///< [m]
  double max_range = 1.0;      ///< [m]
  /// The camera's offset from the laser origin along the sensor's y axis (perpendicular to the
  /// laser line and to the view) [m], finite; its sign is the side the camera is mounted on
  /// (positive: +y, which is down in a look_at() view with z up; negative: -y, up); 0: a coaxial
  /// sensor.
  double baseline = kDefaultBaseline;
  /// The range along the sensor's z axis at which the camera's optical axis crosses the laser
  /// plane [m], finite and > 0 (it sets triangulation_angle(); the simulator does not use it).
  double camera_crossing = kDefaultCameraCrossing;

  /// A striper of \p samples samples over \p opening [rad], range window [\p min_range,
  /// \p max_range] [m], and camera \p baseline, \p camera_crossing [m] (by default those of
  /// scancontrol_2700()).
  /// \throws InvalidArgument as validate().
  static LaserStriper make(int samples, double opening, double min_range, double max_range,
                           double baseline = kDefaultBaseline, double camera_crossing = kDefaultCameraCrossing) {
    LaserStriper s;
    s.samples = samples;
    s.opening = opening;
    s.min_range = min_range;
    s.max_range = max_range;
    s.baseline = baseline;
    s.camera_crossing = camera_crossing;
    s.validate();
    return s;
  }

  /// The Micro-Epsilon scanCONTROL 2700-100 of the thesis' arm (Tab. 5.1): 640 samples over 14°.
  /// The range window 0.1 to 1 m is wider than the real device's (about 0.3 to 0.6 m) so that
  /// sweeps from viewpoints on a sphere around a tabletop object reach it. The thesis gives no
  /// triangulation geometry: the camera baseline of 0.15 m, crossing the laser plane at 0.45 m
  /// (a triangulation angle of 18.4°), is representative of such sensors, not the datasheet's.
  static LaserStriper scancontrol_2700() {
    return make(640, deg(14.0), 0.1, 1.0, kDefaultBaseline, kDefaultCameraCrossing);
  }

  /// \throws InvalidArgument unless samples >= 2, opening in (0, pi), finite 0 <= min < max range,
  /// a finite baseline and a finite camera_crossing > 0.
  void validate() const {
    const ParamCheck check("intervox::LaserStriper");
    check.at_least("samples", samples, 2);
    check.in_range("opening (radians)", opening, 0, std::numbers::pi, RangeEnds::Open);
    check.nonnegative("min_range", min_range);
    check.finite("max_range", max_range);
    if (!(min_range < max_range)) check.fail("need min_range < max_range");
    check.finite("baseline", baseline);
    check.positive("camera_crossing", camera_crossing);
  }

  std::size_t beam_count() const noexcept { return static_cast<std::size_t>(samples); }

  /// Unit direction of sample \p i in the sensor frame.
  Point3 direction(int i) const noexcept {
    const double a = -0.5 * opening + opening * i / (samples - 1);
    return {std::sin(a), 0.0, std::cos(a)};
  }

  /// The camera's position in the sensor frame: (0, baseline, 0).
  Point3 camera_position() const noexcept { return {0.0, baseline, 0.0}; }

  /// The triangulation angle [rad] between the laser's z axis and the camera's optical axis:
  /// atan(|baseline| / camera_crossing), in [0, pi/2); 0 for a coaxial sensor.
  double triangulation_angle() const noexcept { return std::atan2(std::abs(baseline), camera_crossing); }
};

/// The optical-frame pose at \p eye looking at \p target: z towards the target, x to the right,
/// y down with respect to \p up. If the view is parallel to \p up, the world x axis (or y, if that
/// is parallel too) serves as up instead.
/// \throws InvalidArgument for non-finite input or eye == target.
inline Pose look_at(const Point3& eye, const Point3& target, const Point3& up = Point3::UnitZ()) {
  detail::require_finite(eye, "look_at eye");
  detail::require_finite(target, "look_at target");
  detail::require_finite(up, "look_at up");
  const Point3 z = target - eye;
  if (!(z.norm() > 1e-12)) ParamCheck("intervox::look_at").fail("eye and target coincide");
  const Point3 zn = z.normalized();
  Point3 x = zn.cross(up);
  if (x.norm() < 1e-9 * std::max(1.0, up.norm())) x = zn.cross(Point3::UnitX());
  if (x.norm() < 1e-9) x = zn.cross(Point3::UnitY());
  x.normalize();
  const Point3 y = zn.cross(x);
  Pose pose = Pose::Identity();
  pose.linear().col(0) = x;
  pose.linear().col(1) = y;
  pose.linear().col(2) = zn;
  pose.translation() = eye;
  return pose;
}

/// A straight striper sweep: \p profiles poses with the orientation of \p center, moved along
/// center's own y axis (perpendicular to the laser line and to the view) evenly from
/// -length/2 to +length/2.
/// \throws InvalidArgument for a bad pose, a non-finite or negative length, or profiles < 1.
inline std::vector<Pose> linear_sweep(const Pose& center, double length, int profiles) {
  detail::validate_pose(center, "sweep centre pose");
  const ParamCheck check("intervox::linear_sweep");
  check.nonnegative("length", length);
  check.at_least("profiles", profiles, 1);
  std::vector<Pose> path;
  path.reserve(static_cast<std::size_t>(profiles));
  const Point3 axis = center.linear().col(1);
  for (int k = 0; k < profiles; ++k) {
    const double s = profiles == 1 ? 0.0 : -0.5 * length + length * k / (profiles - 1);
    Pose p = center;
    p.translation() += s * axis;
    path.push_back(p);
  }
  return path;
}

/// A sweep that looks from \p viewpoint at \p target and moves across it over \p length:
/// `linear_sweep(look_at(viewpoint, target, up), length, profiles)`.
inline std::vector<Pose> sweep_towards(const Point3& viewpoint, const Point3& target, double length, int profiles,
                                       const Point3& up = Point3::UnitZ()) {
  return linear_sweep(look_at(viewpoint, target, up), length, profiles);
}

/// Any sensor a rig can carry.
using Sensor = std::variant<DepthCamera, LaserStriper>;

/// A sensor with its mount pose (sensor optical frame to body frame) and a name.
struct MountedSensor {
  Sensor sensor;
  Pose mount = Pose::Identity();
  std::string name;
};

/// One noise-free beam of a rig in world coordinates: the Ray to cast (reaching the sensor's max
/// range), the sensor's min range, and which beam of which sensor it is.
struct SensorRay {
  Ray ray;                   ///< origin, unit direction, range = the sensor's max range
  double min_range = 0;      ///< the sensor's min range [m]
  std::uint32_t sensor = 0;  ///< index of the sensor in the rig
  std::uint32_t beam = 0;    ///< index of the beam within its sensor (row-major pixel / sample)
};

/// Options of the mobile base preset. The body frame has x forward, y left, z up, its origin at
/// the centre of the base's footprint on the floor.
struct MobileBaseOptions {
  double length = 0.6;         ///< footprint along x [m]
  double width = 0.4;          ///< footprint along y [m]
  double camera_height = 0.5;  ///< height of the cameras above the floor (knee height) [m]
  double pitch = 0.0;          ///< upward tilt of every camera [rad], in (-pi/2, pi/2)
  DepthCamera camera = DepthCamera::o3d100();
};

/// Options of the arm preset. The body frame is the flange: z out of the flange.
struct ArmOptions {
  LaserStriper striper = LaserStriper::scancontrol_2700();
  double standoff = 0.1;  ///< the striper's optical centre this far along the flange z axis [m]
};

/// A set of sensors rigidly mounted on one body.
///
/// A description only: the simulator renders it (sim::simulate(rig, scene, body, seed)), the
/// planners cast its rays() for the information gain (rig_bundle()).
///
/// Thread safety: const member functions may be called concurrently; add() must not overlap any call.
class SensorRig {
 public:
  /// Adds a sensor; returns its index.
  /// \throws InvalidArgument for an invalid sensor or a non-rigid / non-finite mount pose.
  std::size_t add(const Sensor& sensor, const Pose& mount, std::string name = {}) {
    std::visit([](const auto& s) { s.validate(); }, sensor);
    detail::validate_pose(mount, "sensor mount pose");
    sensors_.push_back({sensor, mount, std::move(name)});
    return sensors_.size() - 1;
  }

  const std::vector<MountedSensor>& sensors() const noexcept { return sensors_; }
  std::size_t size() const noexcept { return sensors_.size(); }

  /// Number of beams of sensor \p s. \throws OutOfRange for an unknown sensor.
  std::size_t beam_count(std::size_t s) const {
    return std::visit([](const auto& x) { return x.beam_count(); }, at(s).sensor);
  }
  /// Number of beams of all sensors.
  std::size_t beam_count() const {
    std::size_t n = 0;
    for (std::size_t s = 0; s < size(); ++s) n += beam_count(s);
    return n;
  }

  /// World pose of sensor \p s for the body at \p body. \throws OutOfRange for an unknown sensor.
  Pose sensor_pose(std::size_t s, const Pose& body) const { return body * at(s).mount; }
  /// The body pose that puts sensor \p s at \p sensor_pose (to turn a striper sweep into a
  /// flange path). \throws OutOfRange for an unknown sensor.
  Pose body_pose_for(std::size_t s, const Pose& sensor_pose) const { return sensor_pose * at(s).mount.inverse(); }

  /// The noise-free beams of every sensor for the body at \p body (sensor-major, then beam
  /// index), keeping only every \p stride-th beam in the centred pattern of camera_rays(): for
  /// cameras pixels (u, v) with u = strided_first(width, stride) + i * stride and likewise v
  /// (about 1/stride² of them), for stripers samples strided_first(samples, stride) + i * stride.
  /// Camera rays follow pixel_ray().
  /// \throws InvalidArgument for a bad pose or stride < 1.
  std::vector<SensorRay> rays(const Pose& body, int stride = 1) const {
    detail::validate_pose(body, "body pose");
    ParamCheck("intervox::SensorRig::rays").at_least("stride", stride, 1);
    std::vector<SensorRay> out;
    out.reserve(beam_count());
    for (std::size_t s = 0; s < size(); ++s) {
      const Pose pose = sensor_pose(s, body);
      const auto sid = static_cast<std::uint32_t>(s);
      if (const auto* cam = std::get_if<DepthCamera>(&sensors_[s].sensor)) {
        const int w = cam->intrinsics.width, h = cam->intrinsics.height;
        for (int v = strided_first(h, stride); v < h; v += stride)
          for (int u = strided_first(w, stride); u < w; u += stride)
            out.push_back({pixel_ray(cam->intrinsics, pose, u, v, cam->max_range), cam->min_range, sid,
                           static_cast<std::uint32_t>(v * w + u)});
      } else {
        const auto& st = std::get<LaserStriper>(sensors_[s].sensor);
        const Point3 o = pose.translation();
        const Eigen::Matrix3d rot = pose.linear();
        for (int i = strided_first(st.samples, stride); i < st.samples; i += stride)
          out.push_back({{o, rot * st.direction(i), st.max_range}, st.min_range, sid, static_cast<std::uint32_t>(i)});
      }
    }
    return out;
  }

  /// True if some camera of the rig, with the body at \p body, has \p point in its field of view
  /// and range window (occlusion ignored). Stripers see only their plane (|y| <= 1e-9 m).
  /// \throws InvalidArgument for a bad pose or a non-finite point.
  bool sees(const Pose& body, const Point3& point) const {
    detail::validate_pose(body, "body pose");
    detail::require_finite(point, "point");
    for (std::size_t s = 0; s < size(); ++s) {
      const Point3 p = sensor_pose(s, body).inverse() * point;
      const double r = p.norm();
      if (const auto* cam = std::get_if<DepthCamera>(&sensors_[s].sensor)) {
        if (p.z() <= 0 || r < cam->min_range || r > cam->max_range) continue;
        const double u = cam->intrinsics.fx * p.x() / p.z() + cam->intrinsics.cx;
        const double v = cam->intrinsics.fy * p.y() / p.z() + cam->intrinsics.cy;
        if (u >= -0.5 && u <= cam->intrinsics.width - 0.5 && v >= -0.5 && v <= cam->intrinsics.height - 0.5)
          return true;
      } else {
        const auto& st = std::get<LaserStriper>(sensors_[s].sensor);
        if (p.z() <= 0 || r < st.min_range || r > st.max_range || std::abs(p.y()) > 1e-9) continue;
        if (std::abs(std::atan2(p.x(), p.z())) <= 0.5 * st.opening) return true;
      }
    }
    return false;
  }

  /// The omniRob of the thesis (chapter 5.1): eight O3D-100 cameras around a cuboid base at knee
  /// height, facing outwards at yaws 0°, 45°, ..., 315° (four at the face centres, four at the
  /// corners). Each camera covers 40° horizontally, so 8 x 40° = 320° of the 360° around the
  /// base are seen (five-degree gaps at the seams between neighbouring cameras, plus the
  /// parallax of the mounts), and 30° vertically (±15° about the horizontal without pitch).
  /// \throws InvalidArgument for non-finite or non-positive sizes or a pitch outside (-pi/2, pi/2).
  static SensorRig mobile_base(const MobileBaseOptions& o = {}) {
    const ParamCheck check("intervox::SensorRig::mobile_base");
    check.positive("length", o.length);
    check.positive("width", o.width);
    check.finite("camera_height", o.camera_height);
    check.in_range("pitch", o.pitch, -0.5 * std::numbers::pi, 0.5 * std::numbers::pi, RangeEnds::Open);
    SensorRig rig;
    for (int i = 0; i < 8; ++i) {
      const double yaw = deg(45.0 * i);
      const double c = std::cos(yaw), s = std::sin(yaw);
      const auto sgn = [](double x) { return x > 1e-9 ? 1.0 : (x < -1e-9 ? -1.0 : 0.0); };
      const Point3 pos(0.5 * o.length * sgn(c), 0.5 * o.width * sgn(s), o.camera_height);
      const Point3 dir(c * std::cos(o.pitch), s * std::cos(o.pitch), std::sin(o.pitch));
      rig.add(o.camera, look_at(pos, pos + dir), "o3d100_" + std::to_string(i));
    }
    return rig;
  }

  /// The KR16 of the thesis (chapter 5.1): one laser striper on the flange, looking along the
  /// flange z axis from \p o.standoff in front of it, its line along the flange x axis.
  /// \throws InvalidArgument for an invalid striper or a non-finite standoff.
  static SensorRig arm(const ArmOptions& o = {}) {
    ParamCheck("intervox::SensorRig::arm").finite("standoff", o.standoff);
    SensorRig rig;
    Pose mount = Pose::Identity();
    mount.translation() = Point3(0, 0, o.standoff);
    rig.add(o.striper, mount, "striper");
    return rig;
  }

 private:
  const MountedSensor& at(std::size_t s) const {
    if (s >= sensors_.size()) throw OutOfRange("intervox::SensorRig: unknown sensor " + std::to_string(s));
    return sensors_[s];
  }
  std::vector<MountedSensor> sensors_;
};

}  // namespace intervox
