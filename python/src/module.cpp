/// \file
/// The Python module `intervox._intervox` (re-exported by the package `intervox`).

#include "common.hpp"

#include <intervox/grid/named_grids.hpp>
#include <intervox/version.hpp>

#include <string>

namespace intervox::python {
void bind_explain(py::module_& m);         // explain.cpp: ExplainedSpace, BeamClass, ExplainedState, PlanePatch
void bind_lying_surfaces(py::module_& m);  // lying_surfaces.cpp: LyingKind, LyingSurface, find_lying_surfaces
}  // namespace intervox::python

PYBIND11_MODULE(_intervox, m) {
  namespace iv = intervox::python;
  m.doc() = "Intervox: probabilistic voxel mapping with interval probabilities and next-best-view planning.\n\n"
            "Grids (BayesGrid, IntervalGrid, ...) take numpy arrays: points as (N, 3) float32/float64,\n"
            "depth images as (H, W), poses as (4, 4). See docs/python.md.";
  m.attr("__version__") = std::to_string(INTERVOX_VERSION_MAJOR) + "." + std::to_string(INTERVOX_VERSION_MINOR) + "." +
                          std::to_string(INTERVOX_VERSION_PATCH);
  iv::bind_core(m);
  iv::bind_grids(m);
  iv::bind_insertion(m);
  iv::bind_explain(m);
  iv::bind_lying_surfaces(m);
  iv::bind_queries(m);
  iv::bind_io(m);
  iv::bind_simulator(m);
  iv::bind_planners(m);
  iv::bind_credal(m);
}
