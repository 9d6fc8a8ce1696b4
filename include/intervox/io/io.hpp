#pragma once
/// \file
/// Umbrella header of the io layer, without PNG (include io/png.hpp and link intervox::png for that).

#include "intervox/io/color.hpp"
#include "intervox/io/grid_file.hpp"
#include "intervox/io/octomap.hpp"
#include "intervox/io/ply.hpp"
#include "intervox/io/point_cloud.hpp"
#include "intervox/io/rgb_image.hpp"
#include "intervox/io/slice.hpp"
