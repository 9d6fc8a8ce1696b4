#pragma once
/// \file
/// GridAccessor: fast repeated reads of one grid, for walks that visit neighbouring voxels in a
/// row (ray casts, the information gain). On the sparse storages it remembers the last 8^3 block
/// it looked up, so a ray costs one hash lookup per block instead of one per voxel (the model is
/// OpenVDB's ValueAccessor); on the dense storage every read is an array index anyway and it
/// reads the grid directly. Every read returns exactly what the grid's own read returns.
///
/// Thread safety: an accessor is not thread-safe (its cache changes on reads): use one accessor
/// per thread; any number of accessors may read one grid concurrently. Any write to the grid
/// (insertion, set/update, clear, load, move or destruction) invalidates every accessor of it:
/// the cached block may be moved, freed or newly allocated, so create a new accessor after it.

#include <intervox/core/key.hpp>
#include <intervox/core/types.hpp>
#include <intervox/grid/occupancy_grid.hpp>

#include <concepts>
#include <cstddef>
#include <cstdint>

namespace intervox {

namespace detail {
/// A container stored in hashed blocks with a public block lookup (SparseBlocks).
template <class C>
concept BlockLookup = requires(const C& c, const Key& k) {
  { C::block_id(k) } -> std::same_as<std::uint64_t>;
  { C::cell_index(k) } -> std::convertible_to<std::size_t>;
  { c.find_block(std::uint64_t{}) } -> std::convertible_to<const typename C::Block*>;
};
}  // namespace detail

/// Reads cells of \p Grid through a one-block cache (see the file comment).
///
/// Reads are those of VoxelGrid: the raw cell (the policy's unobserved sentinel for a voxel
/// without storage, outside the grid's bounds or outside the key range), its occupancy, whether it
/// was observed, and its utility.
///
/// \tparam Grid a VoxelGrid (any update, utility and storage)
/// Thread safety: one accessor per thread; invalidated by any write to the grid (file comment).
template <OccupancyGrid Grid>
class GridAccessor {
 public:
  using Cell = typename Grid::Cell;

  /// An accessor of \p grid, which must outlive it.
  explicit GridAccessor(const Grid& grid) noexcept : grid_(grid) {}

  /// The raw cell of \p k: grid.cell(k).
  Cell cell(const Key& k) const noexcept { return grid_.cell(k); }
  /// The classification of \p k: grid.occupancy(k).
  Occupancy occupancy(const Key& k) const noexcept { return grid_.update_policy().occupancy(cell(k)); }
  /// True if \p k has been observed: grid.is_observed(k).
  bool is_observed(const Key& k) const noexcept { return grid_.update_policy().is_observed(cell(k)); }
  /// The utility of \p k: grid.utility(k).
  double utility(const Key& k) const noexcept { return grid_.utility_of(cell(k)); }
  /// The grid read.
  const Grid& grid() const noexcept { return grid_; }

 private:
  const Grid& grid_;
};

/// The sparse storages (hashed 8^3 blocks): caches the last block looked up.
template <OccupancyGrid Grid>
requires detail::BlockLookup<typename Grid::Container>
class GridAccessor<Grid> {
 public:
  using Cell = typename Grid::Cell;
  using Container = typename Grid::Container;

  /// An accessor of \p grid, which must outlive it.
  explicit GridAccessor(const Grid& grid) noexcept : grid_(grid), unobserved_(grid.update_policy().unobserved()) {}

  /// The raw cell of \p k: grid.cell(k). One hash lookup when \p k lies in another block than
  /// the previous read's, none otherwise.
  Cell cell(const Key& k) noexcept {
    const auto& s = grid_.storage();
    if (!in_key_range(k) || (s.box() && !s.box()->contains(k))) return unobserved_;
    const std::uint64_t id = Container::block_id(k);
    if (id != id_) {
      block_ = s.find_block(id);
      id_ = id;
    }
    return block_ ? (*block_)[Container::cell_index(k)] : unobserved_;
  }
  /// The classification of \p k: grid.occupancy(k).
  Occupancy occupancy(const Key& k) noexcept { return grid_.update_policy().occupancy(cell(k)); }
  /// True if \p k has been observed: grid.is_observed(k).
  bool is_observed(const Key& k) noexcept { return grid_.update_policy().is_observed(cell(k)); }
  /// The utility of \p k: grid.utility(k).
  double utility(const Key& k) noexcept { return grid_.utility_of(cell(k)); }
  /// The grid read.
  const Grid& grid() const noexcept { return grid_; }

 private:
  const Grid& grid_;
  Cell unobserved_;
  std::uint64_t id_ = ~std::uint64_t{0};  // never a packed block id
  const typename Container::Block* block_ = nullptr;
};

}  // namespace intervox
