/// \file
/// Files on every grid type: the grid file (save/load, bytes), OctoMap .bt export/import, PLY
/// export, slice images (numpy RGB) and PNG files.

#include "io_bind.hpp"

#include <intervox/core/path.hpp>

#include <intervox/io/io.hpp>
#include <intervox/view/view.hpp>
#if INTERVOX_PYTHON_PNG
#include <intervox/io/png.hpp>
#endif

#include <cstring>

namespace intervox::python {

using namespace bind;

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
        intervox::detail::check_path(path);
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
        intervox::detail::check_path(path);
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
        intervox::detail::check_path(path);
        const RgbImage img = from_numpy(image);
        py::gil_scoped_release release;
        write_png(path, img);
      },
      py::arg("path"), py::arg("image"), "Writes a (H, W, 3) uint8 array as an 8-bit RGB PNG. Raises IoError.");
  m.def(
      "read_png",
      [](const std::string& path) {
        intervox::detail::check_path(path);
        return to_numpy(read_png(path));
      },
      py::arg("path"), "Reads a PNG as a (H, W, 3) uint8 RGB array. Raises IoError.");
  m.attr("HAS_PNG") = true;
#else
  (void)&from_numpy;
  m.attr("HAS_PNG") = false;
#endif
  for_each_grid([&]<class G>() { add_io<G>(m); });
}

}  // namespace intervox::python
