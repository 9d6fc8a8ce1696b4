#pragma once
/// \file
/// The load budget shared by the grid loaders (load_grid, read_bt): how much memory a file may
/// make the loader allocate, checked before anything large is allocated, so that a tiny crafted
/// or corrupt file cannot request gigabytes.
///
/// What is counted: the cells of the grid being built — the whole box for a dense (bounded
/// storage) grid, 8^3 cells per allocated block for a sparse grid — and, for compressed grid
/// files, the decompressed body. The default, kDefaultLoadBudgetBytes (256 MiB), is far below
/// the memory of the machines Intervox runs on and far above the maps of the examples; raise it
/// through GridLoadOptions::max_bytes or OctomapImportOptions::max_bytes for larger maps.
///
/// Thread safety: stateless functions.

#include <intervox/core/checked_math.hpp>
#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/grid/sparse_storage.hpp>

#include <cstdint>
#include <new>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

namespace intervox {

/// Default load budget of the grid loaders: 256 MiB of cells.
inline constexpr std::uint64_t kDefaultLoadBudgetBytes = std::uint64_t{1} << 28;

namespace detail {

/// Bytes one sparse block of \p Cell costs (its cells plus its share of the table and lists).
template <class Cell>
constexpr std::uint64_t sparse_block_bytes() noexcept {
  return std::uint64_t{sizeof(typename SparseBlocks<Cell>::Block)} + 64;
}

/// Memory the cells of a grid of type \p Grid would take: the box's volume for bounded storage,
/// \p blocks sparse blocks otherwise. Saturates at UINT64_MAX instead of overflowing.
template <class Grid>
std::uint64_t grid_cell_bytes(const std::optional<KeyBox>& box, std::uint64_t blocks) noexcept {
  using Cell = typename Grid::Cell;
  if constexpr (Grid::StorageType::kBounded) {
    constexpr std::uint64_t kMax = ~std::uint64_t{0};
    if (!box) return 0;
    const std::optional<std::uint64_t> volume = box->checked_volume();  // never wraps
    return volume ? saturating_mul(*volume, std::uint64_t{sizeof(Cell)}) : kMax;
  } else {
    return saturating_mul(blocks, sparse_block_bytes<Cell>());
  }
}

/// Throws IoError "<source>: <what> needs N bytes, more than the load budget of M bytes (<option>)"
/// if \p needed exceeds \p budget (N is "more than 2^64 - 1" for a saturated UINT64_MAX).
inline void check_load_budget(std::uint64_t needed, std::uint64_t budget, const std::string& source,
                              const std::string& what, const char* option) {
  if (needed > budget) {
    // A saturated size (see grid_cell_bytes) is the size of something too large to count.
    const std::string amount = needed == ~std::uint64_t{0} ? "more than 2^64 - 1" : std::to_string(needed);
    throw IoError(source + ": " + what + " needs " + amount + " bytes, more than the load budget of " +
                  std::to_string(budget) + " bytes (raise " + option + " to load it)");
  }
}

/// Runs \p f and turns allocation failures (std::bad_alloc, std::length_error) into IoError
/// naming \p source.
template <class F>
auto guard_allocation(const std::string& source, F&& f) -> decltype(f()) {
  try {
    return std::forward<F>(f)();
  } catch (const std::bad_alloc&) {
    throw IoError(source + ": out of memory while loading (the file needs more memory than is available)");
  } catch (const std::length_error& e) {
    throw IoError(source + ": out of memory while loading (" + e.what() + ")");
  }
}

}  // namespace detail
}  // namespace intervox
