#include <catch2/catch.hpp>

#include <string>

#include <intervox/grid/named_grids.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/view/bitmap_font.hpp>
#include <intervox/view/image_annotation.hpp>
#include <intervox/view/slice.hpp>

using namespace intervox;

namespace {
Rgb px(const RgbImage& im, int x, int y) {
  const auto i = (static_cast<std::size_t>(y) * static_cast<std::size_t>(im.width) + static_cast<std::size_t>(x)) * 3;
  return {im.rgb[i], im.rgb[i + 1], im.rgb[i + 2]};
}
int ink(const RgbImage& im) {
  int n = 0;
  for (std::size_t i = 0; i < im.rgb.size(); i += 3) n += im.rgb[i] == 0 && im.rgb[i + 1] == 0 && im.rgb[i + 2] == 0;
  return n;
}
int hashes(char c) {
  int n = 0;
  for (const char* row : detail::glyph(c).rows)
    for (int i = 0; i < 5; ++i) n += row[i] == '#';
  return n;
}
/// Position of \p inner inside \p outer (first exact match), or (-1, -1).
std::pair<int, int> find(const RgbImage& outer, const RgbImage& inner) {
  for (int y = 0; y + inner.height <= outer.height; ++y)
    for (int x = 0; x + inner.width <= outer.width; ++x) {
      bool same = true;
      for (int j = 0; j < inner.height && same; ++j)
        for (int i = 0; i < inner.width && same; ++i) same = px(outer, x + i, y + j) == px(inner, i, j);
      if (same) return {x, y};
    }
  return {-1, -1};
}
}  // namespace

TEST_CASE("the font draws each glyph's pixels, scaled, upper case for lower case, '?' for the unknown", "[io][font]") {
  for (const char c : std::string("0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZ.,:;-+/()[]%=<>_'\"!?#*|~^@&")) {
    RgbImage im = RgbImage::filled(20, 20, 255, 255, 255);
    draw_text(im, 1, 1, std::string(1, c), {0, 0, 0});
    INFO(c);
    CHECK(ink(im) == hashes(c));
    CHECK(ink(im) > 0);
    RgbImage big = RgbImage::filled(20, 20, 255, 255, 255);
    draw_text(big, 1, 1, std::string(1, c), {0, 0, 0}, 2);
    CHECK(ink(big) == 4 * hashes(c));
  }
  RgbImage lower = RgbImage::filled(40, 10, 255, 255, 255), upper = lower, unknown = lower, question = lower;
  draw_text(lower, 0, 0, "abc", {0, 0, 0});
  draw_text(upper, 0, 0, "ABC", {0, 0, 0});
  draw_text(unknown, 0, 0, "\x01", {0, 0, 0});
  draw_text(question, 0, 0, "?", {0, 0, 0});
  CHECK(lower.rgb == upper.rgb);
  CHECK(unknown.rgb == question.rgb);
  CHECK(text_width("") == 0);
  CHECK(text_width("ab") == 11);
  CHECK(text_width("ab", 3) == 33);
  RgbImage edge = RgbImage::filled(4, 4, 255, 255, 255);
  draw_text(edge, -3, -3, "#", {0, 0, 0});  // clipped, no crash
  CHECK(ink(edge) > 0);
}

TEST_CASE("annotate_image keeps the picture's pixels and adds title, legend and a scale bar of a nice length",
          "[io][annotation]") {
  RgbImage pic = RgbImage::filled(500, 60, 0, 150, 150);
  pic.set(0, 0, 255, 0, 0);
  pic.set(499, 59, 0, 255, 0);
  CHECK(annotate_image(pic, {}).rgb == pic.rgb);  // nothing asked: unchanged
  const Legend legend = legend_for(ColorBy::Table52);
  const RgbImage out = annotate_image(pic, {"title", true, true, 1}, &legend, 0.01);  // 5 m wide picture
  const auto [x0, y0] = find(out, pic);
  REQUIRE(x0 >= 0);
  CHECK(y0 > kGlyphLineHeight);                                // below the title
  CHECK(out.height > y0 + pic.height + 6 * kGlyphLineHeight);  // six swatches below
  // The scale bar: 40 % of 5 m is 2 m -> a 2 m bar of 200 pixels: the longest black run in a row.
  int longest = 0;
  for (int y = y0 + pic.height; y < out.height; ++y) {
    int run = 0;
    for (int x = 0; x < out.width; ++x) {
      run = px(out, x, y) == Rgb{0, 0, 0} ? run + 1 : 0;
      longest = std::max(longest, run);
    }
  }
  CHECK(longest == 200);
  CHECK(detail::nice_length(2.0) == 2.0);
  CHECK(detail::nice_length(0.37) == Approx(0.2));
  CHECK(detail::nice_length(9.9) == 5.0);
  CHECK(detail::nice_length(1.0) == 1.0);
  CHECK(detail::metres_text(0.2) == "20 cm");
  CHECK(detail::metres_text(2) == "2 m");
  CHECK(detail::metres_text(0.005) == "5 mm");
  CHECK_THROWS_AS(annotate_image(pic, {"", false, true, 0}), InvalidArgument);
  CHECK_THROWS_AS(annotate_image(pic, {"t", false, false, 9}), InvalidArgument);
}

TEST_CASE("a slice with labels is the plain slice framed, with the colour code's legend", "[io][annotation][slice]") {
  BayesGrid grid(0.05);
  for (int i = 0; i < 5; ++i) grid.update(Key{0, 0, 0}, Observation::Hit);
  grid.update(Key{9, 4, 0}, Observation::Miss);
  SliceOptions o;
  o.pixels_per_voxel = 8;
  const RgbImage plain = render_slice(grid, o);
  o.labels = {"slice z = 0", true, true, 0};
  const RgbImage labelled = render_slice(grid, o);
  CHECK(labelled.width >= plain.width);
  CHECK(labelled.height > plain.height);
  CHECK(find(labelled, plain).first >= 0);
  // The gradient legend of the state code runs from white to black.
  o.labels = {"", true, false, 0};
  const RgbImage legend_only = render_slice(grid, o);
  CHECK(legend_only.height > plain.height + 2 * kGlyphLineHeight);
}
