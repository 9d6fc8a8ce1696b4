#pragma once
/// \file
/// The simulator as a sensor source for the episode runner (plan/episode.hpp): a rig in a scene
/// that returns a simulated scan for every body pose it is asked at.

#include <intervox/core/sensor_data.hpp>
#include <intervox/core/sensors.hpp>
#include <intervox/sim/beam_rng.hpp>
#include <intervox/sim/rig.hpp>
#include <intervox/sim/scene.hpp>
#include <intervox/sim/simulate.hpp>

#include <cstdint>
#include <vector>

namespace intervox::sim {

/// A sensor rig in a simulated scene, as a SensorSource: `source(body)` returns one simulated scan
/// of every sensor (sim::simulate) with the body at \p body.
///
/// Noise: scan n (counted from 1) draws with the seed splitmix64(seed + n * 0x9E3779B97F4A7C15),
/// so the same seed and the same sequence of poses give the same beams.
///
/// Thread safety: not thread-safe (it counts scans); the scene must outlive it.
class SimulatedRig {
 public:
  /// \param scene the world (kept by reference)
  /// \param rig the sensors (copied)
  /// \param seed the noise seed
  /// \param options simulation options (threads, bounce limit)
  SimulatedRig(const Scene& scene, SensorRig rig, std::uint64_t seed, SimOptions options = {})
      : scene_(&scene), rig_(std::move(rig)), seed_(seed), options_(options) {}

  /// One scan with the body at \p body. \throws InvalidArgument for a bad pose.
  std::vector<Beam> operator()(const Pose& body) {
    const std::uint64_t n = ++scans_;
    const std::uint64_t seed = detail::mix64(seed_ + detail::kGamma * n + detail::kGamma);
    return simulate(rig_, *scene_, body, seed, options_, &last_paths_);
  }

  /// The simulator's ground truth of the last scan: how each of its beams ended (parallel to the
  /// beams it returned; empty before the first scan).
  const std::vector<BeamPath>& last_paths() const noexcept { return last_paths_; }

  const SensorRig& rig() const noexcept { return rig_; }
  const Scene& scene() const noexcept { return *scene_; }
  /// Scans taken so far.
  std::uint64_t scans() const noexcept { return scans_; }

 private:
  const Scene* scene_;
  SensorRig rig_;
  std::uint64_t seed_;
  SimOptions options_;
  std::uint64_t scans_ = 0;
  std::vector<BeamPath> last_paths_;
};

}  // namespace intervox::sim
