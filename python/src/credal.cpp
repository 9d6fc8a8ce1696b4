/// \file
/// The credal grids (docs/concepts.md "Beyond the thesis: credal cells"): the imprecise Dirichlet
/// counts (DirichletGrid, DenseDirichletGrid) and Dempster–Shafer belief (BeliefGrid,
/// DenseBeliefGrid), with their parameters, the per-cell evidence (counts, masses, conflict mass)
/// and every method the other grids have (the per-grid templates of the *_bind.hpp headers,
/// instantiated here only, so that the other sources do not grow).

#include "grids_bind.hpp"
#include "insertion_bind.hpp"
#include "io_bind.hpp"
#include "planners_bind.hpp"
#include "queries_bind.hpp"

#include <cstdint>
#include <sstream>
#include <string>
#include <vector>
#include <intervox/update/dempster_shafer.hpp>
#include <intervox/update/imprecise_dirichlet.hpp>
#include <intervox/update/interval_update.hpp>

namespace intervox::python {

namespace {

/// Evaluates f(cell, out) for every point, writing `width` values per point (shape (..., width)).
/// \throws InvalidArgument (ValueError) for a NaN or infinite point, before anything is computed.
template <class T, class G, class F>
py::array_t<T> per_point_n(const G& g, const py::object& points, const char* what, py::ssize_t width, F&& f) {
  const PointsView pts(points, what);
  for (std::size_t i = 0; i < pts.size(); ++i)
    if (!is_finite(pts[i]))
      throw InvalidArgument(std::string(what) + ": point " + std::to_string(i) + " has a NaN or infinite coordinate");
  auto out = make_array<T>(pts.shape(), {width});
  T* w = out.mutable_data();
  {
    py::gil_scoped_release release;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const auto k = g.try_key(pts[i]);
      f(k ? g.cell(*k) : g.update_policy().unobserved(), w + static_cast<py::ssize_t>(i) * width);
    }
  }
  return out;
}

void bind_params(py::module_& m) {
  py::enum_<DirichletForgetting>(m, "DirichletForgetting", "What an imprecise Dirichlet cell does at a full counter.")
      .value("SATURATE", DirichletForgetting::Saturate, "the full counter stops counting: nothing is forgotten")
      .value("HALVE_AT_MAX", DirichletForgetting::HalveAtMax, "both counters are halved (rounded up) before the step");
  py::class_<DirichletParams>(
      m, "DirichletParams",
      "Parameters of the imprecise Dirichlet model: with h hits, m misses (N = h + m) and prior "
      "strength s\nthe interval is [h / (N + s), (h + s) / (N + s)].")
      .def(py::init([](double prior_strength, double free_threshold, double occupied_threshold,
                       DirichletForgetting forgetting, std::uint32_t max_count) {
             return DirichletParams{prior_strength, free_threshold, occupied_threshold, forgetting, max_count};
           }),
           py::kw_only(), py::arg("prior_strength") = DirichletParams{}.prior_strength,
           py::arg("free_threshold") = DirichletParams{}.free_threshold,
           py::arg("occupied_threshold") = DirichletParams{}.occupied_threshold,
           py::arg("forgetting") = DirichletParams{}.forgetting, py::arg("max_count") = DirichletParams{}.max_count)
      .def_readwrite("prior_strength", &DirichletParams::prior_strength,
                     "s > 0: the width after N observations is s / (N + s)")
      .def_readwrite("free_threshold", &DirichletParams::free_threshold, "free at or below")
      .def_readwrite("occupied_threshold", &DirichletParams::occupied_threshold, "occupied at or above")
      .def_readwrite("forgetting", &DirichletParams::forgetting, "what a full counter does (DirichletForgetting)")
      .def_readwrite("max_count", &DirichletParams::max_count, "counter limit, in [2, 65535]")
      .def(
          "validate", [](const DirichletParams& p) { ImpreciseDirichletUpdate<MeanState>::validate(p); },
          "Raises ValueError naming the first violated rule.")
      .def("__eq__",
           [](const DirichletParams& a, const DirichletParams& b) {
             return ImpreciseDirichletUpdate<MeanState>(a) == ImpreciseDirichletUpdate<MeanState>(b);
           })
      .def("__repr__", [](const DirichletParams& p) {
        std::ostringstream s;
        s << "DirichletParams(prior_strength=" << p.prior_strength << ", free_threshold=" << p.free_threshold
          << ", occupied_threshold=" << p.occupied_threshold
          << ", forgetting=" << (p.forgetting == DirichletForgetting::Saturate ? "SATURATE" : "HALVE_AT_MAX")
          << ", max_count=" << p.max_count << ")";
        return s.str();
      });
  py::enum_<BeliefCombination>(m, "BeliefCombination", "How a Dempster–Shafer cell combines a measurement.")
      .value("DEMPSTER", BeliefCombination::Dempster,
             "Dempster's rule: the conflicting mass K is removed, the rest renormalised")
      .value("CONJUNCTIVE", BeliefCombination::Conjunctive,
             "the conjunctive rule: the same masses, and the accumulated conflict 1 - prod(1 - K_i) is kept");
  py::class_<BeliefParams>(
      m, "BeliefParams",
      "Parameters of the Dempster–Shafer update: a hit is m({occ}) = hit_support, a miss m({free}) = "
      "miss_support,\nthe rest on ignorance; after each step the masses are discounted by `discount`.")
      .def(py::init([](double hit_support, double miss_support, double discount, double free_threshold,
                       double occupied_threshold, BeliefCombination combination) {
             return BeliefParams{hit_support, miss_support, discount, free_threshold, occupied_threshold, combination};
           }),
           py::kw_only(), py::arg("hit_support") = BeliefParams{}.hit_support,
           py::arg("miss_support") = BeliefParams{}.miss_support, py::arg("discount") = BeliefParams{}.discount,
           py::arg("free_threshold") = BeliefParams{}.free_threshold,
           py::arg("occupied_threshold") = BeliefParams{}.occupied_threshold,
           py::arg("combination") = BeliefParams{}.combination)
      .def_readwrite("hit_support", &BeliefParams::hit_support, "mass a hit puts on {occupied}, in (0, 1)")
      .def_readwrite("miss_support", &BeliefParams::miss_support, "mass a miss puts on {free}, in (0, 1)")
      .def_readwrite("discount", &BeliefParams::discount, "minimum ignorance kept after each step, in [0, 0.5)")
      .def_readwrite("free_threshold", &BeliefParams::free_threshold, "free at or below")
      .def_readwrite("occupied_threshold", &BeliefParams::occupied_threshold, "occupied at or above")
      .def_readwrite("combination", &BeliefParams::combination, "combination rule (BeliefCombination)")
      .def(
          "validate", [](const BeliefParams& p) { DempsterShaferUpdate<MeanState>::validate(p); },
          "Raises ValueError naming the first violated rule.")
      .def("__eq__",
           [](const BeliefParams& a, const BeliefParams& b) {
             return DempsterShaferUpdate<MeanState>(a) == DempsterShaferUpdate<MeanState>(b);
           })
      .def("__repr__", [](const BeliefParams& p) {
        std::ostringstream s;
        s << "BeliefParams(hit_support=" << p.hit_support << ", miss_support=" << p.miss_support
          << ", discount=" << p.discount << ", free_threshold=" << p.free_threshold
          << ", occupied_threshold=" << p.occupied_threshold
          << ", combination=" << (p.combination == BeliefCombination::Dempster ? "DEMPSTER" : "CONJUNCTIVE") << ")";
        return s.str();
      });
}

/// The per-cell evidence of a credal grid: counts (Dirichlet), masses and conflict (belief).
template <class G>
void add_evidence(py::module_& m) {
  using Cell = typename G::Cell;
  using U = typename G::UpdateType;
  auto c = grid_class<G>(m);
  if constexpr (std::is_same_v<Cell, DirichletCell>) {
    c.def(
        "evidence",
        [](const G& g, const py::object& points) {
          return per_point_n<std::int64_t>(g, points, "evidence: points", 2, [](const Cell& cell, std::int64_t* w) {
            w[0] = cell.hits;
            w[1] = cell.misses;
          });
        },
        py::arg("points"),
        "Hit and miss counts (int64, shape (..., 2)) of each point's voxel; [0, 0] where unobserved.\n"
        "Raises ValueError for NaN/Inf points.");
  } else {
    c.def(
        "masses",
        [](const G& g, const py::object& points) {
          const U& u = g.update_policy();
          return per_point_n<double>(g, points, "masses: points", 3, [&u](const Cell& cell, double* w) {
            const Interval i = u.interval(cell);  // [Bel(occ), Pl(occ)] = [m(occ), 1 - m(free)]
            w[0] = i.lower;
            w[1] = 1.0 - i.upper;
            w[2] = i.upper - i.lower;
          });
        },
        py::arg("points"),
        "Masses [m({occ}), m({free}), m(ignorance)] (float64, shape (..., 3)) of each point's voxel; [0, 0, 1] where\n"
        "unobserved. Raises ValueError for NaN/Inf points.");
    c.def(
        "conflict",
        [](const G& g, const py::object& points) {
          return bind::per_point<double>(g, points, "conflict: points",
                                         [](const Cell& cell) { return U::conflict(cell); });
        },
        py::arg("points"),
        "The accumulated conflict mass 1 - prod(1 - K_i) (float64, shape (...)) of each point's voxel under the\n"
        "conjunctive rule; 0 under Dempster's rule and where unobserved. Raises ValueError for NaN/Inf points.");
  }
}

}  // namespace

void bind_credal(py::module_& m) {
  bind_params(m);
  guarded_class<ScanInserter> inserter(py::reinterpret_borrow<py::class_<ScanInserter>>(m.attr("ScanInserter")));
  guarded_class<ProjectiveInserter> projective(
      py::reinterpret_borrow<py::class_<ProjectiveInserter>>(m.attr("ProjectiveInserter")));
  guarded_class<MobilePlanner> mobile(py::reinterpret_borrow<py::class_<MobilePlanner>>(m.attr("MobilePlanner")));
  guarded_class<ArmPlanner> arm(py::reinterpret_borrow<py::class_<ArmPlanner>>(m.attr("ArmPlanner")));
  guarded_class<bind::PyEpisode> episode(py::reinterpret_borrow<py::class_<bind::PyEpisode>>(m.attr("Episode")));
  for_each_credal_grid([&]<class G>() {
    bind::bind_grid<G>(m);
    bind::add_insertion<G>(m, inserter, projective);
    bind::add_queries<G>(m);
    bind::add_io<G>(m);
    bind::add_planning<G>(mobile, arm, episode);
    add_evidence<G>(m);
  });
}

}  // namespace intervox::python
