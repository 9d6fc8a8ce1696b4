#pragma once
/// \file
/// Information gain of a candidate view (thesis 3.4, eq. 3.17; 4.3.2): every beam of the sensor
/// rig is cast from the candidate pose through the grid, and the utility policy's value of the
/// voxels it crosses is summed until the beam reaches an occupied voxel or its maximum range.
/// Candidates are evaluated in parallel; results do not depend on the number of threads.

#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/key_box_set.hpp>
#include <intervox/core/key_set.hpp>
#include <intervox/core/parallel.hpp>
#include <intervox/core/point.hpp>
#include <intervox/core/ray.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/core/types.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/grid/accessor.hpp>
#include <intervox/grid/cell_memo.hpp>
#include <intervox/grid/occupancy_grid.hpp>
#include <intervox/raycast/cast.hpp>
#include <intervox/raycast/traversal.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace intervox {

/// How often a voxel counts in the gain of one view.
enum class GainCount : std::uint8_t {
  /// Once per beam that crosses it (the thesis' sum over beams; dense beam bundles weight near
  /// voxels more, as they are crossed by many beams).
  PerBeam = 0,
  /// Once per view, however many beams cross it (the sum over the set of visible voxels).
  PerView = 1,
};

/// Which voxels a beam's utilities are summed over.
enum class GainVoxels : std::uint8_t {
  /// Every voxel the beam crosses, known voxels too (near zero for Bayes, not necessarily for
  /// intervals, which is the point of max-entropy). The library's default.
  All = 0,
  /// Only voxels whose state is unknown (never observed, or observed with a state between the
  /// thresholds): the thesis' gain (section 3.4), where a classified voxel adds nothing whatever
  /// its interval.
  Unknown = 1,
};

/// Options of the gain computation.
struct GainOptions {
  double max_range = 5.0;  ///< m; beams are cast this far unless stopped earlier, > 0
  GainCount count = GainCount::PerBeam;
  /// If set, beams are clipped to this box: voxels outside never count (e.g. the room or the
  /// workcell, so that unobserved space outside the scene does not attract the planner).
  std::optional<Bounds> bounds;
  GainVoxels voxels = GainVoxels::All;  ///< which voxels count (the thesis: Unknown)
  /// \throws InvalidArgument if max_range is not finite and > 0 or bounds are not valid.
  void validate() const {
    const ParamCheck check("intervox::GainOptions");
    check.positive("max_range", max_range);
    if (bounds) check.valid_bounds("bounds", *bounds);
  }
};

/// The gain of one view and what it cost.
struct ViewGain {
  double gain = 0.0;         ///< sum of utilities (see GainCount)
  std::uint64_t voxels = 0;  ///< voxels counted (after de-duplication for GainCount::PerView)
  std::uint64_t steps = 0;   ///< voxel steps of the traversal (the work done)
};

/// A sensor rig's beams in its body frame: Rays (origin, unit direction, the sensor's own range).
/// Cast from a body pose to predict what a view would see.
///
/// Thread safety: a plain value type.
class RayBundle {
 public:
  /// Adds one ray; it is cast min(ray.range, GainOptions::max_range) far.
  /// \throws InvalidArgument for a non-finite origin, a direction that is not unit length (within
  ///         1e-9) or a range that is NaN or <= 0.
  void add(const Ray& ray) {
    if (!is_finite(ray.origin) || !(std::abs(ray.direction.norm() - 1.0) <= 1e-9))
      ParamCheck("intervox::RayBundle").fail("ray origin must be finite and direction unit length");
    if (!(ray.range > 0)) ParamCheck("intervox::RayBundle").fail("ray range must be > 0");
    rays_.push_back(ray);
  }
  /// Adds one ray from \p origin along \p direction (normalised here).
  /// \throws InvalidArgument for a non-finite origin, a zero / non-finite direction or a range
  ///         that is NaN or <= 0.
  void add(const Point3& origin, const Point3& direction, double range = std::numeric_limits<double>::infinity()) {
    const double n = direction.norm();
    if (!std::isfinite(n) || n <= 0)
      ParamCheck("intervox::RayBundle").fail("ray origin must be finite and direction non-zero");
    add(Ray{origin, direction / n, range});
  }
  /// Adds the rays of a pinhole camera mounted at \p mount (camera to body), one per \p stride
  /// pixels in u and v: camera_rays(k, mount, stride), the centred pattern.
  /// \throws InvalidArgument for invalid intrinsics or stride < 1.
  void add_camera(const PinholeIntrinsics& k, const Pose& mount, int stride = 1) {
    for (const Ray& r : camera_rays(k, mount, stride)) add(r);
  }
  /// Adds the beams' directions (origin and end of each, in the body frame); beams with
  /// coincident ends are skipped.
  void add_beams(const std::vector<Beam>& beams) {
    for (const Beam& b : beams)
      if ((b.end - b.origin).norm() > 0) add(b.origin, b.end - b.origin);
  }
  const std::vector<Ray>& rays() const noexcept { return rays_; }
  std::size_t size() const noexcept { return rays_.size(); }
  bool empty() const noexcept { return rays_.empty(); }

 private:
  std::vector<Ray> rays_;
};

namespace detail {

/// A beam segment of a view in voxel units (detail::voxel_of()), with its end voxels' keys.
struct GainSegment {
  Point3 v0, v1;
  Key k0, k1;
};

/// Clips the segment [a, b] to box \p box (slab method). False if it misses the box.
inline bool clip_segment(const Bounds& box, Point3& a, Point3& b) noexcept {
  double t0 = 0.0, t1 = 1.0;
  const Point3 d = b - a;
  for (int i = 0; i < 3; ++i) {
    if (d[i] == 0.0) {
      if (a[i] < box.min[i] || a[i] > box.max[i]) return false;
      continue;
    }
    double ta = (box.min[i] - a[i]) / d[i], tb = (box.max[i] - a[i]) / d[i];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return false;
  }
  const Point3 a0 = a;
  a = a0 + t0 * d;
  b = a0 + t1 * d;
  return true;
}

/// Calls \p f(a, b) for every beam of \p rays seen from every body pose of \p path, pose after
/// pose: from the beam's origin to min(its range, options.max_range), clipped to options.bounds
/// (beams that miss the bounds are skipped).
/// \throws InvalidArgument (naming \p who, e.g. "intervox::view_gain", a literal) when it reaches a
/// pose that is not finite.
template <class F>
void for_each_beam_segment(const RayBundle& rays, const std::vector<Pose>& path, const GainOptions& options,
                           const char* who, F&& f) {
  for (const Pose& pose : path) {
    if (!pose.matrix().allFinite()) ParamCheck(who).fail("pose is not finite");
    for (const Ray& r : rays.rays()) {
      Point3 a = pose * r.origin;
      Point3 b = a + pose.linear() * r.direction * std::min(r.range, options.max_range);
      if (options.bounds && !clip_segment(*options.bounds, a, b)) continue;
      f(a, b);
    }
  }
}

}  // namespace detail

/// Accumulates the gain of one view, beam after beam; use it as the visitor of traverse().
/// Exposed so that other traversals (or tests) can drive it.
///
/// A voxel counts with its utility: every voxel with GainVoxels::All (known voxels too: near
/// zero for Bayes, not necessarily for intervals, which is the point of max-entropy), only voxels
/// of unknown state with GainVoxels::Unknown. A beam stops after the first occupied voxel; that
/// voxel itself counts (it is seen).
///
/// \tparam Grid a VoxelGrid
/// Thread safety: one accumulator per thread; the grid is only read (through a GridAccessor), and
/// must not be written while the accumulator lives.
template <OccupancyGrid Grid>
class GainAccumulator {
 public:
  /// \param scratch a set to remember the voxels of a view in (GainCount::PerView) instead of the
  ///        accumulator's own, e.g. one kept per thread so that its slots are allocated once; it
  ///        is cleared here and by finish(), and must outlive the accumulator.
  /// \param box if given, the voxels of the view are remembered in this bitmap instead
  ///        (GainCount::PerView; same voxels, same order, same sums): the caller has reset() it
  ///        to a box holding every voxel the view will visit (a visit outside it throws
  ///        InvalidArgument), and it must outlive the accumulator. finish() lets go of it: later
  ///        views use the KeySet again.
  GainAccumulator(const Grid& grid, GainCount count, GainVoxels voxels = GainVoxels::All, KeySet* scratch = nullptr,
                  KeyBoxSet* box = nullptr)
      : count_(count), voxels_(voxels), read_(grid), memo_(grid), seen_(scratch ? *scratch : own_), box_(box) {
    seen_.clear();
  }
  GainAccumulator(const GainAccumulator&) = delete;
  GainAccumulator& operator=(const GainAccumulator&) = delete;

  /// Visits one voxel of the current beam; false once the beam is blocked.
  bool operator()(const Key& k) {
    ++result_.steps;
    // One hash lookup per 8^3 block on sparse grids; the cell value's class and utility from the
    // memo (computed once per distinct value, exact).
    const CellSummary& s = memo_(read_.cell(k));
    const Occupancy occ = s.occupancy;
    // A voxel counts on every visit (per beam) or on its first visit of the view (per view).
    if ((voxels_ == GainVoxels::All || occ == Occupancy::Unknown) &&
        (count_ == GainCount::PerBeam || (box_ ? box_->insert(k) : seen_.insert(k)))) {
      result_.gain += s.utility;
      ++result_.voxels;
    }
    return occ != Occupancy::Occupied;
  }

  /// Visits the voxels of the segment [\p a, \p b] in the order of traverse(), as operator()
  /// would, until the first occupied voxel: the planners' path (one loop, its counters in
  /// registers). Nothing is visited if an endpoint is not finite or lies outside the key range.
  void walk(const GridGeometry& geometry, const Point3& a, const Point3& b) {
    Point3 v0, v1;
    Key k0, k1;
    if (!detail::voxel_of(geometry, a, v0, k0) || !detail::voxel_of(geometry, b, v1, k1)) return;
    walk_voxels(v0, v1, k0, k1);
  }

  /// walk() of a segment already converted by detail::voxel_of(): its end points \p v0, \p v1 in
  /// voxel units and their keys \p k0, \p k1.
  void walk_voxels(const Point3& v0, const Point3& v1, const Key& k0, const Key& k1) {
    // One loop per way of remembering the view's voxels, none for per beam: no test of the
    // count in the loop.
    if (count_ == GainCount::PerBeam) {
      EveryVisit every;
      walk_with(every, v0, v1, k0, k1);
    } else if (box_) {
      walk_with(*box_, v0, v1, k0, k1);
    } else {
      walk_with(seen_, v0, v1, k0, k1);
    }
  }

  /// The gain of everything visited so far, and a fresh start: the sum of the counted voxels'
  /// utilities in the order they were first counted. Lets go of the constructor's \p box.
  ViewGain finish() {
    ViewGain r = result_;
    result_ = {};
    seen_.clear();
    box_ = nullptr;
    return r;
  }

 private:
  // GainCount::PerBeam's "set": every visit counts.
  struct EveryVisit {
    static constexpr bool insert(const Key&) noexcept { return true; }
  };

  // walk() with the voxels that count remembered in \p seen (EveryVisit, a KeySet or a
  // KeyBoxSet).
  template <class Seen>
  [[gnu::flatten]] void walk_with(Seen& seen, const Point3& v0, const Point3& v1, const Key& k0, const Key& k1) {
    detail::SegmentDda dda(v0, v1, k0, k1);
    const bool all = voxels_ == GainVoxels::All;
    // The running sum continues result_'s, voxel after voxel: the same additions in the same
    // order as operator(), so the same bits.
    double gain = result_.gain;
    std::uint64_t voxels = result_.voxels, steps = result_.steps;
    // Neighbouring voxels often hold the same value (unobserved space, free space at a clamp):
    // the previous value's summary is reused without a memo lookup.
    using Cell = typename Grid::Cell;
    Cell last = read_.cell(dda.key);
    CellSummary s = memo_(last);
    for (;;) {
      ++steps;
      const Cell c = read_.cell(dda.key);
      if (std::memcmp(&c, &last, sizeof(Cell)) != 0) {
        s = memo_(c);
        last = c;
      }
      if ((all || s.occupancy == Occupancy::Unknown) && seen.insert(dda.key)) {
        gain += s.utility;
        ++voxels;
      }
      if (s.occupancy == Occupancy::Occupied || dda.remaining == 0) break;
      dda.advance();
    }
    result_.gain = gain;
    result_.voxels = voxels;
    result_.steps = steps;
  }

  GainCount count_;
  GainVoxels voxels_;
  GridAccessor<Grid> read_;
  CellMemo<Grid> memo_;
  ViewGain result_;
  KeySet own_;      // used when no scratch set is given
  KeySet& seen_;    // voxels counted in this view (GainCount::PerView), unless box_ is set
  KeyBoxSet* box_;  // the caller's bitmap of the view's box, if any
};

/// The information gain of the rig \p rays seen from every body pose of \p path together (a
/// scan path, e.g. the profiles of a striper sweep): one accumulator over all its beams, so
/// GainCount::PerView counts a voxel once per path.
///
/// Memory: per view, the path's beam segments (72 bytes each) and a set of the voxels counted,
/// kept per calling thread between calls: a bitmap of the segments' key box (KeyBoxSet) when
/// the box holds at most 64 voxels per voxel step of the walks (at most 16 MiB), else a hashed
/// KeySet (16 bytes per slot, at most 4x the view's voxels). Both count the same voxels.
///
/// \tparam Grid a VoxelGrid
/// \throws InvalidArgument if the options are invalid or a pose is not finite.
/// Thread safety: reads the grid only; may run concurrently with other readers.
template <OccupancyGrid Grid>
ViewGain path_gain(const Grid& grid, const RayBundle& rays, const std::vector<Pose>& path,
                   const GainOptions& options = {}) {
  options.validate();
  // One visited-voxel set per thread, kept between calls: a view of the mobile rig counts some
  // 10^5 voxels, and allocating the set's slots anew for every candidate costs more than the
  // walk. Its memory (16 bytes per slot, at most 4x the largest view's voxels) stays with the
  // thread.
  thread_local KeySet scratch;
  if (options.count == GainCount::PerBeam) {
    GainAccumulator<Grid> acc(grid, options.count, options.voxels, &scratch);
    detail::for_each_beam_segment(rays, path, options, "intervox::view_gain",
                                  [&](const Point3& a, const Point3& b) { acc.walk(grid.geometry(), a, b); });
    return acc.finish();
  }
  // Per view: the segments first, with the key box they span (a segment's voxels lie in the box
  // of its end voxels) and their voxel steps. If clearing the box's bitmap costs no more word
  // writes than the walks take steps, the view's voxels are remembered in a bitmap of the box
  // (a bit test per step) instead of the hashed KeySet; both give the same voxels in the same
  // order, so the same sum. The bitmap (at most KeyBoxSet::kMaxVoxels bits, 16 MiB) stays with
  // the thread, like the KeySet.
  thread_local KeyBoxSet box;
  thread_local std::vector<detail::GainSegment> segments;
  segments.clear();
  const GridGeometry& geometry = grid.geometry();
  Key lo{}, hi{};
  std::int64_t steps = 0;
  detail::for_each_beam_segment(rays, path, options, "intervox::view_gain", [&](const Point3& a, const Point3& b) {
    detail::GainSegment g;
    if (!detail::voxel_of(geometry, a, g.v0, g.k0) || !detail::voxel_of(geometry, b, g.v1, g.k1)) return;
    if (segments.empty()) lo = hi = g.k0;
    for (int i = 0; i < 3; ++i) {
      lo[i] = std::min({lo[i], g.k0[i], g.k1[i]});
      hi[i] = std::max({hi[i], g.k0[i], g.k1[i]});
      steps += std::abs(std::int64_t{g.k1[i]} - std::int64_t{g.k0[i]});
    }
    ++steps;
    segments.push_back(g);
  });
  const bool bitmap = !segments.empty() && box.reset(lo, hi, 64 * steps);
  GainAccumulator<Grid> acc(grid, options.count, options.voxels, &scratch, bitmap ? &box : nullptr);
  for (const detail::GainSegment& g : segments) acc.walk_voxels(g.v0, g.v1, g.k0, g.k1);
  return acc.finish();
}

/// The gain the scan path \p path would have in a world where every voxel is unobserved: every
/// beam runs to its full (clipped) range and every voxel it crosses counts with the utility of an
/// unobserved voxel. The planners divide a candidate's gain by it, so that a gain threshold means
/// the same fraction of the sensor's possible gain whatever the sensor, its stride and its range.
///
/// \tparam Grid a VoxelGrid (only its geometry and policies are used, not its cells)
/// \throws InvalidArgument if the options are invalid or a pose is not finite.
/// Thread safety: reads the grid's geometry and policies only.
template <OccupancyGrid Grid>
ViewGain unknown_path_gain(const Grid& grid, const RayBundle& rays, const std::vector<Pose>& path,
                           const GainOptions& options = {}) {
  options.validate();
  const double unknown = grid.utility_of(grid.update_policy().unobserved());
  ViewGain result;
  KeySet seen;
  detail::for_each_beam_segment(rays, path, options, "intervox::unknown_path_gain",
                                [&](const Point3& a, const Point3& b) {
                                  traverse(grid.geometry(), a, b, [&](const Key& k) {
                                    ++result.steps;
                                    if (options.count == GainCount::PerBeam || seen.insert(k)) ++result.voxels;
                                    return true;
                                  });
                                });
  result.gain = unknown * double(result.voxels);
  return result;
}

/// The information gain of the rig \p rays seen from body pose \p pose.
/// \tparam Grid a VoxelGrid
/// \throws InvalidArgument if the options are invalid or the pose is not finite.
/// Thread safety: reads the grid only; may run concurrently with other readers.
template <OccupancyGrid Grid>
ViewGain view_gain(const Grid& grid, const RayBundle& rays, const Pose& pose, const GainOptions& options = {}) {
  return path_gain(grid, rays, std::vector<Pose>{pose}, options);
}

/// Gains of many candidate scan paths, evaluated on \p threads threads (0: all hardware threads)
/// into a pre-sized vector: entry i belongs to paths[i], whatever the thread count.
/// \tparam Grid a VoxelGrid
/// \throws InvalidArgument if the options are invalid or a pose is not finite.
/// Thread safety: reads the grid only; the grid must not be modified meanwhile.
template <OccupancyGrid Grid>
std::vector<ViewGain> evaluate_paths(const Grid& grid, const RayBundle& rays,
                                     const std::vector<std::vector<Pose>>& paths, const GainOptions& options = {},
                                     unsigned threads = 0) {
  options.validate();
  std::vector<ViewGain> gains(paths.size());
  parallel_for(paths.size(), threads, [&](std::size_t i) { gains[i] = path_gain(grid, rays, paths[i], options); });
  return gains;
}

/// Gains of many candidate poses (see evaluate_paths): entry i belongs to poses[i].
/// \tparam Grid a VoxelGrid
/// \throws InvalidArgument if the options are invalid or a pose is not finite.
template <OccupancyGrid Grid>
std::vector<ViewGain> evaluate_views(const Grid& grid, const RayBundle& rays, const std::vector<Pose>& poses,
                                     const GainOptions& options = {}, unsigned threads = 0) {
  options.validate();
  std::vector<ViewGain> gains(poses.size());
  parallel_for(poses.size(), threads, [&](std::size_t i) { gains[i] = view_gain(grid, rays, poses[i], options); });
  return gains;
}

/// Index of the highest gain; ties go to the lowest index. Nothing for an empty list.
inline std::optional<std::size_t> best_view(const std::vector<ViewGain>& gains) noexcept {
  if (gains.empty()) return std::nullopt;
  std::size_t best = 0;
  for (std::size_t i = 1; i < gains.size(); ++i)
    if (gains[i].gain > gains[best].gain) best = i;
  return best;
}

}  // namespace intervox
