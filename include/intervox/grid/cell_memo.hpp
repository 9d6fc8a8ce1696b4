#pragma once
/// \file
/// CellMemo: the occupancy and utility of cell values, remembered. A grid's cells take few
/// distinct values (every update adds one of two log-odds steps and clamps, so the maps of a
/// whole exploration hold a few hundred different cells), while computing a value's utility costs
/// two to four `exp` and a `log2`. Walks that read many cells (the information gain) look each
/// value up in a small direct-mapped table instead and compute it only on a miss. The results are
/// exactly those of the grid's own reads, bit for bit: a table entry holds the value computed for
/// a cell whose bytes equal the ones asked for.

#include <intervox/core/types.hpp>
#include <intervox/grid/occupancy_grid.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

namespace intervox {

/// What a walk needs of a cell value: its class and its utility.
struct CellSummary {
  double utility = 0.0;                      ///< grid.utility_of(cell)
  Occupancy occupancy = Occupancy::Unknown;  ///< grid.update_policy().occupancy(cell)
};

/// Memoised occupancy and utility of the cell values of one grid (see the file comment).
///
/// A direct-mapped table of 2^10 entries keyed by the cell's bytes (cells of up to 16 bytes;
/// every update policy of the library qualifies). A lookup whose slot holds another value
/// recomputes and replaces it, so the table never grows and every answer is exact.
///
/// \tparam Grid a VoxelGrid (any update, utility and storage)
/// Thread safety: not thread-safe (lookups fill the table): one memo per thread. It reads only the
/// grid's policies, never its cells, so writes to the grid's cells do not invalidate it.
template <OccupancyGrid Grid>
class CellMemo {
 public:
  using Cell = typename Grid::Cell;
  static_assert(sizeof(Cell) <= 16, "intervox::CellMemo: cells of up to 16 bytes");
  /// Entries of the table: 2^kBits.
  static constexpr unsigned kBits = 10;
  static constexpr std::size_t kSize = std::size_t{1} << kBits;

  /// A memo of \p grid's policies; \p grid must outlive it.
  explicit CellMemo(const Grid& grid) : grid_(grid) {
    // Every slot starts out holding the unobserved value (the most common one), so that every
    // slot is valid and a lookup is one compare.
    const Cell u = grid.update_policy().unobserved();
    Entry e;
    std::memcpy(e.words.data(), &u, sizeof(Cell));
    e.summary = {grid.utility_of(u), grid.update_policy().occupancy(u)};
    table_.assign(kSize, e);
  }

  /// The summary of cell value \p c: {grid.utility_of(c), grid.update_policy().occupancy(c)}.
  const CellSummary& operator()(const Cell& c) {
    Words w{};
    std::memcpy(w.data(), &c, sizeof(Cell));
    std::uint64_t h = w[0] * 0x9E3779B97F4A7C15ULL;
    if constexpr (kWords > 1) h ^= w[1] * 0xC2B2AE3D27D4EB4FULL;
    Entry& e = table_[static_cast<std::size_t>(h >> (64 - kBits))];
    bool same = true;
    for (std::size_t i = 0; i < kWords; ++i) same = same && e.words[i] == w[i];
    if (!same) {
      e.words = w;
      e.summary = {grid_.utility_of(c), grid_.update_policy().occupancy(c)};
    }
    return e.summary;
  }

 private:
  static constexpr std::size_t kWords = (sizeof(Cell) + 7) / 8;
  using Words = std::array<std::uint64_t, kWords>;
  struct Entry {
    Words words{};
    CellSummary summary{};
  };
  const Grid& grid_;
  std::vector<Entry> table_;
};

}  // namespace intervox
