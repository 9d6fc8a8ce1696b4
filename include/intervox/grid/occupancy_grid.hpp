#pragma once
/// \file
/// The OccupancyGrid concept: what every algorithm of Intervox that takes "any grid" (insertion,
/// ray casting, information gain, the planners, the analysis and evaluation functions, the
/// accessor and the cell memo) needs of it, and OccupancyView, the less that the exploration
/// map's projection reads. VoxelGrid<U, H, S> satisfies both, and so does a type derived from
/// one; anything else is rejected at the call with one line naming the concept.
///
/// Thread safety: a concept; nothing to run.

#include <intervox/core/key.hpp>
#include <intervox/core/types.hpp>
#include <intervox/grid/storage.hpp>
#include <intervox/update/concepts.hpp>
#include <intervox/utility/utility_policies.hpp>

#include <concepts>
#include <optional>
#include <type_traits>

namespace intervox {

/// Less than a grid: what the projection of the exploration map reads, `g.geometry()` and
/// `g.occupancy(k)` (a grid, or a view of one that changes the state of some voxels, as the
/// mobile planner's view that treats return-less free space as unknown).
/// \tparam G the candidate view type
template <class G>
concept OccupancyView = requires(const G& g, const Key& k) {
  { g.geometry() } -> std::same_as<const GridGeometry&>;
  { g.occupancy(k) } -> std::same_as<Occupancy>;
};

/// A grid the algorithms can read: a voxel geometry, a cell per key interpreted by an update
/// policy, a utility, and a storage container.
///
/// With `g` a const grid and `k` a Key:
///  - the types `UpdateType` (an UpdatePolicy), `UtilityType` (a UtilityPolicy), `StorageType`,
///    `Cell` (the update policy's cell) and `Container`;
///  - `g.geometry()` (const GridGeometry&), `g.key_box()` (the bounds' keys, if any);
///  - `g.cell(k)`, `g.is_observed(k)`, `g.probability(k)`, `g.occupancy(k)`, `g.utility(k)`;
///  - `g.update_policy()`, `g.utility_policy()` and `g.storage()`.
/// \tparam G the candidate grid type (const-qualified or not)
template <class G>
concept OccupancyGrid =
    UpdatePolicy<typename std::remove_cv_t<G>::UpdateType> &&
    UtilityPolicy<typename std::remove_cv_t<G>::UtilityType> && std::same_as < typename std::remove_cv_t<G>::Cell,
typename std::remove_cv_t<G>::UpdateType::Cell > &&requires(const std::remove_cv_t<G>& g, const Key& k) {
  typename std::remove_cv_t<G>::StorageType;
  typename std::remove_cv_t<G>::Container;
  { g.geometry() } -> std::same_as<const GridGeometry&>;
  { g.key_box() } -> std::convertible_to<std::optional<KeyBox>>;
  { g.cell(k) } -> std::same_as<typename std::remove_cv_t<G>::Cell>;
  { g.is_observed(k) } -> std::same_as<bool>;
  { g.probability(k) } -> std::convertible_to<double>;
  { g.occupancy(k) } -> std::same_as<Occupancy>;
  { g.utility(k) } -> std::convertible_to<double>;
  g.update_policy();
  g.utility_policy();
  g.storage();
}
&&OccupancyView<G>;

}  // namespace intervox
