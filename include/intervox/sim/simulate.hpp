#pragma once
/// \file
/// Simulated measurements: the noise model applied along beams through a scene, for depth
/// cameras (depth images or beams) and laser striper sweeps.
/// Thread safety: simulation reads the scene only; concurrent simulations of one scene are safe.

#include <intervox/core/error.hpp>
#include <intervox/core/parallel.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/sim/material.hpp>
#include <intervox/sim/random.hpp>
#include <intervox/sim/scene.hpp>
#include <intervox/sim/sensors.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <thread>
#include <vector>

namespace intervox::sim {

/// Options of a simulation call.
struct SimOptions {
  /// Worker threads (0: std::thread::hardware_concurrency(); more are capped at it). Results are
  /// identical for every thread count: each beam draws from its own stream BeamRng(seed, sensor, beam).
  unsigned threads = 1;
};

/// The outcome of one simulated beam.
struct TraceResult {
  enum class Kind : std::uint8_t {
    Return = 0,    ///< a measured range
    NoReturn = 1,  ///< nothing came back (out of range, or absorbed): the sensor reports max range
    Invalid = 2,   ///< the first surface lies closer than min_range: no measurement at all
  };
  Kind kind = Kind::NoReturn;
  double range = std::numeric_limits<double>::infinity();  ///< the measured range for Return
};

/// Follows one beam from \p origin along the unit direction \p dir through \p scene, applying
/// each surface's Material (see Material for the model) until a return, a loss, or max_range.
/// Transparent passes continue 1 µm beyond the surface; after 64 passes the beam counts as lost.
inline TraceResult trace(const Scene& scene, const Point3& origin, const Point3& dir, double min_range,
                         double max_range, BeamRng& rng) noexcept {
  double from = 0.0;
  for (int pass = 0; pass < 64; ++pass) {
    const auto hit = scene.intersect(origin, dir, from, max_range);
    if (!hit) return {};
    if (hit->t < min_range) return {TraceResult::Kind::Invalid, std::numeric_limits<double>::quiet_NaN()};
    double range = 0;
    switch (respond(scene.material(hit->object), hit->t, min_range, max_range, rng, range)) {
      case Response::Return: return {TraceResult::Kind::Return, range};
      case Response::NoReturn: return {};
      case Response::Pass: from = hit->t + 1e-6; break;
    }
  }
  return {};
}

namespace detail {
/// Runs f(begin, end) over [0, n) split into contiguous chunks on \p threads threads (0: all);
/// exceptions are rethrown on the calling thread.
template <class F>
void parallel_for(std::size_t n, unsigned threads, F&& f) {
  threads = static_cast<unsigned>(std::min<std::size_t>(resolve_threads(threads), std::max<std::size_t>(1, n / 256)));
  const std::size_t chunk = (n + threads - 1) / threads;
  run_on_threads(threads, [&](unsigned t) {
    const std::size_t b = std::min(n, t * chunk), e = std::min(n, b + chunk);
    f(b, e);
  });
}

/// A Beam from a trace result (Invalid results are for the caller to drop).
inline Beam to_beam(const Point3& origin, const Point3& dir, double max_range, const TraceResult& r) {
  if (r.kind == TraceResult::Kind::Return) return {origin, origin + r.range * dir, true};
  return {origin, origin + max_range * dir, false};
}
}  // namespace detail

/// A simulated depth-camera view, ready for `insert_depth_image(grid, image, intrinsics, pose, ...)`.
struct CameraMeasurement {
  DepthImage image;              ///< z-depth; +inf = no return; NaN = invalid (closer than min_range)
  PinholeIntrinsics intrinsics;  ///< the camera's intrinsics
  Pose pose = Pose::Identity();  ///< camera (optical frame) to world
  double max_range = 0;          ///< the camera's max range (for the inserting side)
};

/// Simulates one view of \p camera at \p pose (optical frame to world). Pixel (u, v) draws from
/// BeamRng(seed, \p sensor, v * width + u).
/// \throws InvalidArgument for an invalid camera or a non-rigid / non-finite pose.
inline CameraMeasurement simulate(const DepthCamera& camera, const Scene& scene, const Pose& pose, std::uint64_t seed,
                                  const SimOptions& options = {}, std::uint64_t sensor = 0) {
  camera.validate();
  detail::validate_pose(pose, "camera pose");
  CameraMeasurement m;
  m.intrinsics = camera.intrinsics;
  m.pose = pose;
  m.max_range = camera.max_range;
  const int w = camera.intrinsics.width, h = camera.intrinsics.height;
  m.image = DepthImage(w, h);
  const Eigen::Matrix3d rot = pose.linear();
  const Point3 origin = pose.translation();
  detail::parallel_for(camera.beam_count(), options.threads, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      const int u = static_cast<int>(i % static_cast<std::size_t>(w)), v = static_cast<int>(i / static_cast<std::size_t>(w));
      const Point3 dc = camera.direction(u, v);
      BeamRng rng(seed, sensor, i);
      const TraceResult r = trace(scene, origin, rot * dc, camera.min_range, camera.max_range, rng);
      float& px = m.image.depth[i];
      if (r.kind == TraceResult::Kind::Return) px = static_cast<float>(r.range * dc.z());
      else if (r.kind == TraceResult::Kind::NoReturn) px = std::numeric_limits<float>::infinity();
      else px = std::numeric_limits<float>::quiet_NaN();
    }
  });
  return m;
}

/// The beams of a camera measurement, row-major, invalid pixels dropped; no-return pixels become
/// Beams with hit = false ending at max_range along their direction.
/// \throws InvalidArgument if the image does not match its intrinsics.
inline std::vector<Beam> to_beams(const CameraMeasurement& m) {
  m.intrinsics.validate();
  if (!m.image.consistent() || m.image.width != m.intrinsics.width || m.image.height != m.intrinsics.height)
    throw InvalidArgument("intervox::sim::to_beams: image size does not match the intrinsics");
  std::vector<Beam> beams;
  beams.reserve(m.image.depth.size());
  const Point3 o = m.pose.translation();
  for (int v = 0; v < m.image.height; ++v)
    for (int u = 0; u < m.image.width; ++u) {
      const double z = m.image.at(u, v);
      const Point3 ray = m.pose.linear() * m.intrinsics.ray(u, v);  // z-component 1 in camera frame
      if (std::isfinite(z) && z > 0) beams.push_back({o, o + z * ray, true});
      else if (z == std::numeric_limits<double>::infinity()) beams.push_back({o, o + m.max_range * ray.normalized(), false});
    }
  return beams;
}

/// A simulated striper sweep.
struct SweepMeasurement {
  /// Every valid sample as a Beam with its own profile's origin (profile-major); invalid samples
  /// (closer than min_range) are dropped.
  std::vector<Beam> beams;
  /// Profile image: width = samples, height = profiles; z-depth in each profile's own sensor
  /// frame (+inf = no return, NaN = invalid). Not a pinhole image: use `beams` for insertion.
  DepthImage image;
};

/// Simulates \p striper along \p path (sensor poses, one per profile). Sample i of profile k
/// draws from BeamRng(seed, \p sensor, k * samples + i).
/// \throws InvalidArgument for an invalid striper or any bad pose in the path.
inline SweepMeasurement simulate_sweep(const LaserStriper& striper, const Scene& scene, const std::vector<Pose>& path,
                                       std::uint64_t seed, const SimOptions& options = {}, std::uint64_t sensor = 0) {
  striper.validate();
  for (const Pose& p : path) detail::validate_pose(p, "striper pose");
  const std::size_t n = striper.beam_count();
  SweepMeasurement m;
  m.image = DepthImage(striper.samples, static_cast<int>(path.size()));
  std::vector<Point3> dirs(n);
  for (std::size_t i = 0; i < n; ++i) dirs[i] = striper.direction(static_cast<int>(i));
  std::vector<TraceResult> results(n * path.size());
  detail::parallel_for(results.size(), options.threads, [&](std::size_t b, std::size_t e) {
    for (std::size_t j = b; j < e; ++j) {
      const Pose& pose = path[j / n];
      BeamRng rng(seed, sensor, j);
      results[j] = trace(scene, pose.translation(), pose.linear() * dirs[j % n], striper.min_range, striper.max_range, rng);
    }
  });
  m.beams.reserve(results.size());
  for (std::size_t j = 0; j < results.size(); ++j) {
    const Pose& pose = path[j / n];
    const Point3& dc = dirs[j % n];
    const auto& r = results[j];
    float& px = m.image.depth[j];
    if (r.kind == TraceResult::Kind::Invalid) continue;  // px stays NaN
    px = r.kind == TraceResult::Kind::Return ? static_cast<float>(r.range * dc.z()) : std::numeric_limits<float>::infinity();
    m.beams.push_back(detail::to_beam(pose.translation(), pose.linear() * dc, striper.max_range, r));
  }
  return m;
}

}  // namespace intervox::sim
