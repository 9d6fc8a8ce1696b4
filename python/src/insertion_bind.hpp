#pragma once
/// \file
/// The per-grid bindings of python/src/insertion.cpp (the template bind_/add_ functions and their
/// helpers), shared with credal.cpp, which instantiates them for the credal grids.

#include "common.hpp"
#include <intervox/raycast/insert.hpp>
#include <cmath>
#include <cstring>
#include <ranges>
#include <span>

namespace intervox::python::bind {

inline InsertOptions make_options(double max_range, double min_range, unsigned threads) {
  InsertOptions o;
  o.max_range = max_range;
  o.min_range = min_range;
  o.threads = threads;
  o.validate();
  return o;
}

/// A depth image from an (H, W) real array (a copy into the float buffer insertion reads).
inline DepthImage to_depth_image(const py::handle& obj) {
  auto a = py::array_t<float, py::array::forcecast | py::array::c_style>::ensure(obj);
  if (!a || a.ndim() != 2) throw InvalidArgument("depth: expected an array of shape (H, W)");
  DepthImage img;
  img.width = static_cast<int>(a.shape(1));
  img.height = static_cast<int>(a.shape(0));
  img.depth.resize(static_cast<std::size_t>(a.size()));
  if (a.size() > 0) std::memcpy(img.depth.data(), a.data(), img.depth.size() * sizeof(float));
  return img;
}

template <class G>
InsertStats insert_cloud(ScanInserter& ins, G& grid, const py::object& points, const Point3& origin) {
  const PointsView pts(points, "insert_point_cloud: points");
  py::gil_scoped_release release;
  auto range = std::views::iota(std::size_t{0}, pts.size()) |
               std::views::transform([&pts](std::size_t i) { return pts[i]; });
  return ins.insert_point_cloud(grid, origin, range);
}

template <class G>
InsertStats insert_depth(ScanInserter& ins, G& grid, const py::object& depth, const PinholeIntrinsics& k,
                         const py::object& pose) {
  const DepthImage img = to_depth_image(depth);
  const Pose p = to_pose(pose);
  py::gil_scoped_release release;
  return ins.insert_depth_image(grid, img, k, p);
}

template <class G>
InsertStats insert_beam_arrays(ScanInserter& ins, G& grid, const py::object& origins, const py::object& ends,
                               const py::object& hits) {
  const std::vector<Beam> beams = beams_from_numpy(origins, ends, hits);
  py::gil_scoped_release release;
  return ins.insert_beams(grid, std::span<const Beam>(beams));
}

constexpr const char* kCloudDoc =
    "Inserts a point cloud seen from `origin` as one scan (OctoMap's insertPointCloud semantics: misses along\n"
    "each ray, a hit at its end, each voxel updated at most once per scan, a hit wins).\n"
    "points: (N, 3) float32 or float64 (read without a copy, any strides); origin: 3-vector.\n"
    "max_range: rays are cut there and carry misses only (negative: none); min_range: closer points are\n"
    "skipped; threads: 1 = calling thread, 0 = all cores (the result is identical for every count).\n"
    "NaN/Inf points are skipped and counted. Returns InsertStats. The GIL is released meanwhile.";
constexpr const char* kDepthDoc =
    "Inserts a depth image: depth (H, W) float z-depth in metres (> 0 finite: a return; +inf: no return, free\n"
    "up to max_range; NaN, 0, negative: invalid, skipped); intrinsics: PinholeIntrinsics of size W x H;\n"
    "pose: (4, 4) camera (optical frame: x right, y down, z forward) to world. Returns InsertStats.";
constexpr const char* kBeamsDoc =
    "Inserts beams with their own origins as one scan: origins (N, 3) or one (3,) origin, ends (N, 3),\n"
    "hits (N,) bool or None (all hits; a beam without a hit is free up to max_range). Returns InsertStats.";

template <class G>
void add_insertion(py::module_& m, py::class_<ScanInserter>& inserter) {
  auto c = grid_class<G>(m);
  c.def(
      "insert_point_cloud",
      [](G& g, const py::object& points, const Point3& origin, double max_range, double min_range, unsigned threads) {
        ScanInserter ins(make_options(max_range, min_range, threads));
        return insert_cloud(ins, g, points, origin);
      },
      py::arg("points"), py::arg("origin"), py::kw_only(), py::arg("max_range") = -1.0, py::arg("min_range") = 0.0,
      py::arg("threads") = 1u, kCloudDoc);
  c.def(
      "insert_depth_image",
      [](G& g, const py::object& depth, const PinholeIntrinsics& k, const py::object& pose, double max_range,
         double min_range, unsigned threads) {
        ScanInserter ins(make_options(max_range, min_range, threads));
        return insert_depth(ins, g, depth, k, pose);
      },
      py::arg("depth"), py::arg("intrinsics"), py::arg("pose"), py::kw_only(), py::arg("max_range") = -1.0,
      py::arg("min_range") = 0.0, py::arg("threads") = 1u, kDepthDoc);
  c.def(
      "insert_beams",
      [](G& g, const py::object& origins, const py::object& ends, const py::object& hits, double max_range,
         double min_range, unsigned threads) {
        ScanInserter ins(make_options(max_range, min_range, threads));
        return insert_beam_arrays(ins, g, origins, ends, hits);
      },
      py::arg("origins"), py::arg("ends"), py::arg("hits") = py::none(), py::kw_only(), py::arg("max_range") = -1.0,
      py::arg("min_range") = 0.0, py::arg("threads") = 1u, kBeamsDoc);
  c.def(
      "insert_ray",
      [](G& g, const Point3& origin, const Point3& end, double max_range) {
        return insert_ray(g, origin, end, make_options(max_range, 0.0, 1));
      },
      py::arg("origin"), py::arg("end"), py::kw_only(), py::arg("max_range") = -1.0,
      "Inserts one ray with a return at `end` (misses along it, a hit at its end). Returns InsertStats.");

  inserter.def("insert_point_cloud", &insert_cloud<G>, py::arg("grid"), py::arg("points"), py::arg("origin"), kCloudDoc);
  inserter.def("insert_depth_image", &insert_depth<G>, py::arg("grid"), py::arg("depth"), py::arg("intrinsics"),
               py::arg("pose"), kDepthDoc);
  inserter.def("insert_beams", &insert_beam_arrays<G>, py::arg("grid"), py::arg("origins"), py::arg("ends"),
               py::arg("hits") = py::none(), kBeamsDoc);
}

}  // namespace intervox::python::bind
