// libFuzzer target: the viewer's run file (view_scene_from_json, which read_view_scene calls
// with the file's text; include/intervox/view/view_scene_json.hpp). A scene that parses is written
// back with view_scene_to_json and parsed again: the second parse must succeed and give the same
// number of poses and regions, with the same labels.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_check.hpp"

#include <intervox/view/view_scene_json.hpp>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  intervox::ViewScene scene;
  try {
    scene = intervox::view_scene_from_json(text, "<fuzz>");
  } catch (const intervox::Error&) {
    return 0;
  }
  const intervox::ViewScene again = intervox::view_scene_from_json(intervox::view_scene_to_json(scene), "<again>");
  if (again.trajectory.size() != scene.trajectory.size() || again.scans.size() != scene.scans.size() ||
      again.regions.size() != scene.regions.size())
    fuzz_check_failed("the written scene reads back with other counts");
  for (std::size_t i = 0; i < scene.regions.size(); ++i) {
    if (again.regions[i].label != scene.regions[i].label) fuzz_check_failed("a region label changed on the way back");
  }
  return 0;
}
