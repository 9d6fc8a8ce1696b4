#pragma once
// The rigs the example programs run besides the thesis' eight cameras (SensorRig::mobile_base()).
#include <intervox/core/sensors.hpp>

namespace examples {

/// One O3D-100 at the front of the mobile base, 0.3 m forward of its axis and 0.5 m up (knee
/// height), looking along the body's x axis: the one-camera robot of docs/planning.md ("Any rig").
/// Its planner wants `MobilePlannerParams::exact_blind_zone` and a few frames per scan.
inline intervox::SensorRig front_camera_rig() {
  intervox::SensorRig rig;
  const intervox::Point3 mount(0.3, 0.0, 0.5);
  rig.add(intervox::DepthCamera::o3d100(), intervox::look_at(mount, mount + intervox::Point3::UnitX()), "front");
  return rig;
}

}  // namespace examples
