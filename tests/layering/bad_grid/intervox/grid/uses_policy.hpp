#pragma once
// A grid header that breaks the layering on purpose: the check must reject this folder
// (ctest layering.grid_includes_detects_policy).
#include <intervox/update/bayes_log_odds.hpp>
