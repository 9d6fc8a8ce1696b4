#pragma once
/// \file
/// ChangeSet: the voxels whose occupancy changed since the last reset, as VoxelGrid's change
/// detection records them (OctoMap's enableChangeDetection / changedKeys): one 512-bit mask per
/// 8^3 block that holds a change, so that a scan changing a whole room costs a few bytes per voxel.
///
/// Thread safety: a plain value type; not thread-safe for concurrent writes.

#include <intervox/core/key.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace intervox {

/// A set of voxel keys kept as per-block bit masks, in the order their blocks first changed.
///
/// Memory: 80 bytes per 8^3 block holding a change (its mask and key) and 16 to 64 bytes of hash
/// table, whatever the number of changed voxels in it.
class ChangeSet {
 public:
  /// Adds the voxels of bits \p bits of z-layer \p w (bit x + 8 y) of the block at \p base (a
  /// multiple of 8 per axis).
  void add_bits(const Key& base, int w, std::uint64_t bits) {
    if (bits == 0) return;
    const std::uint64_t id = pack(base);
    std::size_t i = find_slot(id);
    if (slots_.empty() || slots_[i].id != id) {
      if (2 * (blocks_.size() + 1) > slots_.size()) {
        grow();
        i = find_slot(id);
      }
      slots_[i] = Slot{id, blocks_.size()};
      blocks_.push_back({base, {}});
    }
    Block& b = blocks_[slots_[i].index];
    count_ -= static_cast<std::size_t>(std::popcount(b.bits[static_cast<std::size_t>(w)]));
    b.bits[static_cast<std::size_t>(w)] |= bits;
    count_ += static_cast<std::size_t>(std::popcount(b.bits[static_cast<std::size_t>(w)]));
  }
  /// Adds voxel \p k.
  void add(const Key& k) {
    const Key base{k.x & ~7, k.y & ~7, k.z & ~7};
    add_bits(base, k.z - base.z, std::uint64_t{1} << ((k.x - base.x) + 8 * (k.y - base.y)));
  }
  /// True if \p k is in the set.
  bool contains(const Key& k) const {
    const Key base{k.x & ~7, k.y & ~7, k.z & ~7};
    if (slots_.empty()) return false;
    const Slot& slot = slots_[find_slot(pack(base))];
    if (slot.id == kEmpty) return false;
    return (blocks_[slot.index].bits[static_cast<std::size_t>(k.z - base.z)] >> ((k.x - base.x) + 8 * (k.y - base.y))) &
           1u;
  }
  /// Number of voxels in the set.
  std::size_t size() const noexcept { return count_; }
  bool empty() const noexcept { return count_ == 0; }
  /// The voxels, block by block in the order the blocks first changed, x fastest within a block.
  std::vector<Key> keys() const {
    std::vector<Key> out;
    out.reserve(count_);
    for (const Block& b : blocks_)
      for (int w = 0; w < 8; ++w)
        for (std::uint64_t m = b.bits[static_cast<std::size_t>(w)]; m; m &= m - 1) {
          const int i = std::countr_zero(m);
          out.push_back(Key{b.base.x + (i & 7), b.base.y + (i >> 3), b.base.z + w});
        }
    return out;
  }
  /// Empties the set (and frees its memory).
  void clear() {
    decltype(blocks_)().swap(blocks_);
    decltype(slots_)().swap(slots_);
    count_ = 0;
  }
  std::size_t memory_bytes() const noexcept {
    return blocks_.capacity() * sizeof(Block) + slots_.capacity() * sizeof(Slot);
  }

 private:
  struct Block {
    Key base;
    std::array<std::uint64_t, 8> bits;
  };
  struct Slot {
    std::uint64_t id;
    std::size_t index;
  };
  static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};  // never a packed id (63 bits)

  /// The slot holding \p id, or the empty slot where it would go (precondition: slots exist).
  std::size_t find_slot(std::uint64_t id) const noexcept {
    if (slots_.empty()) return 0;
    const std::size_t mask = slots_.size() - 1;
    std::uint64_t h = id ^ (id >> 31);
    h *= 0x9E3779B97F4A7C15ULL;
    for (std::size_t i = static_cast<std::size_t>(h ^ (h >> 29)) & mask;; i = (i + 1) & mask)
      if (slots_[i].id == id || slots_[i].id == kEmpty) return i;
  }
  void grow() {
    std::vector<Slot> old(std::max<std::size_t>(64, 2 * slots_.size()), Slot{kEmpty, 0});
    old.swap(slots_);
    for (const Slot& s : old)
      if (s.id != kEmpty) slots_[find_slot(s.id)] = s;
  }
  static std::uint64_t pack(const Key& base) noexcept {
    const auto c = [](std::int32_t v) {
      return static_cast<std::uint64_t>(static_cast<std::uint32_t>((v >> 3) + (1 << 20)) & 0x1FFFFFu);
    };
    return c(base.x) | (c(base.y) << 21) | (c(base.z) << 42);
  }

  std::vector<Block> blocks_;
  std::vector<Slot> slots_;  // open addressing, at most half full: block id -> index into blocks_
  std::size_t count_ = 0;
};

}  // namespace intervox
