#pragma once
/// \file
/// Sensor models of the simulator: a pinhole depth camera (ToF camera) and a laser striper, plus
/// pose helpers (look_at) and striper sweep paths.
///
/// Sensor frames are optical frames, as for PinholeIntrinsics: x right, y down, z forward.

#include <intervox/core/error.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/sim/scene.hpp>

#include <cmath>
#include <string>
#include <vector>

namespace intervox::sim {

inline constexpr double kPi = 3.14159265358979323846;

/// Degrees to radians.
constexpr double deg(double degrees) noexcept { return degrees * kPi / 180.0; }

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
    if (!(std::isfinite(min_range) && std::isfinite(max_range) && min_range >= 0 && min_range < max_range))
      throw InvalidArgument("intervox::sim::DepthCamera: need finite 0 <= min_range < max_range");
  }

  /// Number of beams (pixels).
  std::size_t beam_count() const noexcept {
    return static_cast<std::size_t>(intrinsics.width) * static_cast<std::size_t>(intrinsics.height);
  }

  /// Unit direction of pixel (u, v) in the camera frame.
  Point3 direction(int u, int v) const noexcept { return intrinsics.ray(u, v).normalized(); }
};

/// A laser striper: one line of samples fanned over an opening angle, measuring by triangulation.
/// Sample i looks along (sin a_i, 0, cos a_i) in the sensor frame, a_i running evenly from
/// -opening/2 (i = 0) to +opening/2 (i = samples - 1): the line lies along the sensor's x axis,
/// and a sweep moves the sensor along its y axis.
///
/// Thread safety: a value type.
struct LaserStriper {
  int samples = 640;        ///< samples per profile, >= 2
  double opening = deg(14); ///< full opening angle of the line [rad], in (0, pi)
  double min_range = 0.1;   ///< [m]
  double max_range = 1.0;   ///< [m]

  /// \throws InvalidArgument as validate().
  static LaserStriper make(int samples, double opening, double min_range, double max_range) {
    LaserStriper s;
    s.samples = samples;
    s.opening = opening;
    s.min_range = min_range;
    s.max_range = max_range;
    s.validate();
    return s;
  }

  /// The Micro-Epsilon scanCONTROL 2700-100 of the thesis' arm (Tab. 5.1): 640 samples over 14°.
  /// The range window 0.1 to 1 m is wider than the real device's (about 0.3 to 0.6 m) so that
  /// sweeps from viewpoints on a sphere around a tabletop object reach it.
  static LaserStriper scancontrol_2700() { return make(640, deg(14), 0.1, 1.0); }

  /// \throws InvalidArgument unless samples >= 2, opening in (0, pi), finite 0 <= min < max range.
  void validate() const {
    if (samples < 2) throw InvalidArgument("intervox::sim::LaserStriper: need at least 2 samples");
    if (!(opening > 0 && opening < kPi)) throw InvalidArgument("intervox::sim::LaserStriper: opening must lie in (0, pi) radians");
    if (!(std::isfinite(min_range) && std::isfinite(max_range) && min_range >= 0 && min_range < max_range))
      throw InvalidArgument("intervox::sim::LaserStriper: need finite 0 <= min_range < max_range");
  }

  std::size_t beam_count() const noexcept { return static_cast<std::size_t>(samples); }

  /// Unit direction of sample \p i in the sensor frame.
  Point3 direction(int i) const noexcept {
    const double a = -0.5 * opening + opening * i / (samples - 1);
    return {std::sin(a), 0.0, std::cos(a)};
  }
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
  if (!(z.norm() > 1e-12)) throw InvalidArgument("intervox::sim::look_at: eye and target coincide");
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
  if (!(std::isfinite(length) && length >= 0)) throw InvalidArgument("intervox::sim::linear_sweep: length must be finite and >= 0");
  if (profiles < 1) throw InvalidArgument("intervox::sim::linear_sweep: need at least one profile");
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

}  // namespace intervox::sim
