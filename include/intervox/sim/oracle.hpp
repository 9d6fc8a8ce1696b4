#pragma once
/// \file
/// The oracle's sensor: the simulator's rig as it is, but for beams that meet a lying surface
/// (a mirror, glass, a black surface, polished metal) first along their line, which it ends there
/// as a return, as if that surface were a diffuse wall. A planner fed by it plans as one that knows
/// every lying surface for what it is (mirrors and glass as walls, black surfaces as obstacles):
/// the reference for how far exploration can go in a world (docs/experiments.md, "Random
/// apartments"). It needs the truth, so it exists only in the simulator.
///
/// Thread safety: as SimulatedRig (one per episode; calls do not overlap).

#include <intervox/core/sensor_data.hpp>
#include <intervox/sim/apartment.hpp>
#include <intervox/sim/scene.hpp>
#include <intervox/sim/source.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

namespace intervox::sim {

/// Ends every beam of \p beams whose line first meets an object of \p lying (flags by ObjectId;
/// ids beyond it are not lying) no farther than the beam's own length (+0.1 m for the noise of a
/// direct return) at that surface, as a return. Beams of length 0 and beams whose first surface
/// is not lying are left as they are. Returns how many were changed.
inline std::size_t end_at_lying_surfaces(const Scene& scene, std::span<const char> lying, std::vector<Beam>& beams) {
  std::size_t changed = 0;
  for (Beam& b : beams) {
    const Point3 d = b.end - b.origin;
    const double length = d.norm();
    if (!(length > 0) || !std::isfinite(length)) continue;
    const Point3 dir = d / length;
    const std::optional<RayHit> first = scene.intersect(b.origin, dir, 0.0, length + 0.1);
    if (!first || first->object >= lying.size() || !lying[first->object]) continue;
    b.end = b.origin + first->t * dir;
    b.hit = true;
    ++changed;
  }
  return changed;
}

/// The rig of SimulatedRig with every beam that meets one of the given lying objects first ended
/// at it (end_at_lying_surfaces()): a SensorSource for the episode runner.
class OracleRig {
 public:
  /// \param scene the world (kept by reference)
  /// \param lying the objects whose surfaces lie (e.g. Apartment::lying_objects())
  /// \param rig, seed, options as SimulatedRig
  /// \throws OutOfRange if an id in \p lying names no object of \p scene.
  OracleRig(const Scene& scene, std::span<const ObjectId> lying, SensorRig rig, std::uint64_t seed,
            SimOptions options = {})
      : rig_(scene, std::move(rig), seed, options), lying_(scene.size(), 0) {
    for (const ObjectId id : lying) {
      if (id >= scene.size()) throw OutOfRange("intervox::sim::OracleRig: unknown object id " + std::to_string(id));
      lying_[id] = 1;
    }
  }

  /// One scan with the body at \p body, lying surfaces ended at. \throws InvalidArgument for a bad pose.
  std::vector<Beam> operator()(const Pose& body) {
    std::vector<Beam> beams = rig_(body);
    corrected_ += end_at_lying_surfaces(rig_.scene(), lying_, beams);
    return beams;
  }

  /// The objects it knows as lying, sorted.
  std::vector<ObjectId> lying_objects() const {
    std::vector<ObjectId> out;
    for (std::size_t i = 0; i < lying_.size(); ++i)
      if (lying_[i]) out.push_back(static_cast<ObjectId>(i));
    return out;
  }
  /// Beams ended at a lying surface so far.
  std::size_t corrected() const noexcept { return corrected_; }
  const SimulatedRig& rig() const noexcept { return rig_; }

 private:
  SimulatedRig rig_;
  std::vector<char> lying_;
  std::size_t corrected_ = 0;
};

/// The oracle of an apartment: OracleRig told every fixture of \p apartment (Apartment::lying_objects()).
inline OracleRig make_oracle_rig(const Apartment& apartment, SensorRig rig, std::uint64_t seed,
                                 SimOptions options = {}) {
  const std::vector<ObjectId> lying = apartment.lying_objects();
  return OracleRig(apartment.scene, lying, std::move(rig), seed, options);
}

}  // namespace intervox::sim
