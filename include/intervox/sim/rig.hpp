#pragma once
/// \file
/// Simulated scans of a sensor rig (core/sensors.hpp: the mobile base's eight ToF cameras, the
/// arm's laser striper): the rig description rendered in a scene.
///
/// Random streams: beam b of sensor s draws from BeamRng(seed, s, b) in simulate(), and from
/// BeamRng(seed, s, k * beam_count(s) + b) for body pose k of simulate_path(); so sensor s of a
/// rig measures exactly what the lone sensor does in simulate() / simulate_sweep() with
/// `sensor = s` (without SimOptions::body, which only the rig calls place: at every body pose).
///
/// Thread safety: pure functions of their arguments (the scene and the rig are only read).

#include <intervox/core/error.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/core/sensors.hpp>
#include <intervox/sim/scene.hpp>
#include <intervox/sim/sensor_aliases.hpp>
#include <intervox/sim/simulate.hpp>

#include <algorithm>
#include <cstdint>
#include <optional>
#include <utility>
#include <variant>
#include <vector>

namespace intervox::sim {

using intervox::ArmOptions;
using intervox::MobileBaseOptions;
using intervox::MountedSensor;
using intervox::Sensor;
using intervox::SensorRay;
using intervox::SensorRig;

namespace detail {
/// The camera-frame pixel directions (DepthCamera::direction(), row-major) of every camera of a
/// rig, computed once per distinct camera model (cameras with equal intrinsics share them).
class PixelDirections {
 public:
  explicit PixelDirections(const SensorRig& rig) : of_(rig.size(), nullptr) {
    for (std::size_t s = 0; s < rig.size(); ++s) {
      const auto* cam = std::get_if<DepthCamera>(&rig.sensors()[s].sensor);
      if (!cam) continue;
      const PinholeIntrinsics& k = cam->intrinsics;
      for (std::size_t r = 0; r < s && !of_[s]; ++r) {
        const auto* other = std::get_if<DepthCamera>(&rig.sensors()[r].sensor);
        if (other && other->intrinsics.width == k.width && other->intrinsics.height == k.height &&
            other->intrinsics.fx == k.fx && other->intrinsics.fy == k.fy && other->intrinsics.cx == k.cx &&
            other->intrinsics.cy == k.cy)
          of_[s] = of_[r];
      }
      if (of_[s]) continue;
      auto& table = tables_.emplace_back(cam->beam_count());
      for (int v = 0; v < k.height; ++v)
        for (int u = 0; u < k.width; ++u)
          table[static_cast<std::size_t>(v) * static_cast<std::size_t>(k.width) + static_cast<std::size_t>(u)] =
              cam->direction(u, v);
      of_[s] = table.data();
    }
  }
  /// The directions of sensor \p s (null for a striper).
  const Point3* of(std::size_t s) const noexcept { return of_[s]; }

 private:
  std::vector<std::vector<Point3>> tables_;
  std::vector<const Point3*> of_;
};

/// One block of a rig's path scan per (body pose, sensor), in output order; its beams are traced
/// in work items (PathItem).
struct PathBlock {
  Pose pose;  // world pose of the sensor
  std::size_t sensor = 0;
  std::uint64_t first_beam = 0;  // k * beam_count(sensor): the stream offset of body pose k
  std::size_t offset = 0;        // index of the block's first beam in the output
  std::size_t body = 0;          // k: the body pose, for the placed body
};
/// A work item of a path scan: a tile of camera pixels or a run of striper samples of a block.
struct PathItem {
  std::size_t block = 0;
  int a = 0, b = 0;  // camera: the tile's top-left pixel (a, b); striper: samples [a, b)
};
/// The blocks and work items of a rig's scans along body poses, and their beams in all.
struct PathPlan {
  std::vector<PathBlock> blocks;
  std::vector<PathItem> items;
  std::size_t total = 0;
};

/// The blocks of \p rig's scans from \p bodies (pose-major, then sensor) and their work items: a
/// tile of camera pixels (detail::kTileSize) or a run of striper samples (detail::kFanRun).
inline PathPlan plan_path(const SensorRig& rig, const std::vector<Pose>& bodies) {
  PathPlan plan;
  for (std::size_t k = 0; k < bodies.size(); ++k)
    for (std::size_t s = 0; s < rig.size(); ++s) {
      const std::size_t n = rig.beam_count(s);
      plan.blocks.push_back({rig.sensor_pose(s, bodies[k]), s, k * n, plan.total, k});
      if (const auto* cam = std::get_if<DepthCamera>(&rig.sensors()[s].sensor)) {
        for (int v = 0; v < cam->intrinsics.height; v += kTileSize)
          for (int u = 0; u < cam->intrinsics.width; u += kTileSize)
            plan.items.push_back({plan.blocks.size() - 1, u, v});
      } else {
        const int samples = std::get<LaserStriper>(rig.sensors()[s].sensor).samples;
        for (int i = 0; i < samples; i += kFanRun)
          plan.items.push_back({plan.blocks.size() - 1, i, std::min(samples, i + kFanRun)});
      }
      plan.total += n;
    }
  return plan;
}

/// The tracing of a path scan's work items: what they read (the rig, the scene, the seed, the
/// pixel directions, each body pose's beam model, the plan) and where each beam's result goes
/// (beams and ends, at the beam's output index).
struct PathTracer {
  const SensorRig& rig;
  const Scene& scene;
  std::uint64_t seed;
  const PixelDirections& directions;
  const std::vector<BeamModel>& models;
  const PathPlan& plan;
  std::vector<Beam>& beams;
  std::vector<BeamPath>& ends;

  /// Traces the beams of \p item: a camera tile through the tile's cone (trace_pixel_tile), a
  /// striper run through the run's fan_cone; \p candidates is the caller's scratch.
  void trace(const PathItem& item, std::vector<ConeCandidate>& candidates) const {
    const PathBlock& blk = plan.blocks[item.block];
    const Sensor& sensor = rig.sensors()[blk.sensor].sensor;
    if (const auto* cam = std::get_if<DepthCamera>(&sensor)) {
      trace_pixel_tile(scene, *cam, blk.pose, item.a, item.b, seed, blk.sensor, blk.first_beam, models[blk.body],
                       directions.of(blk.sensor), candidates,
                       [&](std::size_t i, const Point3&, const Point3& dir, const TraceResult& r) {
                         beams[blk.offset + i] = to_beam({blk.pose.translation(), dir, cam->max_range}, r);
                         ends[blk.offset + i] = r.path;
                       });
    } else {
      const auto& st = std::get<LaserStriper>(sensor);
      const Point3 o = blk.pose.translation();
      const Eigen::Matrix3d rot = blk.pose.linear();
      const Point3 camera = blk.pose * st.camera_position();  // the triangulation camera, as simulate_sweep()
      scene.cone_primitives(fan_cone(st, blk.pose, item.a, item.b - 1), candidates);
      for (int i = item.a; i < item.b; ++i) {
        const Point3 dir = rot * st.direction(i);  // as SensorRig::rays()
        BeamRng rng(seed, blk.sensor, blk.first_beam + static_cast<std::uint64_t>(i));
        const TraceResult r =
            trace_among(scene, o, dir, st.min_range, st.max_range, rng, models[blk.body], candidates, true, &camera);
        beams[blk.offset + static_cast<std::size_t>(i)] = to_beam({o, dir, st.max_range}, r);
        ends[blk.offset + static_cast<std::size_t>(i)] = r.path;
      }
    }
  }
};

/// Drops the invalid beams (BeamPath::Invalid) of the first \p total of \p beams and \p ends,
/// keeping the order; \p paths (if given) receives the kept ends.
inline void drop_invalid_beams(std::vector<Beam>& beams, std::vector<BeamPath>& ends, std::size_t total,
                               std::vector<BeamPath>* paths) {
  std::size_t kept = 0;
  while (kept < total && ends[kept] != BeamPath::Invalid) ++kept;
  for (std::size_t j = kept; j < total; ++j)
    if (ends[j] != BeamPath::Invalid) {
      beams[kept] = beams[j];
      ends[kept++] = ends[j];
    }
  beams.resize(kept);
  if (paths) {
    ends.resize(kept);
    *paths = std::move(ends);
  }
}
}  // namespace detail

/// Simulated scans of \p rig along a path of body poses (e.g. a flange path sweeping the arm's
/// striper), all beams in one vector (pose-major, then sensor, then beam). Invalid beams (closer
/// than min_range) are dropped; no-return beams have hit = false and end at their sensor's max range.
/// If \p paths is given, it receives the simulator's ground truth of every returned beam
/// (BeamPath, parallel to the result). With SimOptions::body, the robot's body is placed at each
/// body pose for the scans of that pose (RobotBody: beams meet it only after a reflection).
/// \throws InvalidArgument for any bad pose or bad options.
inline std::vector<Beam> simulate_path(const SensorRig& rig, const Scene& scene, const std::vector<Pose>& bodies,
                                       std::uint64_t seed, const SimOptions& options = {},
                                       std::vector<BeamPath>* paths = nullptr) {
  options.validate();
  for (const Pose& body : bodies) detail::validate_pose(body, "body pose");
  // One block per (body pose, sensor), in output order; its beams are traced in work items of a
  // tile of camera pixels (through the tile's cone, detail::trace_pixel_tile) or a run of striper
  // samples (through the run's detail::fan_cone). Every beam's result depends only on its ray and
  // its random stream.
  const detail::PixelDirections directions(rig);
  // The robot's body at every body pose (SimOptions::body), and each pose's beam model.
  std::vector<detail::PlacedBody> placed;
  if (options.body)
    for (const Pose& body : bodies) placed.push_back(detail::place_body(*options.body, body));
  std::vector<detail::BeamModel> models;
  for (std::size_t k = 0; k < bodies.size(); ++k)
    models.push_back(detail::beam_model(options, placed.empty() ? nullptr : &placed[k]));
  const detail::PathPlan plan = detail::plan_path(rig, bodies);
  const std::size_t total = plan.total;
  std::vector<Beam> beams(total);
  std::vector<BeamPath> ends(total, BeamPath::NoReturn);
  const detail::PathTracer tracer{rig, scene, seed, directions, models, plan, beams, ends};
  intervox::parallel_for_chunks(
      plan.items.size(), options.threads,
      [&](std::size_t b, std::size_t e) {
        std::vector<ConeCandidate> candidates;
        for (std::size_t it = b; it < e; ++it) tracer.trace(plan.items[it], candidates);
      },
      1);
  // Drop the invalid beams, keeping the order.
  detail::drop_invalid_beams(beams, ends, total, paths);
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
/// `insert_depth_image`. The same random streams as simulate(); with SimOptions::body, the body
/// placed at \p body as there.
/// \throws InvalidArgument for a bad pose or bad options.
inline std::vector<CameraMeasurement> simulate_images(const SensorRig& rig, const Scene& scene, const Pose& body,
                                                      std::uint64_t seed, const SimOptions& options = {}) {
  options.validate();
  detail::validate_pose(body, "body pose");
  const detail::PixelDirections directions(rig);
  std::optional<detail::PlacedBody> placed;
  if (options.body) placed = detail::place_body(*options.body, body);
  std::vector<CameraMeasurement> out;
  for (std::size_t s = 0; s < rig.size(); ++s)
    if (const auto* cam = std::get_if<DepthCamera>(&rig.sensors()[s].sensor))
      out.push_back(detail::simulate_camera(*cam, scene, rig.sensor_pose(s, body), seed, options, s, directions.of(s),
                                            placed ? &*placed : nullptr));
  return out;
}

}  // namespace intervox::sim
