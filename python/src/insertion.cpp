/// \file
/// Insertion from numpy: point clouds, depth images, beams and single rays, on every grid type, and
/// a reusable ScanInserter. No per-point Python loop; the GIL is released while C++ inserts.

#include "insertion_bind.hpp"

#include <intervox/raycast/insert.hpp>
#include <intervox/raycast/projective.hpp>
#include <intervox/raycast/vector_walks.hpp>

#include <cmath>
#include <cstring>
#include <ranges>
#include <span>

namespace intervox::python {

using namespace bind;

std::vector<Beam> beams_from_numpy(const py::handle& origins, const py::handle& ends, const py::handle& hits) {
  const PointsView e(ends, "ends");
  std::vector<Beam> beams(e.size());
  auto o_arr = py::array::ensure(origins);
  if (o_arr && o_arr.ndim() == 1) {
    const Point3 o = py::cast<Point3>(origins);
    for (auto& b : beams) b.origin = o;
  } else {
    const PointsView o(origins, "origins");
    if (o.size() != e.size()) throw InvalidArgument("insert_beams: origins and ends differ in length");
    for (std::size_t i = 0; i < beams.size(); ++i) beams[i].origin = o[i];
  }
  for (std::size_t i = 0; i < beams.size(); ++i) beams[i].end = e[i];
  if (!hits.is_none()) {
    const py::array raw = py::array::ensure(hits);
    const char kind = raw ? raw.dtype().kind() : '?';
    if (raw && kind != 'b' && kind != 'i' && kind != 'u')
      throw InvalidArgument("insert_beams: hits must be a bool (or integer) array of shape (N,), got dtype " +
                            std::string(py::str(raw.dtype())));
    auto h = py::array_t<bool, py::array::forcecast>::ensure(hits);
    if (!h || h.ndim() != 1 || static_cast<std::size_t>(h.shape(0)) != beams.size())
      throw InvalidArgument("insert_beams: hits must be a bool array of shape (N,)");
    auto r = h.unchecked<1>();
    for (std::size_t i = 0; i < beams.size(); ++i) beams[i].hit = r(static_cast<py::ssize_t>(i));
  }
  return beams;
}

py::tuple beams_to_numpy(const std::vector<Beam>& beams) {
  const auto n = static_cast<py::ssize_t>(beams.size());
  py::array_t<double> o({n, py::ssize_t{3}}), e({n, py::ssize_t{3}});
  py::array_t<bool> h(n);
  auto ow = o.mutable_unchecked<2>();
  auto ew = e.mutable_unchecked<2>();
  auto hw = h.mutable_unchecked<1>();
  for (py::ssize_t i = 0; i < n; ++i) {
    const Beam& b = beams[static_cast<std::size_t>(i)];
    for (int a = 0; a < 3; ++a) {
      ow(i, a) = b.origin[a];
      ew(i, a) = b.end[a];
    }
    hw(i) = b.hit;
  }
  return py::make_tuple(o, e, h);
}

void bind_insertion(py::module_& m) {
  // Every insertion of the module walks with the AVX-512 / AVX2 walks where the processor has them.
  intervox::use_vector_walks();
  m.def("insertion_walk", &intervox::insertion_walk,
        "The walk ray insertion uses on this processor: 'AVX-512', 'AVX2' or 'table' (the same voxels with any).");
  guarded_class<ScanInserter> inserter(
      m, "ScanInserter",
      "Inserts scans with fixed options and keeps its scratch buffers between calls (faster for many scans).\n"
      "Thread safety: one inserter per thread; the grid needs exclusive access during a call (a call that finds\n"
      "the inserter or the grid in use by another thread raises RuntimeError).");
  inserter
      .def(py::init([](double max_range, double min_range, unsigned threads, std::uint64_t max_grid_bytes) {
             return ScanInserter(make_options(max_range, min_range, threads, max_grid_bytes));
           }),
           py::kw_only(), py::arg("max_range") = -1.0, py::arg("min_range") = 0.0, py::arg("threads") = 1u,
           py::arg("max_grid_bytes") = kDefaultInsertBudgetBytes,
           "max_range, min_range, threads and max_grid_bytes (the insertion budget) as for Grid.insert_point_cloud.")
      .def_property_readonly("max_range", [](const ScanInserter& s) { return s.options().max_range; })
      .def_property_readonly("min_range", [](const ScanInserter& s) { return s.options().min_range; })
      .def_property_readonly("threads", [](const ScanInserter& s) { return s.options().threads; })
      .def_property_readonly(
          "max_grid_bytes", [](const ScanInserter& s) { return s.options().max_grid_bytes; },
          "the insertion budget: bytes of new cells one call may add to a sparse map")
      .def("scratch_bytes", &ScanInserter::scratch_bytes, "Bytes held by the scratch buffers.")
      .def("release_scratch", &ScanInserter::release_scratch, "Frees every scratch buffer.");
  guarded_class<ProjectiveInserter> projective(
      m, "ProjectiveInserter",
      "Inserts depth images by projection (Grid.insert_depth_image_projective) with fixed options, keeping its\n"
      "scratch (per-pixel tables, block marks) between frames: the way to insert a depth stream at sensor rate.\n"
      "Thread safety: one inserter per thread; the grid needs exclusive access during a call.");
  projective
      .def(
          py::init([](double max_range, double min_range, unsigned threads, std::uint64_t max_grid_bytes,
                      double surface_band) {
            return ProjectiveInserter(make_options(max_range, min_range, threads, max_grid_bytes), surface_band);
          }),
          py::kw_only(), py::arg("max_range") = -1.0, py::arg("min_range") = 0.0, py::arg("threads") = 1u,
          py::arg("max_grid_bytes") = kDefaultInsertBudgetBytes, py::arg("surface_band") = kDefaultSurfaceBand,
          "max_range, min_range, threads and max_grid_bytes as for Grid.insert_point_cloud; surface_band: voxel edges\n"
          "in front of each return that get no miss (default 0.5). Raises ValueError for invalid options.")
      .def_property_readonly("max_range", [](const ProjectiveInserter& s) { return s.options().max_range; })
      .def_property_readonly("threads", [](const ProjectiveInserter& s) { return s.options().threads; })
      .def_property_readonly("surface_band", &ProjectiveInserter::surface_band)
      .def("scratch_bytes", &ProjectiveInserter::scratch_bytes, "Bytes held by the scratch.")
      .def("release_scratch", &ProjectiveInserter::release_scratch, "Frees the scratch.");
  for_each_grid([&]<class G>() { add_insertion<G>(m, inserter, projective); });
}

}  // namespace intervox::python
