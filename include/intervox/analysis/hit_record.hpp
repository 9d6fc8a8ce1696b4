#pragma once
/// \file
/// The voxels that returned a beam: evidence an ExplainedMap keeps for views that seek normals
/// (plan/normal_seeking.hpp, ArmPlannerParams::normals), which look for surfaces the striper hit
/// now and then but whose voxels are not decided yet.
///
/// Thread safety: a value type (not thread-safe for concurrent writes).

#include <intervox/core/key.hpp>
#include <intervox/core/key_set.hpp>
#include <intervox/core/sensor_data.hpp>

#include <cstddef>
#include <optional>
#include <span>

namespace intervox {

/// The voxels that returned a beam (the end voxels of beams with a return), of one geometry.
/// Memory: KeySet's, at most 64 bytes per voxel held.
class HitRecord {
 public:
  /// Records the end voxel of every beam of \p beams that returned (hit = true); beams whose end
  /// is not finite or lies outside the key range are skipped. Keys are taken in \p geometry.
  void add(const GridGeometry& geometry, std::span<const Beam> beams) {
    for (const Beam& b : beams)
      if (b.hit)
        if (const std::optional<Key> k = geometry.try_key(b.end)) hits_.insert(*k);
  }
  bool contains(const Key& k) const noexcept { return hits_.contains(k); }
  std::size_t size() const noexcept { return hits_.size(); }

 private:
  KeySet hits_;
};

}  // namespace intervox
