#pragma once
// The grid configurations the io tests run over (the one list of tests/common), how they are
// constructed, and a seeded grid filler.

#include <cstdint>
#include <cstring>
#include <random>

#include "../common/grid_types.hpp"
#include <intervox/grid/voxel_grid.hpp>

/// A grid of type G at 0.1 m: over [-1, 1]^3 if dense, over [-1, 1]^2 x [-1, 0.45] (smaller than
/// what fill_randomly writes) if BoundedSparse, unbounded otherwise.
template <class G>
G make_test_grid(typename G::UpdateType update = typename G::UpdateType{}) {
  if constexpr (G::StorageType::kBounded) {
    intervox::Bounds b{intervox::Point3(-1, -1, -1), intervox::Point3(1, 1, 1)};
    return G(0.1, b, update);
  } else if constexpr (test::kConstructBounded<G>) {
    intervox::Bounds b{intervox::Point3(-1, -1, -1), intervox::Point3(1, 1, 0.45)};
    return G(0.1, b, update);
  } else {
    return G(0.1, update);
  }
}

/// Applies `n` seeded random hits and misses inside [-1, 1)^3 (hits biased to z < 0).
template <class G>
void fill_randomly(G& grid, int n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> coord(-10, 9);
  for (int i = 0; i < n; ++i) {
    const intervox::Key k{coord(rng), coord(rng), coord(rng)};
    const bool hit = k.z < 0 ? (rng() % 4 != 0) : (rng() % 4 == 0);
    for (int r = 0; r < 1 + static_cast<int>(rng() % 6); ++r) {
      grid.update(k, hit ? intervox::Observation::Hit : intervox::Observation::Miss);
    }
  }
}

/// Bitwise equality of two cells (NaN patterns and latched infinities included).
template <class Cell>
bool same_bits(const Cell& a, const Cell& b) {
  return std::memcmp(&a, &b, sizeof(Cell)) == 0;
}
