#pragma once
/// \file
/// Free space that rests on beams without a return only (thesis 5.2, 5.5). A depth sensor reports
/// nothing where a surface absorbs its light (or lets it through, or mirrors it away): the
/// insertion then counts the beam as free up to the max range, through the absorbing surface and
/// whatever lies behind it. Such free space was never confirmed by a beam that came back, so a
/// robot must not trust it: NoReturnEvidence records, per voxel, whether a beam without a return
/// crossed it and whether a beam with a return did, and names the voxels crossed by the first
/// kind only. The conflict-aware mobile planner keeps them out of the drivable space with its
/// safety margin (MobilePlanner::observe).
///
/// It sees the beams as they are inserted (world frame, `Beam::hit = false` for no return, ending
/// at the sensor's max range as the simulator and the depth-image converters give them) and
/// follows the insertion's rule for what a beam makes free: a return frees the voxels from its
/// origin up to (not including) its end voxel, cut at `max_range`; a beam without a return frees
/// the voxels up to `max_range` along its direction (all of them, the last included).
///
/// Memory: one hash-map entry (about 40 bytes) per distinct voxel crossed, so bounded by the
/// voxels within `max_range` of the sensor origins seen.
///
/// Thread safety: add() modifies; the queries are const and may run concurrently with each other.

#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/raycast/traversal.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

namespace intervox {

/// Which voxels were made free by beams without a return only (see the file comment).
class NoReturnEvidence {
 public:
  /// \param geometry the grid's geometry (keys and resolution; copied)
  /// \param max_range m; the insertion's max range (beams without a return are free up to it)
  /// \throws InvalidArgument unless max_range is finite and > 0.
  NoReturnEvidence(const GridGeometry& geometry, double max_range) : geometry_(geometry), max_range_(max_range) {
    ParamCheck("intervox::NoReturnEvidence").positive("max_range", max_range);
  }

  /// Records the free space of \p beams (see the file comment). Beams with a non-finite or
  /// coincident origin and end, a length that overflows, or an end (after the cut at max range)
  /// outside the key range are skipped, as by the insertion.
  void add(std::span<const Beam> beams) {
    for (const Beam& b : beams) {
      const Point3 d = b.end - b.origin;
      const double len = d.norm();
      if (!std::isfinite(len) || !(len > 0) || !is_finite(b.origin)) continue;
      if (b.hit && len <= max_range_) {
        // Misses from the origin up to, not including, the end voxel.
        const std::optional<Key> end = geometry_.try_key(b.end);
        if (!end) continue;
        traverse(geometry_, b.origin, b.end, [&](const Key& k) {
          if (k == *end) return false;
          marks_[k] |= kReturned;
          return true;
        });
      } else {
        const Point3 to = b.origin + d * (max_range_ / len);
        const std::uint8_t bit = b.hit ? kReturned : kNoReturn;  // a return beyond max range: cut, still confirmed
        traverse(geometry_, b.origin, to, [&](const Key& k) {
          marks_[k] |= bit;
          return true;
        });
      }
    }
  }

  /// True if \p k was crossed by a beam without a return and by no beam with one.
  bool unconfirmed(const Key& k) const {
    const auto it = marks_.find(k);
    return it != marks_.end() && it->second == kNoReturn;
  }

  /// The unconfirmed voxels (sorted by Key), those whose centre lies in \p limit if given.
  /// \throws InvalidArgument for an invalid limit.
  std::vector<Key> unconfirmed_voxels(const std::optional<Bounds>& limit = std::nullopt) const {
    if (limit) ParamCheck("intervox::NoReturnEvidence").valid_bounds("limit", *limit);
    std::vector<Key> out;
    for (const auto& [k, m] : marks_)
      if (m == kNoReturn && (!limit || limit->contains(geometry_.center(k)))) out.push_back(k);
    std::sort(out.begin(), out.end());
    return out;
  }

  /// Distinct voxels crossed by any beam so far.
  std::size_t size() const noexcept { return marks_.size(); }
  double max_range() const noexcept { return max_range_; }
  const GridGeometry& geometry() const noexcept { return geometry_; }

 private:
  static constexpr std::uint8_t kNoReturn = 1, kReturned = 2;
  GridGeometry geometry_;
  double max_range_;
  std::unordered_map<Key, std::uint8_t, KeyHash> marks_;
};

}  // namespace intervox
