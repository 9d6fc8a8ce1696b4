#pragma once
/// \file
/// What a rig sees when the base turns on the spot: the yaws of the look-around that make the
/// rig's fields of view cover the full circle, the blind zone around the base inside which the
/// rig cannot see the whole height band the exploration map projects, and which voxels of it it
/// cannot see at all (docs/planning.md, "Using the planners on your robot"). All depend only on
/// the rig's geometry, not on a scene.
///
/// Thread safety: the functions are pure functions of their arguments; a BlindZone is immutable
/// after construction.

#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/sensors.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/raycast/traversal.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <span>
#include <string>
#include <unordered_set>
#include <vector>

namespace intervox {

/// The horizontal fields of view of a rig's sensors about the body's z axis, in the body frame.
struct RigCoverage {
  /// One arc per sensor with a horizontal component: it starts at `start` (rad, counter-clockwise
  /// from the body's x axis, in [0, 2 pi)) and spans `width` (rad, >= 0) counter-clockwise.
  struct Arc {
    double start = 0;
    double width = 0;
  };
  std::vector<Arc> arcs;
  /// The widest arc of directions no sensor covers (0 when the arcs cover the full circle; 2 pi
  /// when there is no arc).
  double largest_gap = 2 * std::numbers::pi;
  /// The narrowest arc's width (0 when there is no arc).
  double narrowest = 0;
};

/// The horizontal coverage of \p rig: for each sensor, the azimuths (about the body's z axis) its
/// beams cover, as one arc around the sensor's mean direction. A beam counts at two places: its
/// direction (what it sees far away) and its point at horizontal distance \p distance from the
/// z axis (what it sees near the base, where a mount's offset from the axis narrows the arc); the
/// sensor's arc is the part both agree on, so it holds from \p distance outwards. Beams within
/// 1e-6 of vertical have no azimuth and are ignored. A camera's arc spans its pixel centres,
/// slightly less than its opening angle.
/// \throws InvalidArgument for a distance that is not finite and > 0.
inline RigCoverage rig_coverage(const SensorRig& rig, double distance = 1.0) {
  ParamCheck("intervox::rig_coverage").positive("distance", distance);
  constexpr double two_pi = 2 * std::numbers::pi;
  RigCoverage c;
  const std::vector<SensorRay> rays = rig.rays(Pose::Identity());
  for (std::size_t s = 0; s < rig.size(); ++s) {
    Point3 mean = Point3::Zero();
    for (const SensorRay& r : rays)
      if (r.sensor == s) mean += Point3(r.ray.direction.x(), r.ray.direction.y(), 0.0);
    if (mean.head<2>().norm() < 1e-9) continue;
    const double axis = std::atan2(mean.y(), mean.x());
    const double inf = std::numeric_limits<double>::infinity();
    double far_lo = inf, far_hi = -inf, near_lo = inf, near_hi = -inf;
    for (const SensorRay& r : rays) {
      const Eigen::Vector2d d = r.ray.direction.head<2>(), o = r.ray.origin.head<2>();
      if (r.sensor != s || d.norm() < 1e-6) continue;
      const double a = std::remainder(std::atan2(d.y(), d.x()) - axis, two_pi);
      far_lo = std::min(far_lo, a);
      far_hi = std::max(far_hi, a);
      // The point at `distance` from the axis: |o + t d| = distance, the larger root (t >= 0).
      const double dd = d.squaredNorm(), od = o.dot(d), oo = o.squaredNorm() - distance * distance;
      const double t = std::max(0.0, (-od + std::sqrt(std::max(0.0, od * od - dd * oo))) / dd);
      const Eigen::Vector2d p = o + t * d;
      const double b = std::remainder(std::atan2(p.y(), p.x()) - axis, two_pi);
      near_lo = std::min(near_lo, b);
      near_hi = std::max(near_hi, b);
    }
    const double lo = std::max(far_lo, near_lo), hi = std::min(far_hi, near_hi);
    if (!(lo <= hi)) continue;
    double start = std::fmod(axis + lo, two_pi);
    if (start < 0) start += two_pi;
    c.arcs.push_back({start, hi - lo});
  }
  if (c.arcs.empty()) return c;
  std::vector<RigCoverage::Arc> sorted = c.arcs;
  std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return a.start < b.start; });
  c.narrowest = sorted.front().width;
  double end = sorted.front().start + sorted.front().width, gap = 0;
  for (std::size_t i = 1; i < sorted.size(); ++i) {
    c.narrowest = std::min(c.narrowest, sorted[i].width);
    gap = std::max(gap, sorted[i].start - end);
    end = std::max(end, sorted[i].start + sorted[i].width);
  }
  gap = std::max(gap, sorted.front().start + two_pi - end);  // from the last arc's end round to the first's start
  c.largest_gap = std::max(0.0, gap);
  return c;
}

/// The yaws (rad, relative to the body's heading, counter-clockwise, increasing from 0) at which
/// a base carrying \p rig scans while it turns on the spot to look around.
///
///  - \p span given: \p scans yaws evenly from 0 to *span (one yaw, 0, for a single scan).
///  - \p span unset (the default of MobilePlannerParams::look_around_span): if the thesis' turn
///    (\p scans scans, 45° / scans apart) already closes the rig's largest gap in coverage
///    (rig_coverage()), those yaws: the eight cameras of SensorRig::mobile_base keep the thesis'
///    look-around. Otherwise the base turns by the largest gap plus an overlap of a tenth of the
///    narrowest arc, in steps of at most the narrowest arc minus that overlap, so that every
///    direction around the base lies in some sensor's field of view at some scan from 1 m out
///    (rig_coverage() at its default distance); at least \p scans scans. One 40° camera on the
///    axis turns in 11 scans of about 32.5°; mounted 0.3 m forward, in 15 of about 24°.
///
/// \throws InvalidArgument for scans < 1, a span that is not finite and >= 0, or (span unset) a
///         rig without a beam with a horizontal component.
inline std::vector<double> look_around_yaws(const SensorRig& rig, int scans,
                                            std::optional<double> span = std::nullopt) {
  const ParamCheck check("intervox::look_around_yaws");
  check.at_least("scans", scans, 1);
  std::vector<double> yaws;
  if (span) {
    check.nonnegative("span", *span);
    for (int i = 0; i < scans; ++i) yaws.push_back(scans == 1 ? 0.0 : *span * i / (scans - 1));
    return yaws;
  }
  const RigCoverage cov = rig_coverage(rig);
  if (cov.arcs.empty()) check.fail("the rig has no beam with a horizontal component; give the span");
  const double thesis_step = std::numbers::pi / 4 / scans;
  if (cov.largest_gap <= thesis_step * (scans - 1)) {
    for (int i = 0; i < scans; ++i) yaws.push_back(thesis_step * i);
    return yaws;
  }
  const double width = std::max(cov.narrowest, std::numbers::pi / 180);  // a line sensor turns by a degree at most
  const double overlap = 0.1 * width;
  const double turn = cov.largest_gap + overlap;
  const int n = std::max(scans, 1 + static_cast<int>(std::ceil(turn / (width - overlap))));
  for (int i = 0; i < n; ++i) yaws.push_back(turn * i / (n - 1));
  return yaws;
}

/// The blind zone of \p rig scanning at \p yaws (look_around_yaws()): the radius about the body's
/// z axis inside which some column's height band [\p z_low, \p z_high] (body frame, the band the
/// exploration map projects) is not wholly seen, so that an obstacle may stand there unseen.
///
/// Formula: for a height z, d_z(phi) is the least horizontal distance from the z axis at which a
/// beam of the rig (every beam, turned by each yaw) crosses height z within its range window
/// [min range, max range], the crossing's azimuth phi binned in 2° bins; the blind radius is the
/// largest over the bins of max(d_{z_low}(phi), d_{z_high}(phi)). For a camera whose vertical
/// opening spans the band this is the distance at which its lowest (or highest) pixel row reaches
/// the band's edge: a camera at height h with half vertical opening beta, z_low < h, mounted r
/// from the axis, looking horizontally, gives r + (h - z_low) / tan(beta) straight ahead (more
/// towards the sides of its image, where the row's distance grows by 1 / cos of the azimuth).
///
/// \returns the radius in metres, or std::nullopt if some azimuth bin never sees one of the two
///          heights (the rig cannot see the band all around: set the start-free radius by hand).
/// \throws InvalidArgument for an empty \p yaws, non-finite yaws, or heights that are not finite
///         with z_low <= z_high.
inline std::optional<double> blind_radius(const SensorRig& rig, std::span<const double> yaws, double z_low,
                                          double z_high) {
  if (yaws.empty()) ParamCheck("intervox::blind_radius").fail("need at least one yaw");
  for (const double y : yaws) ParamCheck("intervox::blind_radius").finite("yaws", y);
  const ParamCheck check("intervox::blind_radius");
  check.finite("z_low", z_low);
  check.finite("z_high", z_high);
  if (!(z_low <= z_high)) check.fail("need z_low <= z_high");
  constexpr int bins = 180;
  constexpr double two_pi = 2 * std::numbers::pi;
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> near_low(bins, inf), near_high(bins, inf);
  const std::vector<SensorRay> rays = rig.rays(Pose::Identity());
  for (const double yaw : yaws) {
    const Eigen::Matrix3d turn = Eigen::AngleAxisd(yaw, Point3::UnitZ()).toRotationMatrix();
    for (const SensorRay& r : rays) {
      const Point3 o = turn * r.ray.origin, d = turn * r.ray.direction;
      if (std::abs(d.z()) < 1e-12) continue;
      for (int h = 0; h < 2; ++h) {
        const double t = ((h == 0 ? z_low : z_high) - o.z()) / d.z();
        if (!(t >= r.min_range && t <= r.ray.range)) continue;
        const Point3 p = o + t * d;
        double az = std::atan2(p.y(), p.x());
        if (az < 0) az += two_pi;
        const int bin = std::min(bins - 1, static_cast<int>(az / two_pi * bins));
        double& best = (h == 0 ? near_low : near_high)[static_cast<std::size_t>(bin)];
        best = std::min(best, p.head<2>().norm());
      }
    }
  }
  double radius = 0;
  for (int b = 0; b < bins; ++b)
    radius = std::max({radius, near_low[static_cast<std::size_t>(b)], near_high[static_cast<std::size_t>(b)]});
  if (!std::isfinite(radius)) return std::nullopt;
  return radius;
}

/// The space around the base that a rig, scanning at the look-around's yaws from one spot, can
/// never see (occlusion aside): tabulated in rings of horizontal distance from the body's z axis
/// (`ring` m apart, out to `radius`) and 2° bins of azimuth, each holding the lowest and highest
/// height at which a beam of the look-around crosses that ring within its range window. Beams fan
/// out continuously between their pixels, so the heights in between are crossed too.
///
/// The mobile planner's start rule uses it (MobilePlannerParams::start_free_radius): within the
/// start-free radius, a voxel that no beam of the look-around could have crossed counts as free
/// (the operator started the robot in a clear spot), while a voxel the rig could see is left to
/// what the rig measured there.
///
/// Thread safety: const members may be called concurrently; trace() is the one that mutates.
class BlindZone {
 public:
  BlindZone() = default;
  /// \param rig the base's sensors; \param yaws the look-around (look_around_yaws())
  /// \param radius m, how far out the zone is tabulated (>= 0; nothing is blind beyond it)
  /// \param ring m between tabulated rings (> 0; at most the voxel size for exact answers)
  /// \throws InvalidArgument for non-finite yaws or a radius / ring outside those ranges.
  BlindZone(const SensorRig& rig, std::span<const double> yaws, double radius, double ring = 0.05)
      : ring_(ring), radius_(radius) {
    const ParamCheck check("intervox::BlindZone");
    check.nonnegative("radius", radius);
    check.positive("ring", ring);
    rings_ = static_cast<int>(std::ceil(radius / ring)) + 2;
    lo_.assign(static_cast<std::size_t>(rings_) * kBins, std::numeric_limits<float>::infinity());
    hi_.assign(lo_.size(), -std::numeric_limits<float>::infinity());
    rays_ = rig.rays(Pose::Identity());
    yaws_.assign(yaws.begin(), yaws.end());
    for (const double yaw : yaws) {
      ParamCheck("intervox::BlindZone").finite("yaws", yaw);
      const Eigen::Matrix3d turn = Eigen::AngleAxisd(yaw, Point3::UnitZ()).toRotationMatrix();
      for (const SensorRay& r : rays_) {
        const Point3 o = turn * r.ray.origin, d = turn * r.ray.direction;
        const double dd = d.head<2>().squaredNorm();
        if (dd < 1e-12) continue;
        const double od = o.head<2>().dot(d.head<2>()), oo = o.head<2>().squaredNorm();
        for (int k = 0; k < rings_; ++k) {
          const double rk = k * ring_;
          const double disc = od * od - dd * (oo - rk * rk);
          if (disc < 0) continue;
          for (const double sign : {-1.0, 1.0}) {
            const double t = (-od + sign * std::sqrt(disc)) / dd;
            if (!(t >= r.min_range && t <= r.ray.range)) continue;
            const Point3 p = o + t * d;
            const std::size_t i = index(k, bin_of(p));
            lo_[i] = std::min(lo_[i], static_cast<float>(p.z()));
            hi_[i] = std::max(hi_[i], static_cast<float>(p.z()));
          }
        }
      }
    }
  }

  double radius() const noexcept { return radius_; }

  /// Exact answers for one start, in voxels of \p geometry: walks every beam of the look-around
  /// at \p start (the body pose of the look-around) through the grid, from its sensor's min
  /// range (a surface nearer than that gives no measurement; blind() starts there too) to its
  /// range or to where it leaves the zone (radius() plus one voxel from the z axis), and keeps
  /// the voxels it crosses (traverse() of raycast/traversal.hpp, the insertion's walk). From
  /// then on traced() is true and crossed() answers for a voxel: a voxel
  /// no beam crosses is blind whatever lies around it, one a beam crosses is not, also where an
  /// obstacle stopped that beam before it. Unlike blind(), no hull over neighbouring azimuths and
  /// rings: a voxel in the gaps between a single camera's turns, which blind() counts as seen, is
  /// blind here. Memory: one key per voxel of the zone that a beam crosses (about 0.1 million
  /// keys for a 1.5 m zone at 5 cm). Cost: one walk per beam and turn (`BM_BlindZone` in
  /// bench/bench_plan.cpp). A second call replaces the first.
  /// Thread safety: mutates the zone; not concurrently with any other member.
  /// \throws InvalidArgument for a non-finite start.
  void trace(const GridGeometry& geometry, const Pose& start) {
    if (!start.matrix().allFinite()) ParamCheck("intervox::BlindZone::trace").fail("the start pose must be finite");
    crossed_.clear();
    traced_ = true;
    const double reach = radius_ + geometry.resolution();
    for (const double yaw : yaws_) {
      const Eigen::Matrix3d turn = Eigen::AngleAxisd(yaw, Point3::UnitZ()).toRotationMatrix();
      const Pose turned = start * Pose(turn);
      for (const SensorRay& r : rays_) {
        // In the start's body frame: how far the beam runs before it leaves the zone's cylinder.
        const Point3 o = turn * r.ray.origin, d = turn * r.ray.direction;
        const double dd = d.head<2>().squaredNorm(), od = o.head<2>().dot(d.head<2>()), oo = o.head<2>().squaredNorm();
        double t = r.ray.range;
        if (dd > 1e-12) {
          const double disc = od * od - dd * (oo - reach * reach);
          if (disc < 0) continue;  // never within the zone
          t = std::min(t, (-od + std::sqrt(disc)) / dd);
        }
        if (!(t > r.min_range)) continue;
        const Point3 from = turned * Point3(r.ray.origin + r.ray.direction * r.min_range);
        const Point3 to = turned * Point3(r.ray.origin + r.ray.direction * t);
        traverse(geometry, from, to, [&](const Key& k) {
          crossed_.insert(k);
          return true;
        });
      }
    }
  }
  /// True once trace() was called.
  bool traced() const noexcept { return traced_; }
  /// True if a beam of the traced look-around crosses voxel \p k (false before trace()).
  bool crossed(const Key& k) const { return crossed_.contains(k); }
  /// The start rule's answer for voxel \p k, whose cube of half side \p half lies about \p p
  /// (body frame at the look-around's spot): !crossed(k) once traced, blind(p, half) before.
  bool blind_voxel(const Key& k, const Point3& p, double half) const { return traced_ ? !crossed(k) : blind(p, half); }

  /// True if the cube of half side \p half about \p p (body frame) lies within radius() of the
  /// z axis.
  bool contains(const Point3& p, double half) const noexcept {
    return p.head<2>().norm() + half * std::numbers::sqrt2 <= radius_;
  }

  /// True if the axis-aligned cube of half side \p half about \p p (body frame at the
  /// look-around's spot) lies within radius() and no beam of the look-around can cross it: over
  /// the rings and azimuth bins the cube's horizontal extent touches, the range from the lowest
  /// to the highest height crossed misses [p.z - half, p.z + half] (conservative: a cube between
  /// two crossed heights counts as seen).
  bool blind(const Point3& p, double half) const noexcept {
    const double reach = half * std::numbers::sqrt2;
    const double d = p.head<2>().norm();
    if (d + reach > radius_ || rings_ == 0) return false;
    const int k0 = std::max(0, static_cast<int>(std::floor((d - reach) / ring_)));
    const int k1 = std::min(rings_ - 1, static_cast<int>(std::ceil((d + reach) / ring_)));
    int b0 = 0, b1 = kBins - 1;
    if (d > reach) {
      const double spread = std::asin(std::min(1.0, reach / d));
      const int centre = bin_of(p);
      const int w = static_cast<int>(std::ceil(spread / (2 * std::numbers::pi) * kBins)) + 1;
      b0 = centre - w;
      b1 = centre + w;
    }
    // The hull of the heights crossed in the window: a beam that passes the cube between two
    // rings (steeply) is above it at one and below it at the other, and still counts.
    float lo = std::numeric_limits<float>::infinity(), hi = -lo;
    for (int k = k0; k <= k1; ++k)
      for (int b = b0; b <= b1; ++b) {
        const std::size_t i = index(k, ((b % kBins) + kBins) % kBins);
        lo = std::min(lo, lo_[i]);
        hi = std::max(hi, hi_[i]);
      }
    return !(lo <= static_cast<float>(p.z() + half) && hi >= static_cast<float>(p.z() - half));
  }

 private:
  static constexpr int kBins = 180;
  static int bin_of(const Point3& p) noexcept {
    double az = std::atan2(p.y(), p.x());
    if (az < 0) az += 2 * std::numbers::pi;
    return std::min(kBins - 1, static_cast<int>(az / (2 * std::numbers::pi) * kBins));
  }
  std::size_t index(int ring, int bin) const noexcept {
    return static_cast<std::size_t>(ring) * kBins + static_cast<std::size_t>(bin);
  }
  int rings_ = 0;
  double ring_ = 0.05;
  double radius_ = 0;
  std::vector<float> lo_, hi_;
  std::vector<SensorRay> rays_;  ///< the rig's beams in the body frame
  std::vector<double> yaws_;     ///< the look-around's yaws
  bool traced_ = false;
  std::unordered_set<Key, KeyHash> crossed_;  ///< trace(): the voxels a beam crosses
};

}  // namespace intervox
