#pragma once
/// \file
/// A 3D viewer page of a grid: one self-contained HTML file with three.js inlined (read at run time
/// from Debian's libjs-three), the voxels binary-packed (base64 of typed arrays) and drawn as
/// instanced cubes, orbit controls, a legend of the colour code, toggles per occupancy class and,
/// when given, the robot's trajectory, its views (camera frustums, striper fans) and conflict regions.
/// Needs no library at build time; writing a page needs the three.js files (see HtmlViewOptions).
/// See docs/viewing.md.

#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/sensors.hpp>
#include <intervox/core/types.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/grid/occupancy_grid.hpp>
#include <intervox/io/color.hpp>
#include <intervox/io/detail/atomic_file.hpp>
#include <intervox/io/detail/base64.hpp>
#include <intervox/io/detail/binary.hpp>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iterator>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <type_traits>
#include <variant>
#include <vector>

namespace intervox {

/// A region of the map to highlight (e.g. where measurements conflict), as a metric box.
struct ViewRegion {
  Bounds box;
  std::string label;
};

/// What the page draws on top of the voxels. Everything is optional.
struct ViewScene {
  std::vector<Pose> trajectory;     ///< body poses in driving order (drawn as a line through their positions)
  std::vector<Pose> scans;          ///< body poses at which the rig sensed (the chosen views)
  std::optional<SensorRig> rig;     ///< draws each scan's sensors: cameras as frustums, stripers as fans
  double view_range = 0.5;          ///< length of the drawn frustums and fans [m] (capped by each sensor's max range)
  std::vector<ViewRegion> regions;  ///< highlighted boxes (conflict regions)
};

/// Options of the viewer page.
struct HtmlViewOptions {
  /// Which voxels the page holds.
  enum class Voxels : std::uint8_t {
    Occupied,  ///< voxels classified occupied
    NotFree,   ///< occupied and unknown (observed, between the thresholds): surfaces and doubt
    Observed,  ///< every observed voxel (free ones hidden until their toggle is switched on)
  };
  ColorBy color = ColorBy::State;
  Voxels voxels = Voxels::NotFree;
  /// Which classes the page shows when opened (occupied, unknown, free); each has a switch.
  std::array<bool, 3> shown{true, true, false};
  /// Beyond this many voxels the page keeps only surface voxels (those with a face not covered by
  /// another held voxel), then merges 2×2×2 voxels into one (repeatedly) until at most this many
  /// remain (see docs/viewing.md). At least 1.
  std::size_t max_voxels = 2'000'000;
  std::string title = "Intervox map";
  /// Folder of three.js (holding build/three.min.js and examples/js/controls/OrbitControls.js).
  /// Empty: the environment variable INTERVOX_THREE_JS_DIR, else Debian's libjs-three folder
  /// /usr/share/javascript/three.
  std::string three_dir;
  /// A colour code from outside the grid's cells (e.g. the explained state of
  /// explained_view_options(), view/explained_page_options.hpp). When set, it is called for every voxel
  /// `voxels` selects, with its key and the grid's occupancy class, and gives the voxel's colour
  /// instead of `color`, or std::nullopt to leave the voxel out of the page; `legend_html` then
  /// replaces the legend of `color`. It must not throw, and is called on the calling thread.
  std::function<std::optional<Rgb>(const Key&, Occupancy)> voxel_colour;
  std::string legend_html;  ///< the legend of voxel_colour, as HTML (html_swatch_legend()); empty: none
  /// The names of the page's switches of the three classes (occupied, unknown, free).
  std::array<std::string, 3> class_names{"occupied", "unknown", "free"};
};

/// The voxels of a page, binary-packed: what write_html_view puts into the page (exposed for tests).
struct ViewVoxels {
  Point3 base = Point3::Zero();            ///< centre of the voxel at offset (0, 0, 0) [m]
  double size = 0;                         ///< edge of a drawn voxel [m] (resolution × 2^level)
  int level = 0;                           ///< number of 2×2×2 merges applied
  bool surface_only = false;               ///< interior voxels were left out
  std::size_t selected = 0;                ///< voxels of the grid that matched HtmlViewOptions::voxels
  std::vector<std::uint16_t> offsets;      ///< x, y, z per voxel, in drawn-voxel units from base
  std::vector<std::uint8_t> rgb;           ///< r, g, b per voxel
  std::array<std::size_t, 3> per_class{};  ///< voxels per class, stored in this order: occupied, unknown, free
  std::size_t size_drawn() const noexcept { return offsets.size() / 3; }
};

namespace detail {

inline int view_class(Occupancy o) noexcept { return o == Occupancy::Occupied ? 0 : o == Occupancy::Unknown ? 1 : 2; }

inline bool view_selected(HtmlViewOptions::Voxels v, Occupancy o) noexcept {
  switch (v) {
    case HtmlViewOptions::Voxels::Occupied:
      return o == Occupancy::Occupied;
    case HtmlViewOptions::Voxels::NotFree:
      return o != Occupancy::Free;
    case HtmlViewOptions::Voxels::Observed:
      return true;
  }
  return false;
}

/// A script file to inline (at most 64 MiB, a regular file).
inline std::string read_whole_file(const std::string& path, const char* what) {
  try {
    return read_file_bytes(path, std::uint64_t{1} << 26);
  } catch (const IoError& e) {
    throw IoError(std::string("intervox::write_html_view: cannot read ") + what + " '" + path + "': " + e.what() +
                  " (install Debian's libjs-three, or set INTERVOX_THREE_JS_DIR or HtmlViewOptions::three_dir "
                  "to a folder holding build/three.min.js and examples/js/controls/OrbitControls.js)");
  }
}

/// \p js made safe to inline in a <script> element: the HTML parser ends an inline script at the
/// first "</script" in any letter case, and "<!--" switches it into a state where "<script" nests,
/// so every "</script" (any case) becomes "<\/script" and every "<!--" becomes "<\!--" (both
/// escapes mean the same characters inside JavaScript strings, regular expressions and comments).
inline std::string inline_script(const std::string& js) {
  static constexpr std::string_view kTag = "script";
  std::string out;
  out.reserve(js.size());
  for (std::size_t i = 0; i < js.size(); ++i) {
    if (js[i] == '<' && i + 1 < js.size() && js[i + 1] == '/' && js.size() - (i + 2) >= kTag.size()) {
      bool tag = true;
      for (std::size_t k = 0; k < kTag.size() && tag; ++k) {
        tag = std::tolower(static_cast<unsigned char>(js[i + 2 + k])) == kTag[k];
      }
      if (tag) {
        out += "<\\/";
        ++i;  // the '/' is written
        continue;
      }
    }
    if (js.compare(i, 4, "<!--") == 0) {
      out += "<\\";  // the "!--" follows
      continue;
    }
    out += js[i];
  }
  return out;
}

inline std::string json_number(double v) {
  if (!std::isfinite(v)) return "0";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

inline std::string html_escape(const std::string& s) {
  std::string out;
  for (const char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

/// Line segments (pairs of points) drawing the rig's sensors at body pose \p body.
inline void append_view_lines(std::vector<float>& out, const SensorRig& rig, const Pose& body, double range) {
  auto push = [&](const Point3& a, const Point3& b) {
    for (const Point3* p : {&a, &b})
      for (int i = 0; i < 3; ++i) out.push_back(static_cast<float>((*p)[i]));
  };
  for (std::size_t s = 0; s < rig.size(); ++s) {
    const Pose pose = rig.sensor_pose(s, body);
    const Point3 eye = pose.translation();
    std::visit(
        [&](const auto& sensor) {
          using T = std::decay_t<decltype(sensor)>;
          const double r = std::min(range, sensor.max_range);
          if constexpr (std::is_same_v<T, DepthCamera>) {
            const int w = sensor.intrinsics.width - 1, h = sensor.intrinsics.height - 1;
            const std::array<Point3, 4> c{pose * (sensor.direction(0, 0) * r), pose * (sensor.direction(w, 0) * r),
                                          pose * (sensor.direction(w, h) * r), pose * (sensor.direction(0, h) * r)};
            for (int i = 0; i < 4; ++i) {
              push(eye, c[static_cast<std::size_t>(i)]);
              push(c[static_cast<std::size_t>(i)], c[static_cast<std::size_t>((i + 1) % 4)]);
            }
          } else {
            const Point3 a = pose * (sensor.direction(0) * r), b = pose * (sensor.direction(sensor.samples - 1) * r);
            push(eye, a);
            push(eye, b);
            push(a, b);
          }
        },
        rig.sensors()[s].sensor);
  }
}

template <class T>
std::string base64_of(const std::vector<T>& v) {
  std::string s;
  append_base64(s, v.data(), v.size() * sizeof(T));
  return s;
}

}  // namespace detail

namespace detail {

/// A voxel selected for the page: its key, its class (view_class) and its colour.
struct ViewItem {
  Key key;
  int cls;
  Rgb rgb;
};

/// The voxels of \p grid that options.voxels (and options.voxel_colour, if set) select, coloured.
template <OccupancyGrid Grid>
std::vector<ViewItem> collect_view_items(const Grid& grid, const HtmlViewOptions& options) {
  std::vector<ViewItem> items;
  const auto& u = grid.update_policy();
  grid.for_each_observed([&](const Key& k, const typename Grid::Cell& c) {
    const Occupancy o = u.occupancy(c);
    if (!detail::view_selected(options.voxels, o)) return;
    if (options.voxel_colour) {
      const std::optional<Rgb> rgb = options.voxel_colour(k, o);
      if (rgb) items.push_back({k, detail::view_class(o), *rgb});
      return;
    }
    items.push_back({k, detail::view_class(o), cell_color(grid, c, options.color)});
  });
  return items;
}

/// The surface of \p items: those whose six face neighbours are not all held (selected voxels).
template <OccupancyGrid Grid>
std::vector<ViewItem> view_surface_items(const Grid& grid, const HtmlViewOptions& options,
                                         const std::vector<ViewItem>& items) {
  const auto& u = grid.update_policy();
  auto held = [&](const Key& k) {
    const auto c = grid.cell(k);
    if (!u.is_observed(c)) return false;
    const Occupancy o = u.occupancy(c);
    return detail::view_selected(options.voxels, o) &&
           (!options.voxel_colour || options.voxel_colour(k, o).has_value());
  };
  std::vector<ViewItem> surface;
  for (const ViewItem& it : items) {
    bool interior = true;
    for (int a = 0; a < 3 && interior; ++a) {
      for (const int d : {-1, 1}) {
        Key n = it.key;
        const std::int64_t v = std::int64_t{n[a]} + d;
        if (v < INT32_MIN || v > INT32_MAX) {
          interior = false;
          break;
        }
        n[a] = static_cast<std::int32_t>(v);
        if (!held(n)) {
          interior = false;
          break;
        }
      }
    }
    if (!interior) surface.push_back(it);
  }
  return surface;
}

/// The smallest key of \p items on each axis (0 without items): merges count from it.
inline std::array<std::int64_t, 3> view_origin(const std::vector<ViewItem>& items) {
  std::array<std::int64_t, 3> origin{0, 0, 0};
  if (!items.empty()) {
    for (int a = 0; a < 3; ++a) {
      origin[static_cast<std::size_t>(a)] =
          std::min_element(items.begin(), items.end(), [&](const ViewItem& x, const ViewItem& y) {
            return x.key[a] < y.key[a];
          })->key[a];
    }
  }
  return origin;
}

/// The coordinate on axis \p a of the voxel holding \p k after \p level merges from \p origin.
inline std::int64_t view_coarse(const Key& k, int a, const std::array<std::int64_t, 3>& origin, int level) {
  return (std::int64_t{k[a]} - origin[static_cast<std::size_t>(a)]) >> level;
}

/// Merges 2×2×2 voxels of \p items (keeping the first of a group by class: occupied before unknown
/// before free) until at most \p max_voxels remain and the extent fits 16-bit offsets, so that every
/// merge halves the extent. Returns the merges applied; \p items is left sorted by coarse key.
inline int merge_view_items(std::vector<ViewItem>& items, std::size_t max_voxels,
                            const std::array<std::int64_t, 3>& origin) {
  int level = 0;
  auto coarse = [&](const Key& k, int a) { return view_coarse(k, a, origin, level); };
  for (;;) {
    std::sort(items.begin(), items.end(), [&](const ViewItem& x, const ViewItem& y) {
      for (int a = 2; a >= 0; --a)
        if (coarse(x.key, a) != coarse(y.key, a)) return coarse(x.key, a) < coarse(y.key, a);
      return x.cls < y.cls;  // the first of a merged group: occupied before unknown before free
    });
    items.erase(std::unique(items.begin(), items.end(),
                            [&](const ViewItem& x, const ViewItem& y) {
                              return coarse(x.key, 0) == coarse(y.key, 0) && coarse(x.key, 1) == coarse(y.key, 1) &&
                                     coarse(x.key, 2) == coarse(y.key, 2);
                            }),
                items.end());
    bool fits = items.size() <= max_voxels;
    for (int a = 0; a < 3 && fits && !items.empty(); ++a) {
      const auto [lo, hi] = std::minmax_element(items.begin(), items.end(), [&](const ViewItem& x, const ViewItem& y) {
        return coarse(x.key, a) < coarse(y.key, a);
      });
      fits = coarse(hi->key, a) - coarse(lo->key, a) <= 65535;
    }
    if (fits) return level;
    ++level;
  }
}

/// Packs the merged \p items into \p out (whose level is set): size, base, and by class the
/// offsets, colours and counts.
inline void pack_view_items(ViewVoxels& out, std::vector<ViewItem>& items, const std::array<std::int64_t, 3>& origin,
                            const GridGeometry& geometry) {
  const double res = geometry.resolution();
  out.size = res * std::ldexp(1.0, out.level);
  // Offset 0 is the coarse voxel whose first fine voxel is at the origin keys: its centre lies
  // (2^level - 1) / 2 fine voxels beyond that voxel's centre.
  const Key first{static_cast<std::int32_t>(origin[0]), static_cast<std::int32_t>(origin[1]),
                  static_cast<std::int32_t>(origin[2])};
  out.base = geometry.center(first) + Point3::Constant(0.5 * (out.size - res));
  std::stable_sort(items.begin(), items.end(), [](const ViewItem& x, const ViewItem& y) { return x.cls < y.cls; });
  out.offsets.reserve(items.size() * 3);
  out.rgb.reserve(items.size() * 3);
  for (const ViewItem& it : items) {
    for (int a = 0; a < 3; ++a)
      out.offsets.push_back(static_cast<std::uint16_t>(view_coarse(it.key, a, origin, out.level)));
    out.rgb.insert(out.rgb.end(), {it.rgb.r, it.rgb.g, it.rgb.b});
    ++out.per_class[static_cast<std::size_t>(it.cls)];
  }
}

}  // namespace detail

/// Selects, colours and packs the voxels of \p grid for the page (the size rule of
/// HtmlViewOptions::max_voxels applied).
/// \tparam Grid any VoxelGrid
/// \throws InvalidArgument if options.max_voxels is 0.
/// Thread safety: reads the grid only.
template <OccupancyGrid Grid>
ViewVoxels pack_view_voxels(const Grid& grid, const HtmlViewOptions& options = {}) {
  ParamCheck("intervox::pack_view_voxels").at_least("max_voxels", options.max_voxels, 1);
  std::vector<detail::ViewItem> items = detail::collect_view_items(grid, options);
  ViewVoxels out;
  out.selected = items.size();
  if (items.size() > options.max_voxels) {
    // Surface only: drop voxels whose six face neighbours are all held.
    items = detail::view_surface_items(grid, options, items);
    out.surface_only = true;
  }
  // Merge 2×2×2 voxels until the count and the extent fit (offsets are 16-bit), counting from the
  // smallest key on each axis (so that every merge halves the extent).
  const std::array<std::int64_t, 3> origin = detail::view_origin(items);
  out.level = detail::merge_view_items(items, options.max_voxels, origin);
  detail::pack_view_items(out, items, origin, grid.geometry());
  return out;
}

/// A legend of swatches as HTML: \p title, then one coloured square and its text a line (the
/// texts are HTML-escaped).
inline std::string html_swatch_legend(const std::string& title,
                                      const std::vector<std::pair<Rgb, std::string>>& swatches) {
  std::string s = "<div class=\"lt\">" + detail::html_escape(title) + "</div>";
  for (const auto& [c, t] : swatches) {
    char css[8];
    std::snprintf(css, sizeof css, "#%02x%02x%02x", c.r, c.g, c.b);
    s += std::string("<div><span class=\"sw\" style=\"background:") + css + "\"></span>" + detail::html_escape(t) +
         "</div>";
  }
  return s;
}

/// The legend of a colour code as HTML (used by the page).
inline std::string html_legend(ColorBy by) {
  auto gradient = [](const char* title, const char* css, const char* left, const char* right) {
    return std::string("<div class=\"lt\">") + title +
           "</div><div class=\"grad\" style=\"background:linear-gradient(to right," + css +
           ")\"></div><div class=\"ends\"><span>" + left + "</span><span>" + right + "</span></div>";
  };
  switch (by) {
    case ColorBy::State:
      return gradient("state (probability of occupancy)", "#fff,#000", "0 free", "1 occupied");
    case ColorBy::IntervalWidth:
      return gradient("interval width (upper &minus; lower)", "#00f,#f00", "0 narrow", "1 broad");
    case ColorBy::Utility:
      return gradient("utility", "#000,#f00,#ff0", "0", "&ge; 1");
    case ColorBy::Table52: {
      std::string s = "<div class=\"lt\">Table 5.2 code (state s, width w, 0..255)</div>";
      const std::array<std::pair<const char*, const char*>, 6> rows{{{"#f00", "red: w &gt; 127 (broad)"},
                                                                     {"#00f", "blue: 75 &lt; s &lt; 180"},
                                                                     {"#000", "black: s &gt; 250 (occupied)"},
                                                                     {"#fff", "white: s &le; 4 (free)"},
                                                                     {"#808080", "gray: other s, w &le; 50"},
                                                                     {"#ff0", "yellow: other s, 50 &lt; w &le; 127"}}};
      for (const auto& [c, t] : rows)
        s += std::string("<div><span class=\"sw\" style=\"background:") + c + "\"></span>" + t + "</div>";
      return s;
    }
  }
  return {};
}

/// Builds the viewer page of \p grid with \p scene drawn on top, inlining the three.js sources given.
/// \throws InvalidArgument as pack_view_voxels.
/// Thread safety: reads the grid only.
template <OccupancyGrid Grid>
std::string html_view_to_string(const Grid& grid, const HtmlViewOptions& options, const ViewScene& scene,
                                const std::string& three_js, const std::string& orbit_controls_js) {
  return html_view_to_string(pack_view_voxels(grid, options), grid.geometry().resolution(),
                             std::string(Grid::UpdateType::kName), options, scene, three_js, orbit_controls_js);
}

namespace detail {

/// The overlays of a page as flat float arrays (x, y, z per point), and the list of region labels.
struct ViewOverlays {
  std::vector<float> path, views, boxes, marks;
  std::string region_list;
};

/// The overlays of \p scene: the trajectory's positions, the scans' positions and sensors (line
/// segments), the regions' 12 edges each (line segments) and their labels as HTML.
inline ViewOverlays view_overlays(const ViewScene& scene) {
  ViewOverlays o;
  auto push = [](std::vector<float>& out, const Point3& p) {
    for (int i = 0; i < 3; ++i) out.push_back(static_cast<float>(p[i]));
  };
  for (const Pose& p : scene.trajectory) push(o.path, p.translation());
  for (const Pose& p : scene.scans) {
    push(o.marks, p.translation());
    if (scene.rig) detail::append_view_lines(o.views, *scene.rig, p, scene.view_range);
  }
  for (const ViewRegion& r : scene.regions) {
    const Point3 a = r.box.min, b = r.box.max;
    for (int e = 0; e < 12; ++e) {  // the 12 edges: along axis e / 4, the other two corners from e % 4
      const int axis = e / 4, o1 = (axis + 1) % 3, o2 = (axis + 2) % 3;
      Point3 p = a, q = a;
      p[o1] = q[o1] = (e & 1) ? b[o1] : a[o1];
      p[o2] = q[o2] = (e & 2) ? b[o2] : a[o2];
      q[axis] = b[axis];
      push(o.boxes, p);
      push(o.boxes, q);
    }
    if (!r.label.empty()) o.region_list += "<div class=\"rl\">" + detail::html_escape(r.label) + "</div>";
  }
  return o;
}

/// Where the page's camera looks first: the centre and radius of the bounds of everything.
struct ViewCamera {
  Point3 centre;
  double radius;
};

/// The initial camera: it frames the voxels; without voxels, the overlays.
inline ViewCamera view_camera(const ViewVoxels& v, const ViewOverlays& o) {
  Point3 lo = Point3::Constant(1e300), hi = Point3::Constant(-1e300);
  auto grow = [&](const Point3& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  };
  for (std::size_t i = 0; i < v.offsets.size(); i += 3)
    grow(v.base + Point3(v.offsets[i], v.offsets[i + 1], v.offsets[i + 2]) * v.size);
  if (v.offsets.empty()) {  // the camera frames the voxels; without voxels, the overlays
    for (const auto* arr : {&o.path, &o.views, &o.boxes})
      for (std::size_t i = 0; i + 2 < arr->size(); i += 3) grow(Point3((*arr)[i], (*arr)[i + 1], (*arr)[i + 2]));
  }
  if (lo.x() > hi.x()) lo = hi = Point3::Zero();
  const Point3 centre = (lo + hi) / 2;
  const double radius = std::max(0.5 * (hi - lo).norm(), 4.0 * v.size + 0.1);
  return {centre, radius};
}

/// The page's info line: voxels drawn and selected, their edge, the rules applied, the map.
inline std::string view_info(const ViewVoxels& v, double res, const std::string& policy) {
  std::string info = std::to_string(v.size_drawn()) + " of " + std::to_string(v.selected) + " voxels drawn, edge " +
                     detail::json_number(v.size) + " m";
  if (v.surface_only) info += "; surface only";
  if (v.level > 0) info += "; " + std::to_string(1 << std::min(v.level, 30)) + "&times; coarser than the map";
  info += " (map " + detail::json_number(res) + " m, " + policy + ")";
  return info;
}

/// Appends the page's head and its panel (title, info line, legend, switches of the classes and
/// of the overlays the page has) to \p h.
inline void append_view_panel(std::string& h, const ViewVoxels& v, const std::string& info,
                              const HtmlViewOptions& options, const ViewScene& scene, const ViewOverlays& o) {
  h += "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>" + detail::html_escape(options.title) +
       "</title>\n<style>\nbody{margin:0;overflow:hidden;font:13px sans-serif;background:#dfe6ec}\n"
       "#panel{position:absolute;top:8px;left:8px;background:rgba(255,255,255,.9);padding:8px 10px;border-radius:4px;"
       "max-width:330px;box-shadow:0 1px 4px rgba(0,0,0,.3)}\n#panel h1{font-size:15px;margin:0 0 4px}\n"
       ".lt{font-weight:bold;margin-top:6px}.grad{height:12px;border:1px solid #444}.ends{display:flex;"
       "justify-content:space-between}.sw{display:inline-block;width:12px;height:12px;border:1px solid #444;"
       "margin-right:5px;vertical-align:middle}\n.rl{margin-left:22px;color:#606}\n#status{font-family:monospace;"
       "margin-top:6px}\nlabel{display:block}\n"
       "</style></head><body>\n<div id=\"panel\"><h1>" +
       detail::html_escape(options.title) + "</h1><div>" + info + "</div>" +
       (options.voxel_colour ? options.legend_html : html_legend(options.color)) + "<div class=\"lt\">show</div>";
  for (std::size_t k = 0; k < 3; ++k) {
    h += "<label><input type=\"checkbox\" id=\"c" + std::to_string(k) + "\"" + (options.shown[k] ? " checked" : "") +
         "> " + detail::html_escape(options.class_names[k]) + " (" + std::to_string(v.per_class[k]) + ")</label>";
  }
  if (!o.path.empty())
    h += "<label><input type=\"checkbox\" id=\"opath\" checked> <span class=\"sw\" "
         "style=\"background:#0a0\"></span>trajectory</label>";
  if (!o.marks.empty())
    h += "<label><input type=\"checkbox\" id=\"oviews\" checked> <span class=\"sw\" "
         "style=\"background:#f80\"></span>views (" +
         std::to_string(scene.scans.size()) + ")</label>";
  if (!o.boxes.empty())
    h += "<label><input type=\"checkbox\" id=\"oregions\" checked> <span class=\"sw\" "
         "style=\"background:#f0f\"></span>regions (" +
         std::to_string(scene.regions.size()) + ")</label>" + o.region_list;
  h += "<div style=\"margin-top:4px\">axes: 1 m (x red, y green, z blue); drag to turn, wheel to zoom, right-drag to "
       "pan</div>"
       "<div id=\"status\">loading</div><div id=\"timing\"></div></div>\n";
}

/// Appends the page's data to \p h: the script element defining IV (base, size, counts per class,
/// camera, and base64 of the offsets, colours and overlays).
inline void append_view_data(std::string& h, const ViewVoxels& v, const ViewCamera& camera, const ViewOverlays& o) {
  h += "<script>\nconst IV={base:[" + detail::json_number(v.base.x()) + "," + detail::json_number(v.base.y()) + "," +
       detail::json_number(v.base.z()) + "],size:" + detail::json_number(v.size) + ",perClass:[" +
       std::to_string(v.per_class[0]) + "," + std::to_string(v.per_class[1]) + "," + std::to_string(v.per_class[2]) +
       "],centre:[" + detail::json_number(camera.centre.x()) + "," + detail::json_number(camera.centre.y()) + "," +
       detail::json_number(camera.centre.z()) + "],radius:" + detail::json_number(camera.radius) + ",\noffsets:\"";
  detail::append_base64(h, v.offsets.data(), v.offsets.size() * 2);
  h += "\",\nrgb:\"";
  detail::append_base64(h, v.rgb.data(), v.rgb.size());
  h += "\",\npath:\"" + detail::base64_of(o.path) + "\",\nviews:\"" + detail::base64_of(o.views) + "\",\nmarks:\"" +
       detail::base64_of(o.marks) + "\",\nboxes:\"" + detail::base64_of(o.boxes) + "\"};\n";
}

/// The page's script (after three.js and the data IV): decodes the data, draws the voxels by class
/// and the overlays, wires the switches and reports its status.
inline constexpr std::string_view kViewPageScript = R"JS((function(){
const status=document.getElementById('status');
const t0=performance.now();
try{
  if(typeof THREE==='undefined'||!THREE.OrbitControls) throw new Error('three.js did not load');
  function bytes(b64){const s=atob(b64);const u=new Uint8Array(s.length);for(let i=0;i<s.length;++i)u[i]=s.charCodeAt(i);return u;}
  function floats(b64){const u=bytes(b64);return new Float32Array(u.buffer,0,u.length/4);}
  const off8=bytes(IV.offsets), offsets=new Uint16Array(off8.buffer,0,off8.length/2), rgb=bytes(IV.rgb);
  const t1=performance.now();
  const renderer=new THREE.WebGLRenderer({antialias:true,preserveDrawingBuffer:true});
  renderer.setPixelRatio(window.devicePixelRatio||1);
  renderer.setSize(window.innerWidth,window.innerHeight);
  renderer.setClearColor(0xdfe6ec);
  document.body.appendChild(renderer.domElement);
  const scene=new THREE.Scene();
  const camera=new THREE.PerspectiveCamera(45,window.innerWidth/window.innerHeight,IV.radius/1000,IV.radius*50);
  camera.up.set(0,0,1);
  const c=new THREE.Vector3(IV.centre[0],IV.centre[1],IV.centre[2]);
  camera.position.set(c.x+1.3*IV.radius,c.y-1.9*IV.radius,c.z+1.5*IV.radius);
  const controls=new THREE.OrbitControls(camera,renderer.domElement);
  controls.target.copy(c);
  controls.update();
  const box=new THREE.BoxBufferGeometry(1,1,1);
  const material=new THREE.ShaderMaterial({
    uniforms:{base:{value:new THREE.Vector3(IV.base[0],IV.base[1],IV.base[2])},size:{value:IV.size}},
    vertexShader:'uniform vec3 base; uniform float size; attribute vec3 offset; attribute vec3 icolor; varying vec3 vc;'+
      'void main(){ vec3 p=base+(offset+position)*size; float l=0.55+0.45*abs(dot(normal,normalize(vec3(0.4,-0.6,0.8))));'+
      'vc=icolor*l+vec3(0.06)*(1.0-l); gl_Position=projectionMatrix*modelViewMatrix*vec4(p,1.0); }',
    fragmentShader:'varying vec3 vc; void main(){ gl_FragColor=vec4(vc,1.0); }'});
  const meshes=[]; let start=0;
  for(let k=0;k<3;++k){
    const n=IV.perClass[k];
    const g=new THREE.InstancedBufferGeometry();
    g.index=box.index; g.setAttribute('position',box.attributes.position); g.setAttribute('normal',box.attributes.normal);
    g.setAttribute('offset',new THREE.InstancedBufferAttribute(offsets.subarray(3*start,3*(start+n)),3,false));
    g.setAttribute('icolor',new THREE.InstancedBufferAttribute(rgb.subarray(3*start,3*(start+n)),3,true));
    g.maxInstancedCount=n; start+=n;
    const m=new THREE.Mesh(g,material); m.frustumCulled=false; m.visible=n>0&&document.getElementById('c'+k).checked;
    scene.add(m); meshes.push(m);
    document.getElementById('c'+k).onchange=function(e){m.visible=n>0&&e.target.checked;draw();};
  }
  function lines(b64,color,segments){
    const p=floats(b64); if(p.length===0) return null;
    const g=new THREE.BufferGeometry(); g.setAttribute('position',new THREE.BufferAttribute(p,3));
    const o=segments?new THREE.LineSegments(g,new THREE.LineBasicMaterial({color:color})):new THREE.Line(g,new THREE.LineBasicMaterial({color:color}));
    scene.add(o); return o;
  }
  function toggle(id,objects){const e=document.getElementById(id); if(!e) return; e.onchange=function(){objects.forEach(function(o){if(o)o.visible=e.checked;});draw();};}
  const path=lines(IV.path,0x00aa00,false), views=lines(IV.views,0xff8800,true), boxes=lines(IV.boxes,0xff00ff,true);
  let marks=null;
  const mp=floats(IV.marks);
  if(mp.length>0){const g=new THREE.BufferGeometry(); g.setAttribute('position',new THREE.BufferAttribute(mp,3));
    marks=new THREE.Points(g,new THREE.PointsMaterial({color:0xff8800,size:6,sizeAttenuation:false})); scene.add(marks);}
  toggle('opath',[path]); toggle('oviews',[views,marks]); toggle('oregions',[boxes]);
  scene.add(new THREE.AxesHelper(1));
  function draw(){renderer.render(scene,camera);}
  controls.addEventListener('change',draw);
  window.addEventListener('resize',function(){camera.aspect=window.innerWidth/window.innerHeight;camera.updateProjectionMatrix();renderer.setSize(window.innerWidth,window.innerHeight);draw();});
  draw();
  const gl=renderer.getContext(); const err=gl.getError();
  if(err!==gl.NO_ERROR) throw new Error('WebGL error '+err);
  status.textContent='ok '+(IV.perClass[0]+IV.perClass[1]+IV.perClass[2])+' voxels';
  document.getElementById('timing').textContent='decoded in '+Math.round(t1-t0)+' ms, first frame after '+Math.round(performance.now()-t0)+' ms';
}catch(e){status.textContent='error: '+(e&&e.message?e.message:e);}
})();
</script>
</body></html>
)JS";

}  // namespace detail

/// Builds the page of already packed voxels \p v of a map of resolution \p res and update policy
/// \p policy (for the page's info line).
/// Thread safety: reentrant.
inline std::string html_view_to_string(const ViewVoxels& v, double res, const std::string& policy,
                                       const HtmlViewOptions& options, const ViewScene& scene,
                                       const std::string& three_js, const std::string& orbit_controls_js) {
  const detail::ViewOverlays overlays = detail::view_overlays(scene);
  const detail::ViewCamera camera = detail::view_camera(v, overlays);
  const std::string info = detail::view_info(v, res, policy);

  std::string h;
  h.reserve(three_js.size() + orbit_controls_js.size() + v.offsets.size() * 3 + 16384);
  detail::append_view_panel(h, v, info, options, scene, overlays);
  h += "<script>\nwindow.onerror=function(m){var s=document.getElementById('status');s.textContent='error: "
       "'+m;};\n</script>\n";
  h += "<script>\n" + detail::inline_script(three_js) + "\n</script>\n<script>\n" +
       detail::inline_script(orbit_controls_js) + "\n</script>\n";
  detail::append_view_data(h, v, camera, overlays);
  h += detail::kViewPageScript;
  return h;
}

/// The three.js folder write_html_view reads: \p configured if not empty, else the environment
/// variable INTERVOX_THREE_JS_DIR if set and not empty, else "/usr/share/javascript/three".
/// Thread safety: reads the environment.
inline std::string three_js_dir(const std::string& configured = {}) {
  if (!configured.empty()) return configured;
  const char* env = std::getenv("INTERVOX_THREE_JS_DIR");
  if (env && *env) return env;
  return "/usr/share/javascript/three";
}

/// What write_html_view wrote.
struct HtmlViewSummary {
  std::size_t drawn = 0;      ///< voxels in the page
  std::size_t selected = 0;   ///< voxels of the grid that matched HtmlViewOptions::voxels
  int level = 0;              ///< 2×2×2 merges applied
  bool surface_only = false;  ///< interior voxels were left out
  std::size_t bytes = 0;      ///< size of the page
};

/// Writes the viewer page of \p grid (with \p scene on top) to \p path (temporary file, then
/// rename), inlining three.js from three_js_dir(options.three_dir).
/// \tparam Grid any VoxelGrid
/// \throws IoError if three.js cannot be read (the message names the file and how to provide it)
///         or the page cannot be written; InvalidArgument as pack_view_voxels.
/// Thread safety: reads the grid only; safe to call concurrently for different paths.
template <OccupancyGrid Grid>
HtmlViewSummary write_html_view(const std::string& path, const Grid& grid, const HtmlViewOptions& options = {},
                                const ViewScene& scene = {}) {
  const std::string dir = three_js_dir(options.three_dir);
  const std::string three = detail::read_whole_file(dir + "/build/three.min.js", "three.js");
  const std::string orbit =
      detail::read_whole_file(dir + "/examples/js/controls/OrbitControls.js", "three.js OrbitControls");
  const ViewVoxels v = pack_view_voxels(grid, options);
  const std::string page = html_view_to_string(v, grid.geometry().resolution(), std::string(Grid::UpdateType::kName),
                                               options, scene, three, orbit);
  detail::write_file_atomically(path, [&](std::FILE* f) { detail::write_bytes(f, page.data(), page.size(), path); });
  return {v.size_drawn(), v.selected, v.level, v.surface_only, page.size()};
}

}  // namespace intervox
