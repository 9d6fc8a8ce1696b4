#pragma once
/// \file
/// Internal part of ray insertion: the per-scan marks of one 8x8x8 block, shared by both mark
/// structures (the box bitmaps, box_marks.hpp, and the block hash, hash_marks.hpp).

#include <cstdint>

namespace intervox::detail {

/// Per-scan marks of one 8x8x8 block: bit (x | y << 3) of word z, for misses and for hits
/// (the layout of a SparseStorage block's cells, 64 per z-slice).
struct BlockMarks {
  std::uint64_t miss[8];
  std::uint64_t hit[8];
};

/// Sets bit \p id of the bitmap \p words (bit id & 63 of word id >> 6).
inline void set_bit(std::uint64_t* words, std::int64_t id) noexcept { words[id >> 6] |= std::uint64_t{1} << (id & 63); }

}  // namespace intervox::detail
