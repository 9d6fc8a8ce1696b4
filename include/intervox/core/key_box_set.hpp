#pragma once
/// \file
/// KeyBoxSet: a set of voxel keys inside a box fixed in advance, one bit per voxel of the box.
/// Inserting is a bounds check, an index and one bit test-and-set, with no hashing and no
/// probing: the information gain counts a view's voxels in one when the view's key box is small
/// enough (information_gain.hpp), and in a KeySet otherwise.

#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/validate.hpp>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace intervox {

/// A set of keys of the box [lo, hi] given to reset(): bit `x + y * nx + z * nx * ny` (relative
/// to lo) of a bitmap. reset() clears exactly the box's bits, so it costs one word write per 64
/// voxels of the box whatever was inserted before; the bitmap's memory is kept between resets.
///
/// Thread safety: a plain value type; one set per thread.
class KeyBoxSet {
 public:
  /// Default and largest box, in voxels: 2^27 (a 16 MiB bitmap).
  static constexpr std::int64_t kMaxVoxels = std::int64_t{1} << 27;

  /// Empties the set and makes it cover the keys [\p lo, \p hi] (inclusive on every axis).
  /// Returns false, and leaves the set covering nothing (every insert() then throws), if
  /// lo > hi on an axis or the box holds more than \p max_voxels voxels (at most kMaxVoxels);
  /// nothing is allocated then.
  bool reset(const Key& lo, const Key& hi, std::int64_t max_voxels = kMaxVoxels) {
    lo_ = lo;
    n_[0] = n_[1] = n_[2] = 0;
    size_ = 0;
    std::int64_t n[3];
    for (int a = 0; a < 3; ++a) {
      n[a] = std::int64_t{hi[a]} - std::int64_t{lo[a]} + 1;
      if (n[a] < 1) return false;
    }
    const std::int64_t limit = std::min(max_voxels, kMaxVoxels);
    // Each factor is at most 2^32, so the first product cannot overflow.
    if (n[0] * n[1] > limit || n[0] * n[1] * n[2] > limit) return false;
    for (int a = 0; a < 3; ++a) n_[a] = n[a];
    const auto words = static_cast<std::size_t>((n[0] * n[1] * n[2] + 63) / 64);
    if (bits_.size() < words) bits_.resize(words);
    std::fill_n(bits_.begin(), words, std::uint64_t{0});
    return true;
  }

  /// Adds \p k; true if it was not in the set.
  /// \throws InvalidArgument if \p k lies outside the box of the last successful reset().
  bool insert(const Key& k) {
    const std::int64_t i = index(k);
    std::uint64_t& w = bits_[static_cast<std::size_t>(i >> 6)];
    const std::uint64_t bit = std::uint64_t{1} << (i & 63);
    if (w & bit) return false;
    w |= bit;
    ++size_;
    return true;
  }
  /// True if \p k is in the set (false for keys outside the box).
  bool contains(const Key& k) const noexcept {
    if (!covers(k)) return false;
    const std::int64_t i = offset(k);
    return (bits_[static_cast<std::size_t>(i >> 6)] >> (i & 63)) & 1;
  }
  /// True if \p k lies in the box.
  bool covers(const Key& k) const noexcept {
    for (int a = 0; a < 3; ++a)
      if (static_cast<std::uint64_t>(std::int64_t{k[a]} - std::int64_t{lo_[a]}) >= static_cast<std::uint64_t>(n_[a]))
        return false;
    return true;
  }
  /// Number of keys in the set.
  std::size_t size() const noexcept { return size_; }
  /// Voxels of the box (0 after a failed reset()).
  std::int64_t box_voxels() const noexcept { return n_[0] * n_[1] * n_[2]; }
  /// Bytes of the bitmap held (kept between resets).
  std::size_t memory_bytes() const noexcept { return bits_.capacity() * sizeof(std::uint64_t); }

 private:
  std::int64_t offset(const Key& k) const noexcept {
    return (std::int64_t{k.x} - lo_.x) + n_[0] * ((std::int64_t{k.y} - lo_.y) + n_[1] * (std::int64_t{k.z} - lo_.z));
  }
  std::int64_t index(const Key& k) const {
    if (!covers(k))
      ParamCheck("intervox::KeyBoxSet")
          .fail("key (" + std::to_string(k.x) + ", " + std::to_string(k.y) + ", " + std::to_string(k.z) +
                ") lies outside the set's box");
    return offset(k);
  }

  std::vector<std::uint64_t> bits_;
  std::size_t size_ = 0;
  Key lo_{};
  std::int64_t n_[3] = {0, 0, 0};
};

}  // namespace intervox
