#pragma once
/// \file
/// A ray to cast (origin, unit direction, range) and the one rule that turns a pinhole camera's
/// pixel into a ray: used by depth-image insertion, the simulator and the information gain.
/// A *measurement* along a ray is a Beam (core/sensor_data.hpp: origin, end, hit).
///
/// The pixel rule: pixel (u, v) of a camera with intrinsics k at pose P (optical frame to world)
/// looks from P.translation() along P.linear() * k.ray(u, v), whose camera-frame z-component is
/// 1; a z-depth d along it is the point P * (k.ray(u, v) * d) (pixel_point()), and its unit
/// direction is P.linear() * k.ray(u, v).normalized() (pixel_ray()).
///
/// Thread safety: plain value types and pure functions.

#include <intervox/core/error.hpp>
#include <intervox/core/point.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/core/validate.hpp>

#include <cstddef>
#include <limits>
#include <vector>

namespace intervox {

/// A ray to cast: from `origin` along the unit vector `direction`, at most `range` far.
struct Ray {
  Point3 origin = Point3::Zero();
  Point3 direction = Point3::UnitZ();                      ///< unit length
  double range = std::numeric_limits<double>::infinity();  ///< how far the ray reaches [m], > 0

  /// The point at distance \p t along the ray.
  Point3 at(double t) const noexcept { return origin + t * direction; }
};

/// The ray of pixel (u, v) of a camera with intrinsics \p k at \p pose (optical frame to world),
/// reaching \p range: origin pose.translation(), direction pose.linear() * k.ray(u, v).normalized().
/// Pixels outside the image are allowed (the rule is the same). No validation: see
/// PinholeIntrinsics::validate().
inline Ray pixel_ray(const PinholeIntrinsics& k, const Pose& pose, int u, int v,
                     double range = std::numeric_limits<double>::infinity()) noexcept {
  return {pose.translation(), pose.linear() * k.ray(u, v).normalized(), range};
}

/// The world point that pixel (u, v) of a camera with intrinsics \p k at \p pose measures at
/// z-depth \p depth (DepthImage's unit): pose * (k.ray(u, v) * depth). It lies on pixel_ray(k,
/// pose, u, v), depth * k.ray(u, v).norm() from its origin.
inline Point3 pixel_point(const PinholeIntrinsics& k, const Pose& pose, int u, int v, double depth) noexcept {
  return pose * (k.ray(u, v) * depth);
}

/// The first of the pixels (or samples) along an axis of \p size that a \p stride keeps: the kept
/// indices are first, first + stride, ... < size, with first = ((size - 1) % stride) / 2, so the
/// pattern is centred (its margins differ by at most one). stride 1 keeps every index.
/// \throws InvalidArgument for stride < 1 or size < 0.
inline int strided_first(int size, int stride) {
  const ParamCheck check("intervox::strided_first");
  check.at_least("stride", stride, 1);
  check.at_least("size", size, 0);
  return size == 0 ? 0 : (size - 1) % stride / 2;
}

/// The rays of every \p stride-th pixel of a camera with intrinsics \p k at \p pose, each reaching
/// \p range: pixels (u, v) with u = strided_first(width, stride) + i * stride and likewise v
/// (the centred pattern), row-major (v outer, u inner). stride 1 gives every pixel, row-major.
/// \throws InvalidArgument for invalid intrinsics or stride < 1.
inline std::vector<Ray> camera_rays(const PinholeIntrinsics& k, const Pose& pose, int stride = 1,
                                    double range = std::numeric_limits<double>::infinity()) {
  k.validate();
  const int u0 = strided_first(k.width, stride), v0 = strided_first(k.height, stride);
  std::vector<Ray> out;
  out.reserve(static_cast<std::size_t>((k.width - u0 + stride - 1) / stride) *
              static_cast<std::size_t>((k.height - v0 + stride - 1) / stride));
  for (int v = v0; v < k.height; v += stride)
    for (int u = u0; u < k.width; u += stride) out.push_back(pixel_ray(k, pose, u, v, range));
  return out;
}

}  // namespace intervox
