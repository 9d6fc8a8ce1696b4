#pragma once
/// \file
/// Sparse block storage: 8x8x8 blocks of cells allocated on first write, found through an
/// open-addressing hash table. Unbounded within the key range.

#include <intervox/core/error.hpp>
#include <intervox/grid/storage.hpp>

#include <array>
#include <cstdint>
#include <memory>
#include <string_view>
#include <vector>

namespace intervox {

namespace detail {

/// The packed coordinate of the 8x8x8 block holding \p k (key >> 3), 21 bits per axis (keys are
/// within +-2^23): the block id of SparseBlocks and of the insertion's block marks.
inline std::uint64_t block_id_of(const Key& k) noexcept {
  auto c = [](std::int32_t v) {
    return static_cast<std::uint64_t>(static_cast<std::uint32_t>((v >> 3) + (1 << 20)) & 0x1FFFFFu);
  };
  return c(k.x) | (c(k.y) << 21) | (c(k.z) << 42);
}

/// The minimum key of the block with packed id \p id (block_id_of()).
inline Key block_base_of(std::uint64_t id) noexcept {
  auto c = [](std::uint64_t v) {
    return static_cast<std::int32_t>(static_cast<std::int64_t>(v & 0x1FFFFFu) - (1 << 20)) * 8;
  };
  return Key{c(id), c(id >> 21), c(id >> 42)};
}

/// Index of a key inside its 8^3 block, x fastest (SparseBlocks::cell_index(); bit masks over a
/// block's cells use the same order).
inline std::size_t cell_index_of(const Key& k) noexcept {
  return static_cast<std::size_t>((k.x & 7) | ((k.y & 7) << 3) | ((k.z & 7) << 6));
}

/// The key of cell \p i (cell_index_of()) of the block whose minimum key is \p base.
inline Key key_in_block(const Key& base, std::size_t i) noexcept {
  return Key{base.x + static_cast<std::int32_t>(i & 7), base.y + static_cast<std::int32_t>((i >> 3) & 7),
             base.z + static_cast<std::int32_t>((i >> 6) & 7)};
}

/// Blocks of kBlockSize^3 cells in a hash table keyed by block coordinates.
///
/// Block pointers are stable: a block never moves once allocated, so cached pointers (see
/// Accessor) stay valid until clear(). Iteration visits blocks in allocation order, which makes
/// it deterministic for a deterministic sequence of writes.
/// Thread safety: concurrent const access is safe; writers need exclusive access.
template <class Cell>
class SparseBlocks {
 public:
  static constexpr int kLog2Block = 3;                // block_id_of() packs 8^3 blocks
  static constexpr int kBlockSize = 1 << kLog2Block;  ///< cells per block edge
  static constexpr int kBlockCells = kBlockSize * kBlockSize * kBlockSize;
  using Block = std::array<Cell, kBlockCells>;

  SparseBlocks(Cell unobserved, std::optional<KeyBox> box) : unobserved_(unobserved), box_(box) {
    table_.assign(kInitialSlots, Slot{kEmpty, 0});
  }

  SparseBlocks(const SparseBlocks& o)
      : unobserved_(o.unobserved_), box_(o.box_), table_(o.table_), coords_(o.coords_), live_(o.live_) {
    blocks_.reserve(o.blocks_.size());
    for (const auto& b : o.blocks_) blocks_.push_back(std::make_unique<Block>(*b));
  }
  SparseBlocks& operator=(const SparseBlocks& o) {
    if (this != &o) *this = SparseBlocks(o);
    return *this;
  }
  // Blocks are heap-allocated, so a move keeps the cached block valid for the target; the
  // source forgets its cache.
  SparseBlocks(SparseBlocks&& o) noexcept
      : unobserved_(o.unobserved_),
        box_(o.box_),
        table_(std::move(o.table_)),
        blocks_(std::move(o.blocks_)),
        coords_(std::move(o.coords_)),
        live_(o.live_),
        last_id_(o.last_id_),
        last_block_(o.last_block_) {
    o.reset_after_move();
  }
  SparseBlocks& operator=(SparseBlocks&& o) noexcept {
    if (this != &o) {
      unobserved_ = o.unobserved_;
      box_ = o.box_;
      table_ = std::move(o.table_);
      blocks_ = std::move(o.blocks_);
      coords_ = std::move(o.coords_);
      live_ = o.live_;
      last_id_ = o.last_id_;
      last_block_ = o.last_block_;
      o.reset_after_move();
    }
    return *this;
  }

  /// Packs the block coordinate of a key (block_id_of()).
  static std::uint64_t block_id(const Key& k) noexcept { return block_id_of(k); }
  /// Index of a key inside its block, x fastest.
  static std::size_t cell_index(const Key& k) noexcept { return cell_index_of(k); }

  /// The block holding \p id, or nullptr.
  Block* find_block(std::uint64_t id) const noexcept {
    const std::size_t mask = table_.size() - 1;
    for (std::size_t i = hash(id) & mask;; i = (i + 1) & mask) {
      const Slot& s = table_[i];
      if (s.id == id) return blocks_[s.index].get();
      if (s.id == kEmpty) return nullptr;
    }
  }

  /// The block holding key \p k, allocated if needed; nullptr if k is outside box or key range.
  /// Writers that touch neighbouring keys in a row (sequential scans, rays) hit a one-block
  /// cache and skip the hash lookup.
  Block* touch_block(const Key& k) {
    if (!in_key_range(k) || (box_ && !box_->contains(k))) return nullptr;
    const std::uint64_t id = block_id(k);
    if (id == last_id_) return last_block_;
    Block* b = find_block(id);
    if (!b) b = insert_block(id, k);
    last_id_ = id;
    last_block_ = b;
    return b;
  }

  Cell* find(const Key& k) noexcept {
    if (!in_key_range(k)) return nullptr;
    Block* b = find_block(block_id(k));
    return b ? &(*b)[cell_index(k)] : nullptr;
  }
  const Cell* find(const Key& k) const noexcept { return const_cast<SparseBlocks*>(this)->find(k); }
  Cell* touch(const Key& k) {
    Block* b = touch_block(k);
    return b ? &(*b)[cell_index(k)] : nullptr;
  }

  template <class F>
  void for_each(F&& f) {
    visit(*this, f);
  }
  template <class F>
  void for_each(F&& f) const {
    visit(*this, f);
  }

  /// Calls `f(const Key&, Cell&)` for every allocated cell whose key lies in \p q, touching only
  /// the blocks that overlap it: the box's blocks looked up one by one when the box holds fewer
  /// blocks than the container (in block order z, y, x), else the container's blocks in
  /// allocation order, skipping those outside. Cells x fastest within a block. O(min(blocks of
  /// q, allocated blocks) + cells visited).
  template <class F>
  void for_each_in(const KeyBox& q, F&& f) {
    visit_box(*this, q, f);
  }
  template <class F>
  void for_each_in(const KeyBox& q, F&& f) const {
    visit_box(*this, q, f);
  }

  /// Cells allocated (blocks x 512).
  std::size_t allocated() const noexcept { return blocks_.size() * kBlockCells; }
  std::size_t block_count() const noexcept { return blocks_.size(); }
  std::size_t memory_bytes() const noexcept {
    return sizeof(*this) + blocks_.size() * (sizeof(Block) + sizeof(std::unique_ptr<Block>) + sizeof(Key)) +
           table_.capacity() * sizeof(Slot);
  }
  const std::optional<KeyBox>& box() const noexcept { return box_; }
  void clear() {
    blocks_.clear();
    coords_.clear();
    table_.assign(kInitialSlots, Slot{kEmpty, 0});
    live_ = 0;
    last_id_ = kEmpty;
    last_block_ = nullptr;
  }

 private:
  struct Slot {
    std::uint64_t id;
    std::uint32_t index;
  };
  static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};  // never a packed id (63 bits)
  static constexpr std::size_t kInitialSlots = 64;

  static std::size_t hash(std::uint64_t id) noexcept {
    id ^= id >> 31;
    id *= 0x9E3779B97F4A7C15ULL;
    return static_cast<std::size_t>(id ^ (id >> 29));
  }

  Block* insert_block(std::uint64_t id, const Key& k) {
    if ((live_ + 1) * 2 > table_.size()) grow();
    const std::size_t mask = table_.size() - 1;
    std::size_t i = hash(id) & mask;
    while (table_[i].id != kEmpty) i = (i + 1) & mask;
    auto block = std::make_unique<Block>();
    block->fill(unobserved_);
    table_[i] = Slot{id, static_cast<std::uint32_t>(blocks_.size())};
    blocks_.push_back(std::move(block));
    constexpr std::int32_t m = ~(kBlockSize - 1);
    coords_.push_back(Key{k.x & m, k.y & m, k.z & m});
    ++live_;
    return blocks_.back().get();
  }

  void grow() {
    std::vector<Slot> old(table_.size() * 2, Slot{kEmpty, 0});
    old.swap(table_);
    const std::size_t mask = table_.size() - 1;
    for (const Slot& s : old) {
      if (s.id == kEmpty) continue;
      std::size_t i = hash(s.id) & mask;
      while (table_[i].id != kEmpty) i = (i + 1) & mask;
      table_[i] = s;
    }
  }

  template <class Self, class F>
  static void visit(Self& self, F& f) {
    for (std::size_t b = 0; b < self.blocks_.size(); ++b) {
      auto& block = *self.blocks_[b];
      const Key o = self.coords_[b];
      std::size_t i = 0;
      for (std::int32_t z = 0; z < kBlockSize; ++z)
        for (std::int32_t y = 0; y < kBlockSize; ++y)
          for (std::int32_t x = 0; x < kBlockSize; ++x) f(Key{o.x + x, o.y + y, o.z + z}, block[i++]);
    }
  }

  /// The cells of \p block (minimum key \p o) whose keys lie in \p q, to \p f.
  template <class B, class F>
  static void visit_cells(B& block, const Key& o, const KeyBox& q, F& f) {
    const std::int32_t x0 = std::max(o.x, q.min.x), x1 = std::min(o.x + kBlockSize - 1, q.max.x);
    const std::int32_t y0 = std::max(o.y, q.min.y), y1 = std::min(o.y + kBlockSize - 1, q.max.y);
    const std::int32_t z0 = std::max(o.z, q.min.z), z1 = std::min(o.z + kBlockSize - 1, q.max.z);
    for (std::int32_t z = z0; z <= z1; ++z)
      for (std::int32_t y = y0; y <= y1; ++y)
        for (std::int32_t x = x0; x <= x1; ++x) {
          const Key k{x, y, z};
          f(k, block[cell_index(k)]);
        }
  }

  template <class Self, class F>
  static void visit_box(Self& self, const KeyBox& box, F& f) {
    KeyBox q = box;
    for (int a = 0; a < 3; ++a) {  // keys outside the key range are never allocated
      q.min[a] = std::max(q.min[a], -kKeyLimit);
      q.max[a] = std::min(q.max[a], kKeyLimit - 1);
      if (q.min[a] > q.max[a]) return;
    }
    std::uint64_t box_blocks = 1;  // <= 2^21 per axis: no overflow
    for (int a = 0; a < 3; ++a)
      box_blocks *= static_cast<std::uint64_t>((q.max[a] >> kLog2Block) - (q.min[a] >> kLog2Block) + 1);
    if (box_blocks <= self.blocks_.size()) {
      for (std::int32_t bz = q.min.z >> kLog2Block; bz <= (q.max.z >> kLog2Block); ++bz)
        for (std::int32_t by = q.min.y >> kLog2Block; by <= (q.max.y >> kLog2Block); ++by)
          for (std::int32_t bx = q.min.x >> kLog2Block; bx <= (q.max.x >> kLog2Block); ++bx) {
            const Key o{bx * kBlockSize, by * kBlockSize, bz * kBlockSize};
            if (auto* b = self.find_block(block_id(o))) visit_cells(*b, o, q, f);
          }
      return;
    }
    for (std::size_t b = 0; b < self.blocks_.size(); ++b) {
      const Key o = self.coords_[b];
      if (o.x + kBlockSize - 1 < q.min.x || o.x > q.max.x || o.y + kBlockSize - 1 < q.min.y || o.y > q.max.y ||
          o.z + kBlockSize - 1 < q.min.z || o.z > q.max.z)
        continue;
      visit_cells(*self.blocks_[b], o, q, f);
    }
  }

  Cell unobserved_;
  std::optional<KeyBox> box_;
  std::vector<Slot> table_;
  std::vector<std::unique_ptr<Block>> blocks_;
  std::vector<Key> coords_;  // minimum key of each block
  std::size_t live_ = 0;
  std::uint64_t last_id_ = kEmpty;  // one-block cache of touch_block (writers only)
  Block* last_block_ = nullptr;

  void reset_after_move() noexcept {
    table_.assign(kInitialSlots, Slot{kEmpty, 0});
    blocks_.clear();
    coords_.clear();
    live_ = 0;
    last_id_ = kEmpty;
    last_block_ = nullptr;
  }
};

}  // namespace detail

/// Storage tag: 8x8x8 blocks in a hash table, allocated on first write. Unbounded (within the
/// key range) unless bounds are given; memory grows with the observed volume.
struct SparseStorage {
  static constexpr bool kBounded = false;
  static constexpr std::string_view kName = "sparse";
  template <class Cell>
  using Container = detail::SparseBlocks<Cell>;
};

static_assert(Storage<SparseStorage>);

}  // namespace intervox
