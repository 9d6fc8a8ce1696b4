#pragma once
/// \file
/// One conversion point for 3D points of any shape (after Bonxai's `ConvertPoint`).
///
/// Intervox accepts, wherever a point is taken:
///  - Eigen fixed-size vectors with three coefficients (`Eigen::Vector3d`, `Eigen::Vector3f`, ...);
///  - `std::array<T, 3>` and `T[3]` of an arithmetic T;
///  - any struct with arithmetic members `x`, `y`, `z` (PCL points, ROS messages, your own);
///  - any type for which you specialise `intervox::PointTraits`.
/// Thread safety: pure functions and traits; safe to call concurrently.

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <type_traits>

namespace intervox {

/// The point type used inside Intervox.
using Point3 = Eigen::Vector3d;

/// Customisation point: specialise with `static Point3 to_point(const T&)` for your own type.
/// \tparam T the user's point type
template <class T, class Enable = void>
struct PointTraits;

/// A struct with arithmetic members x, y, z.
template <class T>
concept XyzStruct = requires(const T& p) {
  requires std::is_arithmetic_v<std::remove_cvref_t<decltype(p.x)>>;
  requires std::is_arithmetic_v<std::remove_cvref_t<decltype(p.y)>>;
  requires std::is_arithmetic_v<std::remove_cvref_t<decltype(p.z)>>;
};

/// An Eigen vector with three coefficients known at compile time.
template <class T>
concept EigenVector3 = std::is_base_of_v<Eigen::MatrixBase<T>, T> &&(T::SizeAtCompileTime == 3);

template <class T>
struct PointTraits<T, std::enable_if_t<EigenVector3<T>>> {
  static Point3 to_point(const T& p) { return p.template cast<double>(); }
};

template <class T>
struct PointTraits<std::array<T, 3>, std::enable_if_t<std::is_arithmetic_v<T>>> {
  static Point3 to_point(const std::array<T, 3>& p) {
    return {static_cast<double>(p[0]), static_cast<double>(p[1]), static_cast<double>(p[2])};
  }
};

template <class T>
struct PointTraits<T[3], std::enable_if_t<std::is_arithmetic_v<T>>> {
  static Point3 to_point(const T (&p)[3]) {
    return {static_cast<double>(p[0]), static_cast<double>(p[1]), static_cast<double>(p[2])};
  }
};

template <class T>
struct PointTraits<T, std::enable_if_t<XyzStruct<T> && !EigenVector3<T>>> {
  static Point3 to_point(const T& p) {
    return {static_cast<double>(p.x), static_cast<double>(p.y), static_cast<double>(p.z)};
  }
};

/// Anything Intervox accepts as a point.
template <class T>
concept PointLike = requires(const T& p) {
  { PointTraits<std::remove_cvref_t<T>>::to_point(p) } -> std::convertible_to<Point3>;
};

/// Converts any PointLike to Point3.
template <PointLike P>
Point3 to_point(const P& p) {
  return PointTraits<std::remove_cvref_t<P>>::to_point(p);
}

/// True if every coordinate is finite (neither NaN nor infinite).
inline bool is_finite(const Point3& p) noexcept {
  return std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.z());
}

}  // namespace intervox
