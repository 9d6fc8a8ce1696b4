#pragma once
// One run of the sweep, by configuration. Defined in run_one.cpp, the one translation unit that
// instantiates every offered platform × update × utility (runs.hpp), compiled once for the
// experiments program and its tests.
#include "config.hpp"
#include "results.hpp"

#include <string>

namespace experiments {

/// Runs one configuration (figures written when figure_stem is not empty).
/// \throws intervox::InvalidArgument for an unknown platform, update, utility, planner, room, rules
///         or sensor condition, or an arm run with the mobile robot's planner, room, rules or sensor.
RunResult run_one(const RunConfig& c, const SweepOptions& o, const std::string& figure_stem = {});

}  // namespace experiments
