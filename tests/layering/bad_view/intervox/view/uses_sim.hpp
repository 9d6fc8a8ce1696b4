#pragma once
// A view header that breaks the layering on purpose: the check must reject this folder
// (ctest layering.view_includes_detects_sim).
#include <intervox/sim/scene.hpp>
