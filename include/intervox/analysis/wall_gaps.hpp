#pragma once
/// \file
/// The gaps of seen walls, and whether what is seen through one could be a mirror's phantom
/// (docs/planning.md, "Gaps in a wall").
///
/// A mirror hung on a wall hides the wall behind it. Its beams cross the wall's plane only where
/// the mirror is, where no voxel of the wall is supported, so the crossing test of ExplainedSpace
/// trusts them and the phantom behind the wall is explained free: no voxel is free only by lying
/// beams, no lying region forms, and find_lying_surfaces() (analysis/lying_surfaces.hpp) has
/// nothing to look at. A planner in an unbounded grid then drives into the phantom room
/// (measured in docs/planning.md). Within a depth camera's range, what a mirror shows of an empty
/// room and what a doorway shows of a room like it agree; what tells them apart is what is seen
/// through the gap that a reflection cannot explain. find_wall_gaps() looks at the walls:
///
///  1. **Walls.** Every supported surface voxel (ExplainedSpace::supported_surface()) whose local
///     plane (ExplainedSpace::surface_normal()) is vertical within `max_wall_tilt_deg` votes for
///     the vertical plane through its centre with its normal (normals binned every
///     `normal_step_deg`, a voxel voting for its own bin and the two beside it; offsets binned
///     every voxel). A bin with at least `min_wall_area` m^2 of voxels (area / resolution^2) is a
///     wall candidate, strongest first, at most `max_walls` walls. Its voxels are the supported
///     voxels not taken by a stronger wall within a voxel of the bin's plane whose local plane is
///     within 2 x normal_step_deg + max_wall_tilt_deg of it; the wall's plane is the vertical
///     plane fitted to their centres (least squares, made vertical), its voxels are collected
///     again around that plane and the plane fitted again (at least min_wall_area each time);
///     they must span `min_wall_height` (furniture faces are lower, even two in one plane), and
///     they span its extent in the plane (along the floor and in height).
///  2. **Gap crossings.** Each returned beam of the channel's ledger (any class) that crosses a
///     wall's plane at least 2 x crossing_tolerance from its origin and more than
///     crossing_tolerance before its end, with its end more than crossing_tolerance behind the
///     plane (a beam that grazes the wall and ends on it is none), inside the wall's extent (at least one voxel-sized
///     cell within its edges) and in a cell of the plane with no voxel of the wall in it or in
///     the 8 cells around it (a gap), is a gap crossing. A beam through a mirror the channel
///     knows is left out (it is suspect already).
///  3. **Reflected ends.** A mirror's phantom return lies where the real surface it lit lies,
///     reflected about the mirror's plane. Each gap crossing's end, reflected about the wall's
///     plane, is
///     - *inconsistent* with a mirror if the reflected path from the crossing to it (up to
///       crossing_tolerance before it) passes a voxel of another wall that it meets at 20 degrees
///       or steeper (the end lies behind a wall on this side), or if the end's voxel and its 26
///       neighbours were all crossed by trusted beams and never hit (it lies in space the map
///       knows to be empty: a point beside an unseen surface, such as the floor under the robot
///       that only a mirror shows, is not);
///     - else *consistent* if its voxel or one of its 26 neighbours is supported (a surface's
///       hits fall in the voxel before or behind its face), and a *vote* if that surface's local
///       plane faces the wall (normal within 70 degrees of the wall's);
///     - else no evidence (space not yet seen).
///  4. **Gaps.** The gap cells a wall's crossings pass form 8-connected groups in its plane. A
///     group is an **opening** if at least `min_inconsistent` of its ends are inconsistent and
///     they are more than `opening_share` of its consistent and inconsistent ends: something seen
///     through it contradicts a reflection. Any other gap may be a mirror.
///
/// MobilePlanner with ExplainedPlanningParams::close_wall_gaps closes every gap that is not an
/// opening for one plan (its footprint counts as an occupied column of the exploration map), so
/// the robot does not drive through a gap before something seen through it rules out a mirror;
/// nothing is told to the channel, so a doorway opens as soon as the evidence says so. The known
/// hard cases: two mirror-symmetric rooms joined by a doorway stay closed (nothing seen through
/// the doorway contradicts a reflection), and so does a doorway into an empty room whose far
/// side lies beyond the sensor's range; a mirror at a wall's end (no wall on one side) lies
/// outside the wall's extent and is not found, nor is one on a wall seen too little to make
/// min_wall_area.
///
/// Only the ledger's scans are looked at (ExplainOptions::ledger_bytes; without a ledger no gap
/// is found). Cost: one pass over the supported voxels per wall candidate, then per wall one pass
/// over the ledger's returned beams (a few multiplications each) and, per gap crossing, one walk
/// of the reflected path and a few dozen lookups; walls spread over `threads` (the same result
/// for any count); measured in docs/performance.md ("Wall gaps").
///
/// Thread safety: reads the channel only; it must not be written meanwhile.

#include <intervox/analysis/lying_surfaces.hpp>
#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/parallel.hpp>
#include <intervox/core/plane_fit.hpp>
#include <intervox/core/plane_patch.hpp>
#include <intervox/core/point.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/explain/explained_space.hpp>
#include <intervox/raycast/traversal.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numbers>
#include <optional>
#include <span>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

namespace intervox {

/// The thresholds of find_wall_gaps() (see the file comment).
struct WallGapParams {
  /// m^2 of supported voxels a vertical plane needs to be a wall, > 0.
  double min_wall_area = 0.5;
  /// m a wall's voxels must span in height (furniture faces, even two in one plane, are lower), >= 0.
  double min_wall_height = 1.5;
  /// Degrees between two candidate wall normals, in (0, 90].
  double normal_step_deg = 2.0;
  /// Degrees a voxel's local plane may lean from the vertical and still vote for a wall, in [0, 90).
  double max_wall_tilt_deg = 15.0;
  /// Walls looked at at most, >= 1 (the strongest).
  std::size_t max_walls = 64;
  /// Inconsistent ends a gap needs to be an opening, >= 1 ...
  std::size_t min_inconsistent = 50;
  /// ... and their share of its consistent and inconsistent ends must exceed this, in [0, 1).
  double opening_share = 0.01;
  /// Threads (0: all hardware threads); the result is the same for any count.
  unsigned threads = 1;

  /// \throws InvalidArgument naming the first invalid parameter.
  void validate() const {
    const ParamCheck check("intervox::WallGapParams");
    check.positive("min_wall_area", min_wall_area);
    check.nonnegative("min_wall_height", min_wall_height);
    check.in_range("normal_step_deg", normal_step_deg, 0.0, 90.0, RangeEnds::OpenClosed);
    check.in_range("max_wall_tilt_deg", max_wall_tilt_deg, 0.0, 90.0, RangeEnds::ClosedOpen);
    check.at_least("max_walls", max_walls, std::size_t{1});
    check.at_least("min_inconsistent", min_inconsistent, std::size_t{1});
    check.in_range("opening_share", opening_share, 0.0, 1.0, RangeEnds::ClosedOpen);
  }
};

/// One gap of a wall that returned beams passed, judged (see the file comment).
struct WallGap {
  bool opening = false;  ///< the verdict: something seen through it contradicts a reflection
  /// The gap's patch: in the wall's plane, spanning the cells its crossings pass (half a voxel
  /// wider), the normal turned towards the mean origin of its beams.
  PlanePatch surface;
  std::size_t wall_voxels = 0;  ///< the voxels of the wall it lies in
  std::size_t cells = 0;        ///< voxel-sized cells of the plane its crossings pass
  std::size_t beams = 0;        ///< gap crossings
  std::size_t votes = 0;        ///< consistent ends on a surface that faces the wall
  std::size_t consistent = 0;   ///< ends reflected onto a supported voxel (votes included)
  /// Ends reflected behind another wall, or into space trusted beams crossed and never hit.
  std::size_t inconsistent = 0;
};

namespace detail {

/// A wall of find_wall_gaps(): the plane n . p = offset (n horizontal), its in-plane axes
/// (u along the floor, v = up) and the occupied voxel-sized cells of the plane with their extent.
struct GapWall {
  Point3 normal;
  double offset = 0.0;
  Point3 axis_u;
  std::unordered_set<std::int64_t> cells;
  std::vector<Key> keys;
  std::int64_t u0 = 0, u1 = -1, v0 = 0, v1 = -1;
  std::size_t voxels = 0;
};

inline std::int64_t gap_cell_id(std::int64_t u, std::int64_t v) noexcept { return u * 4294967311LL + v; }

/// What every phase of find_wall_gaps() reads: the channel, the thresholds, the quantities derived
/// from them once, and the supported and crossed bits of the trusted counts (the region
/// analysis' tables, read per thread).
struct WallGapContext {
  const ExplainedSpace& space;
  const WallGapParams& params;
  const GridGeometry& g;
  double res = 0.0;
  double tol = 0.0;         ///< the channel's crossing_tolerance
  double deg = 0.0;         ///< radians per degree
  double min_facing = 0.0;  ///< sin 20 degrees: a surface met at 20 degrees or steeper faces
  const TrustedBits& bits;
};

/// A supported voxel whose local plane is vertical within max_wall_tilt_deg, and that plane's normal.
struct WallSurface {
  Key key;
  Point3 normal;
};

/// A bin of the wall votes: angle bin a, offset bin d, its votes n.
struct WallPeak {
  int a;
  std::int64_t d;
  std::size_t n;
};

/// Wall search, the voters: the supported voxels with a vertical local plane, in key order.
inline std::vector<WallSurface> wall_surfaces(const WallGapContext& ctx) {
  std::vector<WallSurface> surfaces;
  std::vector<Key> supported;
  ctx.space.counts(BeamClass::Trusted).for_each_observed([&](const Key& k, const HitMissCount::Cell& c) {
    if (ctx.space.supported_counts(c)) supported.push_back(k);
  });
  TrustedBits::Reader read(ctx.bits);
  const double max_z = std::sin(ctx.params.max_wall_tilt_deg * ctx.deg);
  for (const Key& k : supported) {
    const std::optional<Point3> n = local_surface(k, [&](const Key& q) { return read.supported(q); }).normal;
    if (n && std::abs(n->z()) <= max_z) surfaces.push_back({k, *n});
  }
  std::sort(surfaces.begin(), surfaces.end(), [](const WallSurface& a, const WallSurface& b) { return a.key < b.key; });
  return surfaces;
}

/// The number of angle bins of the wall votes (normals over 180 degrees).
inline int wall_angle_bins(const WallGapParams& p) {
  return static_cast<int>(std::ceil(180.0 / p.normal_step_deg - 1e-9));
}

/// The horizontal normal of angle bin \p a (its centre).
inline Point3 wall_bin_normal(const WallGapContext& ctx, int a) {
  const double t = (a + 0.5) * ctx.params.normal_step_deg * ctx.deg;
  return Point3(std::cos(t), std::sin(t), 0.0);
}

/// The voxels a wall needs (min_wall_area in voxel faces).
inline std::size_t wall_min_voxels(const WallGapContext& ctx) {
  return static_cast<std::size_t>(std::ceil(ctx.params.min_wall_area / (ctx.res * ctx.res)));
}

/// Wall search, the votes: each voxel votes for the vertical plane through its centre in its
/// normal's angle bin and the two beside it (offsets binned every voxel); the bins with at least
/// wall_min_voxels() votes, strongest first (ties: by angle bin, then offset bin).
inline std::vector<WallPeak> wall_peaks(const WallGapContext& ctx, const std::vector<WallSurface>& surfaces) {
  const int angle_bins = wall_angle_bins(ctx.params);
  std::unordered_map<std::int64_t, std::size_t> hough;
  const auto hough_id = [&](int a, std::int64_t d) { return d * angle_bins + a; };
  for (const WallSurface& s : surfaces) {
    double a = std::atan2(s.normal.y(), s.normal.x()) / ctx.deg;
    if (a < 0.0) a += 180.0;
    if (a >= 180.0) a -= 180.0;
    const int ab = std::min(angle_bins - 1, static_cast<int>(a / ctx.params.normal_step_deg));
    for (int da = -1; da <= 1; ++da) {
      const int b = (ab + da + angle_bins) % angle_bins;
      const Point3 n = wall_bin_normal(ctx, b);
      // a bin that wraps past 180 degrees holds the opposite normal: same plane, negated offset
      const double d = n.dot(ctx.g.center(s.key));
      hough[hough_id(b, static_cast<std::int64_t>(std::floor(d / ctx.res)))] += 1;
    }
  }
  std::vector<WallPeak> peaks;
  const std::size_t min_voxels = wall_min_voxels(ctx);
  for (const auto& [id, n] : hough)
    if (n >= min_voxels) {
      const std::int64_t d = id >= 0 ? id / angle_bins : -((-id + angle_bins - 1) / angle_bins);
      peaks.push_back({static_cast<int>(id - d * angle_bins), d, n});
    }
  std::sort(peaks.begin(), peaks.end(), [](const WallPeak& x, const WallPeak& y) {
    return x.n != y.n ? x.n > y.n : (x.a != y.a ? x.a < y.a : x.d < y.d);
  });
  return peaks;
}

/// The wall search's state: the voters and which of them a stronger wall took already.
struct WallSearch {
  const std::vector<WallSurface>& surfaces;
  std::vector<char> used;
  double same_cos = 0.0;  ///< a voxel's local plane within 2 x normal_step_deg + max_wall_tilt_deg
};

/// The voxels not taken within a voxel of the plane n . p = offset whose local plane is near it.
inline std::vector<std::size_t> wall_members(const WallGapContext& ctx, const WallSearch& ws, const Point3& n,
                                             double offset) {
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < ws.surfaces.size(); ++i)
    if (!ws.used[i] && std::abs(n.dot(ctx.g.center(ws.surfaces[i].key)) - offset) <= ctx.res &&
        std::abs(ws.surfaces[i].normal.dot(n)) >= ws.same_cos)
      out.push_back(i);
  return out;
}

/// The vertical plane fitted to the centres of \p idx (least squares, made vertical), its normal
/// on \p towards's side; false if the fit leans too far from the vertical.
inline bool fit_wall_plane(const WallGapContext& ctx, const WallSearch& ws, const std::vector<std::size_t>& idx,
                           const Point3& towards, Point3& n, double& offset) {
  std::vector<Point3> centres;
  Point3 mean = Point3::Zero();
  for (const std::size_t i : idx) {
    centres.push_back(ctx.g.center(ws.surfaces[i].key));
    mean += centres.back();
  }
  mean /= static_cast<double>(centres.size());
  const std::optional<Point3> f = plane_normal(std::span<const Point3>(centres));
  if (!f || std::hypot(f->x(), f->y()) < std::cos(ctx.params.max_wall_tilt_deg * ctx.deg)) return false;
  n = Point3(f->x(), f->y(), 0.0).normalized();
  if (n.dot(towards) < 0.0) n = -n;
  offset = n.dot(mean);
  return true;
}

/// The wall of voxels \p idx in the plane n . p = offset, its voxels marked taken.
inline GapWall make_wall(const WallGapContext& ctx, WallSearch& ws, const std::vector<std::size_t>& idx,
                         const Point3& n, double offset) {
  GapWall w;
  w.normal = n;
  w.offset = offset;
  w.axis_u = PlanePatch::floor_axis(n);
  w.voxels = idx.size();
  w.u0 = w.v0 = std::numeric_limits<std::int64_t>::max();
  w.u1 = w.v1 = std::numeric_limits<std::int64_t>::min();
  for (const std::size_t i : idx) {
    ws.used[i] = 1;
    const Point3 c = ctx.g.center(ws.surfaces[i].key);
    const auto u = static_cast<std::int64_t>(std::floor(c.dot(w.axis_u) / ctx.res));
    const auto v = static_cast<std::int64_t>(std::floor(c.z() / ctx.res));
    w.cells.insert(gap_cell_id(u, v));
    w.keys.push_back(ws.surfaces[i].key);
    w.u0 = std::min(w.u0, u);
    w.u1 = std::max(w.u1, u);
    w.v0 = std::min(w.v0, v);
    w.v1 = std::max(w.v1, v);
  }
  return w;
}

/// Wall search, one peak: its voxels, the plane fitted to them (the bin's normal is known only to
/// normal_step_deg: a degree off moves a reflection 5 m away by 17 cm), and the voxels of that
/// plane, fitted again, if they make min_wall_area each time and span min_wall_height. A voxel
/// belongs to the first (strongest) wall that takes it.
inline std::optional<GapWall> wall_of_peak(const WallGapContext& ctx, WallSearch& ws, const WallPeak& p) {
  const std::size_t min_voxels = wall_min_voxels(ctx);
  const Point3 bn = wall_bin_normal(ctx, p.a);
  std::vector<std::size_t> idx = wall_members(ctx, ws, bn, (static_cast<double>(p.d) + 0.5) * ctx.res);
  if (idx.size() < min_voxels) return std::nullopt;
  Point3 n;
  double offset = 0.0;
  if (!fit_wall_plane(ctx, ws, idx, bn, n, offset)) return std::nullopt;
  idx = wall_members(ctx, ws, n, offset);
  if (idx.size() < min_voxels || !fit_wall_plane(ctx, ws, idx, bn, n, offset)) return std::nullopt;
  double z0 = std::numeric_limits<double>::infinity(), z1 = -z0;
  for (const std::size_t i : idx) {
    z0 = std::min(z0, ctx.g.center(ws.surfaces[i].key).z());
    z1 = std::max(z1, ctx.g.center(ws.surfaces[i].key).z());
  }
  if (z1 - z0 + ctx.res < ctx.params.min_wall_height) return std::nullopt;  // furniture, not a wall
  return make_wall(ctx, ws, idx, n, offset);
}

/// Wall search: the walls of the peaks, strongest first, at most max_walls.
inline std::vector<GapWall> find_walls(const WallGapContext& ctx, const std::vector<WallSurface>& surfaces,
                                       const std::vector<WallPeak>& peaks) {
  std::vector<GapWall> walls;
  WallSearch ws{surfaces, std::vector<char>(surfaces.size(), 0),
                std::cos((2.0 * ctx.params.normal_step_deg + ctx.params.max_wall_tilt_deg) * ctx.deg)};
  for (const WallPeak& p : peaks) {
    if (walls.size() >= ctx.params.max_walls) break;
    if (std::optional<GapWall> w = wall_of_peak(ctx, ws, p)) walls.push_back(std::move(*w));
  }
  return walls;
}

/// The evidence of one gap cell: its gap crossings, their reflected ends judged, their origins summed.
struct GapCellCount {
  std::size_t beams = 0, votes = 0, consistent = 0, inconsistent = 0;
  Point3 origins = Point3::Zero();
};

/// The gap search of one wall: the walls (the reflected paths' blocking test), what it gathers
/// per gap cell, and per thread a reader of the trusted bits with the local surface normals
/// asked so far.
struct WallScan {
  const std::vector<GapWall>& walls;
  const std::unordered_map<Key, std::size_t, KeyHash>& wall_of;  ///< which wall each wall voxel belongs to
  std::size_t wi;                                                ///< the wall searched
  TrustedBits::Reader at;
  std::unordered_map<Key, std::optional<Point3>, KeyHash> normals{};
  std::unordered_map<std::int64_t, GapCellCount> gap{};
  std::unordered_map<std::int64_t, std::pair<std::int64_t, std::int64_t>> where{};  ///< a gap cell's (u, v)
};

/// A gap crossing: where the beam crosses the wall's plane, its end's signed distance from it and
/// the crossing's cell.
struct GapCrossing {
  Point3 m;
  double se = 0.0;
  std::int64_t u = 0, v = 0;
};

/// Gap search, one beam: its crossing of wall \p w if it is a gap crossing (see the file comment,
/// step 2).
inline std::optional<GapCrossing> gap_crossing(const WallGapContext& ctx, const GapWall& w, const Beam& b) {
  const Point3& n = w.normal;
  const double so = n.dot(b.origin) - w.offset, se = n.dot(b.end) - w.offset;
  if ((so > 0) == (se > 0) || so == se) return std::nullopt;
  const double len = (b.end - b.origin).norm();
  const double t = so / (so - se);
  if (t * len < 2.0 * ctx.tol || (1.0 - t) * len <= ctx.tol || std::abs(se) <= ctx.tol) return std::nullopt;
  const Point3 m = b.origin + (b.end - b.origin) * t;
  const auto u = static_cast<std::int64_t>(std::floor(m.dot(w.axis_u) / ctx.res));
  const auto v = static_cast<std::int64_t>(std::floor(m.dot(Point3::UnitZ()) / ctx.res));
  if (u <= w.u0 || u >= w.u1 || v <= w.v0 || v >= w.v1) return std::nullopt;
  for (std::int64_t du = -1; du <= 1; ++du)
    for (std::int64_t dv = -1; dv <= 1; ++dv)
      if (w.cells.count(gap_cell_id(u + du, v + dv))) return std::nullopt;
  for (const PlanePatch& known : ctx.space.mirrors())
    if (known.contains(m, ctx.res)) return std::nullopt;
  return GapCrossing{m, se, u, v};
}

/// k and its 26 neighbours were crossed by trusted beams and never hit: a point in it lies in
/// space the map knows to be empty (a point beside an unseen surface, such as the floor under
/// the robot that only a mirror shows, is not).
inline bool gap_in_free_space(const WallGapContext& ctx, const Key& k) {
  const auto& trusted = ctx.space.counts(BeamClass::Trusted).storage();
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const Key q{k.x + dx, k.y + dy, k.z + dz};
        if (!in_key_range(q)) return false;
        const HitMissCount::Cell* c = trusted.find(q);
        if (!c || c->hits > 0 || c->misses == 0) return false;
      }
  return true;
}

/// The local plane at supported voxel k meets direction d at 20 degrees or steeper (its normal,
/// cached per voxel).
inline bool gap_facing_at(const WallGapContext& ctx, WallScan& scan, const Key& k, const Point3& d) {
  auto it = scan.normals.find(k);
  if (it == scan.normals.end())
    it = scan.normals.emplace(k, local_surface(k, [&](const Key& q) { return scan.at.supported(q); }).normal).first;
  return it->second && std::abs(it->second->dot(d)) >= ctx.min_facing;
}

/// What a gap crossing's reflected end says of a mirror (see the file comment, step 3).
enum class ReflectedEnd : std::uint8_t { NoEvidence, Consistent, Vote, Inconsistent };

/// Reflection test: the end of gap crossing \p x of beam \p b, reflected about the wall's plane.
inline ReflectedEnd reflection_test(const WallGapContext& ctx, WallScan& scan, const Beam& b, const GapCrossing& x) {
  const Point3& n = scan.walls[scan.wi].normal;
  // The reflected end's voxel, or else the first of its 26 neighbours, that is supported (the
  // wall's plane is known to about half a voxel, a surface's hits fall in the voxel before or
  // behind its face).
  const Point3 r = b.end - 2.0 * x.se * n;
  const std::optional<Key> centre = ctx.g.try_key(r);
  if (!centre) return ReflectedEnd::NoEvidence;
  std::optional<Key> landed;
  if (scan.at.supported(*centre)) landed = centre;
  for (int dz = -1; dz <= 1 && !landed; ++dz)
    for (int dy = -1; dy <= 1 && !landed; ++dy)
      for (int dx = -1; dx <= 1 && !landed; ++dx)
        if (const Key q{centre->x + dx, centre->y + dy, centre->z + dz}; in_key_range(q) && scan.at.supported(q))
          landed = q;
  const bool facing_end = landed && gap_facing_at(ctx, scan, *landed, n);
  if (landed && !facing_end)
    return ReflectedEnd::Consistent;  // a floor, a side wall: consistent, but every wall folds them so
  // The reflected path from the crossing to the end (up to tol before it) passes a voxel of
  // another wall it meets at 20 degrees or steeper: the end lies behind a wall this side.
  const Point3 dir = r - x.m;
  const double dlen = dir.norm();
  bool blocked = false;
  if (dlen > ctx.tol + ctx.res)
    traverse(ctx.g, x.m, Point3(x.m + dir * ((dlen - ctx.tol) / dlen)), [&](const Key& k) {
      const auto it = scan.wall_of.find(k);
      blocked = it != scan.wall_of.end() && it->second != scan.wi &&
                std::abs(scan.walls[it->second].normal.dot(dir)) >= ctx.min_facing * dlen;
      return !blocked;
    });
  if (blocked) return ReflectedEnd::Inconsistent;
  if (landed) return ReflectedEnd::Vote;
  if (gap_in_free_space(ctx, *centre)) return ReflectedEnd::Inconsistent;
  return ReflectedEnd::NoEvidence;
}

/// Gap search of one wall: the ledger's returned beams (not skipped) that are gap crossings,
/// counted per gap cell with their reflected ends judged.
inline void scan_wall_gaps(const WallGapContext& ctx, WallScan& scan) {
  const GapWall& w = scan.walls[scan.wi];
  for (const LedgerScan& ledger_scan : ctx.space.ledger().scans())
    ledger_scan.for_each([&](std::size_t, const Beam& b, BeamClass c) {
      if (!b.hit || c == BeamClass::Skipped) return;
      const std::optional<GapCrossing> x = gap_crossing(ctx, w, b);
      if (!x) return;
      const std::int64_t id = gap_cell_id(x->u, x->v);
      scan.where.emplace(id, std::make_pair(x->u, x->v));
      GapCellCount& cc = scan.gap[id];
      ++cc.beams;
      cc.origins += b.origin;
      switch (reflection_test(ctx, scan, b, *x)) {
        case ReflectedEnd::Consistent:
          ++cc.consistent;
          break;
        case ReflectedEnd::Vote:
          ++cc.consistent;
          ++cc.votes;
          break;
        case ReflectedEnd::Inconsistent:
          ++cc.inconsistent;
          break;
        case ReflectedEnd::NoEvidence:
          break;
      }
    });
}

/// The gaps of a wall's gap search: 8-connected groups of the cells crossed, in the order of
/// their smallest cell, each group's cells as (u, v).
inline std::vector<std::vector<std::pair<std::int64_t, std::int64_t>>> gap_groups(const WallScan& scan) {
  std::vector<std::pair<std::int64_t, std::int64_t>> order;
  for (const auto& [id, uv] : scan.where) order.push_back(uv);
  std::sort(order.begin(), order.end());
  std::unordered_set<std::int64_t> done;
  std::vector<std::vector<std::pair<std::int64_t, std::int64_t>>> groups;
  for (const auto& seed : order) {
    if (done.count(gap_cell_id(seed.first, seed.second))) continue;
    std::vector<std::pair<std::int64_t, std::int64_t>> group{seed};
    done.insert(gap_cell_id(seed.first, seed.second));
    for (std::size_t i = 0; i < group.size(); ++i)
      for (std::int64_t du = -1; du <= 1; ++du)
        for (std::int64_t dv = -1; dv <= 1; ++dv) {
          const std::int64_t id = gap_cell_id(group[i].first + du, group[i].second + dv);
          if (!scan.gap.count(id) || done.count(id)) continue;
          done.insert(id);
          group.push_back(scan.where.at(id));
        }
    groups.push_back(std::move(group));
  }
  return groups;
}

/// Verdict: one gap of wall \p w, its evidence summed over its cells, judged opening or not, with
/// its patch (see WallGap).
inline WallGap gap_verdict(const WallGapContext& ctx, const GapWall& w, const WallScan& scan,
                           const std::vector<std::pair<std::int64_t, std::int64_t>>& group) {
  const double res = ctx.res;
  WallGap out;
  out.wall_voxels = w.voxels;
  out.cells = group.size();
  Point3 origins = Point3::Zero();
  double cu0 = std::numeric_limits<double>::infinity(), cu1 = -cu0, cv0 = cu0, cv1 = -cu0;
  for (const auto& [cu, cv] : group) {
    const GapCellCount& cc = scan.gap.at(gap_cell_id(cu, cv));
    out.beams += cc.beams;
    out.votes += cc.votes;
    out.consistent += cc.consistent;
    out.inconsistent += cc.inconsistent;
    origins += cc.origins;
    cu0 = std::min(cu0, static_cast<double>(cu) * res);
    cu1 = std::max(cu1, static_cast<double>(cu + 1) * res);
    cv0 = std::min(cv0, static_cast<double>(cv) * res);
    cv1 = std::max(cv1, static_cast<double>(cv + 1) * res);
  }
  origins /= static_cast<double>(out.beams);
  out.opening = out.inconsistent >= ctx.params.min_inconsistent &&
                static_cast<double>(out.inconsistent) >
                    ctx.params.opening_share * static_cast<double>(out.consistent + out.inconsistent);
  const Point3& n = w.normal;
  PlanePatch& p = out.surface;
  p.normal = n.dot(origins) - w.offset >= 0.0 ? n : Point3(-n);
  p.axis_u = PlanePatch::floor_axis(p.normal);
  // the cells' u runs along w.axis_u, which is p.axis_u or its opposite
  const double su = p.axis_u.dot(w.axis_u) >= 0.0 ? 1.0 : -1.0;
  const Point3 pv = p.axis_v();  // +z or -z
  const double sv = pv.z() >= 0.0 ? 1.0 : -1.0;
  const double mu = 0.5 * (cu0 + cu1), mv = 0.5 * (cv0 + cv1);
  p.center = n * w.offset + p.axis_u * (su * mu) + pv * (sv * mv);
  p.half_u = 0.5 * (cu1 - cu0) + 0.5 * res;
  p.half_v = 0.5 * (cv1 - cv0) + 0.5 * res;
  return out;
}

}  // namespace detail

/// The gaps of \p space's walls that its ledger's returned beams crossed, judged opening or not
/// (see the file comment), wall by wall (strongest first), each wall's gaps in the order of their
/// smallest cell.
/// \throws InvalidArgument for invalid parameters.
inline std::vector<WallGap> find_wall_gaps(const ExplainedSpace& space, const WallGapParams& params = {}) {
  params.validate();
  const GridGeometry& g = space.geometry();
  const double deg = std::numbers::pi / 180.0;
  const detail::TrustedBits bits(space);
  const detail::WallGapContext ctx{
      space, params, g, g.resolution(), space.options().crossing_tolerance, deg, std::sin(20.0 * deg), bits};
  // 1. Wall search: the supported voxels with a vertical local plane vote for (normal bin, offset
  // bin); the strongest bins, fitted, are the walls.
  const std::vector<detail::WallSurface> surfaces = detail::wall_surfaces(ctx);
  const std::vector<detail::GapWall> walls = detail::find_walls(ctx, surfaces, detail::wall_peaks(ctx, surfaces));
  std::unordered_map<Key, std::size_t, KeyHash> wall_of;
  for (std::size_t wi = 0; wi < walls.size(); ++wi)
    for (const Key& k : walls[wi].keys) wall_of.emplace(k, wi);
  // 2.-4. Per wall: the gap search (its gap crossings, their reflected ends judged) and the verdict
  // on each gap they pass.
  std::vector<std::vector<WallGap>> per_wall(walls.size());
  parallel_for(walls.size(), params.threads, [&](std::size_t wi) {
    detail::WallScan scan{walls, wall_of, wi, detail::TrustedBits::Reader(bits)};
    detail::scan_wall_gaps(ctx, scan);
    for (const auto& group : detail::gap_groups(scan))
      per_wall[wi].push_back(detail::gap_verdict(ctx, walls[wi], scan, group));
  });
  std::vector<WallGap> out;
  for (auto& list : per_wall)
    for (WallGap& gp : list) out.push_back(std::move(gp));
  return out;
}

}  // namespace intervox
