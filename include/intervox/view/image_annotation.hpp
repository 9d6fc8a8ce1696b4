#pragma once
/// \file
/// Title, legend and scale bar around a picture (slices, projections, exploration maps), drawn
/// with the one bitmap font (view/bitmap_font.hpp). Needs no library.
/// Thread safety: pure functions.

#include <intervox/core/error.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/io/color.hpp>
#include <intervox/io/rgb_image.hpp>
#include <intervox/view/bitmap_font.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace intervox {

/// A colour code's legend: a gradient between two end texts and/or swatches with a text each.
struct Legend {
  std::string title;
  std::vector<std::pair<Rgb, std::string>> swatches;  ///< drawn below the gradient, one a line
  std::vector<Rgb> gradient;                          ///< colours from left to right (none: no gradient)
  std::string low, high;                              ///< texts under the gradient's ends
};

/// What to draw around a picture. Nothing set: the picture unchanged.
struct ImageLabels {
  std::string title;       ///< above the picture
  bool legend = false;     ///< the colour code's legend below the picture
  bool scale_bar = false;  ///< a scale bar in metres below the picture
  int text_scale = 0;      ///< font pixels per pixel; 0: 1 for pictures narrower than 400 px, else 2
  bool any() const noexcept { return !title.empty() || legend || scale_bar; }
};

/// The legend of a voxel colour code (io/color.hpp).
inline Legend legend_for(ColorBy by) {
  switch (by) {
    case ColorBy::State:
      return {"state", {}, {{255, 255, 255}, {0, 0, 0}}, "0 free", "1 occupied"};
    case ColorBy::IntervalWidth:
      return {"interval width", {}, {{0, 0, 255}, {255, 0, 0}}, "0 narrow", "1 broad"};
    case ColorBy::Utility:
      return {"utility", {}, {{0, 0, 0}, {255, 0, 0}, {255, 255, 0}}, "0", ">= 1"};
    case ColorBy::Table52:
      return {"table 5.2 (state s, width w of 255)",
              {{{255, 0, 0}, "w > 127"},
               {{0, 0, 255}, "75 < s < 180"},
               {{0, 0, 0}, "s > 250"},
               {{255, 255, 255}, "s <= 4"},
               {{128, 128, 128}, "w <= 50"},
               {{255, 255, 0}, "50 < w <= 127"}},
              {},
              {},
              {}};
  }
  return {};
}

namespace detail {

inline void fill_rect(RgbImage& im, int x0, int y0, int w, int h, Rgb c) {
  for (int y = y0; y < y0 + h; ++y)
    for (int x = x0; x < x0 + w; ++x) im.set(x, y, c.r, c.g, c.b);
}

inline Rgb lerp_colours(const std::vector<Rgb>& g, double t) {
  if (g.size() == 1) return g[0];
  const double s = std::clamp(t, 0.0, 1.0) * static_cast<double>(g.size() - 1);
  const auto i = std::min(static_cast<std::size_t>(s), g.size() - 2);
  const double f = s - static_cast<double>(i);
  auto mix = [&](std::uint8_t a, std::uint8_t b) { return static_cast<std::uint8_t>(std::lround(a + (b - a) * f)); };
  return {mix(g[i].r, g[i + 1].r), mix(g[i].g, g[i + 1].g), mix(g[i].b, g[i + 1].b)};
}

/// The longest "nice" length (1, 2 or 5 × 10^k metres) of at most \p max_metres.
inline double nice_length(double max_metres) {
  const double p = std::pow(10.0, std::floor(std::log10(max_metres)));
  for (const double m : {5.0, 2.0, 1.0})
    if (m * p <= max_metres) return m * p;
  return p;
}

inline std::string metres_text(double m) {
  char buf[32];
  if (m >= 1.0)
    std::snprintf(buf, sizeof buf, "%g m", m);
  else if (m >= 0.01)
    std::snprintf(buf, sizeof buf, "%g cm", m * 100.0);
  else
    std::snprintf(buf, sizeof buf, "%g mm", m * 1000.0);
  return buf;
}

}  // namespace detail

/// \p picture with \p labels around it on white: the title above, then below the picture the
/// legend (if labels.legend and \p legend is given) and a scale bar of a nice length (1, 2 or 5 ×
/// 10^k m, at most 40 % of the picture's width) labelled in m, cm or mm. The picture keeps its
/// pixels; it is placed at (margin, title band) with a one-pixel gray frame around it.
/// \param metres_per_pixel the picture's scale (needed for the scale bar)
/// \throws InvalidArgument for a scale bar without a positive, finite metres_per_pixel, a
///         text_scale outside 0..8, or an empty picture.
inline RgbImage annotate_image(const RgbImage& picture, const ImageLabels& labels, const Legend* legend = nullptr,
                               double metres_per_pixel = 0) {
  if (picture.width <= 0 || picture.height <= 0) ParamCheck("intervox::annotate_image").fail("empty picture");
  if (!labels.any()) return picture;
  const ParamCheck check("intervox::annotate_image");
  if (labels.scale_bar) check.positive("metres_per_pixel (for the scale bar)", metres_per_pixel);
  check.in_range("text_scale", labels.text_scale, 0, 8);
  const int ts = labels.text_scale > 0 ? labels.text_scale : (picture.width < 400 ? 1 : 2);
  const int line = kGlyphLineHeight * ts, margin = 4 * ts;
  const Rgb ink{0, 0, 0};
  const bool with_legend = labels.legend && legend;
  // Width needed by the texts.
  int width = picture.width + 2 * margin;
  width = std::max(width, text_width(labels.title, ts) + 2 * margin);
  if (with_legend) {
    width = std::max(width, text_width(legend->title, ts) + 2 * margin);
    for (const auto& s : legend->swatches) width = std::max(width, text_width(s.second, ts) + line + ts + 2 * margin);
    if (!legend->gradient.empty())
      width = std::max(width, text_width(legend->low + "  " + legend->high, ts) + 2 * margin);
  }
  int height = margin + picture.height + margin;
  if (!labels.title.empty()) height += line + margin;
  int legend_rows = 0;
  if (with_legend) legend_rows = 1 + (legend->gradient.empty() ? 0 : 2) + static_cast<int>(legend->swatches.size());
  height += legend_rows * line + (with_legend ? margin : 0);
  if (labels.scale_bar) height += 2 * line + margin;
  RgbImage out = RgbImage::filled(width, height, 255, 255, 255);
  int y = margin;
  if (!labels.title.empty()) {
    draw_text(out, margin, y, labels.title, ink, ts);
    y += line + margin;
  }
  detail::fill_rect(out, margin - 1, y - 1, picture.width + 2, picture.height + 2, {128, 128, 128});
  for (int py = 0; py < picture.height; ++py)
    for (int px = 0; px < picture.width; ++px) {
      const std::size_t i =
          (static_cast<std::size_t>(py) * static_cast<std::size_t>(picture.width) + static_cast<std::size_t>(px)) * 3;
      out.set(margin + px, y + py, picture.rgb[i], picture.rgb[i + 1], picture.rgb[i + 2]);
    }
  y += picture.height + margin;
  if (with_legend) {
    draw_text(out, margin, y, legend->title, ink, ts);
    y += line;
    if (!legend->gradient.empty()) {
      const int w = std::max(std::min(width - 2 * margin, 256 * ts), text_width(legend->low + "  " + legend->high, ts));
      for (int x = 0; x < w; ++x)
        detail::fill_rect(out, margin + x, y, 1, line - 2 * ts,
                          detail::lerp_colours(legend->gradient, w > 1 ? x / double(w - 1) : 0.0));
      y += line;
      draw_text(out, margin, y, legend->low, ink, ts);
      draw_text(out, margin + w - text_width(legend->high, ts), y, legend->high, ink, ts);
      y += line;
    }
    for (const auto& [c, text] : legend->swatches) {
      detail::fill_rect(out, margin, y, line - 2 * ts, line - 2 * ts, {96, 96, 96});
      detail::fill_rect(out, margin + ts, y + ts, line - 4 * ts, line - 4 * ts, c);
      draw_text(out, margin + line + ts, y, text, ink, ts);
      y += line;
    }
    y += margin;
  }
  if (labels.scale_bar) {
    const double metres = detail::nice_length(0.4 * picture.width * metres_per_pixel);
    const int px = std::max(1, static_cast<int>(std::lround(metres / metres_per_pixel)));
    detail::fill_rect(out, margin, y + line / 2 - ts, px, 2 * ts, ink);
    detail::fill_rect(out, margin, y, ts, line, ink);
    detail::fill_rect(out, margin + px - ts, y, ts, line, ink);
    y += line;
    draw_text(out, margin, y, detail::metres_text(metres), ink, ts);
  }
  return out;
}

}  // namespace intervox
