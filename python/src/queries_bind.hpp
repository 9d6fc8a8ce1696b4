#pragma once
/// \file
/// The per-grid bindings of python/src/queries.cpp (the template bind_/add_ functions and their
/// helpers), shared with credal.cpp, which instantiates them for the credal grids.

#include "guard.hpp"
#include <intervox/grid/coarse_summary.hpp>
#include <intervox/raycast/cast.hpp>

#include <algorithm>
#include <cmath>
#include <tuple>
#include <utility>
#include <vector>

namespace intervox::python::bind {

/// Evaluates f(cell) -> T for every point, with the GIL released; checks finiteness first.
template <class T, class G, class F>
py::array_t<T> per_point(const G& g, const py::object& points, const char* what, F&& f) {
  const PointsView pts(points, what);
  auto out = make_array<T>(pts.shape());
  T* w = out.mutable_data();
  bool bad = false;
  std::size_t first_bad = 0;
  {
    py::gil_scoped_release release;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const Point3 p = pts[i];
      if (!is_finite(p)) {
        bad = true;
        first_bad = i;
        break;
      }
      const auto k = g.try_key(p);
      w[i] = f(k ? g.cell(*k) : g.update_policy().unobserved());
    }
  }
  if (bad)
    throw InvalidArgument(std::string(what) + ": point " + std::to_string(first_bad) +
                          " has a NaN or infinite coordinate");
  return out;
}

/// Result of cast_ray with the voxel's centre.
struct CastHit {
  CastStatus status;
  Key key;
  Point3 center;
  double distance;
  std::uint64_t voxels;
};

/// Cast options; \p bounded: the grid has a key box (a cast then ends where it leaves the grid).
/// \throws InvalidArgument for a NaN max_range, or no finite max_range on an unbounded grid (a ray
///         would walk up to 2^24 voxels to the key limit, about 0.1 s each).
inline CastOptions cast_options(const char* what, double max_range, bool stop_at_unknown, bool ignore_origin_voxel,
                                bool bounded) {
  if (std::isnan(max_range)) throw InvalidArgument(std::string(what) + ": max_range is NaN");
  if (!bounded && !(max_range >= 0.0 && std::isfinite(max_range)))
    throw InvalidArgument(std::string(what) +
                          ": an unbounded grid needs a finite max_range >= 0 (without one each ray walks to the key "
                          "limit, millions of voxels); pass max_range=... in metres");
  CastOptions o;
  o.max_range = max_range;
  o.unknown = stop_at_unknown ? UnknownVoxels::Stop : UnknownVoxels::Pass;
  o.ignore_origin_voxel = ignore_origin_voxel;
  return o;
}

/// The arrays of coarse_query and coarse_cubes: one CubeSummary per entry.
struct CubeArrays {
  py::array_t<std::uint64_t> observed, occupied;
  py::array_t<double> max_probability, max_upper;
  explicit CubeArrays(const std::vector<py::ssize_t>& shape)
      : observed(make_array<std::uint64_t>(shape)),
        occupied(make_array<std::uint64_t>(shape)),
        max_probability(make_array<double>(shape)),
        max_upper(make_array<double>(shape)),
        w_observed_(observed.mutable_data()),
        w_occupied_(occupied.mutable_data()),
        w_max_probability_(max_probability.mutable_data()),
        w_max_upper_(max_upper.mutable_data()) {}
  /// Writes entry \p i through pointers taken at construction (callable without the GIL).
  void set(std::size_t i, const CubeSummary& s) noexcept {
    w_observed_[i] = s.observed;
    w_occupied_[i] = s.occupied;
    w_max_probability_[i] = s.max_probability;
    w_max_upper_[i] = s.max_upper;
  }
  void into(py::dict& d) const {
    d["observed"] = observed;
    d["occupied"] = occupied;
    d["max_probability"] = max_probability;
    d["max_upper"] = max_upper;
  }

 private:
  std::uint64_t *w_observed_, *w_occupied_;
  double *w_max_probability_, *w_max_upper_;
};

template <class G>
void add_queries(py::module_& m) {
  using Cell = typename G::Cell;
  auto c = grid_class<G>(m);
  c.def(
      "probability",
      [](const G& g, const py::object& pts) {
        return per_point<double>(g, pts, "probability: points",
                                 [&](const Cell& cell) { return g.update_policy().state(cell); });
      },
      py::arg("points"),
      "The state (probability of occupancy, float64, shape (...)) at each point; the policy's prior for\n"
      "unobserved voxels. Raises ValueError for NaN/Inf points.");
  c.def(
      "interval",
      [](const G& g, const py::object& points) {
        const PointsView pts(points, "interval: points");
        std::vector<py::ssize_t> shape = pts.shape();
        shape.push_back(2);
        py::array_t<double> out(shape);
        double* w = out.mutable_data();
        for (std::size_t i = 0; i < pts.size(); ++i)
          if (!is_finite(pts[i]))
            throw InvalidArgument("interval: point " + std::to_string(i) + " has a NaN or infinite coordinate");
        {
          py::gil_scoped_release release;
          for (std::size_t i = 0; i < pts.size(); ++i) {
            const Interval iv = g.interval(pts[i]);
            w[2 * i] = iv.lower;
            w[2 * i + 1] = iv.upper;
          }
        }
        return out;
      },
      py::arg("points"), "Probability intervals [lower, upper] (float64, shape (..., 2)); degenerate for Bayes grids.");
  c.def(
      "occupancy",
      [](const G& g, const py::object& pts) {
        return per_point<std::uint8_t>(g, pts, "occupancy: points", [&](const Cell& cell) {
          return static_cast<std::uint8_t>(g.update_policy().occupancy(cell));
        });
      },
      py::arg("points"), "Occupancy classes (uint8: 0 unknown, 1 free, 2 occupied; see Occupancy), shape (...).");
  c.def(
      "utility",
      [](const G& g, const py::object& pts) {
        return per_point<double>(g, pts, "utility: points", [&](const Cell& cell) { return g.utility_of(cell); });
      },
      py::arg("points"), "The utility policy's value (float64, shape (...)) of each point's voxel.");
  c.def(
      "is_observed",
      [](const G& g, const py::object& pts) {
        return per_point<bool>(g, pts, "is_observed: points",
                               [&](const Cell& cell) { return g.update_policy().is_observed(cell); });
      },
      py::arg("points"), "True (shape (...)) where a measurement has touched the point's voxel.");
  c.def(
      "observed_voxels",
      [](const G& g, const py::object& bounds) {
        std::vector<Key> keys;
        std::vector<Cell> cells;
        const std::optional<Bounds> box = bounds.is_none() ? std::nullopt : std::optional<Bounds>(to_bounds(bounds));
        {
          py::gil_scoped_release release;
          const auto add = [&](const Key& k, const Cell& cell) {
            keys.push_back(k);
            cells.push_back(cell);
          };
          if (box)
            g.for_each_observed_in(*box, add);
          else
            g.for_each_observed(add);
        }
        const auto n = static_cast<py::ssize_t>(keys.size());
        py::array_t<std::int32_t> k_out({n, py::ssize_t{3}});
        py::array_t<double> c_out({n, py::ssize_t{3}});
        py::array_t<double> p_out(n);
        py::array_t<double> i_out({n, py::ssize_t{2}});
        py::array_t<std::uint8_t> o_out(n);
        py::array_t<double> u_out(n);
        auto kw = k_out.mutable_unchecked<2>();
        auto cw = c_out.mutable_unchecked<2>();
        auto pw = p_out.mutable_unchecked<1>();
        auto iw = i_out.mutable_unchecked<2>();
        auto ow = o_out.mutable_unchecked<1>();
        auto uw = u_out.mutable_unchecked<1>();
        const auto& u = g.update_policy();
        for (py::ssize_t i = 0; i < n; ++i) {
          const Key& k = keys[static_cast<std::size_t>(i)];
          const Cell& cell = cells[static_cast<std::size_t>(i)];
          const Point3 ctr = g.center(k);
          for (int a = 0; a < 3; ++a) {
            kw(i, a) = k[a];
            cw(i, a) = ctr[a];
          }
          pw(i) = u.state(cell);
          const Interval iv = u.interval(cell);
          iw(i, 0) = iv.lower;
          iw(i, 1) = iv.upper;
          ow(i) = static_cast<std::uint8_t>(u.occupancy(cell));
          uw(i) = g.utility_of(cell);
        }
        py::dict d;
        d["keys"] = k_out;
        d["centers"] = c_out;
        d["probability"] = p_out;
        d["interval"] = i_out;
        d["occupancy"] = o_out;
        d["utility"] = u_out;
        return d;
      },
      py::arg("bounds") = py::none(),
      "Every observed voxel, in the grid's deterministic order, as a dict of arrays: 'keys' (M, 3) int32,\n"
      "'centers' (M, 3), 'probability' (M,), 'interval' (M, 2), 'occupancy' (M,) uint8, 'utility' (M,).\n"
      "bounds: a (2, 3) metric box [[min], [max]]: only the voxels that intersect it, found without visiting\n"
      "the rest of the grid (OctoMap's leaf_bbx iterator; a box beyond the key range is cut to it).");
  c.def(
      "coarse_query",
      [](const G& g, const py::object& points, int level) {
        const PointsView pts(points, "coarse_query: points");
        for (std::size_t i = 0; i < pts.size(); ++i)
          if (!is_finite(pts[i]))
            throw InvalidArgument("coarse_query: point " + std::to_string(i) + " has a NaN or infinite coordinate");
        if (level < 0 || level > CoarseSummary<G>::kMaxLevel)
          throw InvalidArgument("coarse_query: level must lie in [0, 23], got " + std::to_string(level));
        CubeArrays out(pts.shape());
        {
          py::gil_scoped_release release;
          const CoarseSummary<G> cs(g);
          for (std::size_t i = 0; i < pts.size(); ++i) out.set(i, cs.summary(pts[i], level));
        }
        py::dict d;
        out.into(d);
        return d;
      },
      py::arg("points"), py::arg("level"),
      "What the cube of 2^level voxels per axis holding each point contains (OctoMap's inner node at depth\n"
      "16 - level): a dict of arrays of shape (...): 'observed' and 'occupied' voxel counts (uint64),\n"
      "'max_probability' and 'max_upper' (the largest state and upper bound of its observed voxels; the prior\n"
      "where nothing is observed). Cubes are aligned: the keys with the same key >> level. One call summarises\n"
      "the grid's 8^3 blocks once (O(observed voxels)) and answers each point with one lookup; ask many points\n"
      "per call. level: 0 to 23. Raises ValueError for NaN/Inf points or a bad level.");
  c.def(
      "coarse_cubes",
      [](const G& g, int level) {
        if (level < CoarseSummary<G>::kBlockLevel || level > CoarseSummary<G>::kMaxLevel)
          throw InvalidArgument("coarse_cubes: level must lie in [3, 23], got " + std::to_string(level));
        std::vector<std::pair<KeyBox, CubeSummary>> cubes;
        {
          py::gil_scoped_release release;
          const CoarseSummary<G> cs(g);
          cubes.reserve(cs.cube_count(level));
          cs.for_each_cube(level, [&](const KeyBox& b, const CubeSummary& s) { cubes.emplace_back(b, s); });
          std::sort(cubes.begin(), cubes.end(), [](const auto& a, const auto& b) {
            const Key &p = a.first.min, &q = b.first.min;
            return std::tie(p.z, p.y, p.x) < std::tie(q.z, q.y, q.x);
          });
        }
        const auto n = static_cast<py::ssize_t>(cubes.size());
        py::array_t<std::int32_t> k_out({n, py::ssize_t{3}});
        py::array_t<double> c_out({n, py::ssize_t{3}});
        CubeArrays out({n});
        auto kw = k_out.mutable_unchecked<2>();
        auto cw = c_out.mutable_unchecked<2>();
        const double half = 0.5 * g.resolution() * double(std::int64_t{1} << level);
        for (py::ssize_t i = 0; i < n; ++i) {
          const auto& [box, s] = cubes[static_cast<std::size_t>(i)];
          const Point3 corner = g.geometry().corner(box.min);
          for (int a = 0; a < 3; ++a) {
            kw(i, a) = box.min[a];
            cw(i, a) = corner[a] + half;
          }
          out.set(static_cast<std::size_t>(i), s);
        }
        py::dict d;
        d["min_keys"] = k_out;
        d["centers"] = c_out;
        d["edge"] = 2.0 * half;
        out.into(d);
        return d;
      },
      py::arg("level"),
      "Every cube of 2^level voxels per axis (level 3 to 23) holding an observed voxel, ordered by z, y, x of\n"
      "its smallest key, as a dict: 'min_keys' (M, 3) int32, 'centers' (M, 3) metres, 'edge' (metres),\n"
      "'observed', 'occupied' (M,) uint64, 'max_probability', 'max_upper' (M,). Raises ValueError for a bad level.");
  c.def("enable_change_detection", &G::enable_change_detection, py::arg("on") = true,
        "Starts (or stops) recording the voxels whose occupancy changes (OctoMap's enableChangeDetection):\n"
        "an update that makes a voxel observed or moves it between free, occupied and unknown records it until\n"
        "reset_change_detection(). Off by default; stopping keeps what was recorded.");
  c.def_property_readonly("change_detection_enabled", &G::change_detection_enabled);
  c.def(
      "changed_keys",
      [](const G& g) {
        const std::vector<Key> keys = g.changed_keys();
        py::array_t<std::int32_t> out({static_cast<py::ssize_t>(keys.size()), py::ssize_t{3}});
        auto w = out.mutable_unchecked<2>();
        for (std::size_t i = 0; i < keys.size(); ++i)
          for (int a = 0; a < 3; ++a) w(static_cast<py::ssize_t>(i), a) = keys[i][a];
        return out;
      },
      "The keys (M, 3) int32 recorded since the last reset (block by block in the order their blocks first\n"
      "changed; the same for any thread count).");
  c.def("changed_count", &G::changed_count, "Number of voxels recorded since the last reset.");
  c.def("reset_change_detection", &G::reset_change_detection,
        "Forgets the recorded voxels (and frees their memory); recording stays on or off.");
  c.def(
      "cast_ray",
      [](const G& g, const Point3& origin, const Point3& direction, double max_range, bool stop_at_unknown,
         bool ignore_origin_voxel) {
        const CastOptions o =
            cast_options("cast_ray", max_range, stop_at_unknown, ignore_origin_voxel, g.key_box().has_value());
        CastResult r;
        {
          py::gil_scoped_release release;
          r = cast_ray(g, origin, direction, o);
        }
        return CastHit{r.status, r.key, g.center(r.key), r.distance, r.voxels};
      },
      py::arg("origin"), py::arg("direction"), py::kw_only(), py::arg("max_range") = -1.0,
      py::arg("stop_at_unknown") = false, py::arg("ignore_origin_voxel") = false,
      "The first occupied voxel along `direction` from `origin` (OctoMap's castRay). Unknown voxels are passed\n"
      "unless stop_at_unknown. max_range: metres, required (finite, >= 0) on an unbounded grid; on a grid with\n"
      "bounds < 0 means none (the cast ends where it leaves the grid). Returns a CastResult.");
  c.def(
      "cast_rays",
      [](const G& g, const py::object& origins, const py::object& directions, double max_range, bool stop_at_unknown,
         bool ignore_origin_voxel) {
        const CastOptions o =
            cast_options("cast_rays", max_range, stop_at_unknown, ignore_origin_voxel, g.key_box().has_value());
        const PointsView d(directions, "cast_rays: directions");
        auto o_arr = py::array::ensure(origins);
        const bool one_origin = o_arr && o_arr.ndim() == 1;
        const Point3 single = one_origin ? py::cast<Point3>(origins) : Point3::Zero();
        std::optional<PointsView> many;
        if (!one_origin) {
          many.emplace(origins, "cast_rays: origins");
          if (many->size() != d.size()) throw InvalidArgument("cast_rays: origins and directions differ in length");
        }
        const auto n = static_cast<py::ssize_t>(d.size());
        py::array_t<std::uint8_t> status(n);
        py::array_t<std::int32_t> keys({n, py::ssize_t{3}});
        py::array_t<double> dist(n);
        auto sw = status.mutable_unchecked<1>();
        auto kw = keys.mutable_unchecked<2>();
        auto dw = dist.mutable_unchecked<1>();
        // In chunks of about kCastCheckVoxels voxels examined, between which the GIL is taken
        // back to check for signals (Ctrl-C raises KeyboardInterrupt within a fraction of a second).
        constexpr std::uint64_t kCastCheckVoxels = std::uint64_t{1} << 22;
        py::ssize_t i = 0;
        while (i < n) {
          {
            py::gil_scoped_release release;
            std::uint64_t voxels = 0;
            for (; i < n && voxels < kCastCheckVoxels; ++i) {
              const auto idx = static_cast<std::size_t>(i);
              const CastResult r = cast_ray(g, one_origin ? single : (*many)[idx], d[idx], o);
              sw(i) = static_cast<std::uint8_t>(r.status);
              for (int a = 0; a < 3; ++a) kw(i, a) = r.key[a];
              dw(i) = r.distance;
              voxels += r.voxels + 1;
            }
          }
          if (PyErr_CheckSignals() != 0) throw py::error_already_set();
        }
        return py::make_tuple(status, keys, dist);
      },
      py::arg("origins"), py::arg("directions"), py::kw_only(), py::arg("max_range") = -1.0,
      py::arg("stop_at_unknown") = false, py::arg("ignore_origin_voxel") = false,
      "cast_ray for many rays: origins (N, 3) or one (3,), directions (N, 3). Returns (status (N,) uint8 of\n"
      "CastStatus values, keys (N, 3) int32, distances (N,)). max_range as for cast_ray (required on an unbounded\n"
      "grid). Long calls check for Ctrl-C (KeyboardInterrupt) every few million voxels.");
}

}  // namespace intervox::python::bind
