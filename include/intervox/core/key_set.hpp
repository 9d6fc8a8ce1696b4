#pragma once
/// \file
/// KeySet: a set of voxel keys for walks that must count each voxel once (the information gain
/// per view), with insertion in O(1) and clearing in O(1) (a generation stamp per slot), so that
/// one set serves many views without being freed or wiped in between.

#include <intervox/core/key.hpp>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace intervox {

/// An open-addressing hash set of Keys (linear probing, at most half full, doubling).
///
/// Memory: 16 bytes per slot; none until the first insert, then 1024 slots, doubled whenever the
/// set would be more than half full (at most 4 slots per key held; never shrinks: clear() keeps
/// the slots).
///
/// Thread safety: a plain value type; not thread-safe for concurrent writes.
class KeySet {
 public:
  /// An empty set; slots are allocated on the first insert.
  KeySet() = default;

  /// Adds \p k; true if it was not in the set.
  bool insert(const Key& k) {
    if (2 * (size_ + 1) > slots_.size()) grow();
    return place(k);
  }
  /// True if \p k is in the set.
  bool contains(const Key& k) const noexcept {
    if (slots_.empty()) return false;
    const std::size_t mask = slots_.size() - 1;
    for (std::size_t i = hash(k) & mask;; i = (i + 1) & mask) {
      const Slot& s = slots_[i];
      if (s.stamp != stamp_) return false;
      if (s.key == k) return true;
    }
  }
  /// Number of keys in the set.
  std::size_t size() const noexcept { return size_; }
  /// Removes every key in O(1) (the slots stay allocated).
  void clear() noexcept {
    size_ = 0;
    if (++stamp_ == 0) {  // the stamp wrapped around: every slot must be wiped once
      for (Slot& s : slots_) s.stamp = 0;
      stamp_ = 1;
    }
  }

 private:
  static constexpr std::size_t kInitial = 1024;
  struct Slot {
    Key key{};
    std::uint32_t stamp = 0;  // the slot holds a key of the current set iff stamp == stamp_
  };

  static std::size_t hash(const Key& k) noexcept {
    std::uint64_t h = static_cast<std::uint32_t>(k.x) * 0x9E3779B97F4A7C15ULL;
    h ^= static_cast<std::uint32_t>(k.y) * 0xC2B2AE3D27D4EB4FULL;
    h ^= static_cast<std::uint32_t>(k.z) * 0x165667B19E3779F9ULL;
    return static_cast<std::size_t>(h ^ (h >> 29));
  }

  bool place(const Key& k) {
    const std::size_t mask = slots_.size() - 1;
    for (std::size_t i = hash(k) & mask;; i = (i + 1) & mask) {
      Slot& s = slots_[i];
      if (s.stamp != stamp_) {
        s.key = k;
        s.stamp = stamp_;
        ++size_;
        return true;
      }
      if (s.key == k) return false;
    }
  }

  void grow() {
    std::vector<Slot> old(slots_.empty() ? kInitial : 2 * slots_.size());
    old.swap(slots_);
    const std::uint32_t stamp = stamp_;
    stamp_ = 1;
    size_ = 0;
    for (const Slot& s : old)
      if (s.stamp == stamp) place(s.key);
  }

  std::vector<Slot> slots_;
  std::size_t size_ = 0;
  std::uint32_t stamp_ = 1;
};

}  // namespace intervox
