#pragma once
/// \file
/// VoxelGrid: a probabilistic occupancy grid chosen at compile time by update policy, utility
/// policy and storage.
///
/// This header includes no update policy: include the one you use beside it (one header per
/// policy), e.g. `<intervox/update/bayes_log_odds.hpp>` for `VoxelGrid<BayesLogOdds>`,
/// `<intervox/update/interval_update.hpp>` for IntervalUpdate and CompactIntervalUpdate,
/// `<intervox/update/imprecise_dirichlet.hpp>`, `<intervox/update/dempster_shafer.hpp>`. The named
/// configurations (BayesGrid, IntervalGrid, ...) are in `<intervox/grid/named_grids.hpp>`, which
/// includes every policy. The utility policies (utility/utility_policies.hpp) are small and always included.

#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/grid/change_set.hpp>
#include <intervox/grid/dense_storage.hpp>
#include <intervox/grid/occupancy_grid.hpp>
#include <intervox/grid/sparse_storage.hpp>
#include <intervox/update/concepts.hpp>
#include <intervox/utility/utility_policies.hpp>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

namespace intervox {

/// The default update policy of VoxelGrid, declared only: a grid that uses it needs
/// `<intervox/update/bayes_log_odds.hpp>`.
class BayesLogOdds;

/// Numbers of observed voxels by class.
struct OccupancyCounts {
  std::size_t free = 0;
  std::size_t occupied = 0;
  std::size_t unknown = 0;  ///< observed, but the state lies between the thresholds
  std::size_t observed() const noexcept { return free + occupied + unknown; }
};

/// A probabilistic voxel occupancy grid.
///
/// \tparam U update policy (BayesLogOdds, IntervalUpdate<LowerState|MeanState|UpperState>,
///           CompactIntervalUpdate<...>, ImpreciseDirichletUpdate<...>, DempsterShaferUpdate<...>,
///           or your own satisfying UpdatePolicy); its `Cell` is the per-voxel storage.
/// \tparam H utility policy (Entropy, MaxEntropy, TotalUncertainty, or your own satisfying
///           UtilityPolicy).
/// \tparam S storage tag (SparseStorage: unbounded hashed 8^3 blocks; DenseStorage: a flat
///           array over bounds given at construction).
///
/// Points may be of any PointLike type. Rules for bad input:
///  - updating or querying at a point with a NaN or infinite coordinate throws InvalidArgument;
///  - updating outside the bounds or the key range (see kKeyLimit) changes nothing and returns
///    false; querying there answers as for an unobserved voxel.
///
/// Thread safety: const members may be called concurrently; any non-const member needs exclusive
/// access to the grid.
template <UpdatePolicy U = BayesLogOdds, UtilityPolicy H = Entropy, Storage S = SparseStorage>
class VoxelGrid {
 public:
  using UpdateType = U;
  using UtilityType = H;
  using StorageType = S;
  using Cell = typename U::Cell;
  using Container = typename S::template Container<Cell>;
  static_assert(StorageContainer<Container, Cell>,
                "the storage tag's Container<Cell> does not satisfy StorageContainer");

  /// An unbounded grid (SparseStorage only).
  /// \param resolution voxel edge length in metres, finite and > 0
  /// \throws InvalidArgument for an invalid resolution or policy parameters
  explicit VoxelGrid(double resolution, U update = U{}, H utility = H{}) requires(!S::kBounded)
      : VoxelGrid(GridGeometry(resolution), std::nullopt, std::move(update), std::move(utility)) {}

  /// A grid limited to the voxels that intersect \p bounds (required for DenseStorage).
  /// \throws InvalidArgument for an invalid resolution, bounds or policy parameters;
  ///         OutOfRange if the bounds leave the key range.
  VoxelGrid(double resolution, const Bounds& bounds, U update = U{}, H utility = H{})
      : VoxelGrid(GridGeometry(resolution), bounds, std::move(update), std::move(utility)) {}

  /// The general constructor: any geometry (resolution and origin), optional bounds.
  VoxelGrid(const GridGeometry& geometry, const std::optional<Bounds>& bounds, U update = U{}, H utility = H{})
      : geometry_(geometry),
        update_(std::move(update)),
        utility_(std::move(utility)),
        storage_(update_.unobserved(), bounds ? std::optional<KeyBox>(geometry_.key_box(*bounds)) : std::nullopt) {}

  // ---- geometry ----------------------------------------------------------------------------
  const GridGeometry& geometry() const noexcept { return geometry_; }
  double resolution() const noexcept { return geometry_.resolution(); }
  /// The key box the grid is limited to, if any.
  const std::optional<KeyBox>& key_box() const noexcept { return storage_.box(); }
  /// True if \p k can hold data (inside the key range and the bounds, if any).
  bool contains(const Key& k) const noexcept {
    return in_key_range(k) && (!storage_.box() || storage_.box()->contains(k));
  }
  /// Key of the voxel containing \p p. \throws InvalidArgument (non-finite), OutOfRange.
  template <PointLike P>
  Key key(const P& p) const {
    return geometry_.key(to_point(p));
  }
  /// Key of the voxel containing \p p, or nothing for a non-finite or out-of-range point.
  template <PointLike P>
  std::optional<Key> try_key(const P& p) const noexcept {
    return geometry_.try_key(to_point(p));
  }
  /// Centre of voxel \p k in metres.
  Point3 center(const Key& k) const noexcept { return geometry_.center(k); }

  // ---- updates -----------------------------------------------------------------------------
  /// Applies one observation to the voxel \p k.
  /// \returns false (and changes nothing) if k lies outside the bounds or the key range.
  bool update(const Key& k, Observation o) {
    Cell* c = storage_.touch(k);
    if (!c) return false;
    if (recording_) {
      const int before = class_code(*c);
      update_.update(*c, o);
      if (class_code(*c) != before) changes_.add(k);
    } else {
      update_.update(*c, o);
    }
    return true;
  }
  /// Applies one observation to the voxel containing \p p.
  /// \throws InvalidArgument if p has a NaN or infinite coordinate.
  /// \returns false if p lies outside the bounds or the key range.
  template <PointLike P>
  bool update(const P& p, Observation o) {
    const auto k = checked_key(p);
    return k ? update(*k, o) : false;
  }

  // ---- change detection (OctoMap's enableChangeDetection / changedKeys) --------------------
  /// Starts (\p on true) or stops recording the voxels whose occupancy changes: every update
  /// (update(), every insertion) that makes an unobserved voxel observed or moves a voxel between
  /// free, occupied and unknown records it, until reset_change_detection(). Off by default; while
  /// off, updates cost nothing extra. Stopping keeps what was recorded.
  void enable_change_detection(bool on = true) noexcept { recording_ = on; }
  bool change_detection_enabled() const noexcept { return recording_; }
  /// The voxels recorded since the last reset, block by block in the order their blocks first
  /// changed (deterministic for a deterministic sequence of updates, for any thread count).
  std::vector<Key> changed_keys() const { return changes_.keys(); }
  /// Number of voxels recorded since the last reset.
  std::size_t changed_count() const noexcept { return changes_.size(); }
  /// Forgets the recorded voxels (and frees their memory); recording stays on or off.
  void reset_change_detection() { changes_.clear(); }
  /// Where updates record changes while detection is on, else null (used by the insertion's last
  /// step, raycast/detail/apply_marks.hpp).
  ChangeSet* change_recorder() noexcept { return recording_ ? &changes_ : nullptr; }
  /// The change code of a cell: -1 unobserved, else its Occupancy.
  int class_code(const Cell& c) const noexcept {
    return update_.is_observed(c) ? static_cast<int>(update_.occupancy(c)) : -1;
  }

  // ---- queries -----------------------------------------------------------------------------
  /// True if any measurement has touched voxel \p k.
  bool is_observed(const Key& k) const noexcept { return update_.is_observed(cell(k)); }
  /// The state: probability of occupancy (the policy's prior for unobserved voxels).
  double probability(const Key& k) const noexcept { return update_.state(cell(k)); }
  /// The probability interval [lower, upper]; degenerate for Bayes policies.
  Interval interval(const Key& k) const noexcept { return update_.interval(cell(k)); }
  /// The classification; Unknown for unobserved voxels.
  Occupancy occupancy(const Key& k) const noexcept { return update_.occupancy(cell(k)); }
  /// The utility policy's value of the voxel.
  double utility(const Key& k) const noexcept { return utility_of(cell(k)); }
  /// The raw cell (the sentinel `unobserved()` for a voxel without storage).
  Cell cell(const Key& k) const noexcept {
    const Cell* c = storage_.find(k);
    return c ? *c : update_.unobserved();
  }

  template <PointLike P>
  bool is_observed(const P& p) const {
    const auto k = checked_key(p);
    return k && is_observed(*k);
  }
  template <PointLike P>
  double probability(const P& p) const {
    return update_.state(cell_at(p));
  }
  template <PointLike P>
  Interval interval(const P& p) const {
    return update_.interval(cell_at(p));
  }
  template <PointLike P>
  Occupancy occupancy(const P& p) const {
    return update_.occupancy(cell_at(p));
  }
  template <PointLike P>
  double utility(const P& p) const {
    return utility_of(cell_at(p));
  }

  /// The utility of a cell value.
  double utility_of(const Cell& c) const noexcept { return utility_.value(update_.state(c), update_.interval(c)); }

  // ---- whole-grid queries ------------------------------------------------------------------
  /// Calls `f(const Key&, const Cell&)` for every observed voxel, in a deterministic order.
  template <class F>
  void for_each_observed(F&& f) const {
    storage_.for_each([&](const Key& k, const Cell& c) {
      if (update_.is_observed(c)) f(k, c);
    });
  }
  /// Calls `f(const Key&, const Cell&)` for every observed voxel whose key lies in \p box,
  /// without visiting the rest of the grid (OctoMap's leaf_bbx iterator): a sparse grid looks up
  /// the box's 8^3 blocks, or scans its own blocks when they are fewer, O(min(blocks of the box,
  /// allocated blocks) + cells in the box's blocks); a dense grid loops over the intersection.
  /// Order: deterministic for a given grid and box (block by block, x fastest within a block).
  /// An empty box (max < min on an axis) visits nothing.
  template <class F>
  void for_each_observed_in(const KeyBox& box, F&& f) const {
    storage_.for_each_in(box, [&](const Key& k, const Cell& c) {
      if (update_.is_observed(c)) f(k, c);
    });
  }
  /// The same for the voxels that intersect the metric box \p bounds (GridGeometry::key_box(); a
  /// box reaching beyond the key range is cut to it).
  /// \throws InvalidArgument if bounds are not finite or min > max on an axis.
  template <class F>
  void for_each_observed_in(const Bounds& bounds, F&& f) const {
    for_each_observed_in(clipped_key_box(bounds), std::forward<F>(f));
  }

  /// Number of observed voxels. O(allocated cells).
  std::size_t observed_count() const {
    std::size_t n = 0;
    for_each_observed([&](const Key&, const Cell&) { ++n; });
    return n;
  }
  /// Observed voxels by class. O(allocated cells).
  OccupancyCounts counts() const {
    OccupancyCounts c;
    for_each_observed([&](const Key&, const Cell& cell) {
      switch (update_.occupancy(cell)) {
        case Occupancy::Free:
          ++c.free;
          break;
        case Occupancy::Occupied:
          ++c.occupied;
          break;
        case Occupancy::Unknown:
          ++c.unknown;
          break;
      }
    });
    return c;
  }
  /// Bytes held by the grid's storage (cells, blocks, hash table) and its change record.
  std::size_t memory_bytes() const noexcept {
    return storage_.memory_bytes() + changes_.memory_bytes() + sizeof(*this) - sizeof(storage_);
  }
  /// Forgets every observation.
  void clear() { storage_.clear(); }

  // ---- policies and raw storage ------------------------------------------------------------
  const U& update_policy() const noexcept { return update_; }
  const H& utility_policy() const noexcept { return utility_; }
  /// Direct storage access for hot loops (ray insertion, I/O). Writing cells bypasses no rule
  /// of the grid, but a cell must only ever hold values produced by the update policy.
  Container& storage() noexcept { return storage_; }
  const Container& storage() const noexcept { return storage_; }

 private:
  /// The keys of the voxels that intersect \p b, the box first cut to the key range.
  KeyBox clipped_key_box(const Bounds& b) const {
    ParamCheck("intervox::VoxelGrid::for_each_observed_in").valid_bounds("bounds", b);
    Bounds c = b;
    const double res = geometry_.resolution();
    for (int a = 0; a < 3; ++a) {
      const double lo = geometry_.origin()[a] - double(kKeyLimit) * res;
      const double hi = geometry_.origin()[a] + (double(kKeyLimit) - 0.5) * res;  // inside the last voxel
      c.min[a] = std::clamp(c.min[a], lo, hi);
      c.max[a] = std::clamp(c.max[a], lo, hi);
    }
    return geometry_.key_box(c);
  }

  template <PointLike P>
  std::optional<Key> checked_key(const P& p) const {
    const Point3 q = to_point(p);
    if (!is_finite(q)) ParamCheck("intervox::VoxelGrid").fail("point has a NaN or infinite coordinate");
    return geometry_.try_key(q);
  }
  template <PointLike P>
  Cell cell_at(const P& p) const {
    const auto k = checked_key(p);
    return k ? cell(*k) : update_.unobserved();
  }

  GridGeometry geometry_;
  U update_;
  H utility_;
  Container storage_;
  // The recorded changes (copied with the grid); empty vectors while nothing was recorded.
  ChangeSet changes_;
  bool recording_ = false;
};

}  // namespace intervox
