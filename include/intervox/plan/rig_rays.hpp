#pragma once
/// \file
/// The bridge from a simulated sensor rig to the planner: its noise-free beams as a RayBundle in
/// the body frame, for information-gain casting.
/// Thread safety: pure function of its arguments.

#include <intervox/plan/information_gain.hpp>
#include <intervox/sim/rig.hpp>

namespace intervox {

/// The body-frame beams of \p rig, every \p stride-th (see sim::SensorRig::rays), each with its
/// sensor's max range.
/// \throws InvalidArgument for stride < 1.
inline RayBundle rig_bundle(const sim::SensorRig& rig, int stride = 1) {
  RayBundle b;
  for (const sim::Ray& r : rig.rays(Pose::Identity(), stride)) b.add(r.origin, r.direction, r.max_range);
  return b;
}

}  // namespace intervox
