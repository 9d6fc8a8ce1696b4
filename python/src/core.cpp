/// \file
/// Exceptions, enumerations, Bounds, policy parameters, intrinsics, insertion statistics, and the
/// numpy conversions declared in common.hpp.

#include "common.hpp"

#include <intervox/core/types.hpp>
#include <intervox/raycast/insert.hpp>
#include <intervox/update/bayes_log_odds.hpp>
#include <intervox/update/interval_update.hpp>

#include <cmath>
#include <exception>
#include <sstream>

namespace intervox::python {

PointsView::PointsView(const py::handle& obj, const char* what) {
  py::array a = py::array::ensure(obj);
  if (!a) throw InvalidArgument(std::string(what) + ": expected an array of shape (N, 3)");
  if (a.ndim() < 1 || a.shape(a.ndim() - 1) != 3) {
    std::ostringstream s;
    s << what << ": expected an array of shape (N, 3), got shape (";
    for (py::ssize_t i = 0; i < a.ndim(); ++i) s << (i ? ", " : "") << a.shape(i);
    s << (a.ndim() == 1 ? ",)" : ")");
    throw InvalidArgument(s.str());
  }
  for (py::ssize_t i = 0; i + 1 < a.ndim(); ++i) shape_.push_back(a.shape(i));
  const auto kind = a.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u' && kind != 'b')
    throw InvalidArgument(std::string(what) + ": expected a real-valued array, got dtype " +
                          std::string(py::str(a.dtype())));
  if (a.ndim() != 2) a = a.attr("reshape")(-1, 3);
  const bool f32 = a.dtype().is(py::dtype::of<float>());
  const bool f64 = a.dtype().is(py::dtype::of<double>());
  if (!f32 && !f64) a = py::array_t<double, py::array::forcecast>::ensure(a);
  array_ = a;
  f32_ = f32;
  data_ = static_cast<const char*>(array_.data());
  n_ = static_cast<std::size_t>(array_.shape(0));
  s0_ = array_.strides(0);
  s1_ = array_.strides(1);
}

namespace {
Eigen::Matrix4d to_matrix4(const py::handle& obj, const char* what) {
  auto a = py::array_t<double, py::array::forcecast>::ensure(obj);
  if (!a || a.ndim() != 2 || a.shape(0) != 4 || a.shape(1) != 4)
    throw InvalidArgument(std::string(what) + ": expected a (4, 4) array");
  auto r = a.unchecked<2>();
  Eigen::Matrix4d mat;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) mat(i, j) = r(i, j);
  return mat;
}

Pose matrix_to_pose(const Eigen::Matrix4d& mat, const std::string& what) {
  if (!mat.allFinite()) throw InvalidArgument(what + ": has a NaN or infinite entry");
  if (!(mat(3, 0) == 0 && mat(3, 1) == 0 && mat(3, 2) == 0 && mat(3, 3) == 1))
    throw InvalidArgument(what + ": the bottom row must be (0, 0, 0, 1)");
  Pose p;
  p.matrix() = mat;
  intervox::detail::validate_pose(p, what.c_str());
  return p;
}
}  // namespace

Pose to_pose(const py::handle& obj, const char* what) { return matrix_to_pose(to_matrix4(obj, what), what); }

py::array_t<double> from_pose(const Pose& pose) {
  py::array_t<double> a({4, 4});
  auto w = a.mutable_unchecked<2>();
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) w(i, j) = pose.matrix()(i, j);
  return a;
}

std::vector<Pose> to_poses(const py::handle& obj, const char* what) {
  auto a = py::array_t<double, py::array::forcecast>::ensure(obj);
  if (!a || !((a.ndim() == 3 && a.shape(1) == 4 && a.shape(2) == 4) || (a.ndim() == 1 && a.shape(0) == 0)))
    throw InvalidArgument(std::string(what) + ": expected an array of shape (N, 4, 4)");
  std::vector<Pose> out;
  if (a.ndim() == 1) return out;
  auto r = a.unchecked<3>();
  for (py::ssize_t k = 0; k < a.shape(0); ++k) {
    Eigen::Matrix4d mat;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) mat(i, j) = r(k, i, j);
    out.push_back(matrix_to_pose(mat, std::string(what) + "[" + std::to_string(k) + "]"));
  }
  return out;
}

py::array_t<double> from_poses(const std::vector<Pose>& poses) {
  py::array_t<double> a({static_cast<py::ssize_t>(poses.size()), py::ssize_t{4}, py::ssize_t{4}});
  auto w = a.mutable_unchecked<3>();
  for (std::size_t k = 0; k < poses.size(); ++k)
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) w(static_cast<py::ssize_t>(k), i, j) = poses[k].matrix()(i, j);
  return a;
}

py::array_t<std::int32_t> from_key_box(const KeyBox& box) {
  py::array_t<std::int32_t> a({2, 3});
  auto w = a.mutable_unchecked<2>();
  for (int i = 0; i < 3; ++i) {
    w(0, i) = box.min[i];
    w(1, i) = box.max[i];
  }
  return a;
}

KeyBox to_key_box(const py::handle& obj) {
  auto a = py::array_t<std::int64_t, py::array::forcecast>::ensure(obj);
  if (!a || a.ndim() != 2 || a.shape(0) != 2 || a.shape(1) != 3)
    throw InvalidArgument("key box: expected a (2, 3) integer array [[min x, y, z], [max x, y, z]]");
  auto r = a.unchecked<2>();
  KeyBox b;
  for (int i = 0; i < 3; ++i) {
    if (r(0, i) < -kKeyLimit || r(1, i) >= kKeyLimit || r(0, i) > r(1, i))
      throw InvalidArgument("key box: need min <= max inside the key range on every axis");
    b.min[i] = static_cast<std::int32_t>(r(0, i));
    b.max[i] = static_cast<std::int32_t>(r(1, i));
  }
  return b;
}

namespace {

constexpr const char* kBoundsShape = "Bounds, a pair ((xmin, ymin, zmin), (xmax, ymax, zmax)) or a (2, 3) array";

std::string repr_of(const py::handle& obj) {
  std::string r = py::repr(obj);
  return r.size() > 80 ? r.substr(0, 77) + "..." : r;
}

/// One corner of a pair of bounds. \throws InvalidArgument naming the expected shape.
Point3 bounds_corner(const py::handle& h, const py::handle& whole, const char* which) {
  try {
    return py::cast<Point3>(h);
  } catch (const py::cast_error&) {
    throw InvalidArgument(std::string("bounds: expected ") + kBoundsShape + "; the " + which + " corner " + repr_of(h) +
                          " of " + repr_of(whole) + " is not 3 numbers");
  }
}

Bounds bounds_from_pair(const py::handle& lo, const py::handle& hi, const py::handle& whole) {
  Bounds b{bounds_corner(lo, whole, "min"), bounds_corner(hi, whole, "max")};
  if (!b.valid()) throw InvalidArgument("Bounds: need finite corners with min <= max");
  return b;
}

template <class P>
void bind_param_fields(py::class_<P>& c);

}  // namespace

Bounds to_bounds(const py::handle& obj) {
  if (py::isinstance<Bounds>(obj)) return py::cast<Bounds>(obj);
  if (py::isinstance<py::sequence>(obj) && !py::isinstance<py::str>(obj)) {
    const auto seq = py::reinterpret_borrow<py::sequence>(obj);
    if (seq.size() == 2) return bounds_from_pair(seq[0], seq[1], obj);
  }
  throw InvalidArgument(std::string("bounds: expected ") + kBoundsShape + ", got " + repr_of(obj));
}

namespace {

template <>
void bind_param_fields(py::class_<BayesParams>& c) {
  c.def_readwrite("p_hit", &BayesParams::p_hit, "Pr(occupied) after one hit from 0.5")
      .def_readwrite("p_miss", &BayesParams::p_miss, "Pr(occupied) after one miss from 0.5")
      .def_readwrite("clamp_min", &BayesParams::clamp_min)
      .def_readwrite("clamp_max", &BayesParams::clamp_max)
      .def_readwrite("free_threshold", &BayesParams::free_threshold, "free at or below")
      .def_readwrite("occupied_threshold", &BayesParams::occupied_threshold, "occupied at or above")
      .def_readwrite("prior", &BayesParams::prior, "state of an unobserved voxel")
      .def_readwrite("latch", &BayesParams::latch, "thesis Table 3.1 latching at 0 and 1")
      .def_static("octomap", &BayesParams::octomap,
                  "OctoMap's defaults (p_hit 0.7, p_miss 0.4, clamps [0.1192, 0.971])")
      .def_static("thesis", &BayesParams::thesis, "The thesis: lq 3 and 1/3, thresholds 0.05 / 0.95, latching")
      .def(
          "validate", [](const BayesParams& p) { BayesLogOdds::validate(p); },
          "Raises ValueError naming the first violated rule.")
      .def("__eq__", [](const BayesParams& a, const BayesParams& b) { return BayesLogOdds(a) == BayesLogOdds(b); })
      .def("__repr__", [](const BayesParams& p) {
        std::ostringstream s;
        s << "BayesParams(p_hit=" << p.p_hit << ", p_miss=" << p.p_miss << ", clamp_min=" << p.clamp_min
          << ", clamp_max=" << p.clamp_max << ", free_threshold=" << p.free_threshold
          << ", occupied_threshold=" << p.occupied_threshold << ", prior=" << p.prior
          << ", latch=" << (p.latch ? "True" : "False") << ")";
        return s.str();
      });
}

template <>
void bind_param_fields(py::class_<IntervalParams>& c) {
  c.def_readwrite("p_hit", &IntervalParams::p_hit)
      .def_readwrite("p_miss", &IntervalParams::p_miss)
      .def_readwrite("initial_lower", &IntervalParams::initial_lower, "lower bound of an unobserved voxel")
      .def_readwrite("initial_upper", &IntervalParams::initial_upper, "upper bound of an unobserved voxel")
      .def_readwrite("clamp_min", &IntervalParams::clamp_min)
      .def_readwrite("clamp_max", &IntervalParams::clamp_max)
      .def_readwrite("free_threshold", &IntervalParams::free_threshold)
      .def_readwrite("occupied_threshold", &IntervalParams::occupied_threshold)
      .def_readwrite("latch", &IntervalParams::latch, "bounds stick at 0 / 1 once they reach a clamp")
      .def_readwrite("classify_unobserved", &IntervalParams::classify_unobserved,
                     "classify never-observed voxels by the state rule on the initial interval (the thesis' "
                     "lower rule: free, upper: occupied); False: always unknown")
      .def_static("thesis", &IntervalParams::thesis, "The thesis' 8-bit behaviour (latching near 0 and 1)")
      .def(
          "validate", [](const IntervalParams& p) { IntervalUpdate<MeanState>::validate(p); },
          "Raises ValueError naming the first violated rule.")
      .def("__eq__",
           [](const IntervalParams& a, const IntervalParams& b) {
             return IntervalUpdate<MeanState>(a) == IntervalUpdate<MeanState>(b);
           })
      .def("__repr__", [](const IntervalParams& p) {
        std::ostringstream s;
        s << "IntervalParams(p_hit=" << p.p_hit << ", p_miss=" << p.p_miss << ", initial_lower=" << p.initial_lower
          << ", initial_upper=" << p.initial_upper << ", clamp_min=" << p.clamp_min << ", clamp_max=" << p.clamp_max
          << ", free_threshold=" << p.free_threshold << ", occupied_threshold=" << p.occupied_threshold
          << ", latch=" << (p.latch ? "True" : "False")
          << ", classify_unobserved=" << (p.classify_unobserved ? "True" : "False") << ")";
        return s.str();
      });
}

}  // namespace

void bind_core(py::module_& m) {
  // ---- exceptions ----------------------------------------------------------------------------
  static PyObject* io_error =
      py::exception<IoError>(m, "IoError", PyExc_OSError).release().ptr();  // the module keeps it alive
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InvalidArgument& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const OutOfRange& e) {
      PyErr_SetString(PyExc_IndexError, e.what());
    } catch (const IoError& e) {
      PyErr_SetString(io_error, e.what());
    } catch (const Error& e) {
      PyErr_SetString(PyExc_RuntimeError, e.what());
    }
  });
  py::object io_error_type = m.attr("IoError");
  io_error_type.attr("__doc__") = "Reading or writing a file failed, or a file is corrupt (an OSError).";

  // ---- enumerations --------------------------------------------------------------------------
  py::enum_<Occupancy>(m, "Occupancy", "The classification of a voxel by its policy's thresholds.")
      .value("UNKNOWN", Occupancy::Unknown, "never observed, or between the thresholds")
      .value("FREE", Occupancy::Free)
      .value("OCCUPIED", Occupancy::Occupied);
  py::enum_<Observation>(m, "Observation", "What a measurement says about one voxel.")
      .value("MISS", Observation::Miss)
      .value("HIT", Observation::Hit);

  // ---- Bounds --------------------------------------------------------------------------------
  py::class_<Bounds>(m, "Bounds", "An axis-aligned box in metres, [min, max]. A pair (min, max) converts implicitly.")
      .def(py::init([](const py::object& lo, const py::object& hi) {
             return bounds_from_pair(lo, hi, py::make_tuple(lo, hi));
           }),
           py::arg("min"), py::arg("max"))
      .def(py::init([](const py::tuple& t) {
             if (t.size() != 2)
               throw InvalidArgument(std::string("Bounds: expected ") + kBoundsShape + ", got " + repr_of(t));
             return bounds_from_pair(t[0], t[1], t);
           }),
           py::arg("pair"))
      .def(py::init([](const py::list& t) {
             if (t.size() != 2)
               throw InvalidArgument(std::string("Bounds: expected ") + kBoundsShape + ", got " + repr_of(t));
             return bounds_from_pair(t[0], t[1], t);
           }),
           py::arg("pair"))
      .def_property_readonly("min", [](const Bounds& b) { return Point3(b.min); })
      .def_property_readonly("max", [](const Bounds& b) { return Point3(b.max); })
      .def(
          "contains", [](const Bounds& b, const Point3& p) { return b.contains(p); }, py::arg("point"))
      .def("__eq__", [](const Bounds& a, const Bounds& b) { return a.min == b.min && a.max == b.max; })
      .def("__repr__", [](const Bounds& b) {
        std::ostringstream s;
        s << "Bounds((" << b.min.x() << ", " << b.min.y() << ", " << b.min.z() << "), (" << b.max.x() << ", "
          << b.max.y() << ", " << b.max.z() << "))";
        return s.str();
      });
  py::implicitly_convertible<py::tuple, Bounds>();
  py::implicitly_convertible<py::list, Bounds>();

  // ---- policy parameters ---------------------------------------------------------------------
  py::class_<BayesParams> bp(m, "BayesParams", "Parameters of the Bayes log-odds update (probabilities of occupancy).");
  bp.def(py::init<>());
  bind_param_fields(bp);
  py::class_<IntervalParams> ip(m, "IntervalParams", "Parameters of the interval update (thesis chapter 4).");
  ip.def(py::init<>());
  bind_param_fields(ip);

  // ---- sensor data ---------------------------------------------------------------------------
  py::class_<PinholeIntrinsics>(m, "PinholeIntrinsics",
                                "Pinhole camera intrinsics; camera frame x right, y down, z forward.\n"
                                "Pixel (u, v) looks along ((u - cx) / fx, (v - cy) / fy, 1).")
      .def(py::init([](int width, int height, double fx, double fy, double cx, double cy) {
             PinholeIntrinsics k{width, height, fx, fy, cx, cy};
             k.validate();
             return k;
           }),
           py::arg("width"), py::arg("height"), py::arg("fx"), py::arg("fy"), py::arg("cx"), py::arg("cy"))
      .def_static("from_fov", &PinholeIntrinsics::from_fov, py::arg("width"), py::arg("height"), py::arg("fov_x"),
                  py::arg("fov_y"), "Intrinsics from full opening angles in radians; principal point at the centre.")
      .def_readonly("width", &PinholeIntrinsics::width)
      .def_readonly("height", &PinholeIntrinsics::height)
      .def_readonly("fx", &PinholeIntrinsics::fx)
      .def_readonly("fy", &PinholeIntrinsics::fy)
      .def_readonly("cx", &PinholeIntrinsics::cx)
      .def_readonly("cy", &PinholeIntrinsics::cy)
      .def("__repr__", [](const PinholeIntrinsics& k) {
        std::ostringstream s;
        s << "PinholeIntrinsics(width=" << k.width << ", height=" << k.height << ", fx=" << k.fx << ", fy=" << k.fy
          << ", cx=" << k.cx << ", cy=" << k.cy << ")";
        return s.str();
      });

  // ---- insertion options and statistics ------------------------------------------------------
  py::class_<InsertStats>(m, "InsertStats",
                          "What one insertion did. Every input ray is counted once: in `rays` or a `skipped_*` field.")
      .def(py::init<>())
      .def_readonly("rays", &InsertStats::rays, "rays traversed")
      .def_readonly("truncated", &InsertStats::truncated, "rays cut at max range")
      .def_readonly("voxel_steps", &InsertStats::voxel_steps, "voxels enumerated, before de-duplication")
      .def_readonly("hits", &InsertStats::hits, "voxels updated with a hit")
      .def_readonly("misses", &InsertStats::misses, "voxels updated with a miss")
      .def_readonly("outside_bounds", &InsertStats::outside_bounds, "updates dropped outside a bounded grid")
      .def_readonly("skipped_invalid", &InsertStats::skipped_invalid, "NaN/Inf point or origin, invalid depth pixel")
      .def_readonly("skipped_zero_length", &InsertStats::skipped_zero_length)
      .def_readonly("skipped_min_range", &InsertStats::skipped_min_range)
      .def_readonly("skipped_key_range", &InsertStats::skipped_key_range)
      .def_readonly("skipped_no_max_range", &InsertStats::skipped_no_max_range)
      .def_readonly("beams_trusted", &InsertStats::beams_trusted, "beams classed trusted (ExplainedSpace; 0 otherwise)")
      .def_readonly("beams_suspect", &InsertStats::beams_suspect, "beams classed suspect (ExplainedSpace; 0 otherwise)")
      .def_readonly("beams_no_return", &InsertStats::beams_no_return,
                    "beams without a return (ExplainedSpace; 0 otherwise)")
      .def_property_readonly("skipped", &InsertStats::skipped, "input rays not traversed, for any reason")
      .def("__iadd__", [](InsertStats& a, const InsertStats& b) -> InsertStats& { return a += b; })
      .def("__eq__", [](const InsertStats& a, const InsertStats& b) { return a == b; })
      .def("__repr__", [](const InsertStats& s) {
        std::ostringstream o;
        o << "InsertStats(rays=" << s.rays << ", truncated=" << s.truncated << ", hits=" << s.hits
          << ", misses=" << s.misses << ", outside_bounds=" << s.outside_bounds << ", skipped=" << s.skipped() << ")";
        return o.str();
      });

  py::class_<OccupancyCounts>(m, "OccupancyCounts", "Numbers of observed voxels by class.")
      .def_readonly("free", &OccupancyCounts::free)
      .def_readonly("occupied", &OccupancyCounts::occupied)
      .def_readonly("unknown", &OccupancyCounts::unknown, "observed, but between the thresholds")
      .def_property_readonly("observed", &OccupancyCounts::observed)
      .def("__repr__", [](const OccupancyCounts& c) {
        return "OccupancyCounts(free=" + std::to_string(c.free) + ", occupied=" + std::to_string(c.occupied) +
               ", unknown=" + std::to_string(c.unknown) + ")";
      });
}

}  // namespace intervox::python
