#pragma once
// A planning header that breaks the layering on purpose: the check must reject this folder
// (ctest layering.plan_includes_detects_sim).
#include <intervox/sim/scene.hpp>
