#pragma once
/// \file
/// Ground truth of conflict voxels and the precision and recall of the conflict detector
/// (analysis/conflicts.hpp) against the simulator, which knows how every beam ended
/// (sim::BeamPath). Used by the examples and the experiments; never by the planners.
///
/// A beam's observations are the insertion's: misses in every voxel its segment crosses before
/// the end voxel, a hit in the end voxel if it returned, the segment cut at the max range (then
/// misses only). An observation is *phantom evidence* if it contradicts the scene (a miss in an
/// occupied voxel, a hit in a free one) and comes from a beam that did not return directly
/// (Reflected, Passed, NoReturn); it is *true evidence* if it agrees with the scene and comes from a
/// direct beam (a non-direct beam that happens to agree, e.g. a phantom ray's misses in free space
/// behind a mirror, is neither: no light travelled there). A voxel is a ground-truth conflict
/// voxel if its data contradict each other (hits and misses each at least `min_share` of its
/// observations) and phantom evidence makes up at least `min_share` of them: phantom data take
/// part in the contradiction. Contradictions among direct beams only (depth noise at surface
/// edges) do not make a conflict voxel.
///
/// Thread safety: ConflictEvidence is not thread-safe (add() mutates); the const members are.

#include <intervox/analysis/conflicts.hpp>
#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/grid/occupancy_grid.hpp>
#include <intervox/raycast/traversal.hpp>
#include <intervox/sim/scene.hpp>
#include <intervox/sim/simulate.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace intervox {

/// Counts phantom and true evidence per voxel from labelled beams.
class ConflictEvidence {
 public:
  /// Per-voxel counts.
  struct Counts {
    std::uint32_t phantom = 0;  ///< observations contradicting the scene from non-direct beams
    std::uint32_t truth = 0;    ///< observations of direct beams agreeing with the scene
    std::uint32_t total = 0;    ///< every observation (direct contradictions included)
    std::uint32_t hits = 0;     ///< hit observations among them
  };

  /// \param geometry the grid's geometry
  /// \param scene the world (its occupied voxels inside \p region are taken once)
  /// \param region voxels outside are not counted
  /// \param max_range the insertion's max range (m; rays are cut there), finite and > 0
  /// \throws InvalidArgument for an invalid region or max range.
  ConflictEvidence(const GridGeometry& geometry, const sim::Scene& scene, const Bounds& region, double max_range)
      : geometry_(geometry), box_(geometry.key_box(region)), max_range_(max_range) {
    ParamCheck("intervox::ConflictEvidence").positive("max_range", max_range);
    const auto occ = scene.ground_truth(geometry, region);
    occupied_.insert(occ.begin(), occ.end());
  }

  /// Adds the observations of \p beams, labelled by \p paths (parallel).
  /// \throws InvalidArgument if the sizes differ.
  void add(std::span<const Beam> beams, std::span<const sim::BeamPath> paths) {
    if (beams.size() != paths.size())
      ParamCheck("intervox::ConflictEvidence::add").fail("beams and paths differ in size");
    for (std::size_t i = 0; i < beams.size(); ++i) {
      const Beam& b = beams[i];
      if (!is_finite(b.origin) || !is_finite(b.end)) continue;
      Point3 end = b.end;
      bool hit = b.hit;
      const Point3 d = b.end - b.origin;
      const double len = d.norm();
      if (len > max_range_) {
        end = b.origin + d * (max_range_ / len);
        hit = false;
      }
      const bool direct = paths[i] == sim::BeamPath::Direct;
      const auto end_key = geometry_.try_key(end);
      if (!end_key) continue;
      traverse(geometry_, b.origin, end, [&](const Key& k) {
        const bool is_end = k == *end_key;
        if (is_end && !hit) return false;  // the end voxel of a beam without a hit is not observed
        observe(k, is_end ? Observation::Hit : Observation::Miss, direct);
        return !is_end;
      });
    }
  }

  /// The ground-truth conflict voxels: the data contradict each other (hits and misses each at
  /// least \p min_share of the voxel's observations) and phantom evidence makes up at least
  /// \p min_share of them (see the file comment). Sorted.
  std::vector<Key> conflict_voxels(double min_share = 0.2) const {
    std::vector<Key> out;
    for (const auto& [k, c] : counts_) {
      const double t = c.total, h = c.hits;
      if (c.phantom > 0 && c.phantom >= min_share * t && h >= min_share * t && t - h >= min_share * t) out.push_back(k);
    }
    std::sort(out.begin(), out.end());
    return out;
  }
  /// The voxels with any phantom evidence. Sorted.
  std::vector<Key> phantom_voxels() const {
    std::vector<Key> out;
    for (const auto& [k, c] : counts_)
      if (c.phantom > 0) out.push_back(k);
    std::sort(out.begin(), out.end());
    return out;
  }
  /// True if the scene occupies \p k (inside the region).
  bool occupied(const Key& k) const { return occupied_.count(k) != 0; }
  const std::unordered_map<Key, Counts, KeyHash>& counts() const noexcept { return counts_; }

 private:
  void observe(const Key& k, Observation o, bool direct) {
    if (!box_.contains(k)) return;
    Counts& c = counts_[k];
    ++c.total;
    if (o == Observation::Hit) ++c.hits;
    const bool agrees = (o == Observation::Hit) == occupied(k);
    if (agrees && direct)
      ++c.truth;
    else if (!agrees && !direct)
      ++c.phantom;
  }

  GridGeometry geometry_;
  KeyBox box_;
  double max_range_;
  std::unordered_set<Key, KeyHash> occupied_;
  std::unordered_map<Key, Counts, KeyHash> counts_;
};

/// Precision and recall of a conflict report against the ground truth.
struct ConflictScore {
  std::size_t flagged = 0;        ///< voxels of the report's regions
  std::size_t truth = 0;          ///< ground-truth conflict voxels
  std::size_t true_positive = 0;  ///< flagged voxels that are ground-truth conflict voxels
  /// Flagged voxels next to (26-neighbourhood) or at a ground-truth conflict voxel: the region a
  /// planner avoids is the same, so this is the precision that matters for planning.
  std::size_t near_positive = 0;
  std::size_t edge_voxels = 0;   ///< surface-edge voxels: observed, occupied in the scene or next to one
  std::size_t edge_flagged = 0;  ///< flagged surface-edge voxels without any phantom evidence
  double precision() const noexcept { return flagged ? double(true_positive) / double(flagged) : 1.0; }
  double near_precision() const noexcept { return flagged ? double(near_positive) / double(flagged) : 1.0; }
  double recall() const noexcept { return truth ? double(true_positive) / double(truth) : 1.0; }
  /// Fraction of the surface-edge voxels flagged although no phantom evidence reached them.
  double edge_rate() const noexcept { return edge_voxels ? double(edge_flagged) / double(edge_voxels) : 0.0; }
};

/// Scores \p report on \p grid against \p evidence (see ConflictEvidence and ConflictScore).
/// \tparam Grid a VoxelGrid
template <OccupancyGrid Grid>
ConflictScore score_conflicts(const Grid& grid, const ConflictReport& report, const ConflictEvidence& evidence,
                              double min_share = 0.2) {
  ConflictScore s;
  const std::vector<Key> truth = evidence.conflict_voxels(min_share);
  const std::unordered_set<Key, KeyHash> gt(truth.begin(), truth.end());
  s.truth = gt.size();
  auto near_gt = [&](const Key& k) {
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
          if (gt.count(Key{k.x + dx, k.y + dy, k.z + dz})) return true;
    return false;
  };
  std::unordered_set<Key, KeyHash> flagged;
  for (const auto& r : report.regions)
    for (const Key& k : r.voxels) {
      flagged.insert(k);
      ++s.flagged;
      if (gt.count(k)) ++s.true_positive;
      if (near_gt(k)) ++s.near_positive;
    }
  const auto& counts = evidence.counts();
  grid.for_each_observed([&](const Key& k, const typename Grid::Cell&) {
    bool edge = false;
    for (int dz = -1; dz <= 1 && !edge; ++dz)
      for (int dy = -1; dy <= 1 && !edge; ++dy)
        for (int dx = -1; dx <= 1 && !edge; ++dx) edge = evidence.occupied(Key{k.x + dx, k.y + dy, k.z + dz});
    if (!edge) return;
    const auto it = counts.find(k);
    if (it != counts.end() && it->second.phantom > 0) return;
    ++s.edge_voxels;
    if (flagged.count(k)) ++s.edge_flagged;
  });
  return s;
}

}  // namespace intervox
