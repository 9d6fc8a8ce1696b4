#pragma once
/// \file
/// Conflict detection (thesis chapter 6): voxels updated with contradicting measurements keep a
/// narrow probability interval while their state stays unknown. Such voxels are grouped into
/// connected conflict regions; the mixed voxels every real surface edge produces are told apart
/// from genuine irregular depth noise (mirrors, glass, multiple bounces) by the surface-fringe
/// rule below. Each region carries its extent, an estimated surface normal and the sensor origins
/// it has been observed from, so that a planner can view it from new directions or give it up.
///
/// Works for every interval policy (IntervalUpdate and CompactIntervalUpdate, any state rule) and
/// for the credal cells (ImpreciseDirichletUpdate, DempsterShaferUpdate), whose interval narrows
/// with the amount of evidence, contradicting or not.
/// Bayes policies are rejected at compile time: their interval is always degenerate ([p, p],
/// width 0), so "narrow interval and unknown state" would hold for every voxel whose state has
/// not reached a threshold, seen once or a hundred times: ignorance and conflict cannot be told
/// apart from a single probability (thesis Fig. 1.3).
///
/// Thread safety: pure functions; the grid is only read (it must not be modified meanwhile).

#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/plane_fit.hpp>
#include <intervox/core/point.hpp>
#include <intervox/core/types.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/grid/occupancy_grid.hpp>
#include <intervox/update/dempster_shafer.hpp>
#include <intervox/update/imprecise_dirichlet.hpp>
#include <intervox/update/interval_update.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numbers>
#include <optional>
#include <span>
#include <string>
#include <type_traits>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace intervox {

namespace detail {
template <class U>
struct is_interval_policy : std::false_type {};
template <class R>
struct is_interval_policy<IntervalUpdate<R>> : std::true_type {};
template <class R>
struct is_interval_policy<CompactIntervalUpdate<R>> : std::true_type {};
template <class R>
struct is_interval_policy<ImpreciseDirichletUpdate<R>> : std::true_type {};
template <class R>
struct is_interval_policy<DempsterShaferUpdate<R>> : std::true_type {};
}  // namespace detail

/// True for the update policies that keep a probability interval (IntervalUpdate,
/// CompactIntervalUpdate, and the credal cells ImpreciseDirichletUpdate and DempsterShaferUpdate):
/// the ones the conflict signature can be computed for.
/// \tparam U an update policy
template <class U>
concept IntervalPolicy = detail::is_interval_policy<U>::value;

/// Parameters of conflict detection. Defaults: the thesis' Table 5.2 and chapter 6.
struct ConflictParams {
  /// The signature's width threshold: an interval at most this wide is narrow. The thesis' colour
  /// code (Table 5.2) calls an 8-bit interval width of at most 127 of 255 narrow.
  double max_width = 127.0 / 255.0;
  /// The signature's undecided band: the interval's midpoint must lie strictly inside
  /// (min_mid, max_mid). Table 5.2 colours a narrow interval blue ("updated with conflicting
  /// measurements") for an 8-bit state in (75, 180) of 255. The policy's own unknown band
  /// (free_threshold, occupied_threshold) = (0.05, 0.95) is too wide: consistent data in transit
  /// passes through it narrow (three misses on an unobserved voxel give [0.01, 0.41]).
  double min_mid = 75.0 / 255.0;
  double max_mid = 180.0 / 255.0;  ///< see min_mid
  /// Surface-fringe rule: a signature voxel with an occupied voxel within this Chebyshev
  /// distance (voxels, 26-neighbourhood for 1) is a surface fringe voxel, the mixed voxel a real
  /// surface produces where hits and misses share a voxel, and not a conflict. 0 disables the
  /// rule. Phantoms of mirrors and glass lie where the scene holds no consistent surface.
  int fringe_distance = 1;
  /// Conflict voxels are grouped by 26-connectivity; a region smaller than this is dropped as
  /// isolated noise ("several of such voxels within a relatively small area", thesis ch. 6).
  std::size_t min_region_voxels = 4;
  /// Occupied voxels within this Chebyshev distance of a region's voxels estimate its normal.
  int normal_distance = 2;
  /// \throws InvalidArgument for a width outside (0, 1], a negative fringe or normal distance
  ///         (or one above 8), or min_region_voxels = 0.
  void validate() const {
    const ParamCheck check("intervox::ConflictParams");
    check.in_range("max_width", max_width, 0, 1, RangeEnds::OpenClosed);
    if (!(min_mid >= 0 && min_mid < max_mid && max_mid <= 1)) check.fail("need 0 <= min_mid < max_mid <= 1");
    check.in_range("fringe_distance", fringe_distance, 0, 8);
    check.in_range("normal_distance", normal_distance, 0, 8);
    check.at_least("min_region_voxels", min_region_voxels, 1);
  }
};

/// The conflict signature of one cell: observed, interval width <= max_width, the interval's
/// midpoint strictly inside (min_mid, max_mid) and the policy's classification Unknown (the state
/// rule may put the state elsewhere than the midpoint).
/// \tparam U an IntervalPolicy (Bayes policies do not compile, see the file comment)
template <class U>
bool conflict_signature(const U& policy, const typename U::Cell& cell, const ConflictParams& params = {}) noexcept {
  static_assert(IntervalPolicy<U>,
                "conflict detection needs an interval policy: a Bayes policy's interval is always "
                "degenerate (width 0), so a conflict cannot be told apart from a voxel seen too little");
  if (!policy.is_observed(cell)) return false;
  const Interval i = policy.interval(cell);
  return i.width() <= params.max_width && i.mid() > params.min_mid && i.mid() < params.max_mid &&
         policy.occupancy(cell) == Occupancy::Unknown;
}

/// Whether the signature voxel \p k of \p grid is a surface fringe voxel (see
/// ConflictParams::fringe_distance).
/// \tparam Grid a VoxelGrid with an IntervalPolicy
template <OccupancyGrid Grid>
bool surface_fringe(const Grid& grid, const Key& k, int distance) {
  for (int dz = -distance; dz <= distance; ++dz)
    for (int dy = -distance; dy <= distance; ++dy)
      for (int dx = -distance; dx <= distance; ++dx) {
        if (dx == 0 && dy == 0 && dz == 0) continue;
        if (grid.occupancy(Key{k.x + dx, k.y + dy, k.z + dz}) == Occupancy::Occupied) return true;
      }
  return false;
}

/// A sensor origin a region was observed from and the unit direction from the region's centroid
/// towards it.
struct RegionView {
  Point3 origin = Point3::Zero();
  Point3 direction = Point3::UnitX();
};

/// A connected conflict region.
struct ConflictRegion {
  std::vector<Key> voxels;           ///< sorted (Key order)
  KeyBox keys;                       ///< inclusive key box of the voxels
  Bounds bounds;                     ///< metric box of the voxels (outer faces)
  Point3 centroid = Point3::Zero();  ///< mean of the voxel centres
  /// Unit normal of the surface the region lies on, estimated from the occupied voxels within
  /// normal_distance (least-squares plane, at least 3 voxels not on a line), oriented towards the
  /// mean of the views' directions if there are views; unset where the neighbourhood does not
  /// allow it.
  std::optional<Point3> normal;
  std::vector<RegionView> views;  ///< origins it was observed from (observe_regions)
  std::size_t size() const noexcept { return voxels.size(); }
};

/// Sorts \p r's voxels (at least one) and fills its key box, metric bounds and centroid from them
/// in geometry \p g (what every region builder shares; normal and views are left as they are).
inline void set_region_extent(ConflictRegion& r, const GridGeometry& g) {
  std::sort(r.voxels.begin(), r.voxels.end());
  r.keys = {r.voxels.front(), r.voxels.front()};
  r.centroid = Point3::Zero();
  for (const Key& k : r.voxels) {
    for (int a = 0; a < 3; ++a) {
      r.keys.min[a] = std::min(r.keys.min[a], k[a]);
      r.keys.max[a] = std::max(r.keys.max[a], k[a]);
    }
    r.centroid += g.center(k);
  }
  r.centroid /= double(r.voxels.size());
  r.bounds = {g.corner(r.keys.min), g.corner(Key{r.keys.max.x + 1, r.keys.max.y + 1, r.keys.max.z + 1})};
}

/// The result of detect_conflicts().
struct ConflictReport {
  std::vector<ConflictRegion> regions;  ///< by decreasing size (ties: smallest first voxel)
  std::size_t signature_voxels = 0;     ///< observed voxels with the signature
  std::size_t fringe_voxels = 0;        ///< of those, surface fringe voxels (dropped)
  std::size_t isolated_voxels = 0;      ///< conflict voxels in regions below min_region_voxels (dropped)
  /// Number of voxels in the regions.
  std::size_t conflict_voxels() const noexcept {
    std::size_t n = 0;
    for (const auto& r : regions) n += r.size();
    return n;
  }
  /// True if \p k belongs to a region. O(regions × log size).
  bool contains(const Key& k) const noexcept {
    for (const auto& r : regions)
      if (r.keys.contains(k) && std::binary_search(r.voxels.begin(), r.voxels.end(), k)) return true;
    return false;
  }
};

/// Finds the conflict regions of \p grid: signature voxels (conflict_signature) that are not
/// surface fringe voxels, grouped by 26-connectivity, regions below min_region_voxels dropped.
/// Regions carry voxels, bounds, centroid and normal; their views are empty (observe_regions).
/// If \p limit is given, only voxels whose centre lies inside it are considered.
///
/// Deterministic: the result depends on the grid's content only (not on its storage order).
/// Cost: O(observed voxels) plus O((2 d + 1)^3) lookups per signature voxel.
/// \tparam Grid a VoxelGrid whose update policy is an IntervalPolicy
/// \throws InvalidArgument for invalid parameters or an invalid limit.
template <OccupancyGrid Grid>
ConflictReport detect_conflicts(const Grid& grid, const ConflictParams& params = {},
                                const std::optional<Bounds>& limit = std::nullopt) {
  static_assert(IntervalPolicy<typename Grid::UpdateType>,
                "conflict detection needs an interval policy: a Bayes policy's interval is always "
                "degenerate (width 0), so a conflict cannot be told apart from a voxel seen too little");
  params.validate();
  if (limit) ParamCheck("intervox::detect_conflicts").valid_bounds("limit", *limit);
  const auto& policy = grid.update_policy();
  const GridGeometry& g = grid.geometry();
  ConflictReport rep;
  std::vector<Key> candidates;
  grid.for_each_observed([&](const Key& k, const typename Grid::Cell& c) {
    if (limit && !limit->contains(g.center(k))) return;
    if (!conflict_signature(policy, c, params)) return;
    ++rep.signature_voxels;
    candidates.push_back(k);
  });
  std::sort(candidates.begin(), candidates.end());
  std::vector<Key> conflict;
  conflict.reserve(candidates.size());
  for (const Key& k : candidates) {
    if (params.fringe_distance > 0 && surface_fringe(grid, k, params.fringe_distance)) {
      ++rep.fringe_voxels;
      continue;
    }
    conflict.push_back(k);
  }
  // Connected components (26-connectivity), seeded in key order.
  std::unordered_map<Key, std::size_t, KeyHash> index;
  index.reserve(conflict.size());
  for (std::size_t i = 0; i < conflict.size(); ++i) index.emplace(conflict[i], i);
  std::vector<std::uint8_t> seen(conflict.size(), 0);
  std::vector<std::size_t> stack;
  for (std::size_t s = 0; s < conflict.size(); ++s) {
    if (seen[s]) continue;
    ConflictRegion r;
    seen[s] = 1;
    stack.push_back(s);
    while (!stack.empty()) {
      const Key k = conflict[stack.back()];
      stack.pop_back();
      r.voxels.push_back(k);
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const auto it = index.find(Key{k.x + dx, k.y + dy, k.z + dz});
            if (it == index.end() || seen[it->second]) continue;
            seen[it->second] = 1;
            stack.push_back(it->second);
          }
    }
    if (r.voxels.size() < params.min_region_voxels) {
      rep.isolated_voxels += r.voxels.size();
      continue;
    }
    set_region_extent(r, g);
    // Normal from the occupied voxels around the region.
    const int d = params.normal_distance;
    std::unordered_set<Key, KeyHash> near;
    std::vector<Key> near_keys;
    for (const Key& k : r.voxels)
      for (int dz = -d; dz <= d; ++dz)
        for (int dy = -d; dy <= d; ++dy)
          for (int dx = -d; dx <= d; ++dx) {
            const Key q{k.x + dx, k.y + dy, k.z + dz};
            if (grid.occupancy(q) == Occupancy::Occupied && near.insert(q).second) near_keys.push_back(q);
          }
    std::sort(near_keys.begin(), near_keys.end());
    std::vector<Point3> pts;
    for (const Key& q : near_keys) pts.push_back(g.center(q));
    r.normal = plane_normal(pts);
    rep.regions.push_back(std::move(r));
  }
  std::stable_sort(rep.regions.begin(), rep.regions.end(),
                   [](const ConflictRegion& a, const ConflictRegion& b) { return a.size() > b.size(); });
  return rep;
}

/// Which sensor origins each region was observed from.
struct ObservationParams {
  double max_range = 4.0;  ///< m; an origin farther than this from the centroid did not see it
  /// Line of sight: no occupied voxel on the segment from the origin to the centroid, except
  /// within this distance (m) of the centroid (the region's own surface). Checked at half-voxel steps.
  double surface_allowance = 0.15;
  /// \throws InvalidArgument unless both are finite and max_range > 0, surface_allowance >= 0.
  void validate() const {
    const ParamCheck check("intervox::ObservationParams");
    check.positive("max_range", max_range);
    check.nonnegative("surface_allowance", surface_allowance);
  }
};

/// Fills each region's views: every origin of \p origins (in the given order; exact duplicates
/// once) within max_range of the region's centroid with a clear line of sight through \p grid
/// (see ObservationParams). The sensors' fields of view are not checked: a rig that sees all
/// around (the mobile base) observes every region in range. Then orients each normal towards the
/// mean view direction (kept as is without views).
/// \tparam Grid a VoxelGrid
/// \throws InvalidArgument for invalid parameters or a non-finite origin.
template <OccupancyGrid Grid>
void observe_regions(const Grid& grid, std::span<const Point3> origins, std::vector<ConflictRegion>& regions,
                     const ObservationParams& params = {}) {
  params.validate();
  for (const Point3& o : origins)
    if (!is_finite(o)) ParamCheck("intervox::observe_regions").fail("origin is not finite");
  const GridGeometry& g = grid.geometry();
  const double step = 0.5 * g.resolution();
  for (ConflictRegion& r : regions) {
    r.views.clear();
    for (std::size_t i = 0; i < origins.size(); ++i) {
      const Point3& o = origins[i];
      bool dup = false;
      for (std::size_t j = 0; j < i && !dup; ++j) dup = origins[j] == o;
      if (dup) continue;
      const Point3 v = r.centroid - o;
      const double len = v.norm();
      if (!(len <= params.max_range) || len <= 0) continue;
      const Point3 u = v / len;
      bool clear = true;
      for (double t = 0; t < len - params.surface_allowance && clear; t += step) {
        const auto k = g.try_key(o + t * u);
        clear = !k || grid.occupancy(*k) != Occupancy::Occupied;
      }
      if (clear) r.views.push_back({o, -u});
    }
    if (r.normal && !r.views.empty()) {
      Point3 m = Point3::Zero();
      for (const auto& v : r.views) m += v.direction;
      if (r.normal->dot(m) < 0) r.normal = -*r.normal;
    }
  }
}

/// The number of distinct directions among \p views: taken in order, a direction counts if it
/// lies at least \p min_angle (rad) from every direction counted before.
inline int distinct_directions(std::span<const RegionView> views, double min_angle) {
  std::vector<Point3> kept;
  const double c = std::cos(min_angle);
  for (const auto& v : views) {
    bool fresh = true;
    for (const auto& k : kept) fresh = fresh && k.dot(v.direction) <= c + 1e-12;
    if (fresh) kept.push_back(v.direction);
  }
  return static_cast<int>(kept.size());
}

/// The object-modelling rule of thesis chapter 6 ("discard before meshing"): the occupied voxels
/// of \p grid inside \p limit (all if unset) minus every voxel of the conflict regions of \p report
/// and every occupied voxel within \p distance (Chebyshev, voxels) of one. Conflict voxels are
/// never occupied themselves; the rule drops the occupied voxels the conflicting data left next to
/// them, which are the least trustworthy part of the surface. Sorted keys.
/// \tparam Grid a VoxelGrid
/// \throws InvalidArgument for a negative distance or an invalid limit.
template <OccupancyGrid Grid>
std::vector<Key> model_voxels(const Grid& grid, const ConflictReport& report, int distance = 1,
                              const std::optional<Bounds>& limit = std::nullopt) {
  ParamCheck("intervox::model_voxels").at_least("distance", distance, 0);
  if (limit) ParamCheck("intervox::model_voxels").valid_bounds("limit", *limit);
  std::unordered_set<Key, KeyHash> drop;
  for (const auto& r : report.regions)
    for (const Key& k : r.voxels)
      for (int dz = -distance; dz <= distance; ++dz)
        for (int dy = -distance; dy <= distance; ++dy)
          for (int dx = -distance; dx <= distance; ++dx) drop.insert(Key{k.x + dx, k.y + dy, k.z + dz});
  std::vector<Key> out;
  grid.for_each_observed([&](const Key& k, const typename Grid::Cell& c) {
    if (limit && !limit->contains(grid.center(k))) return;
    if (grid.update_policy().occupancy(c) == Occupancy::Occupied && !drop.count(k)) out.push_back(k);
  });
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace intervox
