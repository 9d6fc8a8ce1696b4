#pragma once
/// \file
/// The simulator's names for the sensor descriptions of core/sensors.hpp (DepthCamera,
/// LaserStriper, look_at, linear_sweep, ...): the simulator renders the same descriptions the
/// planners cast their gain rays from.

#include <intervox/core/sensors.hpp>
#include <intervox/sim/scene.hpp>

#include <numbers>

namespace intervox::sim {

inline constexpr double kPi = std::numbers::pi;

using intervox::deg;
using intervox::DepthCamera;
using intervox::LaserStriper;
using intervox::linear_sweep;
using intervox::look_at;
using intervox::sweep_towards;

}  // namespace intervox::sim
