/// \file
/// Files on every grid type: the grid file (save/load, bytes), OctoMap .bt export/import, PLY
/// export, slice images (numpy RGB) and PNG files.

#include "common.hpp"

#include <intervox/io/io.hpp>
#if INTERVOX_PYTHON_PNG
#include <intervox/io/png.hpp>
#endif

#include <cstring>

namespace intervox::python {

namespace {

py::array_t<std::uint8_t> to_numpy(const RgbImage& img) {
  py::array_t<std::uint8_t> a({static_cast<py::ssize_t>(img.height), static_cast<py::ssize_t>(img.width), py::ssize_t{3}});
  if (!img.rgb.empty()) std::memcpy(a.mutable_data(), img.rgb.data(), img.rgb.size());
  return a;
}

RgbImage from_numpy(const py::handle& obj) {
  auto a = py::array_t<std::uint8_t, py::array::c_style>::ensure(obj);
  if (!a || a.ndim() != 3 || a.shape(2) != 3 || !py::array::ensure(obj).dtype().is(py::dtype::of<std::uint8_t>()))
    throw InvalidArgument("image: expected a uint8 array of shape (H, W, 3)");
  RgbImage img{static_cast<int>(a.shape(1)), static_cast<int>(a.shape(0)), {}};
  img.rgb.assign(a.data(), a.data() + a.size());
  return img;
}

SliceOptions slice_options(ColorBy color, SliceMode mode, std::int32_t z, const py::object& window, int ppv) {
  SliceOptions o;
  o.color = color;
  o.mode = mode;
  o.z = z;
  if (!window.is_none()) o.window = to_key_box(window);
  o.pixels_per_voxel = ppv;
  return o;
}

PlyExportOptions ply_options(const std::string& geometry, const std::string& voxels, ColorBy color, bool binary) {
  PlyExportOptions o;
  if (geometry == "points") o.geometry = PlyExportOptions::Geometry::Points;
  else if (geometry == "cubes") o.geometry = PlyExportOptions::Geometry::Cubes;
  else throw InvalidArgument("write_ply: geometry must be 'points' or 'cubes', got '" + geometry + "'");
  if (voxels == "occupied") o.voxels = PlyExportOptions::Voxels::Occupied;
  else if (voxels == "observed") o.voxels = PlyExportOptions::Voxels::Observed;
  else throw InvalidArgument("write_ply: voxels must be 'occupied' or 'observed', got '" + voxels + "'");
  o.color = color;
  o.binary = binary;
  return o;
}

GridSaveOptions save_options(std::uint32_t version, int level) {
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
        py::gil_scoped_release release;
        save_grid(path, g, save_options(version, level));
      },
      py::arg("path"), py::kw_only(), py::arg("version") = kGridFormatVersion, py::arg("compression_level") = 9,
      "Saves the grid in Intervox's grid file format (atomically: a failed save never leaves a partial file).\n"
      "version 2 (block runs + zstd, level 0-19) or 1 (uncompressed). Raises IoError (an OSError).");
  c.def_static(
      "load",
      [](const std::string& path, std::uint64_t max_bytes) {
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
      py::arg("data"), py::kw_only(), py::arg("max_bytes") = kDefaultLoadBudgetBytes, "Loads a grid from bytes (as load()).");
  c.def(
      "write_bt",
      [](const G& g, const std::string& path, double occupied_threshold, bool include_unknown) {
        OctomapExportOptions o;
        o.occupied_threshold = occupied_threshold;
        o.include_unknown = include_unknown;
        py::gil_scoped_release release;
        write_bt(path, g, o);
      },
      py::arg("path"), py::kw_only(), py::arg("occupied_threshold") = 0.5, py::arg("include_unknown") = true,
      "Exports the observed voxels as an OctoMap .bt file (maximum-likelihood: occupied at or above\n"
      "occupied_threshold). include_unknown=False leaves voxels between the grid's thresholds out.");
  if constexpr (std::is_same_v<typename G::UpdateType, BayesLogOdds>) {
    c.def_static(
        "read_bt",
        [](const std::string& path, const BayesParams& params, std::uint64_t max_voxels, std::uint64_t max_bytes) {
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
        const PlyExportOptions o = ply_options(geometry, voxels, color, binary);
        py::gil_scoped_release release;
        write_ply(path, g, o);
      },
      py::arg("path"), py::kw_only(), py::arg("geometry") = "points", py::arg("voxels") = "occupied",
      py::arg("color") = ColorBy::State, py::arg("binary") = true,
      "Exports voxels as PLY: geometry 'points' (one vertex per voxel centre) or 'cubes'; voxels 'occupied'\n"
      "or 'observed'; coloured by `color` (ColorBy).");
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

}  // namespace

void bind_io(py::module_& m) {
  py::enum_<ColorBy>(m, "ColorBy", "What a voxel's colour shows (PLY export, slices).")
      .value("STATE", ColorBy::State, "grayscale: white = free, black = occupied")
      .value("INTERVAL_WIDTH", ColorBy::IntervalWidth, "blue = narrow interval to red = broad")
      .value("UTILITY", ColorBy::Utility, "black (0) to red to yellow (>= 1)")
      .value("TABLE52", ColorBy::Table52, "the thesis' Table 5.2 code");
  py::enum_<SliceMode>(m, "SliceMode", "What a slice image shows along z.")
      .value("SLICE", SliceMode::Slice, "the voxels of one z layer")
      .value("MAX_PROJECTION", SliceMode::MaxProjection)
      .value("MEAN_PROJECTION", SliceMode::MeanProjection);
  m.def(
      "read_grid_file_info",
      [](const std::string& path) {
        const GridFileInfo i = read_grid_file_info(path);
        py::dict d;
        d["version"] = i.version;
        d["update_policy"] = i.update_policy;
        d["storage"] = i.storage;
        d["utility"] = i.utility;
        d["params"] = i.params;
        d["resolution"] = i.resolution;
        d["origin"] = Point3(i.origin);
        d["key_box"] = i.key_box ? py::object(from_key_box(*i.key_box)) : py::object(py::none());
        d["voxel_count"] = i.voxel_count;
        return d;
      },
      py::arg("path"), "The header of a grid file as a dict (policy, storage, resolution, voxel_count, ...).");
  m.def(
      "read_point_cloud",
      [](const std::string& path) {
        PointCloud pc;
        {
          py::gil_scoped_release release;
          pc = read_point_cloud(path);
        }
        py::array_t<double> a({static_cast<py::ssize_t>(pc.points.size()), py::ssize_t{3}});
        auto w = a.mutable_unchecked<2>();
        for (std::size_t i = 0; i < pc.points.size(); ++i)
          for (int k = 0; k < 3; ++k) w(static_cast<py::ssize_t>(i), k) = pc.points[i][k];
        return a;
      },
      py::arg("path"), "Reads a .ply, .pcd or .xyz point cloud as an (N, 3) float64 array. Raises IoError.");
#if INTERVOX_PYTHON_PNG
  m.def(
      "write_png",
      [](const std::string& path, const py::object& image) {
        const RgbImage img = from_numpy(image);
        py::gil_scoped_release release;
        write_png(path, img);
      },
      py::arg("path"), py::arg("image"), "Writes a (H, W, 3) uint8 array as an 8-bit RGB PNG. Raises IoError.");
  m.def(
      "read_png", [](const std::string& path) { return to_numpy(read_png(path)); }, py::arg("path"),
      "Reads a PNG as a (H, W, 3) uint8 RGB array. Raises IoError.");
  m.attr("HAS_PNG") = true;
#else
  (void)&from_numpy;
  m.attr("HAS_PNG") = false;
#endif
  for_each_grid([&]<class G>() { add_io<G>(m); });
}

}  // namespace intervox::python
