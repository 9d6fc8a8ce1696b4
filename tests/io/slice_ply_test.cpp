#include <catch2/catch.hpp>

#include <cstring>
#include <sstream>
#include <string>

#include "grid_types.hpp"
#include <intervox/grid/named_grids.hpp>
#include <intervox/io/io.hpp>
#include <intervox/view/view.hpp>
#include <intervox/io/png.hpp>
#include "io_test_util.hpp"

using namespace intervox;

namespace {
Rgb pixel(const RgbImage& im, int x, int y) {
  const auto i = (static_cast<std::size_t>(y) * static_cast<std::size_t>(im.width) + static_cast<std::size_t>(x)) * 3;
  return {im.rgb[i], im.rgb[i + 1], im.rgb[i + 2]};
}
bool dark(const Rgb& c) { return c.r < 10 && c.g < 10 && c.b < 10 && c.r == c.g && c.g == c.b; }
bool light(const Rgb& c) { return c.r > 245 && c.r == c.g && c.g == c.b; }
}  // namespace

TEST_CASE("Table 5.2 colours follow the thesis' thresholds", "[io][color]") {
  CHECK(table52_color(0.5, 0.9) == Rgb{255, 0, 0});        // broad: red whatever the state
  CHECK(table52_color(0.5, 0.3) == Rgb{0, 0, 255});        // narrow, 75 < state < 180: blue
  CHECK(table52_color(0.99, 0.01) == Rgb{0, 0, 0});        // occupied: black
  CHECK(table52_color(0.01, 0.01) == Rgb{255, 255, 255});  // free: white
  CHECK(table52_color(0.2, 0.1) == Rgb{128, 128, 128});    // width <= 50 of 255, other state: gray
  CHECK(table52_color(0.2, 0.4) == Rgb{255, 255, 0});      // 50 < width <= 127: yellow
  CHECK(voxel_color(ColorBy::IntervalWidth, 0.5, 0.0, 0) == Rgb{0, 0, 255});
  CHECK(voxel_color(ColorBy::IntervalWidth, 0.5, 1.0, 0) == Rgb{255, 0, 0});
  CHECK(voxel_color(ColorBy::State, 1.0, 0, 0) == Rgb{0, 0, 0});
  CHECK(voxel_color(ColorBy::State, 0.0, 0, 0) == Rgb{255, 255, 255});
}

TEMPLATE_TEST_CASE("a slice image shows occupied, free and unobserved voxels where they are", "[io][slice]",
                   INTERVOX_TEST_GRIDS) {
  using G = TestType;
  G grid = make_test_grid<G>();
  // 200 observations: enough for the count policies, whose bounds approach 0 and 1 as 1/N.
  for (int i = 0; i < 200; ++i) {
    grid.update(Key{-10, -10, 0}, Observation::Hit);  // bottom-left corner of the window
    grid.update(Key{9, 9, 0}, Observation::Miss);     // top-right
    grid.update(Key{0, 0, 3}, Observation::Hit);      // another layer
  }
  SliceOptions options;
  options.window = KeyBox{Key{-10, -10, -10}, Key{9, 9, 9}};
  options.pixels_per_voxel = 2;
  const RgbImage image = render_slice(grid, options);
  REQUIRE(image.width == 40);
  REQUIRE(image.height == 40);
  CHECK(dark(pixel(image, 0, 39)));  // occupied: black
  CHECK(dark(pixel(image, 1, 38)));
  CHECK(light(pixel(image, 39, 0)));                // free: white
  CHECK(pixel(image, 20, 19) == kUnobservedColor);  // (0, 0) is only observed in layer 3
  options.mode = SliceMode::MaxProjection;
  CHECK(dark(pixel(render_slice(grid, options), 20, 19)));
  options.mode = SliceMode::Slice;
  options.color = ColorBy::IntervalWidth;
  const Rgb w = pixel(render_slice(grid, options), 0, 39);
  CHECK(w.b > w.r);  // narrow after many hits (degenerate for Bayes): blue
}

TEST_CASE("a slice renders to a PNG file", "[io][slice][png]") {
  const TempDir dir;
  IntervalGrid grid(0.1);
  fill_randomly(grid, 400, 8);
  SliceOptions options;
  options.color = ColorBy::Table52;
  options.mode = SliceMode::MeanProjection;
  const RgbImage image = render_slice(grid, options);
  write_png(dir.file("slice.png"), image);
  CHECK(read_png(dir.file("slice.png")).rgb == image.rgb);
  CHECK_THROWS_AS(render_slice(IntervalGrid(0.1)), InvalidArgument);
  options.pixels_per_voxel = 0;
  CHECK_THROWS_AS(render_slice(grid, options), InvalidArgument);
}

TEMPLATE_TEST_CASE("a PLY export holds one coloured point per selected voxel", "[io][ply]", INTERVOX_TEST_GRIDS) {
  using G = TestType;
  G grid = make_test_grid<G>();
  fill_randomly(grid, 500, 12);
  PlyExportOptions options;
  options.binary = GENERATE(true, false);
  options.voxels = GENERATE(PlyExportOptions::Voxels::Occupied, PlyExportOptions::Voxels::Observed);
  const PointCloud cloud = read_ply_points_from_memory(write_ply_to_memory(grid, options));
  const std::size_t expected =
      options.voxels == PlyExportOptions::Voxels::Occupied ? grid.counts().occupied : grid.observed_count();
  REQUIRE(cloud.points.size() == expected);
  for (const Point3& p : cloud.points) {
    const Key k = grid.key(p);
    CHECK(grid.is_observed(k));
    CHECK((grid.center(k) - p).norm() < 1e-6);
  }
}

TEMPLATE_TEST_CASE("a PLY export keeps only the voxels its filter accepts", "[io][ply]", INTERVOX_TEST_GRIDS) {
  using G = TestType;
  G grid = make_test_grid<G>();
  fill_randomly(grid, 500, 13);
  PlyExportOptions options;
  options.voxels = PlyExportOptions::Voxels::Observed;
  options.keep = [](const Key& k) { return k.x % 2 == 0; };
  // Brute force: the observed voxels with an even x key.
  std::size_t expected = 0;
  grid.for_each_observed([&](const Key& k, const auto&) { expected += k.x % 2 == 0 ? 1 : 0; });
  REQUIRE(expected > 0);
  REQUIRE(expected < grid.observed_count());
  const PointCloud cloud = read_ply_points_from_memory(write_ply_to_memory(grid, options));
  REQUIRE(cloud.points.size() == expected);
  for (const Point3& p : cloud.points) CHECK(grid.key(p).x % 2 == 0);
}

TEST_CASE("a PLY cube export has eight vertices and six quads per voxel", "[io][ply]") {
  BayesGrid grid(0.2);
  for (int i = 0; i < 10; ++i) {
    grid.update(Key{1, 2, 3}, Observation::Hit);
    grid.update(Key{-1, 0, 0}, Observation::Hit);
  }
  PlyExportOptions options;
  options.geometry = PlyExportOptions::Geometry::Cubes;
  options.binary = false;
  const std::string ply = write_ply_to_memory(grid, options);
  CHECK(ply.find("element vertex 16\n") != std::string::npos);
  CHECK(ply.find("element face 12\n") != std::string::npos);
  const PointCloud corners = read_ply_points_from_memory(ply);
  REQUIRE(corners.points.size() == 16);
  CHECK(corners.points[0].isApprox(Point3(0.2, 0.4, 0.6), 1e-6));
  CHECK(corners.points[7].isApprox(Point3(0.4, 0.6, 0.8), 1e-6));
  options.binary = true;
  const PointCloud binary = read_ply_points_from_memory(write_ply_to_memory(grid, options));
  REQUIRE(binary.points.size() == corners.points.size());
  for (std::size_t i = 0; i < binary.points.size(); ++i) CHECK(binary.points[i].isApprox(corners.points[i], 1e-6));
}

TEMPLATE_TEST_CASE("PLY vertices carry the voxel's probability, interval bounds and class", "[io][ply]",
                   INTERVOX_TEST_GRIDS) {
  using G = TestType;
  G grid = make_test_grid<G>();
  fill_randomly(grid, 300, 21);
  PlyExportOptions options;
  options.voxels = PlyExportOptions::Voxels::Observed;
  options.binary = false;
  const std::string ascii = write_ply_to_memory(grid, options);
  REQUIRE(
      ascii.find("property float probability\nproperty float lower\nproperty float upper\nproperty uchar class\n") !=
      std::string::npos);
  options.binary = true;
  const std::string binary = write_ply_to_memory(grid, options);
  const std::size_t a0 = ascii.find("end_header\n") + 11, b0 = binary.find("end_header\n") + 11;
  REQUIRE(binary.size() - b0 == grid.observed_count() * 28);  // 3 floats, 3 uchar, 3 floats, 1 uchar
  std::istringstream lines(ascii.substr(a0));
  std::size_t n = 0;
  for (std::string line; std::getline(lines, line); ++n) {
    std::istringstream f(line);
    double x, y, z, p, lo, up;
    unsigned r, g, b, cls;
    REQUIRE(static_cast<bool>(f >> x >> y >> z >> r >> g >> b >> p >> lo >> up >> cls));
    const Key k = grid.key(Point3(x, y, z));
    // The oracle: the grid's own answers for the voxel at the vertex.
    CHECK(p == Approx(grid.probability(k)).margin(1e-6));
    CHECK(lo == Approx(grid.interval(k).lower).margin(1e-6));
    CHECK(up == Approx(grid.interval(k).upper).margin(1e-6));
    CHECK(cls == static_cast<unsigned>(grid.occupancy(k)));
    // The binary record holds the same values.
    float bp, blo, bup;
    const char* rec = binary.data() + b0 + n * 28;
    std::memcpy(&bp, rec + 15, 4);
    std::memcpy(&blo, rec + 19, 4);
    std::memcpy(&bup, rec + 23, 4);
    CHECK(bp == static_cast<float>(grid.probability(k)));
    CHECK(blo == static_cast<float>(grid.interval(k).lower));
    CHECK(bup == static_cast<float>(grid.interval(k).upper));
    CHECK(static_cast<unsigned>(rec[27]) == cls);
  }
  CHECK(n == grid.observed_count());
  options.voxel_properties = false;
  CHECK(write_ply_to_memory(grid, options).find("probability") == std::string::npos);
}

TEST_CASE("a slice window whose pixel count overflows 64 bits is refused, never wrapped", "[io][slice][errors]") {
  // 2^32 x 2^32 keys at 64 pixels per voxel: 2^76 pixels, which a 64-bit product wraps to 0.
  BayesGrid grid(0.1);
  grid.update(Key{0, 0, 0}, Observation::Hit);
  SliceOptions options;
  options.window = KeyBox{Key{INT32_MIN, INT32_MIN, 0}, Key{INT32_MAX, INT32_MAX, 0}};
  options.pixels_per_voxel = 64;
  CHECK_THROWS_WITH(render_slice(grid, options), Catch::Contains("2^28 pixels"));
}
