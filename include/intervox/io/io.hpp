#pragma once
/// \file
/// Umbrella header of the io layer (file formats and loaders), without PNG (include io/png.hpp and
/// link intervox::png for that). The pictures and the 3D page moved to view/ (view/view.hpp); this
/// header still includes view/view.hpp for one release, so that programs that took them from here
/// keep compiling: that include goes in the next release (include view/view.hpp for them).

#include <intervox/io/color.hpp>
#include <intervox/io/grid_file.hpp>
#include <intervox/io/octomap.hpp>
#include <intervox/io/ply_writer.hpp>
#include <intervox/io/point_cloud.hpp>
#include <intervox/io/rgb_image.hpp>

// For one release only (see above); goes in the next release.
#include <intervox/view/view.hpp>
