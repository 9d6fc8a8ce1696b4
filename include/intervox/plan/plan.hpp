#pragma once
/// \file
/// Umbrella header of the planning layer: column map, exploration map, view sampling, information
/// gain, candidate scoring, the planners (decide only) and the episode runner. Needs neither the
/// simulator nor libpng.

#include <intervox/plan/arm_planner.hpp>
#include <intervox/plan/candidate_scoring.hpp>
#include <intervox/plan/column_map.hpp>
#include <intervox/plan/episode.hpp>
#include <intervox/plan/explained_planning.hpp>
#include <intervox/plan/exploration_map.hpp>
#include <intervox/plan/information_gain.hpp>
#include <intervox/plan/mobile_planner.hpp>
#include <intervox/plan/planner.hpp>
#include <intervox/plan/rig_rays.hpp>
#include <intervox/plan/view_sampling.hpp>
