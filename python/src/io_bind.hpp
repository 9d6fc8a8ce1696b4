#pragma once
/// \file
/// The per-grid bindings of python/src/io.cpp (the template bind_/add_ functions and their
/// helpers), shared with credal.cpp, which instantiates them for the credal grids.

#include "guard.hpp"
#include <intervox/core/path.hpp>
#include <intervox/io/io.hpp>
#include <intervox/view/explained_page_options.hpp>
#include <intervox/view/view.hpp>
#if INTERVOX_PYTHON_PNG
#include <intervox/io/png.hpp>
#include <intervox/update/bayes_log_odds.hpp>
#endif
#include <algorithm>
#include <cstring>
#include <iterator>
#include <string>
#include <vector>

namespace intervox::python::bind {

inline py::array_t<std::uint8_t> to_numpy(const RgbImage& img) {
  py::array_t<std::uint8_t> a(
      {static_cast<py::ssize_t>(img.height), static_cast<py::ssize_t>(img.width), py::ssize_t{3}});
  if (!img.rgb.empty()) std::memcpy(a.mutable_data(), img.rgb.data(), img.rgb.size());
  return a;
}

inline RgbImage from_numpy(const py::handle& obj) {
  auto a = py::array_t<std::uint8_t, py::array::c_style>::ensure(obj);
  if (!a || a.ndim() != 3 || a.shape(2) != 3 || !py::array::ensure(obj).dtype().is(py::dtype::of<std::uint8_t>()))
    throw InvalidArgument("image: expected a uint8 array of shape (H, W, 3)");
  RgbImage img{static_cast<int>(a.shape(1)), static_cast<int>(a.shape(0)), {}};
  img.rgb.assign(a.data(), a.data() + a.size());
  return img;
}

inline SliceOptions slice_options(ColorBy color, SliceMode mode, std::int32_t z, const py::object& window, int ppv) {
  SliceOptions o;
  o.color = color;
  o.mode = mode;
  o.z = z;
  if (!window.is_none()) o.window = to_key_box(window);
  o.pixels_per_voxel = ppv;
  return o;
}

inline PlyExportOptions ply_options(const std::string& geometry, const std::string& voxels, ColorBy color,
                                    bool binary) {
  PlyExportOptions o;
  if (geometry == "points")
    o.geometry = PlyExportOptions::Geometry::Points;
  else if (geometry == "cubes")
    o.geometry = PlyExportOptions::Geometry::Cubes;
  else
    throw InvalidArgument("write_ply: geometry must be 'points' or 'cubes', got '" + geometry + "'");
  if (voxels == "occupied")
    o.voxels = PlyExportOptions::Voxels::Occupied;
  else if (voxels == "observed")
    o.voxels = PlyExportOptions::Voxels::Observed;
  else
    throw InvalidArgument("write_ply: voxels must be 'occupied' or 'observed', got '" + voxels + "'");
  o.color = color;
  o.binary = binary;
  return o;
}

inline HtmlViewOptions html_view_options(ColorBy color, const std::string& voxels, const std::vector<std::string>& show,
                                         std::size_t max_voxels, const std::string& title,
                                         const std::string& three_dir) {
  HtmlViewOptions o;
  o.color = color;
  if (voxels == "occupied")
    o.voxels = HtmlViewOptions::Voxels::Occupied;
  else if (voxels == "not_free")
    o.voxels = HtmlViewOptions::Voxels::NotFree;
  else if (voxels == "observed")
    o.voxels = HtmlViewOptions::Voxels::Observed;
  else
    throw InvalidArgument("write_html_view: voxels must be 'occupied', 'not_free' or 'observed', got '" + voxels + "'");
  const char* classes[3] = {"occupied", "unknown", "free"};
  o.shown = {false, false, false};
  for (const std::string& c : show) {
    const auto* it = std::find_if(std::begin(classes), std::end(classes), [&](const char* n) { return c == n; });
    if (it == std::end(classes))
      throw InvalidArgument("write_html_view: show holds 'occupied', 'unknown' or 'free', got '" + c + "'");
    o.shown[static_cast<std::size_t>(it - std::begin(classes))] = true;
  }
  if (max_voxels == 0) throw InvalidArgument("write_html_view: max_voxels must be at least 1");
  o.max_voxels = max_voxels;
  o.title = title;
  o.three_dir = three_dir;
  return o;
}

inline std::vector<Pose> poses_of(const py::object& obj, const char* what) {
  std::vector<Pose> out;
  if (obj.is_none()) return out;
  for (const py::handle& p : obj) out.push_back(to_pose(p, what));
  return out;
}

inline GridSaveOptions save_options(std::uint32_t version, int level) {
  GridSaveOptions o;
  o.version = version;
  o.compression_level = level;
  return o;
}

template <class G>
void add_io(py::module_& m) {
  auto c = grid_class<G>(m);
  c.def(
      "save",
      [](const G& g, const std::string& path, std::uint32_t version, int level) {
        intervox::detail::check_path(path);
        py::gil_scoped_release release;
        save_grid(path, g, save_options(version, level));
      },
      py::arg("path"), py::kw_only(), py::arg("version") = kGridFormatVersion, py::arg("compression_level") = 9,
      "Saves the grid in Intervox's grid file format (atomically: a failed save never leaves a partial file).\n"
      "version 2 (block runs + zstd, level 0-19) or 1 (uncompressed). Raises IoError (an OSError).");
  c.def_static(
      "load",
      [](const std::string& path, std::uint64_t max_bytes) {
        intervox::detail::check_path(path);
        GridLoadOptions o;
        o.max_bytes = max_bytes;
        py::gil_scoped_release release;
        return load_grid<G>(path, o);
      },
      py::arg("path"), py::kw_only(), py::arg("max_bytes") = kDefaultLoadBudgetBytes,
      "Loads a grid file saved from a grid of the same policy. Raises IoError for a missing, corrupt or\n"
      "mismatching file, or one that needs more than max_bytes.");
  c.def(
      "to_bytes",
      [](const G& g, std::uint32_t version, int level) {
        std::string s;
        {
          py::gil_scoped_release release;
          s = save_grid_to_memory(g, save_options(version, level));
        }
        return py::bytes(s);
      },
      py::kw_only(), py::arg("version") = kGridFormatVersion, py::arg("compression_level") = 9,
      "The grid file as bytes (as save()).");
  c.def_static(
      "from_bytes",
      [](const py::bytes& data, std::uint64_t max_bytes) {
        GridLoadOptions o;
        o.max_bytes = max_bytes;
        const std::string_view v(data);
        return load_grid_from_memory<G>(v, "<bytes>", o);
      },
      py::arg("data"), py::kw_only(), py::arg("max_bytes") = kDefaultLoadBudgetBytes,
      "Loads a grid from bytes (as load()).");
  c.def(
      "write_bt",
      [](const G& g, const std::string& path, double occupied_threshold, bool include_unknown) {
        intervox::detail::check_path(path);
        OctomapExportOptions o;
        o.occupied_threshold = occupied_threshold;
        o.include_unknown = include_unknown;
        py::gil_scoped_release release;
        return write_bt(path, g, o).out_of_range;
      },
      py::arg("path"), py::kw_only(), py::arg("occupied_threshold") = 0.5, py::arg("include_unknown") = true,
      "Exports the observed voxels as an OctoMap .bt file (maximum-likelihood: occupied at or above\n"
      "occupied_threshold). include_unknown=False leaves voxels between the grid's thresholds out. Voxels\n"
      "beyond OctoMap's 16-bit keys (32768 voxels from the origin: 1.6 km at 5 cm) are left out; returns\n"
      "how many.");
  if constexpr (std::is_same_v<typename G::UpdateType, BayesLogOdds>) {
    c.def_static(
        "read_bt",
        [](const std::string& path, const BayesParams& params, std::uint64_t max_voxels, std::uint64_t max_bytes) {
          intervox::detail::check_path(path);
          OctomapImportOptions o;
          o.max_voxels = max_voxels;
          o.max_bytes = max_bytes;
          const BayesLogOdds policy(params);
          py::gil_scoped_release release;
          return read_bt<G>(path, policy, o);
        },
        py::arg("path"), py::arg("params") = BayesParams::octomap(), py::kw_only(),
        py::arg("max_voxels") = OctomapImportOptions{}.max_voxels, py::arg("max_bytes") = kDefaultLoadBudgetBytes,
        "Reads an OctoMap .bt file: occupied leaves get the policy's upper clamp, free leaves the lower one.\n"
        "Raises IoError for a malformed or too large file.");
  }
  c.def(
      "write_ply",
      [](const G& g, const std::string& path, const std::string& geometry, const std::string& voxels, ColorBy color,
         bool binary) {
        intervox::detail::check_path(path);
        const PlyExportOptions o = ply_options(geometry, voxels, color, binary);
        py::gil_scoped_release release;
        write_ply(path, g, o);
      },
      py::arg("path"), py::kw_only(), py::arg("geometry") = "points", py::arg("voxels") = "occupied",
      py::arg("color") = ColorBy::State, py::arg("binary") = true,
      "Exports voxels as PLY: geometry 'points' (one vertex per voxel centre) or 'cubes'; voxels 'occupied'\n"
      "or 'observed'; coloured by `color` (ColorBy).");
  c.def(
      "write_html_view",
      [](const G& g, const std::string& path, ColorBy color, const py::object& voxels, const py::object& show,
         std::size_t max_voxels, const std::string& title, const std::string& three_dir, const py::object& trajectory,
         const py::object& scans, const py::object& explained) {
        intervox::detail::check_path(path);
        const bool by_explained = !explained.is_none();
        const std::string vox =
            voxels.is_none() ? (by_explained ? "observed" : "not_free") : voxels.cast<std::string>();
        const std::vector<std::string> shown =
            show.is_none() ? (by_explained ? std::vector<std::string>{"occupied", "unknown", "free"}
                                           : std::vector<std::string>{"occupied", "unknown"})
                           : show.cast<std::vector<std::string>>();
        HtmlViewOptions o = html_view_options(color, vox, shown, max_voxels, title, three_dir);
        if (by_explained) {
          const HtmlViewOptions chosen = o;
          o = explained_view_options(g, explained.cast<const ExplainedSpace&>(), o);
          o.voxels = chosen.voxels;  // the caller's (or the explained defaults above)
          o.shown = chosen.shown;
        }
        ViewScene scene;
        scene.trajectory = poses_of(trajectory, "write_html_view: trajectory pose");
        scene.scans = poses_of(scans, "write_html_view: scan pose");
        HtmlViewSummary s;
        {
          py::gil_scoped_release release;
          s = write_html_view(path, g, o, scene);
        }
        py::dict d;
        d["drawn"] = s.drawn;
        d["selected"] = s.selected;
        d["level"] = s.level;
        d["surface_only"] = s.surface_only;
        d["bytes"] = s.bytes;
        return d;
      },
      py::arg("path"), py::kw_only(), py::arg("color") = ColorBy::State, py::arg("voxels") = py::none(),
      py::arg("show") = py::none(), py::arg("max_voxels") = HtmlViewOptions{}.max_voxels,
      py::arg("title") = HtmlViewOptions{}.title, py::arg("three_dir") = "", py::arg("trajectory") = py::none(),
      py::arg("scans") = py::none(), py::arg("explained") = py::none(),
      "Writes the 3D viewer page of the map (docs/viewing.md): one self-contained HTML file, three.js inlined\n"
      "from three_dir (default: $INTERVOX_THREE_JS_DIR, else Debian's libjs-three folder). voxels: 'occupied',\n"
      "'not_free' (occupied and unknown; the default) or 'observed'; show: the classes visible when the page\n"
      "opens (default: occupied and unknown); beyond max_voxels the page keeps surface voxels, then merges 2x2x2\n"
      "voxels. trajectory, scans: (4, 4) body poses drawn as a line and as markers. explained: an ExplainedSpace\n"
      "of this grid's geometry: every voxel is coloured by its explained state instead of `color` (gray no\n"
      "evidence, white explained free, black explained occupied, orange unexplained) and the free class holds\n"
      "only free voxels that are not explained free (what lying beams alone made free); voxels then defaults to\n"
      "'observed' and show to every class (view/explained_page_options.hpp). Returns a dict: drawn, selected, level,\n"
      "surface_only, bytes. Raises IoError when three.js is missing (the message says how to provide it) or the\n"
      "page cannot be written; InvalidArgument (ValueError) for an explained space of another geometry.");
  c.def(
      "render_slice",
      [](const G& g, ColorBy color, SliceMode mode, std::int32_t z, const py::object& window, int ppv) {
        const SliceOptions o = slice_options(color, mode, z, window, ppv);
        RgbImage img;
        {
          py::gil_scoped_release release;
          img = render_slice(g, o);
        }
        return to_numpy(img);
      },
      py::kw_only(), py::arg("color") = ColorBy::State, py::arg("mode") = SliceMode::Slice, py::arg("z") = 0,
      py::arg("window") = py::none(), py::arg("pixels_per_voxel") = 1,
      "Renders a z slice (key z) or a projection as a (H, W, 3) uint8 RGB array; row 0 is the top (largest y).\n"
      "window: (2, 3) key box drawn (default: the grid's key box or the observed voxels' extent).");
}

}  // namespace intervox::python::bind
