// The viewer page in a real browser (CTest view.browser): writes the page of a small map and of an
// empty map, renders each with headless Chromium (screenshot + dumped DOM) and checks that
//  - the page reported success in its status element ("ok N voxels", no script error),
//  - the map's page has blue voxel pixels (interval width 0 of a Bayes grid: pure blue, shaded)
//    in the middle of the window, where the camera looks at the voxels' centre, and
//  - the empty map's page has none there (so the pixels come from the voxels).
// Usage: intervox_view_browser_check CHROMIUM_PROGRAM [SCREENSHOT_COPY.png]
// Exit codes: 0 pass, 1 fail, 77 skip (no Chromium: the program argument is empty or not found).
#include <intervox/grid/named_grids.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/io/png.hpp>
#include <intervox/view/html_view.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <string>

namespace iv = intervox;
namespace fs = std::filesystem;

namespace {

constexpr int kWidth = 800, kHeight = 600;

struct Rendered {
  std::string status;
  iv::RgbImage image;
};

Rendered render(const std::string& chromium, const std::string& page) {
  const std::string shot = page + ".png", dom = page + ".dom.html", log = page + ".log";
  fs::remove(shot);
  const std::string cmd = "'" + chromium +
                          "' --headless=new --no-sandbox --disable-gpu --use-angle=swiftshader "
                          "--enable-unsafe-swiftshader --hide-scrollbars --no-first-run --disable-extensions "
                          "--user-data-dir='" +
                          page + ".profile' --window-size=" + std::to_string(kWidth) + "," + std::to_string(kHeight) +
                          " --screenshot='" + shot + "' --dump-dom 'file://" + fs::absolute(page).string() + "' > '" +
                          dom + "' 2> '" + log + "'";
  const int rc = std::system(cmd.c_str());
  if (rc != 0) throw iv::IoError("chromium failed (" + std::to_string(rc) + "), see " + log);
  std::ifstream in(dom);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::smatch m;
  Rendered r;
  if (std::regex_search(text, m, std::regex("<div id=\"status\">([^<]*)</div>"))) r.status = m[1];
  r.image = iv::read_png(shot);
  return r;
}

/// Pixels in the middle of the window (right of the panel) that are voxel blue.
int blue_pixels(const iv::RgbImage& im) {
  int n = 0;
  for (int y = kHeight / 2 - 80; y < kHeight / 2 + 80; ++y)
    for (int x = kWidth / 2 + 20; x < kWidth / 2 + 180; ++x) {
      const std::size_t i =
          (static_cast<std::size_t>(y) * static_cast<std::size_t>(im.width) + static_cast<std::size_t>(x)) * 3;
      if (x < im.width && y < im.height && im.rgb[i + 2] > 100 && im.rgb[i] < 40 && im.rgb[i + 1] < 40) ++n;
    }
  return n;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string chromium = argc > 1 ? argv[1] : "";
  if (chromium.empty() || !fs::exists(chromium)) {
    std::printf("SKIPPED: Chromium not found (Debian package 'chromium'; scripts/setup.sh installs it)\n");
    return 77;
  }
  try {
    // A 1.6 m cube of voxels around the origin: the camera looks at its centre.
    iv::BayesGrid grid(0.1);
    for (int x = -8; x < 8; ++x)
      for (int y = -8; y < 8; ++y)
        for (int z = -8; z < 8; ++z)
          for (int i = 0; i < 3; ++i) grid.update(iv::Key{x, y, z}, iv::Observation::Hit);
    iv::HtmlViewOptions options;
    options.color = iv::ColorBy::IntervalWidth;
    options.title = "browser check";
    iv::write_html_view("view_browser_map.html", grid, options);
    iv::write_html_view("view_browser_empty.html", iv::BayesGrid(0.1), options);

    const Rendered map = render(chromium, "view_browser_map.html");
    const Rendered empty = render(chromium, "view_browser_empty.html");
    const int blue = blue_pixels(map.image), blue_empty = blue_pixels(empty.image);
    std::printf("map page: status '%s', %d blue pixels of %d in the middle\n", map.status.c_str(), blue, 160 * 160);
    std::printf("empty page: status '%s', %d blue pixels\n", empty.status.c_str(), blue_empty);
    if (argc > 2) fs::copy_file("view_browser_map.html.png", argv[2], fs::copy_options::overwrite_existing);
    bool ok = true;
    auto expect = [&](bool c, const char* what) {
      if (!c) std::printf("FAILED: %s\n", what);
      ok = ok && c;
    };
    expect(map.status == "ok 4096 voxels", "the map's page reports 'ok 4096 voxels'");
    expect(empty.status == "ok 0 voxels", "the empty page reports 'ok 0 voxels'");
    expect(map.image.width == kWidth && map.image.height == kHeight, "the screenshot has the window's size");
    expect(blue > 160 * 160 / 2, "more than half of the middle is voxel blue");
    expect(blue_empty == 0, "the empty page has no voxel blue");
    std::printf("%s\n", ok ? "PASSED" : "FAILED");
    return ok ? 0 : 1;
  } catch (const std::exception& e) {
    std::printf("FAILED: %s\n", e.what());
    return 1;
  }
}
