#pragma once
/// \file
/// Sensor rigs: sensors mounted on a body (the mobile base's eight ToF cameras, the arm's laser
/// striper), their noise-free beams for information-gain casting, and simulated scans.

#include <intervox/core/error.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/sim/scene.hpp>
#include <intervox/sim/sensors.hpp>
#include <intervox/sim/simulate.hpp>

#include <cmath>
#include <cstdint>
#include <string>
#include <variant>
#include <vector>

namespace intervox::sim {

/// Any sensor a rig can carry.
using Sensor = std::variant<DepthCamera, LaserStriper>;

/// A sensor with its mount pose (sensor optical frame to body frame) and a name.
struct MountedSensor {
  Sensor sensor;
  Pose mount = Pose::Identity();
  std::string name;
};

/// One noise-free beam of a rig in world coordinates.
struct Ray {
  Point3 origin = Point3::Zero();
  Point3 direction = Point3::UnitZ();  ///< unit length
  double min_range = 0;
  double max_range = 0;
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
/// Random streams: beam b of sensor s draws from BeamRng(seed, s, b) in simulate(), and from
/// BeamRng(seed, s, k * beam_count(s) + b) for body pose k of simulate_path(); so sensor s of a
/// rig measures exactly what the lone sensor does in simulate() / simulate_sweep() with
/// `sensor = s`.
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
  /// index), keeping only every \p stride-th beam: for cameras pixels with u and v multiples of
  /// stride (about 1/stride² of them), for stripers samples with an index multiple of stride.
  /// \throws InvalidArgument for a bad pose or stride < 1.
  std::vector<Ray> rays(const Pose& body, int stride = 1) const {
    detail::validate_pose(body, "body pose");
    if (stride < 1) throw InvalidArgument("intervox::sim::SensorRig::rays: stride must be >= 1");
    std::vector<Ray> out;
    out.reserve(beam_count());
    for (std::size_t s = 0; s < size(); ++s) {
      const Pose pose = sensor_pose(s, body);
      const Point3 o = pose.translation();
      const Eigen::Matrix3d rot = pose.linear();
      const auto sid = static_cast<std::uint32_t>(s);
      if (const auto* cam = std::get_if<DepthCamera>(&sensors_[s].sensor)) {
        const int w = cam->intrinsics.width, h = cam->intrinsics.height;
        for (int v = 0; v < h; v += stride)
          for (int u = 0; u < w; u += stride)
            out.push_back({o, rot * cam->direction(u, v), cam->min_range, cam->max_range, sid,
                           static_cast<std::uint32_t>(v * w + u)});
      } else {
        const auto& st = std::get<LaserStriper>(sensors_[s].sensor);
        for (int i = 0; i < st.samples; i += stride)
          out.push_back({o, rot * st.direction(i), st.min_range, st.max_range, sid, static_cast<std::uint32_t>(i)});
      }
    }
    return out;
  }

  /// One simulated scan of every sensor for the body at \p body: the union of all beams
  /// (sensor-major), ready for `insert_beams`. Invalid beams (closer than min_range) are dropped;
  /// no-return beams have hit = false and end at their sensor's max range.
  /// \throws InvalidArgument for a bad pose.
  std::vector<Beam> simulate(const Scene& scene, const Pose& body, std::uint64_t seed, const SimOptions& options = {}) const {
    return simulate_path(scene, std::vector<Pose>{body}, seed, options);
  }

  /// Simulated scans along a path of body poses (e.g. a flange path sweeping the arm's striper),
  /// all beams in one vector (pose-major, then sensor, then beam).
  /// \throws InvalidArgument for any bad pose.
  std::vector<Beam> simulate_path(const Scene& scene, const std::vector<Pose>& bodies, std::uint64_t seed,
                                  const SimOptions& options = {}) const {
    std::vector<Ray> all;
    std::vector<std::uint64_t> index;  // the beam counter of each ray's random stream
    for (std::size_t k = 0; k < bodies.size(); ++k) {
      auto rs = rays(bodies[k]);
      for (const Ray& r : rs) index.push_back(k * beam_count(r.sensor) + r.beam);
      all.insert(all.end(), rs.begin(), rs.end());
    }
    std::vector<TraceResult> results(all.size());
    detail::parallel_for(all.size(), options.threads, [&](std::size_t b, std::size_t e) {
      for (std::size_t j = b; j < e; ++j) {
        BeamRng rng(seed, all[j].sensor, index[j]);
        results[j] = trace(scene, all[j].origin, all[j].direction, all[j].min_range, all[j].max_range, rng);
      }
    });
    std::vector<Beam> beams;
    beams.reserve(all.size());
    for (std::size_t j = 0; j < all.size(); ++j)
      if (results[j].kind != TraceResult::Kind::Invalid)
        beams.push_back(detail::to_beam(all[j].origin, all[j].direction, all[j].max_range, results[j]));
    return beams;
  }

  /// One depth image per camera of the rig (stripers are skipped), each with its world pose,
  /// for `insert_depth_image`. The same random streams as simulate().
  /// \throws InvalidArgument for a bad pose.
  std::vector<CameraMeasurement> simulate_images(const Scene& scene, const Pose& body, std::uint64_t seed,
                                                 const SimOptions& options = {}) const {
    detail::validate_pose(body, "body pose");
    std::vector<CameraMeasurement> out;
    for (std::size_t s = 0; s < size(); ++s)
      if (const auto* cam = std::get_if<DepthCamera>(&sensors_[s].sensor))
        out.push_back(sim::simulate(*cam, scene, sensor_pose(s, body), seed, options, s));
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
        if (u >= -0.5 && u <= cam->intrinsics.width - 0.5 && v >= -0.5 && v <= cam->intrinsics.height - 0.5) return true;
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
    if (!(std::isfinite(o.length) && o.length > 0 && std::isfinite(o.width) && o.width > 0 &&
          std::isfinite(o.camera_height) && std::isfinite(o.pitch) && std::abs(o.pitch) < 0.5 * kPi))
      throw InvalidArgument("intervox::sim::SensorRig::mobile_base: sizes must be finite and > 0, |pitch| < pi/2");
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
    if (!std::isfinite(o.standoff)) throw InvalidArgument("intervox::sim::SensorRig::arm: standoff must be finite");
    SensorRig rig;
    Pose mount = Pose::Identity();
    mount.translation() = Point3(0, 0, o.standoff);
    rig.add(o.striper, mount, "striper");
    return rig;
  }

 private:
  const MountedSensor& at(std::size_t s) const {
    if (s >= sensors_.size()) throw OutOfRange("intervox::sim::SensorRig: unknown sensor " + std::to_string(s));
    return sensors_[s];
  }
  std::vector<MountedSensor> sensors_;
};

}  // namespace intervox::sim
