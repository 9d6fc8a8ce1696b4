#pragma once
/// \file
/// The count store of the explained channel (ExplainedSpace, explain/explained_space.hpp): the
/// evidence of each beam class in its own count grid (VoxelGrid<HitMissCount>, one per class:
/// trusted, suspect, no return), the blocks that hold a trusted hit (every supported voxel lies in
/// one: the crossing test walks those only) and the trusted extent (the key box of the trusted
/// beams' walks). A scan's contribution per class comes in as a count grid of its own (merge()) or,
/// when the revision moves a kept scan's beams, as the difference between its old and new
/// footprints (apply_difference()); both tell the caller how each trusted voxel changed, for the
/// revision to look at (explain/ledger_revision.hpp).
///
/// Memory: three sparse grids of 4-byte cells (2 KiB per 8^3 block and class) over the voxels the
/// beams of each class crossed, and one key per block that holds a trusted hit.
///
/// Thread safety: the const members may run concurrently with each other; the others need
/// exclusive access.

#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/key_set.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/explain/beam_ledger.hpp>
#include <intervox/explain/evidence.hpp>
#include <intervox/grid/sparse_storage.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/raycast/detail/prepare_ray.hpp>
#include <intervox/raycast/insert_options.hpp>
#include <intervox/update/hit_miss_count.hpp>

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

namespace intervox::detail {

/// The three count grids of an ExplainedSpace, with the blocks of its trusted hits and its
/// trusted extent. The callbacks \p note of merge() and apply_difference() are called as
/// note(key, cell before, cell after) for every trusted voxel they change.
class ExplainedCounts {
 public:
  /// A count grid: one class's hits and misses (ExplainedSpace::CountGrid).
  using CountGrid = VoxelGrid<HitMissCount, Entropy, SparseStorage>;

  /// Empty unbounded grids of geometry \p g.
  explicit ExplainedCounts(const GridGeometry& g)
      : trusted_(g, std::nullopt), suspect_(g, std::nullopt), no_return_(g, std::nullopt) {}

  /// Saved grids, taken as given; load() checks them and finds what they imply.
  ExplainedCounts(CountGrid trusted, CountGrid suspect, CountGrid no_return)
      : trusted_(std::move(trusted)), suspect_(std::move(suspect)), no_return_(std::move(no_return)) {}

  /// Checks saved grids (the constructor's) and finds the blocks that hold a trusted hit and,
  /// without \p extent, the trusted extent (the box of the trusted voxels).
  /// \throws InvalidArgument for count grids of different geometries, a bounded count grid, or
  ///         an extent with min > max.
  void load(const std::optional<KeyBox>& extent) {
    const ParamCheck check("intervox::ExplainedSpace");
    const GridGeometry& geometry = trusted_.geometry();
    for (const CountGrid* g : {&suspect_, &no_return_})
      if (g->resolution() != geometry.resolution() || g->geometry().origin() != geometry.origin())
        check.fail("the count grids have different geometries");
    for (const CountGrid* g : {&trusted_, &suspect_, &no_return_})
      if (g->key_box()) check.fail("count grids must be unbounded");
    trusted_.for_each_observed([&](const Key& k, const HitMissCount::Cell& c) {
      if (c.hits > 0) surface_blocks_.insert(block_of(k));
      if (!extent) grow_extent(k);
    });
    if (extent) {
      for (int a = 0; a < 3; ++a)
        if (extent->min[a] > extent->max[a]) check.fail("the trusted extent has min > max");
      trusted_extent_ = extent;
    }
  }

  const CountGrid& trusted() const noexcept { return trusted_; }
  const CountGrid& suspect() const noexcept { return suspect_; }
  const CountGrid& no_return() const noexcept { return no_return_; }
  /// The blocks (block_of()) that hold a trusted hit: every supported voxel lies in one.
  const KeySet& surface_blocks() const noexcept { return surface_blocks_; }
  /// The key box of the trusted beams' walks (ExplainedSpace::trusted_extent()).
  const std::optional<KeyBox>& trusted_extent() const noexcept { return trusted_extent_; }

  /// The counts of \p k in \p g (zero if none).
  static HitMissCount::Cell count(const CountGrid& g, const Key& k) noexcept {
    const HitMissCount::Cell* c = g.storage().find(k);
    return c ? *c : HitMissCount::Cell{};
  }
  /// The evidence of voxel \p k (all zero if none).
  EvidenceCell evidence(const Key& k) const noexcept {
    const HitMissCount::Cell t = count(trusted_, k), s = count(suspect_, k), n = count(no_return_, k);
    return {t.hits, t.misses, s.hits, s.misses, n.misses};
  }
  /// Calls f(key, const EvidenceCell&) once for every voxel with evidence: those with trusted
  /// evidence first, then those with suspect evidence, then the rest (ExplainedSpace::for_each()).
  template <class F>
  void for_each(F&& f) const {
    trusted_.for_each_observed([&](const Key& k, const HitMissCount::Cell&) { f(k, evidence(k)); });
    suspect_.for_each_observed([&](const Key& k, const HitMissCount::Cell&) {
      if (!trusted_.is_observed(k)) f(k, evidence(k));
    });
    no_return_.for_each_observed([&](const Key& k, const HitMissCount::Cell&) {
      if (!trusted_.is_observed(k) && !suspect_.is_observed(k)) f(k, evidence(k));
    });
  }
  /// Bytes held by the three grids.
  std::size_t memory_bytes() const noexcept {
    return trusted_.memory_bytes() + suspect_.memory_bytes() + no_return_.memory_bytes();
  }
  /// Forgets all counts, the blocks and the extent.
  void clear() {
    trusted_.clear();
    suspect_.clear();
    no_return_.clear();
    surface_blocks_.clear();
    trusted_extent_.reset();
  }

  /// The block coordinate (8^3 blocks) of a key.
  static Key block_of(const Key& k) noexcept { return Key{k.x >> 3, k.y >> 3, k.z >> 3}; }

  /// Grows the trusted extent to hold \p k.
  void grow_extent(const Key& k) noexcept {
    if (!trusted_extent_) {
      trusted_extent_ = KeyBox{k, k};
      return;
    }
    for (int a = 0; a < 3; ++a) {
      trusted_extent_->min[a] = std::min(trusted_extent_->min[a], k[a]);
      trusted_extent_->max[a] = std::max(trusted_extent_->max[a], k[a]);
    }
  }
  /// Grows the trusted extent by the key box of each of \p trusted's rays as the insertion under
  /// \p insert prepares them in geometry \p g (a ray's walk stays in its box).
  void grow_extent_by(const std::vector<Beam>& trusted, const GridGeometry& g, const InsertOptions& insert) {
    InsertStats ignored;
    for (const Beam& b : trusted)
      if (const std::optional<detail::PreparedRay> p = detail::prepare_ray(g, insert, b, ignored)) {
        grow_extent(p->k0);
        grow_extent(p->k1);
      }
  }
  /// The trusted extent again from the trusted voxels (after a trusted beam became suspect).
  void recompute_extent() {
    trusted_extent_.reset();
    trusted_.for_each_observed([&](const Key& k, const HitMissCount::Cell&) { grow_extent(k); });
  }

  /// Adds the counts of \p src (one scan's contribution) into class \p c's grid; into the trusted
  /// grid, notes the blocks of trusted hits and calls \p note for each voxel.
  template <class Note>
  void merge(const CountGrid& src, BeamClass c, Note&& note) {
    const bool trusted = c == BeamClass::Trusted;
    auto& cells = grid(c).storage();
    src.for_each_observed([&](const Key& k, const HitMissCount::Cell& d) {
      HitMissCount::Cell* cell = cells.touch(k);
      if (!cell) return;  // unreachable: the same unbounded geometry
      const HitMissCount::Cell before = *cell;
      cell->hits = add_saturated(cell->hits, d.hits);
      cell->misses = add_saturated(cell->misses, d.misses);
      if (!trusted) return;
      if (cell->hits > 0) surface_blocks_.insert(block_of(k));
      note(k, before, *cell);
    });
  }

  /// Changes class \p c's grid (Trusted or Suspect) from holding a scan's evidence \p was to
  /// holding \p now, touching only the voxels where the two differ; into the trusted grid, notes
  /// the blocks of trusted hits and calls \p note for each voxel.
  template <class Note>
  void apply_difference(const ScanFootprint& was, const ScanFootprint& now, BeamClass c, Note&& note) {
    const bool trusted = c == BeamClass::Trusted;
    auto& cells = grid(c).storage();
    const auto& a = was.all();
    const auto& b = now.all();
    const ScanFootprint::Block none{};
    std::size_t i = 0, j = 0;
    while (i < a.size() || j < b.size()) {
      const bool take_a = j == b.size() || (i < a.size() && a[i].id <= b[j].id);
      const bool take_b = i == a.size() || (j < b.size() && b[j].id <= a[i].id);
      const ScanFootprint::Block& x = take_a ? a[i] : none;
      const ScanFootprint::Block& y = take_b ? b[j] : none;
      const std::uint64_t id = take_a ? x.id : y.id;
      const Key base = detail::block_base_of(id);
      for (std::size_t w = 0; w < 8; ++w)
        for (std::uint64_t m = (x.hit[w] ^ y.hit[w]) | (x.miss[w] ^ y.miss[w]); m != 0; m &= m - 1) {
          const std::size_t ci = w * 64 + static_cast<std::size_t>(std::countr_zero(m));
          const std::uint64_t bit = std::uint64_t{1} << (ci & 63);
          const Key k = detail::key_in_block(base, ci);
          HitMissCount::Cell* cell = cells.touch(k);
          if (!cell) continue;  // unreachable: the same unbounded geometry
          const HitMissCount::Cell before = *cell;
          take(*cell, {static_cast<std::uint16_t>((x.hit[w] & bit) ? 1 : 0),
                       static_cast<std::uint16_t>((x.miss[w] & bit) ? 1 : 0)});
          cell->hits = add_saturated(cell->hits, (y.hit[w] & bit) ? 1 : 0);
          cell->misses = add_saturated(cell->misses, (y.miss[w] & bit) ? 1 : 0);
          if (!trusted) continue;
          if (cell->hits > 0) surface_blocks_.insert(block_of(k));
          note(k, before, *cell);
        }
      i += take_a;
      j += take_b;
    }
  }

 private:
  CountGrid& grid(BeamClass c) noexcept {
    return c == BeamClass::Trusted ? trusted_ : c == BeamClass::Suspect ? suspect_ : no_return_;
  }
  static std::uint16_t add_saturated(std::uint16_t a, std::uint16_t b) noexcept {
    const unsigned s = unsigned{a} + b;
    return static_cast<std::uint16_t>(std::min(s, 65535u));
  }
  static void take(HitMissCount::Cell& c, const HitMissCount::Cell& d) noexcept {
    // exact unless a count saturated (then at 65535 it stays as good as infinite)
    if (c.hits != 65535) c.hits = static_cast<std::uint16_t>(c.hits - std::min(c.hits, d.hits));
    if (c.misses != 65535) c.misses = static_cast<std::uint16_t>(c.misses - std::min(c.misses, d.misses));
  }

  CountGrid trusted_, suspect_, no_return_;
  KeySet surface_blocks_;  ///< blocks (block_of()) that hold a trusted hit: every supported voxel lies in one
  std::optional<KeyBox> trusted_extent_;
};

}  // namespace intervox::detail
