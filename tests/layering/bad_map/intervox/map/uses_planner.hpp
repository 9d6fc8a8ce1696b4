#pragma once
// A map header that breaks the layering on purpose: the check must reject this folder
// (ctest layering.map_includes_detects_planner).
#include <intervox/plan/mobile_planner.hpp>
