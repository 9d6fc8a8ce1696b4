#pragma once
/// \file
/// Shared pieces of the Python module `intervox._intervox`: the list of bound grid types, numpy
/// conversions (points, poses, bounds) and the declarations of the per-job binding functions
/// (one source file each, so that they compile in parallel).

#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/point.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/core/sensors.hpp>
#include <intervox/grid/named_grids.hpp>
#include <intervox/grid/voxel_grid.hpp>

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <compare>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <iterator>
#include <string>
#include <type_traits>
#include <vector>

namespace intervox::python {

namespace py = pybind11;

/// Interval grids with the lower and upper state rules (the named aliases cover the mean only).
using IntervalLowerGrid = VoxelGrid<IntervalUpdate<LowerState>, MaxEntropy, SparseStorage>;
using IntervalUpperGrid = VoxelGrid<IntervalUpdate<UpperState>, MaxEntropy, SparseStorage>;
/// Their dense forms, and the compact interval grid over dense storage.
using DenseIntervalLowerGrid = VoxelGrid<IntervalUpdate<LowerState>, MaxEntropy, DenseStorage>;
using DenseIntervalUpperGrid = VoxelGrid<IntervalUpdate<UpperState>, MaxEntropy, DenseStorage>;
using DenseCompactIntervalGrid = VoxelGrid<CompactIntervalUpdate<MeanState>, MaxEntropy, DenseStorage>;
/// The dense forms of the credal grids (DirichletGrid, BeliefGrid: mean rule, total uncertainty).
using DenseDirichletGrid = VoxelGrid<ImpreciseDirichletUpdate<MeanState>, TotalUncertainty, DenseStorage>;
using DenseBeliefGrid = VoxelGrid<DempsterShaferUpdate<MeanState>, TotalUncertainty, DenseStorage>;

/// The Python name of each bound grid type.
template <class G>
inline constexpr const char* kGridName = nullptr;
template <>
inline constexpr const char* kGridName<BayesGrid> = "BayesGrid";
template <>
inline constexpr const char* kGridName<DenseBayesGrid> = "DenseBayesGrid";
template <>
inline constexpr const char* kGridName<IntervalGrid> = "IntervalGrid";
template <>
inline constexpr const char* kGridName<IntervalLowerGrid> = "IntervalLowerGrid";
template <>
inline constexpr const char* kGridName<IntervalUpperGrid> = "IntervalUpperGrid";
template <>
inline constexpr const char* kGridName<DenseIntervalGrid> = "DenseIntervalGrid";
template <>
inline constexpr const char* kGridName<CompactIntervalGrid> = "CompactIntervalGrid";
template <>
inline constexpr const char* kGridName<DenseIntervalLowerGrid> = "DenseIntervalLowerGrid";
template <>
inline constexpr const char* kGridName<DenseIntervalUpperGrid> = "DenseIntervalUpperGrid";
template <>
inline constexpr const char* kGridName<DenseCompactIntervalGrid> = "DenseCompactIntervalGrid";
template <>
inline constexpr const char* kGridName<DirichletGrid> = "DirichletGrid";
template <>
inline constexpr const char* kGridName<DenseDirichletGrid> = "DenseDirichletGrid";
template <>
inline constexpr const char* kGridName<BeliefGrid> = "BeliefGrid";
template <>
inline constexpr const char* kGridName<DenseBeliefGrid> = "DenseBeliefGrid";

/// The Python name of a type whose objects the busy guard holds (guard.hpp; nullptr: not
/// guarded): every bound grid type, and ScanInserter, the planners and Episode, specialised next
/// to their bindings (before any use).
template <class T>
inline constexpr const char* kGuardedName = kGridName<T>;

/// Calls `f.template operator()<G>()` for every bound grid type, in a fixed order.
template <class F>
void for_each_grid(F&& f) {
  f.template operator()<BayesGrid>();
  f.template operator()<DenseBayesGrid>();
  f.template operator()<IntervalGrid>();
  f.template operator()<IntervalLowerGrid>();
  f.template operator()<IntervalUpperGrid>();
  f.template operator()<DenseIntervalGrid>();
  f.template operator()<CompactIntervalGrid>();
  f.template operator()<DenseIntervalLowerGrid>();
  f.template operator()<DenseIntervalUpperGrid>();
  f.template operator()<DenseCompactIntervalGrid>();
}

/// Calls `f.template operator()<G>()` for every credal grid type (bound in credal.cpp, after the
/// others: the per-grid templates of the *_bind.hpp headers are instantiated there only).
template <class F>
void for_each_credal_grid(F&& f) {
  f.template operator()<DirichletGrid>();
  f.template operator()<DenseDirichletGrid>();
  f.template operator()<BeliefGrid>();
  f.template operator()<DenseBeliefGrid>();
}

/// The parameter struct of a grid's update policy (BayesParams, IntervalParams, DirichletParams or
/// BeliefParams).
template <class G>
using ParamsOf = std::remove_cvref_t<decltype(std::declval<const typename G::UpdateType&>().params())>;

/// A read-only view of an (N, 3) float32 or float64 array, without a copy (any strides). Other
/// real dtypes and other shapes (..., 3) are converted or reshaped first (then a copy may be made).
/// \throws InvalidArgument (ValueError) if the array is not (..., 3) or not numeric.
class PointsView {
 public:
  PointsView(const py::handle& obj, const char* what);
  std::size_t size() const noexcept { return n_; }
  /// The leading shape of the input (its shape without the final 3), for results.
  const std::vector<py::ssize_t>& shape() const noexcept { return shape_; }
  Point3 operator[](std::size_t i) const noexcept {
    const char* p = data_ + static_cast<py::ssize_t>(i) * s0_;
    return f32_ ? Point3(load<float>(p), load<float>(p + s1_), load<float>(p + 2 * s1_))
                : Point3(load<double>(p), load<double>(p + s1_), load<double>(p + 2 * s1_));
  }

  /// A random-access iterator over the points, each read when dereferenced, so that a view is an
  /// intervox::PointRange the insertion takes as it is (no copy). (Not std::views::iota |
  /// std::views::transform: clang 14 cannot compile libstdc++ 12's iota_view.)
  class Iterator {
   public:
    using iterator_concept = std::random_access_iterator_tag;
    using iterator_category = std::input_iterator_tag;  // dereferences to a value, not a reference
    using value_type = Point3;
    using difference_type = std::ptrdiff_t;
    Iterator() = default;
    Iterator(const PointsView* view, difference_type i) noexcept : view_(view), i_(i) {}
    Point3 operator*() const noexcept { return (*view_)[static_cast<std::size_t>(i_)]; }
    Point3 operator[](difference_type d) const noexcept { return (*view_)[static_cast<std::size_t>(i_ + d)]; }
    Iterator& operator++() noexcept {
      ++i_;
      return *this;
    }
    Iterator operator++(int) noexcept {
      Iterator t = *this;
      ++i_;
      return t;
    }
    Iterator& operator--() noexcept {
      --i_;
      return *this;
    }
    Iterator operator--(int) noexcept {
      Iterator t = *this;
      --i_;
      return t;
    }
    Iterator& operator+=(difference_type d) noexcept {
      i_ += d;
      return *this;
    }
    Iterator& operator-=(difference_type d) noexcept {
      i_ -= d;
      return *this;
    }
    friend Iterator operator+(Iterator a, difference_type d) noexcept { return a += d; }
    friend Iterator operator+(difference_type d, Iterator a) noexcept { return a += d; }
    friend Iterator operator-(Iterator a, difference_type d) noexcept { return a -= d; }
    friend difference_type operator-(const Iterator& a, const Iterator& b) noexcept { return a.i_ - b.i_; }
    friend bool operator==(const Iterator& a, const Iterator& b) noexcept { return a.i_ == b.i_; }
    friend auto operator<=>(const Iterator& a, const Iterator& b) noexcept { return a.i_ <=> b.i_; }

   private:
    const PointsView* view_ = nullptr;
    difference_type i_ = 0;
  };
  Iterator begin() const noexcept { return {this, 0}; }
  Iterator end() const noexcept { return {this, static_cast<std::ptrdiff_t>(n_)}; }

 private:
  py::array array_;  // keeps the data alive
  const char* data_ = nullptr;
  std::size_t n_ = 0;
  py::ssize_t s0_ = 0, s1_ = 0;
  bool f32_ = false;
  std::vector<py::ssize_t> shape_;

  /// numpy data need not be aligned (views into byte buffers): read through memcpy.
  template <class T>
  static double load(const char* p) noexcept {
    T v;
    std::memcpy(&v, p, sizeof(T));
    return static_cast<double>(v);
  }
};

/// A new array of shape `lead` + `tail`.
template <class T>
py::array_t<T> make_array(const std::vector<py::ssize_t>& lead, std::initializer_list<py::ssize_t> tail = {}) {
  std::vector<py::ssize_t> shape = lead;
  shape.insert(shape.end(), tail.begin(), tail.end());
  return py::array_t<T>(shape);
}

/// A 4x4 rigid transform from anything numpy turns into a (4, 4) float array.
/// \throws InvalidArgument for another shape, non-finite entries, a bottom row other than
///         (0, 0, 0, 1) or a rotation that is not orthonormal.
Pose to_pose(const py::handle& obj, const char* what = "pose");
/// The (4, 4) float64 array of \p pose.
py::array_t<double> from_pose(const Pose& pose);
/// Poses from an (N, 4, 4) array (or a sequence of 4x4 arrays).
std::vector<Pose> to_poses(const py::handle& obj, const char* what = "poses");
/// The (N, 4, 4) float64 array of \p poses.
py::array_t<double> from_poses(const std::vector<Pose>& poses);
/// Bounds from a Bounds object, or a pair (min, max) of 3-vectors, or a (2, 3) array.
Bounds to_bounds(const py::handle& obj);
/// A key box as a (2, 3) int32 array [[min], [max]].
py::array_t<std::int32_t> from_key_box(const KeyBox& box);
/// A key box from a (2, 3) integer array.
KeyBox to_key_box(const py::handle& obj);

/// Beams from (N, 3) origins (or one (3,) origin for all), (N, 3) ends and optional (N,) bool hits
/// (None: all hits). \throws InvalidArgument for mismatching shapes.
std::vector<Beam> beams_from_numpy(const py::handle& origins, const py::handle& ends, const py::handle& hits);
/// Beams as the tuple (origins (N, 3), ends (N, 3), hits (N,) bool).
py::tuple beams_to_numpy(const std::vector<Beam>& beams);

/// Per-job binding functions (python/src/<job>.cpp).
void bind_core(py::module_& m);       // exceptions, enums, Bounds, params, intrinsics, stats
void bind_grids(py::module_& m);      // grid classes: construction, geometry, updates
void bind_insertion(py::module_& m);  // point clouds, depth images, beams; ScanInserter
void bind_queries(py::module_& m);    // vectorised queries, observed voxels, cast_ray
void bind_io(py::module_& m);         // grid files, .bt, PLY, slices, PNG
void bind_simulator(py::module_& m);  // materials, scenes, sensors, rigs, simulate
void bind_planners(py::module_& m);   // mobile and arm planners, episodes
void bind_credal(py::module_& m);     // credal grids and their parameters (after the others)

}  // namespace intervox::python
