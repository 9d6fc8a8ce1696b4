#pragma once
/// \file
/// The per-grid bindings of python/src/grids.cpp (the template bind_/add_ functions and their
/// helpers), shared with credal.cpp, which instantiates them for the credal grids.

#include "guard.hpp"
#include <optional>
#include <sstream>
#include <string_view>
#include <intervox/update/bayes_log_odds.hpp>

namespace intervox::python::bind {

template <class G>
G make_grid(double resolution, const py::object& bounds, const ParamsOf<G>& params, const py::object& origin) {
  using U = typename G::UpdateType;
  std::optional<Bounds> b;
  if (!bounds.is_none()) b = to_bounds(bounds);
  if constexpr (G::StorageType::kBounded) {
    if (!b) throw InvalidArgument(std::string(kGridName<G>) + ": a dense grid needs bounds");
  }
  const Point3 o = origin.is_none() ? Point3::Zero() : py::cast<Point3>(origin);
  return G(GridGeometry(resolution, o), b, U(params));
}

inline std::string_view storage_doc(bool bounded) {
  return bounded ? "dense storage: a flat array over the bounds given at construction (bounds required)"
                 : "sparse storage: unbounded hashed 8^3 blocks (bounds optional)";
}

template <class G>
void bind_grid(py::module_& m) {
  using P = ParamsOf<G>;
  using U = typename G::UpdateType;
  constexpr bool bounded = G::StorageType::kBounded;
  const std::string name = kGridName<G>;
  const std::string doc = name + ": a voxel occupancy grid with the '" + std::string(U::kName) + "' update, the '" +
                          std::string(G::UtilityType::kName) + "' utility and " + std::string(storage_doc(bounded)) +
                          ".\n\nConstruct with " + name +
                          "(resolution, bounds=None, params=None, origin=None); points are numpy arrays of shape "
                          "(N, 3).\nThread safety: queries may run concurrently; insertion, updates and clear need the "
                          "grid alone (the GIL is released while C++ works). A call that finds the grid in use by "
                          "another thread in a conflicting way raises RuntimeError instead.";
  guarded_class<G> c(m, name.c_str(), doc.c_str());
  c.def(py::init([](double resolution, const py::object& bounds, const py::object& params, const py::object& origin) {
          if (!params.is_none() && !py::isinstance<P>(params))
            throw py::type_error(std::string(kGridName<G>) + ": params must be " +
                                 py::str(py::type::of<P>().attr("__name__")).cast<std::string>());
          const P p = params.is_none() ? P{} : py::cast<P>(params);
          return make_grid<G>(resolution, bounds, p, origin);
        }),
        py::arg("resolution"), py::arg("bounds") = py::none(), py::arg("params") = py::none(),
        py::arg("origin") = py::none(),
        "resolution: voxel edge in metres (> 0); bounds: Bounds or (min, max) limiting the grid (required for "
        "dense grids); params: the policy parameters (default: the class's defaults); origin: corner of voxel "
        "(0, 0, 0).\nRaises ValueError for invalid arguments.");
  if constexpr (requires { P::thesis(); }) {  // the credal cells have no thesis preset
    c.def_static(
        "thesis",
        [](double resolution, const py::object& bounds) {
          return make_grid<G>(resolution, bounds, P::thesis(), py::none());
        },
        py::arg("resolution"), py::arg("bounds") = py::none(), "A grid with the thesis' parameters (params.thesis()).");
  }
  if constexpr (std::is_same_v<P, BayesParams>) {
    c.def_static(
        "octomap",
        [](double resolution, const py::object& bounds) {
          return make_grid<G>(resolution, bounds, P::octomap(), py::none());
        },
        py::arg("resolution"), py::arg("bounds") = py::none(),
        "A grid with OctoMap's parameters (BayesParams.octomap()).");
  }
  c.def_property_readonly_static(
      "policy", [](const py::object&) { return std::string(U::kName); }, "name of the update policy, as in grid files");
  c.def_property_readonly_static("utility_name", [](const py::object&) { return std::string(G::UtilityType::kName); });
  c.def_property_readonly_static("storage", [](const py::object&) { return std::string(G::StorageType::kName); });
  c.def_property_readonly("resolution", &G::resolution, "voxel edge length in metres");
  c.def_property_readonly(
      "origin", [](const G& g) { return Point3(g.geometry().origin()); }, "corner of voxel (0, 0, 0)");
  c.def_property_readonly(
      "params", [](const G& g) { return P(g.update_policy().params()); }, "a copy of the update policy's parameters");
  c.def_property_readonly(
      "key_box",
      [](const G& g) -> py::object {
        if (!g.key_box()) return py::none();
        return from_key_box(*g.key_box());
      },
      "the (2, 3) int32 key box [[min], [max]] the grid is limited to, or None");
  c.def("observed_count", &G::observed_count, "Number of observed voxels (O(allocated cells)).");
  c.def("counts", &G::counts, "Observed voxels by class (OccupancyCounts).");
  c.def("memory_bytes", &G::memory_bytes, "Bytes held by the grid's storage.");
  c.def("clear", &G::clear, "Forgets every observation.");
  c.def(
      "copy", [](const G& g) { return G(g); }, "A deep copy of the grid.");
  c.def("__copy__", [](const G& g) { return G(g); });
  c.def(
      "__deepcopy__", [](const G& g, const py::object&) { return G(g); }, py::arg("memo"));
  c.def(
      "keys",
      [](const G& g, const py::object& points) {
        const PointsView pts(points, "keys: points");
        auto out = make_array<std::int32_t>({static_cast<py::ssize_t>(pts.size())}, {3});
        auto w = out.template mutable_unchecked<2>();
        for (std::size_t i = 0; i < pts.size(); ++i) {
          const Key k = g.key(pts[i]);
          for (int a = 0; a < 3; ++a) w(static_cast<py::ssize_t>(i), a) = k[a];
        }
        std::vector<py::ssize_t> shape = pts.shape();
        shape.push_back(3);
        return out.reshape(shape);
      },
      py::arg("points"),
      "Keys (int32, shape (..., 3)) of the voxels containing the points.\n"
      "Raises ValueError for a NaN/Inf point, IndexError for one outside the key range.");
  c.def(
      "centers",
      [](const G& g, const py::array_t<std::int64_t, py::array::forcecast>& keys) {
        if (keys.ndim() < 1 || keys.shape(keys.ndim() - 1) != 3)
          throw InvalidArgument("centers: expected keys of shape (N, 3)");
        auto flat = py::array_t<std::int64_t, py::array::forcecast | py::array::c_style>::ensure(keys);
        const auto n = static_cast<std::size_t>(flat.size() / 3);
        const std::int64_t* k = flat.data();
        py::array_t<double> out(std::vector<py::ssize_t>(keys.shape(), keys.shape() + keys.ndim()));
        double* o = out.mutable_data();
        for (std::size_t i = 0; i < 3 * n; ++i)
          if (k[i] < -kKeyLimit || k[i] >= kKeyLimit)
            throw OutOfRange("centers: key " + std::to_string(i / 3) + " has the coordinate " + std::to_string(k[i]) +
                             ", outside the key range [" + std::to_string(-kKeyLimit) + ", " +
                             std::to_string(kKeyLimit - 1) + "]");
        for (std::size_t i = 0; i < n; ++i) {
          const Point3 p =
              g.geometry().center(Key{static_cast<std::int32_t>(k[3 * i]), static_cast<std::int32_t>(k[3 * i + 1]),
                                      static_cast<std::int32_t>(k[3 * i + 2])});
          for (int a = 0; a < 3; ++a) o[3 * i + a] = p[a];
        }
        return out;
      },
      py::arg("keys"),
      "Centres (float64, shape (..., 3)) of the voxels with the given keys.\n"
      "Raises IndexError for a key outside the key range [-2^23, 2^23 - 1] (nothing is wrapped).");
  c.def(
      "update",
      [](G& g, const py::object& points, Observation o) {
        const PointsView pts(points, "update: points");
        for (std::size_t i = 0; i < pts.size(); ++i)
          if (!is_finite(pts[i]))
            throw InvalidArgument("update: point " + std::to_string(i) + " has a NaN or infinite coordinate");
        auto out = make_array<bool>(pts.shape());
        bool* w = out.mutable_data();
        {
          py::gil_scoped_release release;
          for (std::size_t i = 0; i < pts.size(); ++i) w[i] = g.update(pts[i], o);
        }
        return out;
      },
      py::arg("points"), py::arg("observation"),
      "Applies one observation to the voxel of each point (one update per point, duplicates included).\n"
      "Returns a bool array: False where the point lies outside the bounds or the key range.\n"
      "Raises ValueError (and changes nothing) if any point has a NaN or infinite coordinate.");
  c.def("__repr__", [name](const G& g) {
    std::ostringstream s;
    s << name << "(resolution=" << g.resolution() << ", observed=" << g.observed_count();
    if (g.key_box()) {
      const KeyBox& b = *g.key_box();
      s << ", key_box=[(" << b.min.x << ", " << b.min.y << ", " << b.min.z << "), (" << b.max.x << ", " << b.max.y
        << ", " << b.max.z << ")]";
    }
    s << ")";
    return s.str();
  });
}

}  // namespace intervox::python::bind
