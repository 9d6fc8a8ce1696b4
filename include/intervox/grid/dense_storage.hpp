#pragma once
/// \file
/// Dense storage: one flat array over a bounded box of keys (a workcell).

#include <intervox/core/error.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/grid/storage.hpp>

#include <algorithm>
#include <cstdint>
#include <optional>
#include <string_view>
#include <string>
#include <vector>

namespace intervox {

namespace detail {

/// A flat array of cells over a KeyBox, x fastest. Every cell is allocated up front.
/// Thread safety: concurrent const access is safe; writers need exclusive access.
template <class Cell>
class DenseArray {
 public:
  /// Largest number of cells a dense grid may hold (2^32): a box larger than that is almost
  /// certainly a mistake in units; use SparseStorage instead.
  static constexpr std::int64_t kMaxCells = std::int64_t{1} << 32;
  /// touch() never allocates: several threads may touch distinct keys at once.
  static constexpr bool kConcurrentTouch = true;

  /// \throws InvalidArgument if no box is given or it is empty or holds more than kMaxCells
  /// voxels (the count is computed without overflow: a box of 2^64 voxels or more is refused,
  /// never wrapped to a small array).
  DenseArray(Cell unobserved, std::optional<KeyBox> box) : unobserved_(unobserved), box_(box) {
    if (!box_) ParamCheck("intervox::DenseStorage").fail("a dense grid needs bounds");
    const KeyBox& b = *box_;
    for (int a = 0; a < 3; ++a) {
      if (b.extent(a) <= 0) ParamCheck("intervox::DenseStorage").fail("empty bounds");
    }
    const std::optional<std::uint64_t> volume = b.checked_volume();
    if (!volume || *volume > static_cast<std::uint64_t>(kMaxCells)) {
      ParamCheck("intervox::DenseStorage")
          .fail("bounds of " + std::to_string(b.extent(0)) + " x " + std::to_string(b.extent(1)) + " x " +
                std::to_string(b.extent(2)) + " voxels hold " +
                (volume ? std::to_string(*volume) : std::string("more than 2^64")) +
                " voxels, more than the limit of 2^32; use SparseStorage");
    }
    nx_ = b.extent(0);
    nxy_ = nx_ * b.extent(1);
    cells_.assign(static_cast<std::size_t>(*volume), unobserved_);
  }

  Cell* find(const Key& k) noexcept { return box_->contains(k) ? &cells_[index(k)] : nullptr; }
  const Cell* find(const Key& k) const noexcept { return box_->contains(k) ? &cells_[index(k)] : nullptr; }
  Cell* touch(const Key& k) noexcept { return find(k); }

  /// Visits every cell of the box in x-fastest order.
  template <class F>
  void for_each(F&& f) {
    visit(*this, f);
  }
  template <class F>
  void for_each(F&& f) const {
    visit(*this, f);
  }

  std::size_t allocated() const noexcept { return cells_.size(); }
  std::size_t memory_bytes() const noexcept { return cells_.capacity() * sizeof(Cell) + sizeof(*this); }
  const std::optional<KeyBox>& box() const noexcept { return box_; }
  void clear() { std::fill(cells_.begin(), cells_.end(), unobserved_); }

  /// Calls `f(const Key&, Cell&)` for every cell whose key lies in \p q (and in the box), x
  /// fastest, then y, then z. O(cells visited).
  template <class F>
  void for_each_in(const KeyBox& q, F&& f) {
    visit_box(*this, q, f);
  }
  template <class F>
  void for_each_in(const KeyBox& q, F&& f) const {
    visit_box(*this, q, f);
  }

  /// Flat index of a key inside the box (precondition: box().contains(k)).
  std::size_t index(const Key& k) const noexcept {
    const KeyBox& b = *box_;
    return static_cast<std::size_t>((std::int64_t{k.z} - b.min.z) * nxy_ + (std::int64_t{k.y} - b.min.y) * nx_ +
                                    (std::int64_t{k.x} - b.min.x));
  }
  /// Raw cells, x fastest, then y, then z.
  std::vector<Cell>& cells() noexcept { return cells_; }
  const std::vector<Cell>& cells() const noexcept { return cells_; }

 private:
  template <class Self, class F>
  static void visit(Self& self, F& f) {
    const KeyBox& b = *self.box_;
    std::size_t i = 0;
    for (std::int32_t z = b.min.z; z <= b.max.z; ++z)
      for (std::int32_t y = b.min.y; y <= b.max.y; ++y)
        for (std::int32_t x = b.min.x; x <= b.max.x; ++x) f(Key{x, y, z}, self.cells_[i++]);
  }

  template <class Self, class F>
  static void visit_box(Self& self, const KeyBox& q, F& f) {
    const KeyBox& b = *self.box_;
    Key lo, hi;
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::max(b.min[a], q.min[a]);
      hi[a] = std::min(b.max[a], q.max[a]);
      if (lo[a] > hi[a]) return;
    }
    for (std::int32_t z = lo.z; z <= hi.z; ++z)
      for (std::int32_t y = lo.y; y <= hi.y; ++y) {
        std::size_t i = self.index(Key{lo.x, y, z});
        for (std::int32_t x = lo.x; x <= hi.x; ++x) f(Key{x, y, z}, self.cells_[i++]);
      }
  }

  Cell unobserved_;
  std::optional<KeyBox> box_;
  std::int64_t nx_ = 0, nxy_ = 0;
  std::vector<Cell> cells_;
};

}  // namespace detail

/// Storage tag: a dense flat array over fixed bounds. Fast, predictable, memory = box volume x
/// bytes per cell. Needs bounds at construction.
struct DenseStorage {
  static constexpr bool kBounded = true;
  static constexpr std::string_view kName = "dense";
  template <class Cell>
  using Container = detail::DenseArray<Cell>;
};

static_assert(Storage<DenseStorage>);

}  // namespace intervox
