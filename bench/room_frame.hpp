#pragma once
// The room frame shared by the benchmarks: a 640x480 depth camera sweeping a furnished
// 6 x 5 x 3 m room in ten frames (yaw -25..+25 deg), analytic ray casting against the room, three
// boxes and a sphere, seeded Kinect-like axial noise. Used at 2 cm with a 5 m max range.
#include <intervox/core/sensor_data.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <utility>
#include <vector>

namespace room_frame {
namespace iv = intervox;

constexpr double kResolution = 0.02;
constexpr double kMaxRange = 5.0;
constexpr int kFrames = 10;
constexpr double kPi = std::numbers::pi;

// ---- the scene: analytic ray casting against the room, three boxes and a sphere -------------

struct Box {
  iv::Point3 lo, hi;
};

/// Entry distance of a ray into a box from outside (inf if it misses or starts inside).
inline double hit_box(const iv::Point3& o, const iv::Point3& d, const Box& b) {
  double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0.0) {
      if (o[a] < b.lo[a] || o[a] > b.hi[a]) return std::numeric_limits<double>::infinity();
      continue;
    }
    double ta = (b.lo[a] - o[a]) / d[a], tb = (b.hi[a] - o[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  return (t0 <= t1 && t0 > 0.0) ? t0 : std::numeric_limits<double>::infinity();
}

/// Exit distance of a ray from the inside of the room box.
inline double exit_room(const iv::Point3& o, const iv::Point3& d, const Box& b) {
  double t = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (d[a] > 0) t = std::min(t, (b.hi[a] - o[a]) / d[a]);
    if (d[a] < 0) t = std::min(t, (b.lo[a] - o[a]) / d[a]);
  }
  return t;
}

inline double hit_sphere(const iv::Point3& o, const iv::Point3& d, const iv::Point3& c, double r) {
  const iv::Point3 oc = o - c;
  const double a = d.squaredNorm(), b = oc.dot(d), cc = oc.squaredNorm() - r * r;
  const double disc = b * b - a * cc;
  if (disc < 0) return std::numeric_limits<double>::infinity();
  const double t = (-b - std::sqrt(disc)) / a;
  return t > 0 ? t : std::numeric_limits<double>::infinity();
}

struct Frame {
  iv::DepthImage image;
  iv::Pose pose;
  std::vector<Eigen::Vector3f> cloud;  // world points, for OctoMap and insert_point_cloud
  iv::Point3 origin;
};

inline iv::PinholeIntrinsics camera() {
  iv::PinholeIntrinsics k;
  k.width = 640;
  k.height = 480;
  k.fx = k.fy = 525.0;
  k.cx = 319.5;
  k.cy = 239.5;
  return k;
}

/// How many frames of the sweep frames() builds (kFrames; a benchmark's smoke run sets 1 before
/// the first call to frames(), so that it proves every row works at a tenth of the cost).
inline int& frame_count() {
  static int n = kFrames;
  return n;
}

/// The frames of the sweep (frame_count() of the ten, from the first), with seeded Kinect-like
/// axial noise.
inline const std::vector<Frame>& frames() {
  static const std::vector<Frame> f = [] {
    const Box room{{0, 0, 0}, {6, 5, 3}};
    const Box boxes[] = {{{2.5, 1.5, 0}, {3.5, 3.0, 0.75}},  // table
                         {{4.5, 0.2, 0}, {5.0, 1.2, 2.0}},   // cabinet
                         {{1.8, 3.8, 0}, {2.4, 4.4, 1.1}}};  // crate
    const iv::Point3 sphere(3.2, 3.5, 1.0);
    const auto k = camera();
    std::mt19937_64 rng(20240611);
    std::normal_distribution<double> gauss(0.0, 1.0);
    std::vector<Frame> out;
    for (int i = 0; i < std::clamp(frame_count(), 1, kFrames); ++i) {
      const double a = double(i) / (kFrames - 1);
      const double yaw = (-25.0 + 50.0 * a) * kPi / 180.0;
      Frame fr;
      fr.origin = iv::Point3(0.8 + 0.5 * a, 2.5, 1.3);
      // Optical frame: z forward along the yawed +x, x right, y down.
      iv::Point3 fwd(std::cos(yaw), std::sin(yaw), 0), down(0, 0, -1);
      iv::Point3 right = down.cross(fwd);  // x = y cross z
      Eigen::Matrix3d r;
      r.col(0) = right;
      r.col(1) = down;
      r.col(2) = fwd;
      fr.pose = iv::Pose::Identity();
      fr.pose.linear() = r;
      fr.pose.translation() = fr.origin;
      fr.image = iv::DepthImage(k.width, k.height);
      for (int v = 0; v < k.height; ++v)
        for (int u = 0; u < k.width; ++u) {
          const iv::Point3 d = r * k.ray(u, v);  // z-depth = ray parameter, since ray.z = 1
          double t = exit_room(fr.origin, d, room);
          for (const auto& b : boxes) t = std::min(t, hit_box(fr.origin, d, b));
          t = std::min(t, hit_sphere(fr.origin, d, sphere, 0.4));
          const double sigma = 0.0012 + 0.0019 * (t - 0.4) * (t - 0.4);
          const double z = t + sigma * gauss(rng);
          fr.image.at(u, v) = static_cast<float>(z);
          fr.cloud.push_back((fr.origin + d * double(static_cast<float>(z))).cast<float>());
        }
      out.push_back(std::move(fr));
    }
    return out;
  }();
  return f;
}

}  // namespace room_frame
