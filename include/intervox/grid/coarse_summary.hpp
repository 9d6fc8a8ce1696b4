#pragma once
/// \file
/// CoarseSummary: what an aligned cube of 2^level voxels holds (how many of its voxels are observed
/// and occupied, the largest probability of occupancy and the largest upper bound among them),
/// answered from summaries of the grid's 8^3 blocks and a pyramid of coarser cubes above them.
/// It is the counterpart of OctoMap's inner nodes (the maximum of their children's log-odds,
/// queried with `search(key, depth)` at depth 16 - level): a planner or collision checker asks
/// "is anything in this 1.6 m cube occupied?" with one lookup instead of 32^3 voxel reads.

#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/point.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/update/concepts.hpp>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

namespace intervox {

/// What a cube of voxels holds. For a cube without an observed voxel, `observed` and `occupied`
/// are 0 and the two maxima are those of an unobserved voxel (the policy's prior): OctoMap has no
/// node there.
struct CubeSummary {
  std::uint64_t observed = 0;  ///< observed voxels in the cube
  std::uint64_t occupied = 0;  ///< voxels classified Occupied
  double max_probability = 0;  ///< the largest state (probability of occupancy) of its observed voxels
  double max_upper = 0;        ///< the largest upper probability bound of its observed voxels
  bool any_observed() const noexcept { return observed != 0; }
  bool any_occupied() const noexcept { return occupied != 0; }
  friend bool operator==(const CubeSummary&, const CubeSummary&) = default;
};

/// Coarse queries on a grid: the summary of the aligned cube of 2^level voxels per axis that holds
/// a key (the keys k with the same k >> level on every axis; level 0 is the voxel itself, level 3
/// one 8^3 block; OctoMap's depth d is level 16 - d, and the cubes are the same because OctoMap's
/// keys are Intervox's plus 2^15).
///
/// How it answers: levels 0 to 2 read the grid's cells (at most 64) and are always current;
/// levels 3 to kMaxLevel are one hash lookup in a pyramid built from per-block summaries, current
/// as of the last rebuild() or refresh(). Building it reads every observed voxel once
/// (O(observed voxels + blocks x levels)); refresh() recomputes only the blocks that hold the keys
/// given and their ancestors. After an insertion, refreshing with the grid's changed_keys()
/// (change detection on) keeps `observed`, `occupied` and any_occupied() exact, because a voxel
/// enters those counts only by changing its class; the two maxima can also move without a class
/// change, so refresh with the keys you updated or rebuild() where they matter.
///
/// \tparam Grid a VoxelGrid (any update policy and storage); the summary keeps a reference to it,
///         which must outlive the summary.
///
/// Thread safety: const members may be called concurrently (also while other threads read the
/// grid); rebuild() and refresh() need exclusive access to the summary and no concurrent writer
/// of the grid.
template <class Grid>
class CoarseSummary {
 public:
  /// The level of the grid's 8^3 blocks: the finest level answered from summaries.
  static constexpr int kBlockLevel = 3;
  /// The coarsest level: a level-23 cube spans half of the key range on each axis.
  static constexpr int kMaxLevel = 23;

  /// Builds the summaries of \p grid (rebuild()).
  explicit CoarseSummary(const Grid& grid) : grid_(&grid) { rebuild(); }

  /// Recomputes every summary from the grid. O(observed voxels + blocks x levels).
  void rebuild() {
    for (auto& l : levels_) l.clear();
    auto& blocks = levels_[0];
    std::uint64_t last = kNone;
    CubeSummary* s = nullptr;  // references into an unordered_map survive rehashing
    grid_->for_each_observed([&](const Key& k, const Cell& c) {
      const std::uint64_t id = cube_id(k, kBlockLevel);
      if (id != last) {
        s = &blocks.try_emplace(id, empty()).first->second;
        last = id;
      }
      add(*s, c);
    });
    for (int level = kBlockLevel + 1; level <= kMaxLevel; ++level) {
      auto& up = at(level);
      up.reserve(at(level - 1).size() / 4 + 1);
      for (const auto& [id, child] : at(level - 1)) merge(up.try_emplace(parent_id(id), empty()).first->second, child);
    }
  }

  /// Recomputes the summaries of the blocks that hold \p keys, and their ancestors. Keys outside
  /// the key range are ignored. O(keys log keys + touched blocks x (512 + 8 x levels)).
  void refresh(std::span<const Key> keys) {
    std::vector<std::uint64_t> ids;
    ids.reserve(keys.size());
    for (const Key& k : keys)
      if (in_key_range(k)) ids.push_back(cube_id(k, kBlockLevel));
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    auto& blocks = levels_[0];
    for (const std::uint64_t id : ids) {
      CubeSummary s = empty();
      grid_->for_each_observed_in(cube_box(id, kBlockLevel), [&](const Key&, const Cell& c) { add(s, c); });
      if (s.observed)
        blocks.insert_or_assign(id, s);
      else
        blocks.erase(id);
    }
    for (int level = kBlockLevel + 1; level <= kMaxLevel; ++level) {
      for (auto& id : ids) id = parent_id(id);
      std::sort(ids.begin(), ids.end());
      ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
      const auto& below = at(level - 1);
      auto& here = at(level);
      for (const std::uint64_t id : ids) {
        CubeSummary s = empty();
        const Key c = unpack(id);
        for (int i = 0; i < 8; ++i) {
          const Key child{2 * c.x + (i & 1), 2 * c.y + ((i >> 1) & 1), 2 * c.z + ((i >> 2) & 1)};
          if (const auto it = below.find(pack(child)); it != below.end()) merge(s, it->second);
        }
        if (s.observed)
          here.insert_or_assign(id, s);
        else
          here.erase(id);
      }
    }
  }

  /// The summary of the level-\p level cube that holds \p k. A key outside the key range answers
  /// as a cube with nothing observed.
  /// \throws InvalidArgument if level is not in [0, kMaxLevel].
  CubeSummary summary(const Key& k, int level) const {
    check_level(level);
    if (!in_key_range(k)) return unobserved_summary();
    if (level < kBlockLevel) {
      CubeSummary s = empty();
      grid_->for_each_observed_in(cube(k, level), [&](const Key&, const Cell& c) { add(s, c); });
      return s.observed ? s : unobserved_summary();
    }
    const auto& map = at(level);
    const auto it = map.find(cube_id(k, level));
    return it == map.end() ? unobserved_summary() : it->second;
  }
  /// The summary of the level-\p level cube that holds the point \p p (metres).
  /// \throws InvalidArgument for a NaN or infinite coordinate or a bad level; a point outside the
  ///         key range answers as a cube with nothing observed.
  template <PointLike P>
  CubeSummary summary(const P& p, int level) const {
    const Point3 q = to_point(p);
    if (!is_finite(q)) ParamCheck("intervox::CoarseSummary").fail("point has a NaN or infinite coordinate");
    check_level(level);
    const auto k = grid_->geometry().try_key(q);
    return k ? summary(*k, level) : unobserved_summary();
  }

  /// True if a voxel of the level-\p level cube that holds \p k is occupied (OctoMap:
  /// isNodeOccupied of the inner node). \throws InvalidArgument for a bad level.
  bool any_occupied(const Key& k, int level) const { return summary(k, level).any_occupied(); }
  /// The largest probability of occupancy in that cube (the prior if nothing in it is observed;
  /// OctoMap: the inner node's occupancy). \throws InvalidArgument for a bad level.
  double max_probability(const Key& k, int level) const { return summary(k, level).max_probability; }

  /// The keys of the level-\p level cube that holds \p k. \throws InvalidArgument for a bad level.
  static KeyBox cube(const Key& k, int level) {
    check_level(level);
    const std::int32_t size = std::int32_t{1} << level;
    KeyBox b;
    for (int a = 0; a < 3; ++a) {
      b.min[a] = static_cast<std::int32_t>((std::int64_t{k[a]} >> level) << level);
      b.max[a] = b.min[a] + (size - 1);
    }
    return b;
  }

  /// Calls `f(const KeyBox& cube, const CubeSummary&)` for every level-\p level cube (level >= 3)
  /// with an observed voxel, in no particular order.
  /// \throws InvalidArgument if level is not in [kBlockLevel, kMaxLevel].
  template <class F>
  void for_each_cube(int level, F&& f) const {
    ParamCheck("intervox::CoarseSummary::for_each_cube").in_range("level", level, kBlockLevel, kMaxLevel);
    for (const auto& [id, s] : at(level)) f(cube_box(id, level), s);
  }

  /// Number of summaries held at \p level (>= 3): the level's cubes with an observed voxel.
  std::size_t cube_count(int level) const {
    if (level < kBlockLevel || level > kMaxLevel) return 0;
    return at(level).size();
  }
  /// The grid summarised.
  const Grid& grid() const noexcept { return *grid_; }
  /// Bytes held by the summaries (an estimate of the hash tables' nodes and buckets).
  std::size_t memory_bytes() const noexcept {
    std::size_t b = sizeof(*this);
    for (const auto& l : levels_)
      b += l.size() * (sizeof(typename Map::value_type) + 2 * sizeof(void*)) + l.bucket_count() * sizeof(void*);
    return b;
  }

 private:
  using Cell = typename Grid::Cell;
  using Map = std::unordered_map<std::uint64_t, CubeSummary>;
  static constexpr std::uint64_t kNone = ~std::uint64_t{0};

  static void check_level(int level) { ParamCheck("intervox::CoarseSummary").in_range("level", level, 0, kMaxLevel); }
  // Cube coordinates (k >> level; within [-2^20, 2^20) for level >= 3) packed 21 bits per axis.
  static std::uint64_t pack(const Key& c) noexcept {
    auto f = [](std::int32_t v) {
      return static_cast<std::uint64_t>(static_cast<std::uint32_t>(v + (1 << 20)) & 0x1FFFFFu);
    };
    return f(c.x) | (f(c.y) << 21) | (f(c.z) << 42);
  }
  static Key unpack(std::uint64_t id) noexcept {
    auto f = [](std::uint64_t v) {
      return static_cast<std::int32_t>(static_cast<std::int64_t>(v & 0x1FFFFFu) - (1 << 20));
    };
    return Key{f(id), f(id >> 21), f(id >> 42)};
  }
  static std::uint64_t cube_id(const Key& k, int level) noexcept {
    return pack(Key{k.x >> level, k.y >> level, k.z >> level});
  }
  static std::uint64_t parent_id(std::uint64_t id) noexcept {
    const Key c = unpack(id);
    return pack(Key{c.x >> 1, c.y >> 1, c.z >> 1});
  }
  static KeyBox cube_box(std::uint64_t id, int level) noexcept {
    const Key c = unpack(id);
    const std::int32_t size = std::int32_t{1} << level;
    return KeyBox{Key{c.x * size, c.y * size, c.z * size},
                  Key{c.x * size + (size - 1), c.y * size + (size - 1), c.z * size + (size - 1)}};
  }

  static CubeSummary empty() noexcept {
    return CubeSummary{0, 0, -std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  }
  CubeSummary unobserved_summary() const noexcept {
    const auto& u = grid_->update_policy();
    const Cell c = u.unobserved();
    return CubeSummary{0, 0, u.state(c), u.interval(c).upper};
  }
  void add(CubeSummary& s, const Cell& c) const noexcept {
    const auto& u = grid_->update_policy();
    ++s.observed;
    s.occupied += u.occupancy(c) == Occupancy::Occupied;
    s.max_probability = std::max(s.max_probability, u.state(c));
    s.max_upper = std::max(s.max_upper, u.interval(c).upper);
  }
  static void merge(CubeSummary& s, const CubeSummary& t) noexcept {
    s.observed += t.observed;
    s.occupied += t.occupied;
    s.max_probability = std::max(s.max_probability, t.max_probability);
    s.max_upper = std::max(s.max_upper, t.max_upper);
  }

  Map& at(int level) noexcept { return levels_[static_cast<std::size_t>(level - kBlockLevel)]; }
  const Map& at(int level) const noexcept { return levels_[static_cast<std::size_t>(level - kBlockLevel)]; }

  const Grid* grid_;
  std::array<Map, kMaxLevel - kBlockLevel + 1> levels_;  // levels 3..23
};

}  // namespace intervox
