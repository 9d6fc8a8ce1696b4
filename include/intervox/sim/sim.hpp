#pragma once
/// \file
/// The built-in raycaster (simulator): scenes with surface materials after the thesis' noise
/// model, simulated scans of the sensor descriptions of core/sensors.hpp, the simulator as a sensor
/// source for the episode runner, the built-in scenes, random apartments and the oracle's sensor. Everything lives in
/// namespace intervox::sim. Include this header, or the single headers below.

#include <intervox/sim/apartment.hpp>
#include <intervox/sim/material.hpp>
#include <intervox/sim/mesh.hpp>
#include <intervox/sim/oracle.hpp>
#include <intervox/sim/beam_rng.hpp>
#include <intervox/sim/rig.hpp>
#include <intervox/sim/scene.hpp>
#include <intervox/sim/scenes.hpp>
#include <intervox/sim/sensor_aliases.hpp>
#include <intervox/sim/source.hpp>
#include <intervox/sim/simulate.hpp>
