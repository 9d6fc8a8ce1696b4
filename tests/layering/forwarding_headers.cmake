# The forwarding headers of issue 73: each header moved or renamed left at its old path a header
# that only includes the new one, for one release. They go in the next release, and this list
# with them. One entry per header, "old>new", both under include/intervox/.
# Used by tests/CMakeLists.txt (the layering rules do not check them) and by
# check_forwarding.cmake (nothing in the tree includes them; each includes its new header only).
set(INTERVOX_FORWARDING_HEADERS
  "io/bitmap_font.hpp>view/bitmap_font.hpp"
  "io/explained_image.hpp>view/explained_image.hpp"
  "io/explained_view.hpp>view/explained_page_options.hpp"
  "io/exploration_image.hpp>view/exploration_image.hpp"
  "io/html_view.hpp>view/html_view.hpp"
  "io/image_annotation.hpp>view/image_annotation.hpp"
  "io/slice.hpp>view/slice.hpp"
  "io/view_scene_json.hpp>view/view_scene_json.hpp"
  "io/ply.hpp>io/ply_writer.hpp"
  "utility/utility.hpp>utility/utility_policies.hpp"
  "eval/conflicts.hpp>eval/conflict_scoring.hpp"
  "sim/sensors.hpp>sim/sensor_aliases.hpp"
  "sim/random.hpp>sim/beam_rng.hpp"
)
