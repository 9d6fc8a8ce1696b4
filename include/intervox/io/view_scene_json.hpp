#pragma once
/// \file
/// Moved to intervox/view/view_scene_json.hpp; this forwarding header goes in the next release.

#include <intervox/view/view_scene_json.hpp>
