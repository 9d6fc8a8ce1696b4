// The 3D viewer page of a saved map: `view MAP_FILE --out map.html`, optionally with the robot's
// trajectory, views and highlighted regions from a run file (docs/viewing.md). Open the page in
// any browser; it needs no network.
#include <intervox/intervox.hpp>
#include <intervox/io/explained_file.hpp>
#include <intervox/io/grid_file.hpp>
#include <intervox/view/explained_page_options.hpp>
#include <intervox/view/html_view.hpp>
#include <intervox/view/view_scene_json.hpp>

#include "common/cli.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace iv = intervox;

namespace {

struct Options {
  std::string map;
  std::string out = "map.html";
  std::string color = "state";
  std::string voxels = "not-free";
  std::string trajectory;
  std::string explained;  ///< explained evidence (.ivxe) of the map: colour by explained state
  std::vector<std::string> show{"occupied", "unknown"};
  std::string title;
  std::size_t max_voxels = iv::HtmlViewOptions{}.max_voxels;
  double max_load_mib = 256;
};

template <class Grid>
int run(const Options& o) {
  iv::GridLoadOptions load;
  load.max_bytes = static_cast<std::uint64_t>(o.max_load_mib * 1024.0 * 1024.0);
  const Grid grid = iv::load_grid<Grid>(o.map, load);
  iv::HtmlViewOptions h;
  const std::map<std::string, iv::ColorBy> colors{{"state", iv::ColorBy::State},
                                                  {"width", iv::ColorBy::IntervalWidth},
                                                  {"table52", iv::ColorBy::Table52},
                                                  {"utility", iv::ColorBy::Utility}};
  const std::map<std::string, iv::HtmlViewOptions::Voxels> voxels{{"occupied", iv::HtmlViewOptions::Voxels::Occupied},
                                                                  {"not-free", iv::HtmlViewOptions::Voxels::NotFree},
                                                                  {"observed", iv::HtmlViewOptions::Voxels::Observed}};
  h.color = colors.at(o.color);
  h.voxels = voxels.at(o.voxels);
  h.max_voxels = o.max_voxels;
  const std::array<const char*, 3> classes{"occupied", "unknown", "free"};
  for (std::size_t k = 0; k < 3; ++k) h.shown[k] = std::find(o.show.begin(), o.show.end(), classes[k]) != o.show.end();
  h.title = o.title.empty() ? o.map : o.title;
  std::optional<iv::ExplainedSpace> explained;
  if (!o.explained.empty()) {
    explained.emplace(iv::load_explained(o.explained, load));
    h = iv::explained_view_options(grid, *explained, h);  // observed voxels, every class shown
  }
  const iv::ViewScene scene = o.trajectory.empty() ? iv::ViewScene{} : iv::read_view_scene(o.trajectory);
  const iv::HtmlViewSummary v = iv::write_html_view(o.out, grid, h, scene);
  std::printf("wrote %s (%zu bytes): %zu of %zu voxels%s (%s%s), %zu trajectory poses, %zu views, %zu regions\n",
              o.out.c_str(), v.bytes, v.drawn, v.selected, v.surface_only ? ", surface only" : "",
              std::string(Grid::UpdateType::kName).c_str(), explained ? ", coloured by explained state" : "",
              scene.trajectory.size(), scene.scans.size(), scene.regions.size());
  return 0;
}

template <class U>
void add(std::map<std::string, std::function<int(const Options&)>>& table) {
  const std::string name(U::kName);
  table[name + "/entropy"] = run<iv::VoxelGrid<U, iv::Entropy>>;
  table[name + "/max-entropy"] = run<iv::VoxelGrid<U, iv::MaxEntropy>>;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{"Intervox: writes a self-contained 3D viewer page (HTML with three.js inlined) of a map file.\n"
               "Open the page in a browser: drag to turn, wheel to zoom, right-drag to pan."};
  app.add_option("map", o.map, "map file written by save_grid (.ivx)")->required();
  app.add_option("--out", o.out, "the page to write")->capture_default_str();
  app.add_option("--color", o.color,
                 "colour code: state (gray), width (interval width, blue to red), table52 "
                 "(thesis Table 5.2), utility")
      ->check(CLI::IsMember({"state", "width", "table52", "utility"}))
      ->capture_default_str();
  app.add_option("--voxels", o.voxels, "voxels in the page (free ones start hidden)")
      ->check(CLI::IsMember({"occupied", "not-free", "observed"}))
      ->capture_default_str();
  app.add_option("--show", o.show, "classes shown when the page opens (the others behind their switches)")
      ->check(CLI::IsMember({"occupied", "unknown", "free"}))
      ->delimiter(',')
      ->capture_default_str();
  app.add_option("--trajectory", o.trajectory, "run file (JSON) with trajectory, views and regions to draw");
  app.add_option("--explained", o.explained,
                 "explained evidence of the map (.ivxe: save_explained, intervox_bag --explained): colour every "
                 "observed voxel by its explained state, and show as free only what lying beams alone made free "
                 "(replaces --color, --voxels and --show)");
  app.add_option("--title", o.title, "title of the page (default: the map file's name)");
  app.add_option("--max-voxels", o.max_voxels, "beyond this many voxels: surface only, then coarser voxels")
      ->check(examples::integer_in<std::size_t>(1))
      ->capture_default_str();
  app.add_option("--max-load-mib", o.max_load_mib, "load budget of the map in MiB (see docs/io.md)")
      ->check(examples::number_in(1, 1 << 20))
      ->capture_default_str();
  return examples::cli_main("view", app, argc, argv, [&] {
    const iv::GridFileInfo info = iv::read_grid_file_info(o.map);
    std::map<std::string, std::function<int(const Options&)>> table;
    add<iv::BayesLogOdds>(table);
    add<iv::IntervalUpdate<iv::LowerState>>(table);
    add<iv::IntervalUpdate<iv::MeanState>>(table);
    add<iv::IntervalUpdate<iv::UpperState>>(table);
    add<iv::CompactIntervalUpdate<iv::LowerState>>(table);
    add<iv::CompactIntervalUpdate<iv::MeanState>>(table);
    add<iv::CompactIntervalUpdate<iv::UpperState>>(table);
    const std::string utility = info.utility == "entropy" ? "entropy" : "max-entropy";
    const auto it = table.find(info.update_policy + "/" + utility);
    if (it == table.end())
      throw iv::IoError(o.map + ": update policy '" + iv::detail::quote_bytes(info.update_policy, 64) +
                        "' is not supported by view");
    return it->second(o);
  });
}
