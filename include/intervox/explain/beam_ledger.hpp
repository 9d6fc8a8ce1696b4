#pragma once
/// \file
/// Explained free space, part 3: the revision ledger, a bounded record of recent scans kept so
/// that their beams can be classed again when the map changes where they pass
/// (ExplainedSpace::add() does the revision; explain/explained_space.hpp).
///
/// What is kept per scan: every beam the insertion took (its end as three doubles, its origin
/// once per run of beams with the same origin, its return flag and its class now), the insertion
/// options it was inserted under, the metric box of its beams, and its trusted and suspect
/// footprints (ScanFootprint: which voxels the scan gave a hit or a miss in that class, so that
/// its own evidence can be left out when it is classed again, without walking its beams). About
/// 25 bytes per beam plus 32 bytes per origin run (a depth frame or a point cloud has one run)
/// plus 136 bytes per 8^3 block a class's beams touched; the exact figure is LedgerScan::bytes().
///
/// The budget: BeamLedger keeps the newest scans whose bytes sum to at most its budget. A new
/// scan that would exceed it makes the oldest scans go first; a scan larger than the whole budget
/// is not kept. A scan that leaves the ledger is forgotten, not undone: its evidence stays in the
/// classes it had last, and it is never classed again.
///
/// Thread safety: a plain value type; not thread-safe for concurrent writes.

#include <intervox/core/error.hpp>
#include <intervox/core/point.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/explain/evidence.hpp>
#include <intervox/grid/sparse_storage.hpp>
#include <intervox/raycast/insert_options.hpp>
#include <intervox/update/hit_miss_count.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <limits>
#include <span>
#include <unordered_map>
#include <string>
#include <vector>

namespace intervox {

/// One class's evidence from one scan: per voxel whether the scan gave it a hit or a miss in that
/// class (at most one, a hit winning, as the insertion counts a scan), as bit masks per 8^3 block
/// sorted by block. 136 bytes per block.
class ScanFootprint {
 public:
  /// The marks of one 8^3 block (bit i: cell i, x fastest, as SparseBlocks::cell_index()).
  struct Block {
    std::uint64_t id = 0;  ///< detail::block_id_of()
    std::array<std::uint64_t, 8> hit{}, miss{};
  };

  /// An empty footprint.
  ScanFootprint() = default;
  /// The footprint of a count grid holding one scan's evidence of one class (every cell 0 or 1 hit
  /// or miss, as a scan's insertion into an empty count grid leaves it).
  template <class CountGrid>
  static ScanFootprint of(const CountGrid& scan) {
    ScanFootprint f;
    std::unordered_map<std::uint64_t, std::size_t> at;
    scan.for_each_observed([&](const Key& k, const HitMissCount::Cell& c) {
      const std::uint64_t id = detail::block_id_of(k);
      auto [it, fresh] = at.try_emplace(id, f.blocks_.size());
      if (fresh) f.blocks_.push_back(Block{id, {}, {}});
      Block& b = f.blocks_[it->second];
      const std::size_t i = cell_of(k);
      if (c.hits > 0)
        b.hit[i >> 6] |= std::uint64_t{1} << (i & 63);
      else if (c.misses > 0)
        b.miss[i >> 6] |= std::uint64_t{1} << (i & 63);
    });
    std::sort(f.blocks_.begin(), f.blocks_.end(), [](const Block& a, const Block& b) { return a.id < b.id; });
    f.blocks_.shrink_to_fit();
    return f;
  }

  /// The block with id \p id, or nullptr (binary search).
  const Block* find(std::uint64_t id) const noexcept {
    const auto it =
        std::lower_bound(blocks_.begin(), blocks_.end(), id, [](const Block& b, std::uint64_t v) { return b.id < v; });
    return it != blocks_.end() && it->id == id ? &*it : nullptr;
  }
  /// The mark of voxel \p k in block \p b (a block find() returned, or nullptr): {1, 0}, {0, 1}
  /// or {0, 0}.
  static HitMissCount::Cell mark(const Block* b, const Key& k) noexcept {
    if (!b) return {};
    const std::size_t i = cell_of(k);
    const std::uint64_t bit = std::uint64_t{1} << (i & 63);
    return {static_cast<std::uint16_t>((b->hit[i >> 6] & bit) ? 1 : 0),
            static_cast<std::uint16_t>((b->miss[i >> 6] & bit) ? 1 : 0)};
  }
  /// Calls f(const Key&, HitMissCount::Cell) for every marked voxel ({1, 0} or {0, 1}).
  template <class F>
  void for_each(F&& f) const {
    for (const Block& b : blocks_) {
      const Key base = detail::block_base_of(b.id);
      for (std::size_t w = 0; w < 8; ++w)
        for (std::uint64_t m = b.hit[w] | b.miss[w]; m != 0; m &= m - 1) {
          const std::size_t i = w * 64 + static_cast<std::size_t>(std::countr_zero(m));
          const bool hit = (b.hit[w] >> (i & 63)) & 1u;
          f(detail::key_in_block(base, i),
            HitMissCount::Cell{static_cast<std::uint16_t>(hit ? 1 : 0), static_cast<std::uint16_t>(hit ? 0 : 1)});
        }
    }
  }
  /// Blocks held.
  std::size_t blocks() const noexcept { return blocks_.size(); }
  /// The blocks, sorted by id.
  const std::vector<Block>& all() const noexcept { return blocks_; }
  /// Bytes held.
  std::size_t bytes() const noexcept { return blocks_.capacity() * sizeof(Block); }

 private:
  static std::size_t cell_of(const Key& k) noexcept { return detail::cell_index_of(k); }
  std::vector<Block> blocks_;
};

/// One scan kept by the ledger (see the file comment): its beams, their classes and its options.
class LedgerScan {
 public:
  /// Keeps \p beams with \p classes (same size; Skipped beams are dropped: they left no evidence)
  /// inserted under \p insert.
  /// \throws InvalidArgument if the sizes differ.
  LedgerScan(std::span<const Beam> beams, std::span<const BeamClass> classes, const InsertOptions& insert)
      : insert_(insert) {
    if (beams.size() != classes.size())
      ParamCheck("intervox::LedgerScan")
          .fail(std::to_string(beams.size()) + " beams but " + std::to_string(classes.size()) + " classes");
    std::size_t n = 0;
    for (const BeamClass c : classes) n += c != BeamClass::Skipped;
    ends_.reserve(n);
    flags_.reserve(n);
    for (std::size_t i = 0; i < beams.size(); ++i) {
      if (classes[i] == BeamClass::Skipped) continue;
      const Beam& b = beams[i];
      if (origins_.empty() || origins_.back() != b.origin) {
        origins_.push_back(b.origin);
        run_start_.push_back(static_cast<std::uint64_t>(ends_.size()));
      }
      ends_.push_back(b.end);
      flags_.push_back(static_cast<std::uint8_t>(static_cast<std::uint8_t>(classes[i]) | (b.hit ? kHit : 0)));
      for (const Point3* p : {&b.origin, &b.end}) {
        lo_ = lo_.cwiseMin(*p);
        hi_ = hi_.cwiseMax(*p);
      }
    }
    origins_.shrink_to_fit();
    run_start_.shrink_to_fit();
  }

  /// Beams kept.
  std::size_t size() const noexcept { return ends_.size(); }
  /// The insertion options the scan was inserted under (its walks are those of these options).
  const InsertOptions& insert() const noexcept { return insert_; }
  /// Beam \p i's class now.
  BeamClass beam_class(std::size_t i) const noexcept { return static_cast<BeamClass>(flags_[i] & kClassMask); }
  /// Sets beam \p i's class.
  void set_class(std::size_t i, BeamClass c) noexcept {
    flags_[i] = static_cast<std::uint8_t>((flags_[i] & kHit) | static_cast<std::uint8_t>(c));
  }
  /// Calls f(i, const Beam&, BeamClass) for every beam in the order of the scan.
  template <class F>
  void for_each(F&& f) const {
    std::size_t run = 0;
    Beam b;
    for (std::size_t i = 0; i < ends_.size(); ++i) {
      while (run < run_start_.size() && run_start_[run] == i) b.origin = origins_[run++];
      b.end = ends_[i];
      b.hit = (flags_[i] & kHit) != 0;
      f(i, b, beam_class(i));
    }
  }
  /// The beams of class \p c, in the order of the scan.
  std::vector<Beam> beams_of(BeamClass c) const {
    std::vector<Beam> out;
    for_each([&](std::size_t, const Beam& b, BeamClass bc) {
      if (bc == c) out.push_back(b);
    });
    return out;
  }
  /// The scan's evidence in class \p c (Trusted or Suspect; empty until set).
  const ScanFootprint& footprint(BeamClass c) const noexcept { return c == BeamClass::Trusted ? trusted_ : suspect_; }
  /// Sets the scan's evidence in class \p c (Trusted or Suspect).
  void set_footprint(BeamClass c, ScanFootprint f) noexcept {
    (c == BeamClass::Trusted ? trusted_ : suspect_) = std::move(f);
  }
  /// The metric box of the beams' origins and ends (empty scans: an inverted box).
  const Point3& min_corner() const noexcept { return lo_; }
  const Point3& max_corner() const noexcept { return hi_; }

  /// Bytes held (capacities of the arrays and the object).
  std::size_t bytes() const noexcept {
    return sizeof(*this) + ends_.capacity() * sizeof(Point3) + flags_.capacity() +
           origins_.capacity() * sizeof(Point3) + run_start_.capacity() * sizeof(std::uint64_t) + trusted_.bytes() +
           suspect_.bytes();
  }

 private:
  static constexpr std::uint8_t kHit = 0x80;
  static constexpr std::uint8_t kClassMask = 0x03;
  InsertOptions insert_;
  std::vector<Point3> ends_;
  std::vector<std::uint8_t> flags_;  // class | kHit
  std::vector<Point3> origins_;      // one per run of equal origins
  std::vector<std::uint64_t> run_start_;
  ScanFootprint trusted_, suspect_;
  Point3 lo_ = Point3::Constant(std::numeric_limits<double>::infinity());
  Point3 hi_ = Point3::Constant(-std::numeric_limits<double>::infinity());
};

/// The newest scans within a byte budget (see the file comment).
class BeamLedger {
 public:
  /// A ledger of at most \p budget_bytes (0: keeps nothing).
  explicit BeamLedger(std::size_t budget_bytes = 0) : budget_(budget_bytes) {}

  /// The budget in bytes.
  std::size_t budget() const noexcept { return budget_; }
  /// Sets the budget; the oldest scans go until the rest fits.
  void set_budget(std::size_t budget_bytes) {
    budget_ = budget_bytes;
    evict_to(budget_);
  }
  /// Keeps \p scan as the newest, after forgetting the oldest scans it needs room from; false (and
  /// nothing kept, nothing forgotten) if it is larger than the whole budget.
  bool push(LedgerScan scan) {
    const std::size_t b = scan.bytes();
    if (b > budget_) {
      ++refused_;
      return false;
    }
    evict_to(budget_ - b);
    bytes_ += b;
    scans_.push_back(std::move(scan));
    return true;
  }
  /// Counts the kept scans' bytes again (after their classes and footprints changed) and forgets
  /// the oldest until the rest fits the budget.
  void refit() {
    bytes_ = 0;
    for (const LedgerScan& s : scans_) bytes_ += s.bytes();
    evict_to(budget_);
  }
  /// The scans kept, oldest first.
  std::deque<LedgerScan>& scans() noexcept { return scans_; }
  const std::deque<LedgerScan>& scans() const noexcept { return scans_; }
  /// Bytes the kept scans hold (sum of LedgerScan::bytes(); <= budget()).
  std::size_t bytes() const noexcept { return bytes_; }
  /// Scans forgotten to make room, and scans never kept because they exceeded the budget.
  std::uint64_t forgotten() const noexcept { return forgotten_; }
  std::uint64_t refused() const noexcept { return refused_; }
  /// Forgets every scan (the counters stay).
  void clear() noexcept {
    scans_.clear();
    bytes_ = 0;
  }

 private:
  void evict_to(std::size_t limit) {
    while (bytes_ > limit && !scans_.empty()) {
      bytes_ -= scans_.front().bytes();
      scans_.pop_front();
      ++forgotten_;
    }
  }

  std::size_t budget_ = 0;
  std::size_t bytes_ = 0;
  std::uint64_t forgotten_ = 0, refused_ = 0;
  std::deque<LedgerScan> scans_;
};

}  // namespace intervox
