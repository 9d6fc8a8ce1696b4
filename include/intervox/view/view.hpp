#pragma once
/// \file
/// Umbrella header of the view layer (what draws or shows a map: slices and pictures, their
/// annotation, the 3D page and its explained-space options), without what needs libpng
/// (view/exploration_image.hpp: include it and link intervox::png) and without the viewer's run
/// file (view/view_scene_json.hpp, which needs nlohmann-json). The file formats are in io/ (io/io.hpp).

#include <intervox/view/bitmap_font.hpp>
#include <intervox/view/explained_image.hpp>
#include <intervox/view/explained_page_options.hpp>
#include <intervox/view/html_view.hpp>
#include <intervox/view/image_annotation.hpp>
#include <intervox/view/slice.hpp>
