/// \file
/// Explained free space from Python: ExplainedSpace with its beam classes, evidence, belief and
/// states as numpy arrays (explain/explained_space.hpp). The grid's own insertion is called
/// through the grid's binding, so the grid is updated exactly as by grid.insert_beams.

#include "common.hpp"

#include <intervox/core/plane_patch.hpp>
#include <intervox/explain/explain.hpp>
#include <intervox/io/explained_file.hpp>

#include "explain_bind.hpp"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <span>
#include <string>
#include <vector>

namespace intervox::python {

namespace {

/// The name of \p o's type, for messages ("dict", "NoneType").
std::string type_name(const py::handle& o) { return py::str(py::type::of(o).attr("__name__")).cast<std::string>(); }

/// The attribute \p name of the grid given to ExplainedSpace.insert_beams as a T, or a TypeError
/// that names the attribute, what it holds and what it must hold (not pybind11's "Unable to cast").
template <class T>
T grid_attribute(const py::object& grid, const char* name, const char* expected) {
  if (!py::hasattr(grid, name))
    throw py::type_error(std::string("ExplainedSpace.insert_beams: the grid (a ") + type_name(grid) + ") has no '" +
                         name + "': `grid` must be an intervox grid (BayesGrid, IntervalGrid, ...)");
  const py::object v = grid.attr(name);
  try {
    return v.cast<T>();
  } catch (const py::cast_error&) {
    throw py::type_error(std::string("ExplainedSpace.insert_beams: the grid's '") + name + "' is a " + type_name(v) +
                         ", expected " + expected + ": `grid` must be an intervox grid (BayesGrid, IntervalGrid, ...)");
  }
}

/// The method \p name of that grid, or a TypeError naming it.
py::object grid_method(const py::object& grid, const char* name) {
  if (!py::hasattr(grid, name) || !PyCallable_Check(grid.attr(name).ptr()))
    throw py::type_error(std::string("ExplainedSpace.insert_beams: the grid (a ") + type_name(grid) +
                         ") has no method '" + name +
                         "': `grid` must be an intervox grid (BayesGrid, IntervalGrid, ...)");
  return grid.attr(name);
}

InsertOptions explain_insert_options(double max_range, double min_range, unsigned threads) {
  InsertOptions o;
  o.max_range = max_range;
  o.min_range = min_range;
  o.threads = threads;
  o.validate();
  return o;
}

/// Evaluates f(key) -> row of T (width columns, width 0: a scalar) for every point.
template <class T, class F>
py::array_t<T> per_key(const ExplainedSpace& s, const py::object& points, const char* what, int width, F&& f) {
  const PointsView pts(points, what);
  auto out = width == 0 ? make_array<T>(pts.shape()) : make_array<T>(pts.shape(), {width});
  T* w = out.mutable_data();
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const Point3 p = pts[i];
    if (!is_finite(p))
      throw InvalidArgument(std::string(what) + ": point " + std::to_string(i) + " has a NaN or infinite coordinate");
    const auto k = s.geometry().try_key(p);
    f(k, w + i * static_cast<std::size_t>(width == 0 ? 1 : width));
  }
  return out;
}

std::vector<BeamClass> classes_from_numpy(const py::handle& obj, std::size_t n) {
  const py::array raw = py::array::ensure(obj);
  if (!raw || raw.ndim() != 1 || static_cast<std::size_t>(raw.shape(0)) != n ||
      (raw.dtype().kind() != 'i' && raw.dtype().kind() != 'u'))
    throw InvalidArgument("ExplainedSpace.add: classes must be an integer array of shape (" + std::to_string(n) +
                          ",) (BeamClass values, as classify() returns)");
  auto a = py::array_t<std::int64_t, py::array::forcecast>::ensure(raw);
  auto r = a.unchecked<1>();
  std::vector<BeamClass> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::int64_t v = r(static_cast<py::ssize_t>(i));
    if (v < 0 || v > 3)
      throw InvalidArgument("ExplainedSpace.add: class " + std::to_string(v) + " at " + std::to_string(i) +
                            " is no BeamClass");
    out[i] = static_cast<BeamClass>(v);
  }
  return out;
}

constexpr const char* kClassDoc =
    "origins (N, 3) or one (3,) origin, ends (N, 3), hits (N,) bool or None (all hits; a beam without a hit is\n"
    "no return, free up to max_range); max_range, min_range: the insertion's rules (a beam the insertion skips\n"
    "is SKIPPED); threads: 1 = calling thread, 0 = all cores (the same result for every count).";

}  // namespace

void bind_explain(py::module_& m) {
  py::enum_<BeamClass>(m, "BeamClass", "How a beam is explained by the map as it stood when it was inserted.")
      .value("TRUSTED", BeamClass::Trusted, "returned, and the map explains it")
      .value("SUSPECT", BeamClass::Suspect,
             "crosses a supported surface (returned or not), or returned in explained-free space")
      .value("NO_RETURN", BeamClass::NoReturn,
             "nothing came back, and no supported surface lies within its range: never evidence that space is free")
      .value("SKIPPED", BeamClass::Skipped, "not inserted (invalid, too short, outside the key range)");
  py::enum_<ExplainedState>(m, "ExplainedState", "The explained state of a voxel.")
      .value("UNKNOWN", ExplainedState::Unknown, "no evidence")
      .value("FREE", ExplainedState::Free, "free on explained evidence")
      .value("OCCUPIED", ExplainedState::Occupied, "occupied on explained evidence")
      .value("UNEXPLAINED", ExplainedState::Unexplained,
             "evidence, but neither: suspect or no-return only, or conflict");

  py::class_<PlanePatch>(
      m, "PlanePatch",
      "A rectangle in a plane (core/plane_patch.hpp): a mirror told to ExplainedSpace.add_mirror, or the\n"
      "plane a LyingSurface names. axis_v = normal x axis_u; the rectangle spans +-half_u along axis_u and\n"
      "+-half_v along axis_v around the centre (metres).")
      .def(py::init(
               [](const Point3& center, const Point3& normal, double half_u, double half_v, const py::object& axis_u) {
                 PlanePatch p;
                 p.center = center;
                 p.normal = normal;
                 p.axis_u = axis_u.is_none() ? PlanePatch::floor_axis(normal) : py::cast<Point3>(axis_u);
                 p.half_u = half_u;
                 p.half_v = half_v;
                 p.validate();
                 return p;
               }),
           py::arg("center"), py::arg("normal"), py::arg("half_u"), py::arg("half_v"), py::kw_only(),
           py::arg("axis_u") = py::none(),
           "center, normal: (3,) (the normal a unit vector); half_u, half_v >= 0; axis_u: a unit vector orthogonal\n"
           "to the normal (None: horizontal, normal x z, or x for a horizontal plane). Raises ValueError otherwise.")
      .def_property_readonly("center", [](const PlanePatch& p) { return p.center; })
      .def_property_readonly("normal", [](const PlanePatch& p) { return p.normal; })
      .def_property_readonly("axis_u", [](const PlanePatch& p) { return p.axis_u; })
      .def_property_readonly("axis_v", [](const PlanePatch& p) { return p.axis_v(); })
      .def_readonly("half_u", &PlanePatch::half_u)
      .def_readonly("half_v", &PlanePatch::half_v)
      .def("__repr__", [](const PlanePatch& p) {
        char buf[256];
        std::snprintf(buf, sizeof buf,
                      "PlanePatch(center=(%.3f, %.3f, %.3f), normal=(%.3f, %.3f, %.3f), %.3f x %.3f m)", p.center.x(),
                      p.center.y(), p.center.z(), p.normal.x(), p.normal.y(), p.normal.z(), 2 * p.half_u, 2 * p.half_v);
        return std::string(buf);
      });

  guarded_class<ExplainedSpace> c(
      m, "ExplainedSpace",
      "Explained free space (docs/concepts.md): classes every beam of a scan against the map as it stood\n"
      "(trusted, suspect, no return) and keeps each class's evidence apart beside a grid, combined as a\n"
      "Dempster-Shafer belief with the suspect and no-return classes discounted. The grid's own update is\n"
      "unchanged. Thread safety: one call at a time per object (a call that finds it in use raises RuntimeError).");
  c.def(py::init([](double resolution, const Point3& origin, double hit_mass, double miss_mass,
                    double trusted_reliability, double suspect_reliability, double no_return_reliability,
                    double free_threshold, double occupied_threshold, int min_surface_hits, double surface_hit_ratio,
                    double crossing_tolerance, int mid_air_misses, std::size_t ledger_bytes, int revision_rounds,
                    int revision_interval, double no_return_crossing_angle, int min_lying_misses,
                    bool returned_crossing_inside) {
          ExplainOptions o;
          o.model.hit_mass = hit_mass;
          o.model.miss_mass = miss_mass;
          o.model.trusted_reliability = trusted_reliability;
          o.model.suspect_reliability = suspect_reliability;
          o.model.no_return_reliability = no_return_reliability;
          o.model.free_threshold = free_threshold;
          o.model.occupied_threshold = occupied_threshold;
          o.min_surface_hits = min_surface_hits;
          o.surface_hit_ratio = surface_hit_ratio;
          o.crossing_tolerance = crossing_tolerance;
          o.mid_air_misses = mid_air_misses;
          o.ledger_bytes = ledger_bytes;
          o.revision_rounds = revision_rounds;
          o.revision_interval = revision_interval;
          o.no_return_crossing_angle = no_return_crossing_angle;
          o.min_lying_misses = min_lying_misses;
          o.returned_crossing_inside = returned_crossing_inside;
          return ExplainedSpace(GridGeometry(resolution, origin), o);
        }),
        py::arg("resolution"), py::arg("origin") = Point3(Point3::Zero()), py::kw_only(), py::arg("hit_mass") = 0.7,
        py::arg("miss_mass") = 0.4, py::arg("trusted_reliability") = 1.0, py::arg("suspect_reliability") = 0.1,
        py::arg("no_return_reliability") = 0.0, py::arg("free_threshold") = 0.35, py::arg("occupied_threshold") = 0.5,
        py::arg("min_surface_hits") = 2, py::arg("surface_hit_ratio") = 1.0, py::arg("crossing_tolerance") = 0.15,
        py::arg("mid_air_misses") = 3, py::arg("ledger_bytes") = ExplainOptions{}.ledger_bytes,
        py::arg("revision_rounds") = ExplainOptions{}.revision_rounds,
        py::arg("revision_interval") = ExplainOptions{}.revision_interval,
        py::arg("no_return_crossing_angle") = ExplainOptions{}.no_return_crossing_angle,
        py::arg("min_lying_misses") = ExplainOptions{}.min_lying_misses,
        py::arg("returned_crossing_inside") = ExplainOptions{}.returned_crossing_inside,
        "An empty channel for grids of this resolution and origin (a grid's .resolution and .origin).\n"
        "ledger_bytes: the revision ledger's budget (the newest scans, classed again when the map changes where\n"
        "their beams pass; 0: every beam keeps the class of its arrival); revision_interval: scans between two\n"
        "revisions; revision_rounds: rounds of one revision at most; no_return_crossing_angle: degrees, how steeply\n"
        "a beam without a return must meet a supported surface's inside to count as passing it (then suspect);\n"
        "min_lying_misses: suspect misses a voxel needs to be free only by lying beams; returned_crossing_inside: a\n"
        "returned beam's crossing counts only at a surface's inside met that steeply, as a no-return beam's (False:\n"
        "any supported voxel counts; ExplainOptions::returned_crossing_inside).\n"
        "Raises ValueError naming the first invalid parameter.");
  c.def_property_readonly("resolution", [](const ExplainedSpace& s) { return s.geometry().resolution(); });
  c.def_property_readonly("origin", [](const ExplainedSpace& s) { return Point3(s.geometry().origin()); });
  c.def(
      "classify",
      [](const ExplainedSpace& s, const py::object& origins, const py::object& ends, const py::object& hits,
         double max_range, double min_range, unsigned threads) {
        const std::vector<Beam> beams = beams_from_numpy(origins, ends, hits);
        const InsertOptions o = explain_insert_options(max_range, min_range, threads);
        std::vector<BeamClass> classes;
        {
          py::gil_scoped_release release;
          classes = s.classify(std::span<const Beam>(beams), o);
        }
        py::array_t<std::uint8_t> out(static_cast<py::ssize_t>(classes.size()));
        for (std::size_t i = 0; i < classes.size(); ++i) out.mutable_data()[i] = static_cast<std::uint8_t>(classes[i]);
        return out;
      },
      py::arg("origins"), py::arg("ends"), py::arg("hits") = py::none(), py::kw_only(), py::arg("max_range") = -1.0,
      py::arg("min_range") = 0.0, py::arg("threads") = 1u,
      (std::string(
           "The class of each beam (uint8 array of BeamClass values) against the evidence so far; changes nothing.\n") +
       kClassDoc)
          .c_str());
  c.def(
      "add",
      [](ExplainedSpace& s, const py::object& origins, const py::object& ends, const py::object& hits,
         const py::object& classes, double max_range, double min_range, unsigned threads) {
        const std::vector<Beam> beams = beams_from_numpy(origins, ends, hits);
        const std::vector<BeamClass> cls = classes_from_numpy(classes, beams.size());
        const InsertOptions o = explain_insert_options(max_range, min_range, threads);
        py::gil_scoped_release release;
        return s.add(std::span<const Beam>(beams), std::span<const BeamClass>(cls), o);
      },
      py::arg("origins"), py::arg("ends"), py::arg("hits"), py::arg("classes"), py::kw_only(),
      py::arg("max_range") = -1.0, py::arg("min_range") = 0.0, py::arg("threads") = 1u,
      (std::string("Adds one scan's evidence, each beam to its class (classes: as classify() returned). Returns\n"
                   "InsertStats with beams_trusted, beams_suspect and beams_no_return.\n") +
       kClassDoc)
          .c_str());
  c.def(
      "insert_beams",
      [](ExplainedSpace& s, const py::object& grid, const py::object& origins, const py::object& ends,
         const py::object& hits, double max_range, double min_range, unsigned threads, std::uint64_t max_grid_bytes) {
        const double res = grid_attribute<double>(grid, "resolution", "a number");
        const Point3 origin = grid_attribute<Point3>(grid, "origin", "3 numbers");
        s.check_geometry(GridGeometry(res, origin), "ExplainedSpace.insert_beams");
        const std::vector<Beam> beams = beams_from_numpy(origins, ends, hits);
        InsertOptions o = explain_insert_options(max_range, min_range, threads);
        o.max_grid_bytes = max_grid_bytes;  // (the channel's scratch too: refused before the grid changes)
        ExplainedSpace::check_scan_scratch(beams.size(), o);
        std::vector<BeamClass> classes;
        {
          py::gil_scoped_release release;
          classes = s.classify(std::span<const Beam>(beams), o);
        }
        // The grid's own insertion, through its binding (its guard, its checks, its budget).
        const py::object returned = grid_method(grid, "insert_beams")(
            origins, ends, hits, py::arg("max_range") = max_range, py::arg("min_range") = min_range,
            py::arg("threads") = threads, py::arg("max_grid_bytes") = max_grid_bytes);
        if (!py::isinstance<InsertStats>(returned))
          throw py::type_error("ExplainedSpace.insert_beams: grid.insert_beams returned " + type_name(returned) +
                               ", not InsertStats: `grid` must be an intervox grid (BayesGrid, IntervalGrid, ...)");
        InsertStats st = returned.cast<InsertStats>();
        {
          py::gil_scoped_release release;
          const InsertStats counted = s.add(std::span<const Beam>(beams), std::span<const BeamClass>(classes), o);
          st.beams_trusted = counted.beams_trusted;
          st.beams_suspect = counted.beams_suspect;
          st.beams_no_return = counted.beams_no_return;
        }
        py::array_t<std::uint8_t> out(static_cast<py::ssize_t>(classes.size()));
        for (std::size_t i = 0; i < classes.size(); ++i) out.mutable_data()[i] = static_cast<std::uint8_t>(classes[i]);
        return py::make_tuple(st, out);
      },
      py::arg("grid"), py::arg("origins"), py::arg("ends"), py::arg("hits") = py::none(), py::kw_only(),
      py::arg("max_range") = -1.0, py::arg("min_range") = 0.0, py::arg("threads") = 1u,
      py::arg("max_grid_bytes") = kDefaultInsertBudgetBytes,
      (std::string("One scan: classes the beams against the evidence so far, inserts them into `grid` (any grid of\n"
                   "the channel's resolution and origin) by grid.insert_beams, unchanged, then adds their evidence.\n"
                   "Returns (InsertStats with the class counts, the classes as a uint8 array).\n") +
       kClassDoc +
       "\nmax_grid_bytes: the grid's insertion budget (as grid.insert_beams), and the channel's for the scan's\n"
       "scratch (about 218 bytes per beam); a scan over either raises ValueError before anything changes.")
          .c_str());
  c.def(
      "state",
      [](const ExplainedSpace& s, const py::object& points) {
        return per_key<std::uint8_t>(s, points, "state: points", 0, [&](const std::optional<Key>& k, std::uint8_t* w) {
          *w = static_cast<std::uint8_t>(k ? s.state(*k) : ExplainedState::Unknown);
        });
      },
      py::arg("points"), "The explained state (uint8 ExplainedState values, shape (...)) at each point.");
  c.def(
      "belief",
      [](const ExplainedSpace& s, const py::object& points) {
        return per_key<double>(s, points, "belief: points", 3, [&](const std::optional<Key>& k, double* w) {
          const ExplainedBelief b = k ? s.belief(*k) : ExplainedBelief{};
          w[0] = b.free;
          w[1] = b.occupied;
          w[2] = b.conflict;
        });
      },
      py::arg("points"),
      "The belief at each point, float64 (..., 3): Bel(free) (the lower probability of free), Bel(occupied)\n"
      "(1 - the upper probability of free) and Dempster's conflict.");
  c.def(
      "evidence",
      [](const ExplainedSpace& s, const py::object& points) {
        return per_key<std::uint16_t>(s, points, "evidence: points", 5,
                                      [&](const std::optional<Key>& k, std::uint16_t* w) {
                                        const EvidenceCell e = k ? s.evidence(*k) : EvidenceCell{};
                                        w[0] = e.trusted_hits;
                                        w[1] = e.trusted_misses;
                                        w[2] = e.suspect_hits;
                                        w[3] = e.suspect_misses;
                                        w[4] = e.no_return_misses;
                                      });
      },
      py::arg("points"),
      "The evidence at each point, uint16 (..., 5): scans that gave a trusted hit, a trusted miss, a suspect hit,\n"
      "a suspect miss, a no-return miss.");
  c.def_property_readonly(
      "trusted_extent",
      [](const ExplainedSpace& s) -> py::object {
        if (!s.trusted_extent()) return py::none();
        return from_key_box(*s.trusted_extent());
      },
      "The (2, 3) int32 key box [[min], [max]] of the trusted beams' walks (suspect and no-return beams never\n"
      "grow it), or None before the first trusted beam.");
  c.def(
      "add_mirror",
      [](ExplainedSpace& s, const PlanePatch& mirror, bool merge) {
        py::gil_scoped_release release;
        s.add_mirror(mirror, merge ? MirrorMerge::Grow : MirrorMerge::Keep);
      },
      py::arg("mirror"), py::kw_only(), py::arg("merge") = true,
      "Tells the channel of a mirror (found by find_lying_surfaces, or known to you): from now on every beam\n"
      "through it (more than crossing_tolerance before its end) is suspect, the ledger's kept ones included\n"
      "(the revision rounds follow), and its voxels are explained occupied. With merge (the default) a mirror in\n"
      "the plane of a known one grows it; merge=False keeps it as given (walls on both sides of a doorway).\n"
      "Saved by save(). Raises ValueError for an invalid patch.");
  c.def_property_readonly(
      "mirrors", [](const ExplainedSpace& s) { return s.mirrors(); },
      "The mirrors the channel was told of (a list of PlanePatch, in order; grown ones as grown).");
  c.def(
      "on_mirror",
      [](const ExplainedSpace& s, const py::object& points) {
        return per_key<bool>(s, points, "on_mirror: points", 0,
                             [&](const std::optional<Key>& k, bool* w) { *w = k && s.on_mirror(*k); });
      },
      py::arg("points"), "True where the point's voxel lies on a known mirror (bool array, shape (...)).");
  c.def("size", &ExplainedSpace::size, "Voxels with evidence.");
  c.def("memory_bytes", &ExplainedSpace::memory_bytes, "Bytes held (the three count grids, the ledger and scratch).");
  c.def("clear", &ExplainedSpace::clear, "Forgets all evidence and the ledger.");
  c.def(
      "revise",
      [](ExplainedSpace& s) {
        py::gil_scoped_release release;
        s.revise();
      },
      "Classes the ledger's scans again now against the changes since the last revision (every\n"
      "revision_interval scans otherwise), moving the evidence of the beams whose class changed.");
  c.def_property_readonly(
      "revision_stats",
      [](const ExplainedSpace& s) {
        const ExplainedSpace::RevisionStats& r = s.revision_stats();
        py::dict d;
        d["rounds"] = r.rounds;
        d["scans_revisited"] = r.scans_revisited;
        d["beams_revisited"] = r.beams_revisited;
        d["to_suspect"] = r.to_suspect;
        d["to_trusted"] = r.to_trusted;
        d["unsettled"] = r.unsettled;
        return d;
      },
      "What revision did so far: dict of rounds, scans_revisited, beams_revisited, to_suspect, to_trusted, unsettled.");
  c.def_property_readonly(
      "ledger",
      [](const ExplainedSpace& s) {
        py::dict d;
        d["scans"] = s.ledger().scans().size();
        d["bytes"] = s.ledger().bytes();
        d["budget"] = s.ledger().budget();
        d["forgotten"] = s.ledger().forgotten();
        d["refused"] = s.ledger().refused();
        return d;
      },
      "The revision ledger: dict of scans kept, bytes, budget, scans forgotten and refused (larger than the budget).");
  c.def(
      "save",
      [](const ExplainedSpace& s, const std::string& path, int level) {
        intervox::detail::check_path(path);
        py::gil_scoped_release release;
        save_explained(path, s, GridSaveOptions{.compression_level = level});
      },
      py::arg("path"), py::kw_only(), py::arg("compression_level") = 9,
      "Saves the evidence (options, trusted extent, the three count grids, the mirrors) in Intervox's "
      "explained-evidence\n"
      "format (.ivxe, docs/io.md), atomically: a failed save never leaves a partial file. Raises IoError.");
  c.def_static(
      "load",
      [](const std::string& path, std::uint64_t max_bytes) {
        intervox::detail::check_path(path);
        py::gil_scoped_release release;
        return load_explained(path, GridLoadOptions{.max_bytes = max_bytes});
      },
      py::arg("path"), py::kw_only(), py::arg("max_bytes") = kDefaultLoadBudgetBytes,
      "Loads evidence saved by save() (or by intervox_bag --explained, the ROS node's ~save_map). Raises IoError\n"
      "for a missing, corrupt or truncated file, or one that needs more than max_bytes per count grid.");
}

}  // namespace intervox::python
