#pragma once
/// \file
/// The bridge from a sensor rig description (core/sensors.hpp) to the planner: its noise-free
/// beams as a RayBundle in the body frame, for information-gain casting.
/// Thread safety: pure function of its arguments.

#include <intervox/core/sensors.hpp>
#include <intervox/plan/information_gain.hpp>

namespace intervox {

/// The body-frame beams of \p rig, every \p stride-th in the centred pattern (see
/// SensorRig::rays), each reaching its sensor's max range.
/// \throws InvalidArgument for stride < 1.
inline RayBundle rig_bundle(const SensorRig& rig, int stride = 1) {
  RayBundle b;
  for (const SensorRay& r : rig.rays(Pose::Identity(), stride)) b.add(r.ray);
  return b;
}

}  // namespace intervox
