#pragma once
/// \file
/// Umbrella header of the planning layer: exploration map, view sampling, information gain, the
/// planners (decide only) and the episode runner. Needs neither the simulator nor libpng.

#include <intervox/plan/arm_planner.hpp>
#include <intervox/plan/episode.hpp>
#include <intervox/plan/exploration_map.hpp>
#include <intervox/plan/information_gain.hpp>
#include <intervox/plan/mobile_planner.hpp>
#include <intervox/plan/planner.hpp>
#include <intervox/plan/rig_rays.hpp>
#include <intervox/plan/view_sampling.hpp>
