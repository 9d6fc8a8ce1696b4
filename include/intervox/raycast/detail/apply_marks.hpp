#pragma once
/// \file
/// Internal part of ray insertion: the last step of a scan, applying its marks to the grid
/// (apply_marks()): a hit where a hit bit is set, else a miss where a miss bit is set, each
/// marked voxel once.
///
/// Thread safety: apply_marks() needs exclusive access to the grid; it splits the blocks
/// between threads itself.

#include <intervox/core/key.hpp>
#include <intervox/core/parallel.hpp>
#include <intervox/core/types.hpp>
#include <intervox/grid/change_set.hpp>
#include <intervox/raycast/detail/block_marks.hpp>
#include <intervox/raycast/insert_options.hpp>

#include <algorithm>
#include <bit>
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

namespace intervox::detail {

/// True for containers laid out in 8^3 blocks exactly as ScanMarks (SparseBlocks).
template <class C>
concept BlockContainer = requires(C& c, const Key& k) {
  {c.touch_block(k)};
  { C::cell_index(k) } -> std::convertible_to<std::size_t>;
}
&&(C::kBlockSize == 8);

/// True for containers whose touch() never allocates (C::kConcurrentTouch), so that several
/// threads may touch distinct keys at once (DenseArray).
template <class C>
concept ConcurrentTouch = requires {
  requires C::kConcurrentTouch;
};

/// The bits of word \p w (z = base.z + w) of the BlockMarks of the block at \p base whose
/// voxels lie inside \p box (bit x + 8 y).
inline std::uint64_t box_word_mask(const KeyBox& box, const Key& base, int w) noexcept {
  const std::int32_t z = base.z + w;
  if (z < box.min.z || z > box.max.z) return 0;
  auto range = [&](int a) {  // the in-box offsets [l, h] of the block along axis a
    const std::int32_t l = std::max(0, box.min[a] - base[a]), h = std::min(7, box.max[a] - base[a]);
    return std::pair{l, h};
  };
  const auto [xl, xh] = range(0);
  const auto [yl, yh] = range(1);
  if (xl > xh || yl > yh) return 0;
  const std::uint64_t row = ((std::uint64_t{1} << (xh + 1)) - 1) & ~((std::uint64_t{1} << xl) - 1);
  std::uint64_t m = 0;
  for (std::int32_t y = yl; y <= yh; ++y) m |= row << (8 * y);
  return m;
}

/// One block with a mark: its minimum key and its marks.
using MarkedBlock = std::pair<Key, const BlockMarks*>;

/// The first cell of each of \p blocks in \p storage (a block container), the block allocated
/// (serially: the only step that changes the container's table), or null where a bounded
/// container's box misses the block.
template <class Cell, class Container>
std::vector<Cell*> first_cells(Container& storage, std::span<const MarkedBlock> blocks,
                               const std::optional<KeyBox>& box) {
  std::vector<Cell*> cells(blocks.size());
  for (std::size_t j = 0; j < blocks.size(); ++j) {
    // A key of the block inside the box (a box may cut blocks), or none.
    Key k = blocks[j].first;
    bool meets = true;
    if (box) {
      for (int a = 0; a < 3; ++a) {
        k[a] = std::max(k[a], box->min[a]);
        meets = meets && k[a] <= std::min(box->max[a], blocks[j].first[a] + 7);
      }
    }
    auto* b = meets ? storage.touch_block(k) : nullptr;
    cells[j] = b ? b->data() : nullptr;
  }
  return cells;
}

/// The voxels of one block word whose class an update changed (change detection).
struct ChangedWord {
  std::size_t block;
  int word;
  std::uint64_t bits;
};

/// What apply_marks() updates, shared by its threads: the grid, its storage and update policy,
/// the storage's box, the change recorder (or null) and, for block containers, each block's
/// first cell.
template <class G>
struct MarkTarget {
  using Container = std::remove_reference_t<decltype(std::declval<G&>().storage())>;
  using Cell = typename G::Cell;
  static constexpr bool kByBlock = BlockContainer<Container>;

  G& grid;
  Container& storage;
  const std::remove_reference_t<decltype(std::declval<G&>().update_policy())>& policy;
  const std::optional<KeyBox>& box;
  ChangeSet* recorder;
  const std::vector<Cell*>& cells;

  /// Applies the marks of block \p j (\p base, \p m) to the grid, counting in \p s; the words
  /// whose voxels changed class go to \p changed (null: change detection off).
  void block(std::size_t j, const Key& base, const BlockMarks& m, InsertStats& s,
             std::vector<ChangedWord>* changed) const {
    for (int w = 0; w < 8; ++w) {
      const std::uint64_t h = m.hit[w], f = m.miss[w] & ~h;
      if ((h | f) == 0) continue;
      std::uint64_t in = box ? box_word_mask(*box, base, w) : ~std::uint64_t{0};
      if constexpr (kByBlock) {
        if (!cells[j]) in = 0;
      }
      s.outside_bounds += static_cast<std::uint64_t>(std::popcount((h | f) & ~in));
      std::uint64_t moved = 0;  // the voxels of this word whose class changed (change detection)
      update(j, base, w, h & in, Observation::Hit, s.hits, s, moved);
      update(j, base, w, f & in, Observation::Miss, s.misses, s, moved);
      if (moved) changed->push_back({j, w, moved});
    }
  }

  /// Updates the voxels \p bits of word \p w of block \p j with \p obs, counting them in \p count
  /// (or in s.outside_bounds where the container has no cell), the changed ones in \p moved.
  void update(std::size_t j, const Key& base, int w, std::uint64_t bits, Observation obs, std::uint64_t& count,
              InsertStats& s, std::uint64_t& moved) const {
    for (; bits; bits &= bits - 1) {
      const int i = std::countr_zero(bits);
      Cell* c = nullptr;
      if constexpr (kByBlock) {
        c = cells[j] + 64 * w + i;
      } else {
        c = storage.touch(Key{base.x + (i & 7), base.y + (i >> 3), base.z + w});
      }
      if (c) {
        if constexpr (requires { grid.class_code(*c); }) {
          if (recorder) {
            const int before = grid.class_code(*c);
            policy.update(*c, obs);
            if (grid.class_code(*c) != before) moved |= std::uint64_t{1} << i;
          } else {
            policy.update(*c, obs);
          }
        } else {
          policy.update(*c, obs);
        }
        ++count;
      } else {
        ++s.outside_bounds;
      }
    }
  }
};

/// Applies the marks of \p blocks to \p grid: a hit where a hit bit is set, else a miss where a
/// miss bit is set; marks outside a bounded grid's box are counted in outside_bounds. Block
/// containers get their blocks allocated first (serially: the only step that changes their
/// table), then every storage is updated in one loop, the blocks split between \p nt threads in
/// contiguous runs: cells are found in their block, or through touch() for other containers
/// (on several threads only if their touch() never allocates, ConcurrentTouch). Returns the
/// hits, misses and outside_bounds counts; they and the cells' values do not depend on \p nt.
/// With the grid's change detection on, the voxels whose class changed are recorded in block
/// order, the same for every \p nt.
/// \tparam G a VoxelGrid
template <class G>
InsertStats apply_marks(G& grid, std::span<const MarkedBlock> blocks, unsigned nt) {
  auto& storage = grid.storage();
  using Container = std::remove_reference_t<decltype(storage)>;
  using Cell = typename G::Cell;
  constexpr bool by_block = BlockContainer<Container>;
  const std::optional<KeyBox>& box = storage.box();

  std::vector<Cell*> cells;  // block containers: the first cell of each block, or null
  if constexpr (by_block) cells = first_cells<Cell>(storage, blocks, box);
  const unsigned workers = by_block || ConcurrentTouch<Container> ? nt : 1u;
  std::vector<InsertStats> part(workers);
  // Change detection (VoxelGrid::enable_change_detection): each thread keeps the voxels whose
  // class its updates changed, per block word; recorded after, in block order.
  ChangeSet* recorder = nullptr;
  if constexpr (requires { grid.change_recorder(); }) recorder = grid.change_recorder();
  std::vector<std::vector<ChangedWord>> changed(recorder ? workers : 0);
  const MarkTarget<G> target{grid, storage, grid.update_policy(), box, recorder, cells};
  run_on_threads(workers, [&](unsigned t) {
    InsertStats& s = part[t];
    const std::size_t b = blocks.size() * t / workers, e = blocks.size() * (t + 1) / workers;
    for (std::size_t j = b; j < e; ++j)
      target.block(j, blocks[j].first, *blocks[j].second, s, recorder ? &changed[t] : nullptr);
  });
  InsertStats st;
  for (const auto& p : part) st += p;
  for (const auto& list : changed)  // threads hold contiguous runs of blocks: block order
    for (const ChangedWord& c : list) recorder->add_bits(blocks[c.block].first, c.word, c.bits);
  return st;
}

}  // namespace intervox::detail
