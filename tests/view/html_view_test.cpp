#include <catch2/catch.hpp>

#include <cstdlib>
#include <set>
#include <string>
#include <tuple>

#include <intervox/grid/named_grids.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/view/html_view.hpp>
#include <intervox/view/view_scene_json.hpp>

using namespace intervox;

namespace {

std::string b64(const std::string& s) {
  std::string out;
  detail::append_base64(out, s.data(), s.size());
  return out;
}

using K = std::tuple<int, int, int>;

/// The keys of the packed voxels (level 0) as grid keys.
std::set<K> packed_keys(const BayesGrid& grid, const ViewVoxels& v) {
  std::set<K> out;
  for (std::size_t i = 0; i < v.offsets.size(); i += 3) {
    const Key k = grid.key(v.base + Point3(v.offsets[i], v.offsets[i + 1], v.offsets[i + 2]) * v.size);
    out.insert({k.x, k.y, k.z});
  }
  return out;
}

void hit(BayesGrid& g, const Key& k, int n = 3) {
  for (int i = 0; i < n; ++i) g.update(k, Observation::Hit);
}
void miss(BayesGrid& g, const Key& k) {
  for (int i = 0; i < 3; ++i) g.update(k, Observation::Miss);
}

}  // namespace

TEST_CASE("base64 gives the RFC 4648 test vectors", "[view][base64]") {
  CHECK(b64("").empty());
  CHECK(b64("f") == "Zg==");
  CHECK(b64("fo") == "Zm8=");
  CHECK(b64("foo") == "Zm9v");
  CHECK(b64("foob") == "Zm9vYg==");
  CHECK(b64("fooba") == "Zm9vYmE=");
  CHECK(b64("foobar") == "Zm9vYmFy");
}

TEST_CASE("packed voxels are the selected voxels at their centres, by class, with their colours", "[view][pack]") {
  BayesGrid grid(0.1);
  hit(grid, Key{-3, 2, 7});
  hit(grid, Key{5, -4, 0});
  miss(grid, Key{0, 0, 0});
  grid.update(Key{1, 1, 1}, Observation::Hit);
  grid.update(Key{1, 1, 1}, Observation::Miss);  // back to 0.5: unknown
  HtmlViewOptions o;
  o.voxels = HtmlViewOptions::Voxels::Observed;
  const ViewVoxels v = pack_view_voxels(grid, o);
  REQUIRE(v.size_drawn() == 4);
  CHECK(v.selected == 4);
  CHECK(v.size == Approx(0.1));
  CHECK(v.level == 0);
  CHECK_FALSE(v.surface_only);
  CHECK(v.per_class == std::array<std::size_t, 3>{2, 1, 1});
  CHECK(packed_keys(grid, v) == std::set<K>{{-3, 2, 7}, {5, -4, 0}, {0, 0, 0}, {1, 1, 1}});
  // Stored by class: occupied (black), unknown (gray), free (white).
  CHECK(v.rgb[0] < 30);
  CHECK(v.rgb[3] < 30);
  CHECK(v.rgb[6] == 128);
  CHECK(v.rgb[9] > 225);
  o.voxels = HtmlViewOptions::Voxels::Occupied;
  CHECK(pack_view_voxels(grid, o).size_drawn() == 2);
  o.voxels = HtmlViewOptions::Voxels::NotFree;
  CHECK(pack_view_voxels(grid, o).size_drawn() == 3);
  o.max_voxels = 0;
  CHECK_THROWS_AS(pack_view_voxels(grid, o), InvalidArgument);
}

TEST_CASE("beyond max_voxels only surface voxels stay: a solid cube keeps its shell", "[view][pack]") {
  BayesGrid grid(0.05);
  const int n = 6;
  for (int x = 0; x < n; ++x)
    for (int y = 0; y < n; ++y)
      for (int z = 0; z < n; ++z) hit(grid, Key{x, y, z});
  HtmlViewOptions o;
  o.max_voxels = n * n * n;  // fits: everything
  CHECK(pack_view_voxels(grid, o).size_drawn() == n * n * n);
  o.max_voxels = n * n * n - 1;
  const ViewVoxels v = pack_view_voxels(grid, o);
  CHECK(v.surface_only);
  CHECK(v.level == 0);
  // Brute force: the shell of the cube.
  std::set<K> shell;
  for (int x = 0; x < n; ++x)
    for (int y = 0; y < n; ++y)
      for (int z = 0; z < n; ++z)
        if (x == 0 || y == 0 || z == 0 || x == n - 1 || y == n - 1 || z == n - 1) shell.insert({x, y, z});
  CHECK(v.size_drawn() == shell.size());
  CHECK(packed_keys(grid, v) == shell);
}

TEST_CASE("beyond max_voxels after the surface rule voxels merge 2x2x2 until they fit", "[view][pack]") {
  BayesGrid grid(0.1);
  for (int x = -8; x < 8; ++x)
    for (int y = -8; y < 8; ++y) hit(grid, Key{x, y, 0});  // a 16 x 16 plate: all surface
  HtmlViewOptions o;
  o.max_voxels = 100;  // 256 -> 64 at level 1 (8 x 8 coarse voxels)
  const ViewVoxels v = pack_view_voxels(grid, o);
  CHECK(v.surface_only);
  CHECK(v.level == 1);
  CHECK(v.size == Approx(0.2));
  REQUIRE(v.size_drawn() == 64);
  // The coarse voxels' centres: x, y in -0.7 .. 0.7 step 0.2, z at the centre of fine layers 0 and 1.
  std::set<std::pair<int, int>> xy;
  for (std::size_t i = 0; i < v.offsets.size(); i += 3) {
    const Point3 c = v.base + Point3(v.offsets[i], v.offsets[i + 1], v.offsets[i + 2]) * v.size;
    CHECK(c.z() == Approx(0.1));
    xy.insert({static_cast<int>(std::lround(c.x() * 10)), static_cast<int>(std::lround(c.y() * 10))});
  }
  CHECK(xy.size() == 64);
  CHECK(xy.begin()->first == -7);
  CHECK(xy.rbegin()->first == 7);
  o.max_voxels = 1;
  const ViewVoxels one = pack_view_voxels(grid, o);
  CHECK(one.size_drawn() == 1);
  CHECK(one.level == 4);
}

TEST_CASE("a map wider than 65536 voxels is merged until its offsets fit 16 bits", "[view][pack]") {
  BayesGrid grid(0.01);
  hit(grid, Key{-40000, 0, 0});
  hit(grid, Key{40000, 0, 0});
  const ViewVoxels v = pack_view_voxels(grid);
  CHECK(v.level == 1);
  REQUIRE(v.size_drawn() == 2);
  CHECK(v.offsets[3] - v.offsets[0] == 40000);
}

TEST_CASE("the page inlines the scripts, packs the data and reports its status", "[view][page]") {
  BayesGrid grid(0.1);
  hit(grid, Key{1, 2, 3});
  ViewScene scene;
  scene.trajectory = {Pose::Identity(), Pose(Eigen::Translation3d(1, 0, 0))};
  scene.scans = {Pose::Identity()};
  scene.rig = SensorRig::mobile_base();
  scene.regions = {{{Point3(0, 0, 0), Point3(1, 1, 1)}, "a <b> & c"}};
  HtmlViewOptions o;
  o.title = "T<1>";
  o.color = ColorBy::Table52;
  const std::string page = html_view_to_string(grid, o, scene, "var THREE_FAKE=1;</script>", "var ORBIT_FAKE=1;");
  CHECK(page.find("var THREE_FAKE=1;<\\/script>") != std::string::npos);  // cannot close the script early
  CHECK(page.find("var ORBIT_FAKE=1;") != std::string::npos);
  CHECK(page.find("<div id=\"status\">loading</div>") != std::string::npos);
  CHECK(page.find("<title>T&lt;1&gt;</title>") != std::string::npos);
  CHECK(page.find("a &lt;b&gt; &amp; c") != std::string::npos);
  CHECK(page.find("Table 5.2") != std::string::npos);
  CHECK(page.find("views (1)") != std::string::npos);
  CHECK(page.find("regions (1)") != std::string::npos);
  CHECK(page.find("id=\"c0\" checked> occupied (1)") != std::string::npos);
  CHECK(page.find("id=\"c1\" checked> unknown (0)") != std::string::npos);
  CHECK(page.find("id=\"c2\"> free (0)") != std::string::npos);
  o.shown = {false, true, true};
  const std::string hidden = html_view_to_string(grid, o, scene, "", "");
  CHECK(hidden.find("id=\"c0\"> occupied (1)") != std::string::npos);
  CHECK(hidden.find("id=\"c2\" checked> free (0)") != std::string::npos);
  // The one voxel: offsets (0, 0, 0) as 6 zero bytes, colour black.
  CHECK(page.find("offsets:\"AAAAAAAA\"") != std::string::npos);
  const Rgb c = cell_color(grid, grid.cell(Key{1, 2, 3}), ColorBy::Table52);
  std::string rgb;
  detail::append_base64(rgb, &c, 3);
  CHECK(page.find("rgb:\"" + rgb + "\"") != std::string::npos);
  // Frustums of the eight cameras: 8 segments each, 2 points of 3 floats.
  ViewScene views;
  views.scans = {Pose::Identity()};
  views.rig = SensorRig::mobile_base();
  std::vector<float> lines;
  detail::append_view_lines(lines, *views.rig, Pose::Identity(), 0.5);
  CHECK(lines.size() == views.rig->size() * 8 * 6);
}

TEST_CASE("write_html_view reads three.js from the configured folder and says how to get it", "[view][page]") {
  BayesGrid grid(0.1);
  HtmlViewOptions o;
  o.three_dir = "no/such/three";
  try {
    write_html_view("view_test_missing.html", grid, o);
    FAIL("expected IoError");
  } catch (const IoError& e) {
    CHECK(std::string(e.what()).find("no/such/three/build/three.min.js") != std::string::npos);
    CHECK(std::string(e.what()).find("libjs-three") != std::string::npos);
  }
  CHECK(three_js_dir("x") == "x");
}

TEST_CASE("run files round-trip and bad ones are refused naming the member", "[view][json]") {
  ViewScene s;
  Pose p = Pose::Identity();
  p.translation() = Point3(1, 2, 3);
  p.linear() = Eigen::AngleAxisd(0.7, Point3::UnitZ()).toRotationMatrix();
  s.trajectory = {Pose::Identity(), p};
  s.scans = {p};
  s.view_range = 0.8;
  s.regions = {{{Point3(0, 0, 0), Point3(1, 2, 3)}, "conflict"}};
  const ViewScene r = view_scene_from_json(view_scene_to_json(s, "arm"), "run.json");
  REQUIRE(r.trajectory.size() == 2);
  CHECK(r.trajectory[1].isApprox(p, 1e-9));
  REQUIRE(r.scans.size() == 1);
  CHECK(r.rig.has_value());
  CHECK(r.rig->size() == SensorRig::arm().size());
  CHECK(r.view_range == 0.8);
  REQUIRE(r.regions.size() == 1);
  CHECK(r.regions[0].box.max.isApprox(Point3(1, 2, 3)));
  CHECK(r.regions[0].label == "conflict");
  CHECK(
      view_scene_from_json("{\"trajectory\": [[1, 2, 3]]}", "x").trajectory[0].translation().isApprox(Point3(1, 2, 3)));
  CHECK_THROWS_AS(view_scene_to_json(s, "tripod"), InvalidArgument);
  auto message = [](const std::string& text) {
    try {
      view_scene_from_json(text, "run.json");
    } catch (const IoError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  CHECK_THAT(message("{"), Catch::Contains("run.json: not valid JSON"));
  CHECK_THAT(message("[]"), Catch::Contains("expected a JSON object"));
  CHECK_THAT(message("{\"trajectory\": [[1, 2]]}"), Catch::Contains("trajectory[0]"));
  CHECK_THAT(message("{\"scans\": [{\"position\": [0, 0, 0], \"quaternion\": [0, 0, 0, 0]}]}"),
             Catch::Contains("zero quaternion"));
  CHECK_THAT(message("{\"rig\": \"tripod\"}"), Catch::Contains("rig"));
  CHECK_THAT(message("{\"view_range\": -1}"), Catch::Contains("view_range"));
  CHECK_THAT(message("{\"regions\": [{\"min\": [1, 1, 1], \"max\": [0, 0, 0]}]}"),
             Catch::Contains("min must not exceed max"));
  CHECK_THAT(message("{\"regions\": [{\"min\": [0, 0, 0], \"max\": [1, 1, \"a\"]}]}"),
             Catch::Contains("regions[0].max"));
  CHECK_THROWS_AS(read_view_scene("no_such_run.json"), IoError);
}

TEST_CASE("an inlined script cannot end its script element in any letter case or open a comment", "[view][escape]") {
  const std::string js = "a='</script>';b='</SCRIPT >';c='</ScRiPt';d='<!--';e='</scrip';f='<\\/script';";
  const std::string out = intervox::detail::inline_script(js);
  std::string lower = out;
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  CHECK(lower.find("</script") == std::string::npos);
  CHECK(out.find("<!--") == std::string::npos);
  CHECK(out == "a='<\\/script>';b='<\\/SCRIPT >';c='<\\/ScRiPt';d='<\\!--';e='</scrip';f='<\\/script';");
}
