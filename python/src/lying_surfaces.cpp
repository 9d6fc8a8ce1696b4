/// \file
/// Surfaces that lie, found and named, from Python (analysis/lying_surfaces.hpp): LyingKind,
/// LyingSurface, find_lying_surfaces() and resolve_mirrors() on an ExplainedSpace.

#include "common.hpp"

#include <intervox/analysis/lying_surfaces.hpp>

#include "explain_bind.hpp"

#include <cstdio>
#include <span>
#include <string>
#include <vector>

namespace intervox::python {

void bind_lying_surfaces(py::module_& m) {
  py::enum_<LyingKind>(m, "LyingKind",
                       "What a lying region is (docs/concepts.md, \"Surfaces that lie, found and named\").")
      .value("MIRROR", LyingKind::Mirror, "its suspect returns are real surfaces reflected about a plane")
      .value("OPENING", LyingKind::Opening,
             "its suspect returns end on surfaces the map supports: real space seen through an opening")
      .value("BLACK", LyingKind::Black, "carved mostly by suspect beams without a return")
      .value("UNRESOLVED", LyingKind::Unresolved, "none of these");

  py::class_<LyingSurface>(m, "LyingSurface",
                           "One region that only lying beams made free, named (find_lying_surfaces). Read-only.")
      .def_readonly("kind", &LyingSurface::kind)
      .def_property_readonly(
          "surface", [](const LyingSurface& s) -> py::object { return s.has_plane ? py::cast(s.surface) : py::none(); },
          "The PlanePatch (a mirror: the plane found; else the plane of the points where the beams enter the\n"
          "region), its normal turned towards the beams' origins; None if the beams gave no plane.")
      .def_readonly("voxels", &LyingSurface::voxels, "the region's voxels (free only by lying beams)")
      .def_property_readonly(
          "extent", [](const LyingSurface& s) { return from_key_box(s.extent); },
          "their key box, (2, 3) int32 [[min], [max]]")
      .def_readonly("suspect_misses", &LyingSurface::suspect_misses, "suspect misses summed over the region's voxels")
      .def_readonly("no_return_misses", &LyingSurface::no_return_misses,
                    "misses of beams without a return, summed likewise")
      .def_readonly("returned_beams", &LyingSurface::returned_beams,
                    "returned suspect beams of the ledger that enter the region")
      .def_readonly("silent_beams", &LyingSurface::silent_beams, "suspect beams without a return that enter it")
      .def_readonly("searched_beams", &LyingSurface::searched_beams, "returned ones the plane search looked at")
      .def_readonly("mirror_votes", &LyingSurface::mirror_votes, "of those, the votes for the best plane")
      .def_readonly("mirror_crossing", &LyingSurface::mirror_crossing, "of those, the ones that cross the best plane")
      .def_readonly("real_ends", &LyingSurface::real_ends, "returned suspect beams that end on a supported surface")
      .def_readonly(
          "consistent_ends", &LyingSurface::consistent_ends,
          "returned beams (any class) crossing the best plane where its votes cross it whose end, reflected about "
          "it, lands on a supported voxel (0 unless the plane had the votes)")
      .def_readonly("inconsistent_ends", &LyingSurface::inconsistent_ends,
                    "... and those whose reflected end lands in space trusted beams crossed and never hit")
      .def_property_readonly(
          "best_normal", [](const LyingSurface& s) { return s.best_normal; },
          "the plane search's best plane, whatever the verdict: best_normal . p = best_offset")
      .def_readonly("best_offset", &LyingSurface::best_offset)
      .def("__repr__", [](const LyingSurface& s) {
        char buf[160];
        std::snprintf(buf, sizeof buf,
                      "LyingSurface(kind=%s, voxels=%zu, returned_beams=%zu, silent_beams=%zu, mirror_votes=%zu)",
                      std::string(to_string(s.kind)).c_str(), s.voxels, s.returned_beams, s.silent_beams,
                      s.mirror_votes);
        return std::string(buf);
      });

  m.def("find_lying_surfaces",
        guarded([](const ExplainedSpace& space, std::size_t min_region_voxels, std::size_t min_mirror_votes,
                   double min_mirror_share, double normal_step_deg, double max_tilt_deg, double tilt_step_deg,
                   std::size_t max_search_beams, std::size_t min_opening_beams, double opening_share, double grow_reach,
                   double max_inconsistent_share, unsigned threads) {
          LyingSurfaceParams p;
          p.min_region_voxels = min_region_voxels;
          p.min_mirror_votes = min_mirror_votes;
          p.min_mirror_share = min_mirror_share;
          p.normal_step_deg = normal_step_deg;
          p.max_tilt_deg = max_tilt_deg;
          p.tilt_step_deg = tilt_step_deg;
          p.max_search_beams = max_search_beams;
          p.min_opening_beams = min_opening_beams;
          p.opening_share = opening_share;
          p.grow_reach = grow_reach;
          p.max_inconsistent_share = max_inconsistent_share;
          p.threads = threads;
          p.validate();
          py::gil_scoped_release release;
          return find_lying_surfaces(space, p);
        }),
        py::arg("space"), py::kw_only(), py::arg("min_region_voxels") = LyingSurfaceParams{}.min_region_voxels,
        py::arg("min_mirror_votes") = LyingSurfaceParams{}.min_mirror_votes,
        py::arg("min_mirror_share") = LyingSurfaceParams{}.min_mirror_share,
        py::arg("normal_step_deg") = LyingSurfaceParams{}.normal_step_deg,
        py::arg("max_tilt_deg") = LyingSurfaceParams{}.max_tilt_deg,
        py::arg("tilt_step_deg") = LyingSurfaceParams{}.tilt_step_deg,
        py::arg("max_search_beams") = LyingSurfaceParams{}.max_search_beams,
        py::arg("min_opening_beams") = LyingSurfaceParams{}.min_opening_beams,
        py::arg("opening_share") = LyingSurfaceParams{}.opening_share,
        py::arg("grow_reach") = LyingSurfaceParams{}.grow_reach,
        py::arg("max_inconsistent_share") = LyingSurfaceParams{}.max_inconsistent_share,
        py::arg("threads") = LyingSurfaceParams{}.threads,
        "The regions of an ExplainedSpace that only lying beams made free, each named mirror, opening, black or\n"
        "unresolved with its plane and evidence counts (a list of LyingSurface, in the order of their smallest key).\n"
        "Reads the channel's ledger (a channel made with ledger_bytes=0, or loaded from a file, has no beams to\n"
        "look at: every region it finds is unresolved). The parameters are LyingSurfaceParams' (docs/\n"
        "concepts.md); threads: 1 = calling thread, 0 = all cores (the same result for every count). Raises\n"
        "ValueError naming the first invalid parameter.");
  m.def("resolve_mirrors", guarded([](ExplainedSpace& space, const std::vector<LyingSurface>& surfaces) {
          py::gil_scoped_release release;
          return resolve_mirrors(space, std::span<const LyingSurface>(surfaces));
        }),
        py::arg("space"), py::arg("surfaces"),
        "Tells the space of every mirror among surfaces (ExplainedSpace.add_mirror); returns how many.");
}

}  // namespace intervox::python
