#pragma once
/// \file
/// Umbrella header of the planning layer (without exploration_image.hpp, which needs libpng:
/// include it and link intervox::png for the exploration map pictures).

#include <intervox/plan/arm_modeller.hpp>
#include <intervox/plan/exploration_map.hpp>
#include <intervox/plan/information_gain.hpp>
#include <intervox/plan/mobile_explorer.hpp>
#include <intervox/plan/rig_rays.hpp>
#include <intervox/plan/view_sampling.hpp>
