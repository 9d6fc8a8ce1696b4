#pragma once
/// \file
/// Simulated scans of a sensor rig (core/sensors.hpp: the mobile base's eight ToF cameras, the
/// arm's laser striper): the rig description rendered in a scene.
///
/// Random streams: beam b of sensor s draws from BeamRng(seed, s, b) in simulate(), and from
/// BeamRng(seed, s, k * beam_count(s) + b) for body pose k of simulate_path(); so sensor s of a
/// rig measures exactly what the lone sensor does in simulate() / simulate_sweep() with
/// `sensor = s`.
///
/// Thread safety: pure functions of their arguments (the scene and the rig are only read).

#include <intervox/core/error.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/core/sensors.hpp>
#include <intervox/sim/scene.hpp>
#include <intervox/sim/sensors.hpp>
#include <intervox/sim/simulate.hpp>

#include <cstdint>
#include <vector>

namespace intervox::sim {

using intervox::ArmOptions;
using intervox::MobileBaseOptions;
using intervox::MountedSensor;
using intervox::Sensor;
using intervox::SensorRay;
using intervox::SensorRig;

/// Simulated scans of \p rig along a path of body poses (e.g. a flange path sweeping the arm's
/// striper), all beams in one vector (pose-major, then sensor, then beam). Invalid beams (closer
/// than min_range) are dropped; no-return beams have hit = false and end at their sensor's max range.
/// If \p paths is given, it receives the simulator's ground truth of every returned beam
/// (BeamPath, parallel to the result).
/// \throws InvalidArgument for any bad pose or bad options.
inline std::vector<Beam> simulate_path(const SensorRig& rig, const Scene& scene, const std::vector<Pose>& bodies,
                                       std::uint64_t seed, const SimOptions& options = {},
                                       std::vector<BeamPath>* paths = nullptr) {
  options.validate();
  std::vector<SensorRay> all;
  std::vector<std::uint64_t> index;  // the beam counter of each ray's random stream
  for (std::size_t k = 0; k < bodies.size(); ++k) {
    auto rs = rig.rays(bodies[k]);
    for (const SensorRay& r : rs) index.push_back(k * rig.beam_count(r.sensor) + r.beam);
    all.insert(all.end(), rs.begin(), rs.end());
  }
  std::vector<TraceResult> results(all.size());
  intervox::parallel_for_chunks(all.size(), options.threads, [&](std::size_t b, std::size_t e) {
    for (std::size_t j = b; j < e; ++j) {
      BeamRng rng(seed, all[j].sensor, index[j]);
      const Ray& ray = all[j].ray;
      results[j] = trace(scene, ray.origin, ray.direction, all[j].min_range, ray.range, rng, options.max_bounces);
    }
  });
  std::vector<Beam> beams;
  beams.reserve(all.size());
  if (paths) {
    paths->clear();
    paths->reserve(all.size());
  }
  for (std::size_t j = 0; j < all.size(); ++j)
    if (results[j].path != BeamPath::Invalid) {
      beams.push_back(detail::to_beam(all[j].ray, results[j]));
      if (paths) paths->push_back(results[j].path);
    }
  return beams;
}

/// One simulated scan of every sensor of \p rig for the body at \p body: the union of all beams
/// (sensor-major), ready for `insert_beams`; \p paths as in simulate_path().
/// \throws InvalidArgument for a bad pose or bad options.
inline std::vector<Beam> simulate(const SensorRig& rig, const Scene& scene, const Pose& body, std::uint64_t seed,
                                  const SimOptions& options = {}, std::vector<BeamPath>* paths = nullptr) {
  return simulate_path(rig, scene, std::vector<Pose>{body}, seed, options, paths);
}

/// One depth image per camera of \p rig (stripers are skipped), each with its world pose, for
/// `insert_depth_image`. The same random streams as simulate().
/// \throws InvalidArgument for a bad pose.
inline std::vector<CameraMeasurement> simulate_images(const SensorRig& rig, const Scene& scene, const Pose& body,
                                                      std::uint64_t seed, const SimOptions& options = {}) {
  detail::validate_pose(body, "body pose");
  std::vector<CameraMeasurement> out;
  for (std::size_t s = 0; s < rig.size(); ++s)
    if (const auto* cam = std::get_if<DepthCamera>(&rig.sensors()[s].sensor))
      out.push_back(simulate(*cam, scene, rig.sensor_pose(s, body), seed, options, s));
  return out;
}

}  // namespace intervox::sim
