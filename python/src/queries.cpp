/// \file
/// Vectorised queries on every grid type: probabilities, intervals, classes, utilities for arrays
/// of points; every observed voxel as arrays; cast_ray.

#include "queries_bind.hpp"

#include <intervox/raycast/cast.hpp>

#include <cmath>

namespace intervox::python {

using namespace bind;

void bind_queries(py::module_& m) {
  py::enum_<CastStatus>(m, "CastStatus", "How a cast ended.")
      .value("OCCUPIED", CastStatus::Occupied)
      .value("UNKNOWN", CastStatus::Unknown)
      .value("MAX_RANGE", CastStatus::MaxRange)
      .value("LEFT_GRID", CastStatus::LeftGrid)
      .value("INVALID", CastStatus::Invalid);
  py::class_<CastHit>(m, "CastResult", "Result of cast_ray.")
      .def_readonly("status", &CastHit::status)
      .def_property_readonly(
          "key", [](const CastHit& h) { return py::make_tuple(h.key.x, h.key.y, h.key.z); },
          "the voxel where the cast stopped (the last one examined otherwise)")
      .def_readonly("center", &CastHit::center, "centre of that voxel")
      .def_readonly("distance", &CastHit::distance, "distance from the origin to where the ray enters the voxel")
      .def_readonly("voxels", &CastHit::voxels, "voxels examined")
      .def_property_readonly("hit", [](const CastHit& h) { return h.status == CastStatus::Occupied; })
      .def("__repr__", [](const CastHit& h) {
        return "CastResult(status=" + std::to_string(int(h.status)) + ", key=(" + std::to_string(h.key.x) + ", " +
               std::to_string(h.key.y) + ", " + std::to_string(h.key.z) + "), distance=" + std::to_string(h.distance) +
               ")";
      });
  for_each_grid([&]<class G>() { add_queries<G>(m); });
}

}  // namespace intervox::python
