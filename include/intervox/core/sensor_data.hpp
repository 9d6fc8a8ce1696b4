#pragma once
/// \file
/// Measurement data exchanged between sensors (the simulator or real hardware) and ray insertion:
/// pinhole intrinsics, depth images, depth frames (image, intrinsics, pose, range), and beams with
/// their own origins.
/// Thread safety: plain value types; concurrent reads are safe, writes need exclusive access.

#include <intervox/core/error.hpp>
#include <intervox/core/point.hpp>
#include <intervox/core/validate.hpp>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

namespace intervox {

/// A rigid pose (sensor or body to world).
using Pose = Eigen::Isometry3d;

namespace detail {
/// \throws InvalidArgument unless \p pose is finite with an orthonormal, right-handed rotation.
inline void validate_pose(const Pose& pose, const char* what) {
  const auto& m = pose.matrix();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      if (!std::isfinite(m(r, c))) ParamCheck("intervox").fail(std::string(what) + " has a NaN or infinite entry");
  const Eigen::Matrix3d rot = pose.linear();
  if (!((rot.transpose() * rot - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-6 && rot.determinant() > 0))
    ParamCheck("intervox").fail(std::string(what) + " is not a rigid transform (rotation not orthonormal)");
}
}  // namespace detail

/// Pinhole camera intrinsics. Camera frame: x right, y down, z forward (optical frame).
/// Pixel (u, v) looks along ((u - cx) / fx, (v - cy) / fy, 1).
struct PinholeIntrinsics {
  int width = 0;
  int height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;

  /// Intrinsics from a field of view: \p fov_x and \p fov_y are the full opening angles in
  /// radians, in (0, pi); the principal point is the image centre.
  /// \throws InvalidArgument for a non-positive size or an angle outside (0, pi).
  static PinholeIntrinsics from_fov(int width, int height, double fov_x, double fov_y) {
    const ParamCheck check("intervox::PinholeIntrinsics::from_fov");
    check.at_least("width", width, 1);
    check.at_least("height", height, 1);
    check.in_range("fov_x (radians)", fov_x, 0, std::numbers::pi, RangeEnds::Open);
    check.in_range("fov_y (radians)", fov_y, 0, std::numbers::pi, RangeEnds::Open);
    PinholeIntrinsics k;
    k.width = width;
    k.height = height;
    k.fx = 0.5 * width / std::tan(0.5 * fov_x);
    k.fy = 0.5 * height / std::tan(0.5 * fov_y);
    k.cx = 0.5 * (width - 1);
    k.cy = 0.5 * (height - 1);
    return k;
  }

  /// \throws InvalidArgument unless width, height > 0, fx, fy finite and > 0, cx, cy finite.
  void validate() const {
    const ParamCheck check("intervox::PinholeIntrinsics");
    check.at_least("width", width, 1);
    check.at_least("height", height, 1);
    check.positive("fx (focal length)", fx);
    check.positive("fy (focal length)", fy);
    check.finite("cx", cx);
    check.finite("cy", cy);
  }

  /// Direction (not normalised, z = 1) of the ray through pixel (u, v), in the camera frame.
  Point3 ray(double u, double v) const noexcept { return {(u - cx) / fx, (v - cy) / fy, 1.0}; }

  /// The opening angle (radians) across the image along x, from the left edge of its first pixel
  /// column to the right edge of its last: fov_x of from_fov() (valid intrinsics; below pi).
  double fov_x() const noexcept { return std::atan((width - 0.5 - cx) / fx) - std::atan((-0.5 - cx) / fx); }
  /// The opening angle (radians) across the image along y (see fov_x()).
  double fov_y() const noexcept { return std::atan((height - 0.5 - cy) / fy) - std::atan((-0.5 - cy) / fy); }
};

/// A depth image: z-depth in metres per pixel, row-major (index v * width + u).
///
/// Value rules, shared by every producer and consumer:
///  - finite and > 0: a return at that depth;
///  - +infinity: no return (the beam reached max range, e.g. an absorbing surface): free space
///    up to the inserting side's max range;
///  - NaN, 0, negative or -infinity: an invalid pixel, ignored.
struct DepthImage {
  int width = 0;
  int height = 0;
  std::vector<float> depth;

  DepthImage() = default;
  /// An image of \p w x \p h invalid (NaN) pixels. \throws InvalidArgument for a negative size.
  DepthImage(int w, int h) : width(w), height(h) {
    const ParamCheck check("intervox::DepthImage");
    check.at_least("width", w, 0);
    check.at_least("height", h, 0);
    depth.assign(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), std::numeric_limits<float>::quiet_NaN());
  }
  float& at(int u, int v) { return depth[static_cast<std::size_t>(v) * width + u]; }
  float at(int u, int v) const { return depth[static_cast<std::size_t>(v) * width + u]; }
  /// True if the buffer size matches width x height.
  bool consistent() const noexcept {
    return width >= 0 && height >= 0 &&
           depth.size() == static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  }
};

/// One depth-camera frame: everything a depth image needs to be inserted, as the simulator
/// returns it (sim::CameraMeasurement) and a recorded sequence yields it (DepthSequence::frame()).
/// Insert it with `insert_depth_image(grid, frame, options)`.
///
/// Thread safety: a plain value type.
struct DepthFrame {
  DepthImage image;              ///< z-depth per pixel (the DepthImage value rules)
  PinholeIntrinsics intrinsics;  ///< the camera's intrinsics; their size is the image's
  Pose pose = Pose::Identity();  ///< camera (optical frame) to world, rigid
  /// The camera's max range [m], > 0: no-return pixels (+inf) are free space up to it. +inf when
  /// unknown (e.g. a recorded sequence, whose format has no "no return"): then only
  /// InsertOptions::max_range applies.
  double max_range = std::numeric_limits<double>::infinity();

  /// \throws InvalidArgument for invalid intrinsics, an image buffer that does not match its size
  ///         or an image size that differs from the intrinsics', a pose that is not finite and
  ///         rigid, or a max range that is NaN or <= 0.
  void validate() const {
    intrinsics.validate();
    if (!image.consistent()) ParamCheck("intervox::DepthFrame").fail("depth buffer size does not match width x height");
    if (image.width != intrinsics.width || image.height != intrinsics.height)
      ParamCheck("intervox::DepthFrame")
          .fail("image is " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                " but the intrinsics are " + std::to_string(intrinsics.width) + "x" +
                std::to_string(intrinsics.height));
    detail::validate_pose(pose, "depth frame pose");
    if (!(max_range > 0))
      ParamCheck("intervox::DepthFrame").fail("max_range must be > 0 (or +inf), got " + detail::param_text(max_range));
  }
};

/// One beam of a measurement, with its own origin (for sweeping sensors such as a laser
/// striper, or to merge several sensors into one scan).
/// If `hit` is true, `end` is where the beam returned; if false the beam had no return and `end`
/// is any point along its direction (insertion marks free space up to its max range; the
/// explained channel reads the nearer of `end` and that range as the sensor's range, so give it
/// at the sensor's range: ExplainedSpace).
struct Beam {
  Point3 origin = Point3::Zero();
  Point3 end = Point3::Zero();
  bool hit = true;
};

/// Removes from \p beams every return that ends at or below the height \p z (world z), e.g. the
/// floor cut out of a mobile robot's depth images before insertion (thesis 3.3.1): such beams are
/// dropped whole, so they carve no free space either. Beams without a return are kept. Order is
/// preserved. Returns the number removed. A conflict-aware MobilePlanner should still be given the
/// removed beams (MobilePlanner::observe): they returned, so the space they crossed is confirmed.
/// \throws InvalidArgument if \p z is NaN.
inline std::size_t remove_returns_below(std::vector<Beam>& beams, double z) {
  if (std::isnan(z)) ParamCheck("intervox::remove_returns_below").fail("height is NaN");
  const auto old = beams.size();
  std::erase_if(beams, [z](const Beam& b) { return b.hit && b.end.z() <= z; });
  return old - beams.size();
}

}  // namespace intervox
