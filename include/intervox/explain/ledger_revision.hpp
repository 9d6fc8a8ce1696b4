#pragma once
/// \file
/// The ledger revision of the explained channel (ExplainedSpace, explain/explained_space.hpp,
/// whose file comment says what it does and why): a phantom often arrives before the wall behind
/// the mirror is known, and is trusted then. The channel keeps its newest scans in a ledger
/// (explain/beam_ledger.hpp) and notes how each trusted voxel's *reading* changed (a supported
/// surface gained or lost, a voxel of mid-air gained or lost: note()). A revision runs in rounds:
/// each round looks at the changes so far, finds the kept returned beams whose class such a change
/// may turn (may_change(): support before the end, support or mid-air around it), classes them
/// again against all evidence but their own scan's (detail::BeamCrossing with the scan's trusted
/// footprint left out of every read), and changes the count grids where a scan's old and new
/// contributions differ (ExplainedCounts::apply_difference()). Its own moves are changes the next
/// round looks at; the rounds stop when one changes nothing, or after
/// ExplainOptions::revision_rounds.
///
/// Memory: the ledger (BeamLedger::bytes(), at most ExplainOptions::ledger_bytes) and 256 bytes
/// per block that holds a change awaiting a revision.
///
/// Uses the ray insertion's preparation (raycast/detail/prepare_ray.hpp: detail::prepare_ray,
/// detail::voxel_of, detail::SegmentDda) and the sparse grid's block coordinates
/// (grid/sparse_storage.hpp: detail::block_id_of, detail::cell_index_of, detail::block_base_of,
/// detail::key_in_block).
///
/// Thread safety: needs exclusive access to the channel (the may_change() tests of a round run on
/// the kept scans' InsertOptions::threads threads, reading only).

#include <intervox/core/key.hpp>
#include <intervox/core/key_set.hpp>
#include <intervox/core/parallel.hpp>
#include <intervox/core/plane_patch.hpp>
#include <intervox/core/point.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/explain/beam_crossing.hpp>
#include <intervox/explain/beam_ledger.hpp>
#include <intervox/explain/evidence.hpp>
#include <intervox/explain/explain_options.hpp>
#include <intervox/explain/explained_counts.hpp>
#include <intervox/explain/known_mirrors.hpp>
#include <intervox/grid/sparse_storage.hpp>
#include <intervox/raycast/detail/prepare_ray.hpp>
#include <intervox/raycast/insert.hpp>
#include <intervox/raycast/insert_options.hpp>
#include <intervox/update/hit_miss_count.hpp>

#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <unordered_map>
#include <utility>
#include <vector>

namespace intervox {

/// What the revision of an explained channel did since the channel was made (or cleared):
/// ExplainedSpace::RevisionStats, ExplainedSpace::revision_stats().
struct ExplainRevisionStats {
  std::uint64_t rounds = 0;           ///< rounds run that had changed voxels to look at
  std::uint64_t scans_revisited = 0;  ///< kept scans classed again (a beam passed a changed voxel)
  std::uint64_t beams_revisited = 0;  ///< returned beams classed again
  std::uint64_t to_suspect = 0;       ///< beams moved from trusted to suspect
  std::uint64_t to_trusted = 0;       ///< beams moved from suspect to trusted
  std::uint64_t unsettled = 0;        ///< scans after whose revision the last round still moved beams
};

namespace detail {

/// What a revision needs of its channel, for one call (never kept: the channel may move). The
/// inserter and the scratch grids are the channel's, shared with its insertion.
struct RevisionContext {
  const GridGeometry& geometry;
  const ExplainOptions& options;
  ExplainedCounts& counts;
  const KnownMirrors& mirrors;
  ScanInserter& inserter;
  std::array<ExplainedCounts::CountGrid, 3>& scratch;

  BeamCrossing crossing() const noexcept { return BeamCrossing(geometry, options, counts, mirrors); }
};

/// The ledger of an ExplainedSpace, the changes of its trusted evidence awaiting a revision, and
/// the revision itself (see the file comment).
class LedgerRevision {
 public:
  /// The ledger of kept scans (ExplainedSpace::ledger()).
  const BeamLedger& ledger() const noexcept { return ledger_; }
  /// What revision did so far (ExplainedSpace::revision_stats()).
  const ExplainRevisionStats& stats() const noexcept { return stats_; }
  /// True with a ledger (ExplainOptions::ledger_bytes > 0).
  bool on() const noexcept { return ledger_.budget() > 0; }
  /// The ledger's budget (a smaller one forgets the oldest scans now).
  void set_budget(std::size_t bytes) { ledger_.set_budget(bytes); }
  /// Bytes held: the ledger and the changes awaiting a revision.
  std::size_t bytes() const noexcept {
    return ledger_.bytes() + changed_.size() * (sizeof(ChangeBlock) + 32) + look_.size() * (sizeof(ChangeBlock) + 32);
  }
  /// Forgets the ledger, the changes and the statistics.
  void clear() {
    ledger_.clear();
    stats_ = {};
    changed_.clear();
    since_revision_ = 0;
  }

  /// Notes how the trusted counts of voxel \p k changed, from \p before to \p after.
  void note(const ExplainOptions& options, const Key& k, const HitMissCount::Cell& before,
            const HitMissCount::Cell& after) {
    note_change(k, reading(options, before), reading(options, after));
  }
  /// Forgets the changes noted (without a ledger nothing looks at them).
  void forget_changes() noexcept { changed_.clear(); }

  /// Keeps a scan just added in the ledger and, every ExplainOptions::revision_interval scans,
  /// revises the kept ones.
  void scan_added(const RevisionContext& ctx, LedgerScan scan) {
    const bool kept = ledger_.push(std::move(scan));
    // The newest scan was classed against all evidence but its own: until other scans come, it
    // needs no second look.
    if (++since_revision_ >= ctx.options.revision_interval) revise_kept(ctx, since_revision_ == 1 && kept);
  }
  /// Revises the kept scans now against the changes since the last revision (ExplainedSpace::revise()).
  void revise(const RevisionContext& ctx) {
    if (on()) revise_kept(ctx, false);
  }
  /// After a mirror was told (ExplainedSpace::add_mirror(); \p mirror as now known): the kept
  /// returned trusted beams that cross it are classed again (they become suspect), and the
  /// revision rounds follow what that changes.
  void mirror_added(const RevisionContext& ctx, const PlanePatch& mirror) {
    if (!on()) return;
    bool demoted = false;
    for (LedgerScan& scan : ledger_.scans()) {
      std::vector<std::size_t> candidates;
      scan.for_each([&](std::size_t i, const Beam& b, BeamClass c) {
        if (b.hit && c == BeamClass::Trusted && KnownMirrors::crosses(mirror, b, ctx.options.crossing_tolerance))
          candidates.push_back(i);
      });
      if (!candidates.empty()) demoted |= revise_scan(ctx, scan, candidates);
    }
    revise_kept(ctx, false);
    if (demoted) ctx.counts.recompute_extent();
  }

 private:
  /// What the tests read of a trusted cell: bit 0 a supported surface, bit 1 a voxel of mid-air.
  static unsigned reading(const ExplainOptions& options, const HitMissCount::Cell& c) noexcept {
    return (BeamCrossing::supported(options, c) ? 1u : 0u) |
           (c.hits == 0 && c.misses >= options.mid_air_misses ? 2u : 0u);
  }

  /// How a voxel's reading() changed: bit 0 support gained, 1 support lost, 2 mid-air gained,
  /// 3 mid-air lost.
  static unsigned transition(unsigned before, unsigned after) noexcept {
    return ((~before & after & 1u) ? 1u : 0u) | ((before & ~after & 1u) ? 2u : 0u) |
           ((~before & after & 2u) ? 4u : 0u) | ((before & ~after & 2u) ? 8u : 0u);
  }

  /// The changes of one 8^3 block: per kind of transition() a bit per cell.
  struct ChangeBlock {
    std::array<std::array<std::uint64_t, 8>, 4> bits{};
  };
  using Changes = std::unordered_map<std::uint64_t, ChangeBlock>;

  void note_change(const Key& k, unsigned before, unsigned after) {
    const unsigned t = transition(before, after);
    if (t == 0) return;
    ChangeBlock& b = changed_[block_id_of(k)];
    const std::size_t i = cell_index_of(k);
    for (int kind = 0; kind < 4; ++kind)
      if (t & (1u << kind)) b.bits[kind][i >> 6] |= std::uint64_t{1} << (i & 63);
  }

  /// True if a change this round looks at (look_) could change the class \p c of returned beam
  /// \p b (prepared as \p p; classify_returned() reads): a voxel more than crossing_tolerance
  /// before its end that became a supported surface (a trusted beam may now cross one) or stopped
  /// being one (a suspect beam may no longer), walked through the blocks that hold such a change
  /// only; or, voxel by voxel within reach of its end, a support or mid-air reading that changed
  /// the way that can turn the end tests' verdict. A trusted beam whose only such change is a
  /// support lost near its end counts only if it crosses a supported voxel (without the evidence
  /// of \p own, its scan's): else near support does not matter to it.
  bool may_change(const RevisionContext& ctx, const Beam& b, const PreparedRay& p, BeamClass c,
                  const ScanFootprint& own) const noexcept {
    const Point3 d = b.end - b.origin;
    const double len = d.norm();
    const Point3 u = d / len;
    const double tol = ctx.options.crossing_tolerance, res = ctx.geometry.resolution();
    const bool trusted = c == BeamClass::Trusted;
    // Support gained (trusted) or lost (suspect) before the end; with the inside rule either,
    // anywhere within one voxel of the path (a neighbour decides whether a voxel is inside).
    const bool inside = ctx.options.returned_crossing_inside;
    const unsigned before_end = inside ? 3u : trusted ? 1u : 2u;
    const unsigned near_end = trusted ? 4u : 1u | 8u;  // what can change the end tests' verdict
    std::uint64_t cached_id = ~std::uint64_t{0};
    const ChangeBlock* cached = nullptr;
    const auto changes = [&](const Key& key) {
      const std::uint64_t id = block_id_of(key);
      if (id != cached_id) {
        cached_id = id;
        const auto it = look_.find(id);
        cached = it == look_.end() ? nullptr : &it->second;
      }
      unsigned t = 0;
      if (!cached) return t;
      const std::size_t i = cell_index_of(key);
      for (int kind = 0; kind < 4; ++kind)
        if ((cached->bits[kind][i >> 6] >> (i & 63)) & 1u) t |= 1u << kind;
      return t;
    };
    // Before the end: through the blocks that hold such a change only.
    const double limit = len - tol - 0.5 * res;
    std::uint64_t near_id = ~std::uint64_t{0};
    const ChangeBlock* near_block = nullptr;
    const auto changes_near = [&](const Key& key) {
      if (!inside) return changes(key);
      const std::uint64_t id = block_id_of(key);
      if (id != near_id) {
        near_id = id;
        const auto it = look_near_.find(id);
        near_block = it == look_near_.end() ? nullptr : &it->second;
      }
      const std::size_t i = cell_index_of(key);
      return near_block && ((near_block->bits[0][i >> 6] >> (i & 63)) & 1u) ? 3u : 0u;
    };
    const auto before = [&](const Key& key) {
      return (changes_near(key) & before_end) && (ctx.geometry.center(key) - b.origin).dot(u) < limit;
    };
    if (limit > 0.0 && BeamCrossing::walk_blocks(p,
                                                 inside    ? look_near_blocks_
                                                 : trusted ? look_gain_blocks_
                                                           : look_lost_blocks_,
                                                 before))
      return true;
    // Around the end, voxel by voxel.
    Point3 v0, v1;
    Key k0, k1;
    const Point3 from = len > tol + res ? Point3(b.end - u * (tol + res)) : b.origin;
    if (!voxel_of(ctx.geometry, from, v0, k0) || !voxel_of(ctx.geometry, b.end + u * tol, v1, k1)) return true;
    bool support_lost_near_end = false;
    for (SegmentDda dda(v0, v1, k0, k1);; dda.advance()) {
      const unsigned t = changes(dda.key);
      if (t & near_end) return true;
      if (trusted && (t & 2u)) support_lost_near_end = true;
      if (dda.remaining == 0) break;
    }
    if (!support_lost_near_end) return false;
    BeamCrossing::CellReader read{ctx.counts.trusted().storage(), &own};
    return ctx.crossing().crosses_support(b, p, read, inside, nullptr);
  }

  /// The box of the centres of the blocks a round looks at.
  struct LookBox {
    Point3 lo, hi;
  };

  /// Starts a revision round: the changes so far become what it looks at (look_; the round's own
  /// moves go to changed_), with their blocks by kind of change and, with the inside rule, every
  /// voxel within one voxel of a support change (mark_near()). Returns the box of their blocks.
  LookBox look_at_changes(const RevisionContext& ctx) {
    std::swap(look_, changed_);
    changed_.clear();
    look_gain_blocks_.clear();
    look_lost_blocks_.clear();
    look_near_blocks_.clear();
    look_near_.clear();
    Point3 lo = Point3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (const auto& entry : look_) {
      // (no structured binding: a lambda below uses the block, and clang before 16 cannot
      // capture a structured binding)
      const ChangeBlock& block = entry.second;
      const Key base = block_base_of(entry.first);
      const auto any = [&](int kind) {
        for (const std::uint64_t w : block.bits[kind])
          if (w) return true;
        return false;
      };
      if (any(0)) look_gain_blocks_.insert(ExplainedCounts::block_of(base));
      if (any(1)) look_lost_blocks_.insert(ExplainedCounts::block_of(base));
      if (ctx.options.returned_crossing_inside) mark_near(base, block);
      lo = lo.cwiseMin(ctx.geometry.center(base));
      hi = hi.cwiseMax(ctx.geometry.center(Key{base.x + 7, base.y + 7, base.z + 7}));
    }
    return {lo, hi};
  }

  /// Marks every voxel within one voxel of a support change of \p block (minimum key \p base) in
  /// look_near_, and their blocks in look_near_blocks_.
  void mark_near(const Key& base, const ChangeBlock& block) {
    for (std::size_t w = 0; w < 8; ++w)
      for (std::uint64_t m = block.bits[0][w] | block.bits[1][w]; m != 0; m &= m - 1) {
        const Key k = key_in_block(base, w * 64 + static_cast<std::size_t>(std::countr_zero(m)));
        for (int dz = -1; dz <= 1; ++dz)
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx)
              if (const Key q{k.x + dx, k.y + dy, k.z + dz}; in_key_range(q)) {
                const std::size_t i = cell_index_of(q);
                look_near_[block_id_of(q)].bits[0][i >> 6] |= std::uint64_t{1} << (i & 63);
                look_near_blocks_.insert(ExplainedCounts::block_of(q));
              }
      }
  }

  /// The returned beams of kept scan \p scan whose class a change of this round may turn
  /// (may_change()), tested on the threads of the scan's options; none if the scan's box lies
  /// more than \p reach from the changes' box \p box.
  std::vector<std::size_t> beams_to_revisit(const RevisionContext& ctx, const LedgerScan& scan, const LookBox& box,
                                            double reach) const {
    std::vector<std::size_t> out;
    bool apart = false;
    for (int a = 0; a < 3; ++a)
      apart = apart || scan.min_corner()[a] > box.hi[a] + reach || scan.max_corner()[a] < box.lo[a] - reach;
    if (apart) return out;
    std::vector<unsigned char> flag(scan.size(), 0);
    std::vector<Beam> beams(scan.size());
    std::vector<BeamClass> cls(scan.size());
    scan.for_each([&](std::size_t i, const Beam& b, BeamClass c) {
      beams[i] = b;
      cls[i] = c;
    });
    parallel_for_chunks(
        beams.size(), scan.insert().threads,
        [&](std::size_t from, std::size_t to) {
          InsertStats ignored;
          for (std::size_t i = from; i < to; ++i) {
            if (!beams[i].hit || (cls[i] != BeamClass::Trusted && cls[i] != BeamClass::Suspect)) continue;
            const std::optional<PreparedRay> p = prepare_ray(ctx.geometry, scan.insert(), beams[i], ignored);
            if (p && may_change(ctx, beams[i], *p, cls[i], scan.footprint(BeamClass::Trusted))) flag[i] = 1;
          }
        },
        1024);
    for (std::size_t i = 0; i < flag.size(); ++i)
      if (flag[i]) out.push_back(i);
    return out;
  }

  /// Revision after a scan was added (see the file comment); \p newest_kept: the ledger's newest
  /// scan is the one just added, classed against all other evidence already, so the first round
  /// skips it.
  void revise_kept(const RevisionContext& ctx, bool newest_kept) {
    since_revision_ = 0;
    bool extent_dirty = false;
    for (int round = 0; round < ctx.options.revision_rounds && !changed_.empty(); ++round) {
      ++stats_.rounds;
      const LookBox box = look_at_changes(ctx);
      const double reach = ctx.options.crossing_tolerance + ctx.geometry.resolution();
      auto& scans = ledger_.scans();
      const std::size_t last = scans.size() - (round == 0 && newest_kept ? 1 : 0);
      // Which kept scans have beams a change may concern (on the threads of their options).
      std::vector<std::vector<std::size_t>> candidates(last);
      for (std::size_t s = 0; s < last; ++s) candidates[s] = beams_to_revisit(ctx, scans[s], box, reach);
      for (std::size_t s = 0; s < last; ++s)
        if (!candidates[s].empty()) extent_dirty |= revise_scan(ctx, scans[s], candidates[s]);
      if (round + 1 == ctx.options.revision_rounds && !changed_.empty()) ++stats_.unsettled;
    }
    changed_.clear();
    ledger_.refit();
    if (extent_dirty) ctx.counts.recompute_extent();  // a trusted beam became suspect: the trusted voxels' box again
  }

  /// Classes the \p candidates of \p scan again against all evidence but the scan's own (its
  /// trusted footprint left out of every read), and moves the evidence of those whose class
  /// changed. True if a trusted beam became suspect.
  bool revise_scan(const RevisionContext& ctx, LedgerScan& scan, const std::vector<std::size_t>& candidates) {
    ++stats_.scans_revisited;
    stats_.beams_revisited += candidates.size();
    std::vector<Beam> beams;
    beams.reserve(candidates.size());
    {
      std::size_t j = 0;
      scan.for_each([&](std::size_t i, const Beam& b, BeamClass) {
        if (j < candidates.size() && candidates[j] == i) {
          beams.push_back(b);
          ++j;
        }
      });
    }
    const ScanFootprint& own = scan.footprint(BeamClass::Trusted);
    std::vector<BeamClass> now(beams.size());
    const BeamCrossing test = ctx.crossing();
    parallel_for_chunks(
        beams.size(), scan.insert().threads,
        [&](std::size_t from, std::size_t to) {
          InsertStats ignored;
          BeamCrossing::InsideCache cache;  // the evidence without this scan's, fixed while it is classed again
          for (std::size_t j = from; j < to; ++j) {
            const std::optional<PreparedRay> p = prepare_ray(ctx.geometry, scan.insert(), beams[j], ignored);
            now[j] = p ? test.classify_returned(beams[j], *p, &own, &cache) : scan.beam_class(candidates[j]);
          }
        },
        256);
    std::vector<std::size_t> moved;
    for (std::size_t j = 0; j < candidates.size(); ++j)
      if (now[j] != scan.beam_class(candidates[j])) moved.push_back(j);
    if (moved.empty()) return false;
    // The new classes, the scan's new evidence per class, and the grids changed by the difference
    // between its old and new evidence, voxel by voxel.
    bool demoted = false;
    std::vector<Beam> promoted;
    for (const std::size_t j : moved) {
      scan.set_class(candidates[j], now[j]);
      if (now[j] == BeamClass::Suspect) {
        ++stats_.to_suspect;
        demoted = true;
      } else {
        ++stats_.to_trusted;
        promoted.push_back(beams[j]);
      }
    }
    ctx.inserter.set_options(scan.insert());
    for (const BeamClass c : {BeamClass::Trusted, BeamClass::Suspect}) {
      ExplainedCounts::CountGrid& part = ctx.scratch[static_cast<int>(c)];
      part.clear();
      ctx.inserter.insert_beams(part, std::span<const Beam>(scan.beams_of(c)));
      ScanFootprint fresh = ScanFootprint::of(part);
      ctx.counts.apply_difference(scan.footprint(c), fresh, c,
                                  [&](const Key& k, const HitMissCount::Cell& before, const HitMissCount::Cell& after) {
                                    note(ctx.options, k, before, after);
                                  });
      scan.set_footprint(c, std::move(fresh));
    }
    ctx.counts.grow_extent_by(promoted, ctx.geometry, scan.insert());
    return demoted;
  }

  BeamLedger ledger_;
  ExplainRevisionStats stats_;
  int since_revision_ = 0;  ///< scans added since the last revision
  Changes changed_;         ///< how voxels' reading() changed (by add() or this round's moves)
  Changes look_;            ///< the changes a revision round looks at
  KeySet look_gain_blocks_,
      look_lost_blocks_;  ///< their blocks (ExplainedCounts::block_of()) with a support gained, lost
  Changes
      look_near_;  ///< with returned_crossing_inside: bits[0] marks every voxel within one voxel of a support change
  KeySet look_near_blocks_;  ///< ... and their blocks (ExplainedCounts::block_of())
};

}  // namespace detail

}  // namespace intervox
