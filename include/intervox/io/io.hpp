#pragma once
/// \file
/// Umbrella header of the io layer, without PNG (include io/png.hpp and link intervox::png for that)
/// and without the viewer's run file (io/view_scene_json.hpp, which needs nlohmann-json).

#include <intervox/io/color.hpp>
#include <intervox/io/grid_file.hpp>
#include <intervox/io/html_view.hpp>
#include <intervox/io/image_annotation.hpp>
#include <intervox/io/octomap.hpp>
#include <intervox/io/ply.hpp>
#include <intervox/io/point_cloud.hpp>
#include <intervox/io/rgb_image.hpp>
#include <intervox/io/slice.hpp>
