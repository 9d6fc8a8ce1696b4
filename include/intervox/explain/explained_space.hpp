#pragma once
/// \file
/// Explained free space, part 2: a second evidence channel beside any grid, fed by classed beams.
///
/// A beam is evidence only as far as the map can explain it. ExplainedSpace classes each beam of
/// a scan against its own trusted evidence *as it stood before the scan* (so a scan's beams never
/// vouch for each other, and the result does not depend on their order or on the thread count):
///
///  - **no return** (Beam::hit false): free up to the max range as in the insertion, but of
///    reliability 0 by default: such space is never explained free. A beam without a return
///    whose walk, more than `crossing_tolerance` before the sensor's range, enters a supported
///    surface's inside at `no_return_crossing_angle` or steeper and leaves it into a voxel no
///    trusted beam crossed is **suspect** instead (it went through a surface the sensor should
///    have seen, into the space behind it: a black surface's beams once the wall behind it is
///    known; a beam that skims an edge, a corner, a thin rod or a surface at a grazing angle, or
///    leaves it into space trusted beams crossed, is no crossing). The sensor's range is the
///    nearer of the beam's `end` and the insertion's max range: give a beam without a return its
///    end at the sensor's range, as the simulator does and insert_depth_image() does from the
///    frame's range (an end nearer than that only shortens the test: fewer beams suspect). Such
///    beams keep the class of their arrival (revision classes returned beams only);
///  - **suspect** if it crosses a mirror the channel was told of (add_mirror(): more than
///    `crossing_tolerance` before its end, or within the sensor's range without a return), or if
///    it returned and
///    1. *crossing*: its walk passes a *supported surface* voxel (at least `min_surface_hits`
///       trusted hits and trusted hits >= `surface_hit_ratio` x trusted misses) more than
///       `crossing_tolerance` before its end, and no supported voxel lies within
///       `crossing_tolerance` of its end along the beam (a beam that grazes a surface and ends
///       on it is not a crossing): a mirror's phantom passing the wall behind the mirror; with
///       `returned_crossing_inside` (off by default) only a voxel of a surface's inside met at
///       `no_return_crossing_angle` or steeper counts, as for a beam without a return (a beam
///       that grazes a door's jamb, a desk's leg, an edge or a corner is no crossing), or
///    2. *mid-air*: every voxel within `crossing_tolerance` of its end along the beam was crossed
///       by at least `mid_air_misses` trusted scans and hit by none: a phantom that lands in
///       space the map knows to be empty;
///  - **trusted** otherwise.
///
/// Its evidence then goes to the class's counts (EvidenceCell, combined as a belief function by
/// EvidenceModel: explain/evidence.hpp). The voxels a beam gives evidence to are exactly those
/// the insertion updates, because the beams of each class are inserted by the insertion itself
/// into that class's count grid: misses from the origin's voxel up to, not including, the end
/// voxel, a hit in the end voxel when the return lies within the max range, and per scan at most
/// one hit or miss per class and voxel, a hit winning within a class.
///
/// Revision (order of arrival): a phantom often arrives before the wall behind the mirror is
/// known, and is trusted then. The channel keeps the newest scans in a ledger
/// (explain/beam_ledger.hpp; ExplainOptions::ledger_bytes, 48 MiB by default) and, every
/// `revision_interval` scans (8 by default) or when revise() is called, classes again the
/// returned beams of kept scans that pass a voxel whose trusted evidence changed in a way that
/// can turn their class (a supported surface gained or lost, a voxel of mid-air gained or lost;
/// may_change() says which way matters where). A kept beam is classed again against all evidence
/// but its own scan's (the scan's trusted footprint is left out of every read), exactly as a new
/// scan is classed against the evidence before it. A scan whose beams change class has its
/// contribution per class inserted again and the count grids changed where its old and new
/// contributions differ, so the counts are what the new classes would have given from the start.
/// A move changes trusted evidence in turn, so a revision runs in rounds (at most
/// `revision_rounds`, 4 by default) until one changes nothing. Within the ledger the final
/// classes do not depend on the order the scans came in whenever the rounds settle (tested:
/// phantom first and wall later gives the classes and evidence of wall first). What the ledger
/// has forgotten keeps its last classes. A mirror found by the region analysis
/// (analysis/lying_surfaces.hpp) or known to the user is told to the channel with add_mirror():
/// every beam through it is suspect from then on, the kept ones included, and its surface is
/// explained occupied. docs/concepts.md, "Explained free space", lists what this finds and what
/// it misses, with measurements.
///
/// How: the evidence lives in three count grids (VoxelGrid<HitMissCount>, one per class), and a
/// scan's beams of each class are inserted into their class's grid by the ray insertion itself,
/// so the per-scan rules (one update per voxel, a hit winning) and the walks are the insertion's
/// own.
///
/// Memory: three sparse grids of 4-byte cells (2 KiB per 8^3 block and class) over the voxels the
/// beams of each class crossed, plus an inserter's scratch (ScanInserter) and three scratch count
/// grids of one scan's voxels. Unbounded within the key range; the insertion's budget
/// (InsertOptions::max_grid_bytes) bounds what a scan adds to each, and the channel's per-scan
/// scratch (ExplainedSpace::kScratchBytesPerBeam per beam: its copies of the beams, their classes,
/// the ledger's record and the count grids' prepared rays), checked before anything is allocated. The ledger holds at most
/// ExplainOptions::ledger_bytes (about 25 bytes per beam kept and 136 bytes per 8^3 block a kept
/// scan's trusted or suspect beams touched), and the changes awaiting a revision 256 bytes per
/// block that holds one.
///
/// Thread safety: the const queries may run concurrently with each other; add() and the insert
/// functions need exclusive access. classify() runs on InsertOptions::threads threads with the
/// same result for any count.

#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/key_set.hpp>
#include <intervox/core/parallel.hpp>
#include <intervox/core/plane_fit.hpp>
#include <intervox/core/plane_patch.hpp>
#include <intervox/core/point.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/explain/beam_ledger.hpp>
#include <intervox/explain/evidence.hpp>
#include <intervox/grid/occupancy_grid.hpp>
#include <intervox/grid/sparse_storage.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/raycast/detail/prepare_ray.hpp>
#include <intervox/raycast/insert.hpp>
#include <intervox/raycast/insert_options.hpp>
#include <intervox/raycast/traversal.hpp>
#include <intervox/update/hit_miss_count.hpp>
#include <intervox/utility/utility_policies.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numbers>
#include <optional>
#include <span>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace intervox {

/// The classification thresholds and the belief model of ExplainedSpace (see its file comment).
struct ExplainOptions {
  /// The belief combination (masses, class reliabilities, state thresholds).
  EvidenceModel model{};
  /// Trusted hits a voxel needs to be a supported surface, >= 1.
  int min_surface_hits = 2;
  /// ... and trusted hits >= this x trusted misses (so that a voxel at an edge, crossed more often
  /// than hit, is no surface), >= 0.
  double surface_hit_ratio = 1.0;
  /// m: how far before a beam's end a supported voxel must lie to count as a crossing, and the
  /// reach along the beam around its end of the grazing and mid-air tests; finite, >= 0.
  double crossing_tolerance = 0.15;
  /// Trusted misses every voxel near a beam's end needs (with no trusted hit) for the end to lie
  /// in mid-air; >= 1.
  int mid_air_misses = 3;
  /// Degrees: a beam without a return counts as passing a supported surface only where it meets
  /// the surface's inside (every neighbour across its local plane supported, the plane fitted to
  /// the supported voxels within one voxel) at this angle to the plane or steeper; a sensor loses
  /// grazing returns, and a beam that skims a surface, an edge, a corner or a thin rod is no
  /// evidence that the surface lied. In [0, 90].
  double no_return_crossing_angle = 20.0;
  /// Suspect misses a voxel needs to be free only by lying beams (free_only_by_lying_beams()), in
  /// [1, 65535]. With 2, one stray suspect miss in space that beams without a return crossed (out
  /// of range, no lie) does not make it lying, but a black surface's space that one suspect beam
  /// crossed is not lying either. Measured on the explained planner with hazards in
  /// docs/planning.md ("Two variants, measured"): 2 brings the lab room's floor known
  /// from 94-97 % to 99.7-99.9 % for every closet, at 17-21 steps instead of 13-15, with one run of
  /// ten meeting the front-only mirror closet (none with 1). 1 by default.
  int min_lying_misses = 1;
  /// A returned beam's crossing (the crossing test of the file comment) counts, as a beam
  /// without a return's does, only at a supported voxel of a surface's *inside* met at
  /// no_return_crossing_angle or steeper: the supported voxels within one voxel span a plane,
  /// the beam meets it that steeply, and every neighbour across the plane is supported. A beam
  /// that passes a door's jamb, a desk's leg, an edge, a corner or a lone voxel (whose hits sit
  /// in the voxel beside the real face), or a surface at a flatter angle, is then no crossing.
  /// Revision stays exact: a change within one voxel of a kept beam's path counts as a change on
  /// it. On the room frame it costs 2 % more without the ledger and a third less with it (fewer
  /// beams move; docs/performance.md, "Explained free space"). Off by default: any supported
  /// voxel counts (docs/concepts.md, "The inside rule for returned beams", measures both).
  bool returned_crossing_inside = false;
  /// Bytes the revision ledger may hold (the newest scans, classed again when the map changes
  /// where their beams pass; see the file comment and explain/beam_ledger.hpp); 0 turns revision
  /// off, and every beam keeps the class of its arrival. 48 MiB holds one to three million beams,
  /// depending on how many blocks their scans touch (LedgerScan::bytes()).
  std::size_t ledger_bytes = std::size_t{48} << 20;
  /// Rounds of one revision at most, >= 1 (a move changes trusted evidence, which can change
  /// another kept beam's class; the rounds stop as soon as one changes nothing).
  int revision_rounds = 4;
  /// Scans between two revisions, >= 1: add() revises after every revision_interval-th scan (the
  /// changes of the scans in between wait for it; ExplainedSpace::revise() runs one at any time,
  /// e.g. before planning). A revision costs about one insertion of every kept scan whose beams
  /// a change concerns, so revising after every scan costs several times the insertion (measured
  /// in docs/performance.md, "Explained free space"); 8 by default.
  int revision_interval = 8;

  /// \throws InvalidArgument naming the first invalid parameter.
  void validate() const {
    model.validate();
    const ParamCheck check("intervox::ExplainOptions");
    check.at_least("min_surface_hits", min_surface_hits, 1);
    check.nonnegative("surface_hit_ratio", surface_hit_ratio);
    check.nonnegative("crossing_tolerance", crossing_tolerance);
    check.at_least("mid_air_misses", mid_air_misses, 1);
    check.in_range("no_return_crossing_angle", no_return_crossing_angle, 0, 90);
    check.in_range("min_lying_misses", min_lying_misses, 1, 65535);
    check.at_least("revision_rounds", revision_rounds, 1);
    check.at_least("revision_interval", revision_interval, 1);
  }
};

namespace detail {
/// The supported voxels of the 3x3x3 block around a key and their least-squares plane (see
/// ExplainedSpace::surface_normal()). `on` is indexed (dz + 1) * 9 + (dy + 1) * 3 + dx + 1.
struct LocalSurface {
  std::array<bool, 27> on{};
  std::optional<Point3> normal;
};

/// The local surface around \p k by the predicate \p supported (called only on keys in range).
template <class Supported>
LocalSurface local_surface(const Key& k, Supported&& supported) {
  LocalSurface out;
  std::array<Point3, 27> pts;
  std::size_t n = 0;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const Key q{k.x + dx, k.y + dy, k.z + dz};
        if (in_key_range(q) && supported(q)) {
          pts[n++] = Point3(dx, dy, dz);
          out.on[static_cast<std::size_t>((dz + 1) * 9 + (dy + 1) * 3 + dx + 1)] = true;
        }
      }
  out.normal = plane_normal(std::span<const Point3>(pts.data(), n), 0.05);
  return out;
}

/// Which known mirrors may hold a voxel or meet a beam, so that a query tests those and not every
/// mirror (ExplainedSpace::on_mirror(), the mirror test of the classes). The key range is covered
/// by cubes at 19 levels, level l of 2^(l+6) voxels a side; a mirror is registered, by its index,
/// in the cubes of one level that its box overlaps: the key box of its rectangle thickened by
/// on_mirror()'s half thickness (and by one voxel against rounding), at the finest level where that
/// box spans at most two cubes per axis (at most 8 cubes, whatever the mirror's size). A voxel's
/// candidates are the mirrors of the cube that holds it at each level in use; a key box's are
/// those of the cubes it overlaps, or every mirror when that is more cubes at a level than a
/// given limit (a long beam). Candidates may repeat and include mirrors that do not hold the
/// voxel: the caller tests each; no mirror that holds it is missed.
class MirrorIndex {
 public:
  void clear() noexcept {
    cubes_.clear();
    levels_ = 0;
  }
  /// Registers mirror \p index, the patch \p m, of a channel of geometry \p g.
  void add(const PlanePatch& m, std::uint32_t index, const GridGeometry& g) {
    const Footprint f = footprint(m, g);
    levels_ |= 1u << f.level;
    for_each_cube(f, [&](std::uint64_t cube) {
      std::vector<std::uint32_t>& list = cubes_[cube];
      if (std::find(list.begin(), list.end(), index) == list.end()) list.push_back(index);
    });
  }
  /// Takes back the registration of mirror \p index made with the patch \p m.
  void remove(const PlanePatch& m, std::uint32_t index, const GridGeometry& g) {
    for_each_cube(footprint(m, g), [&](std::uint64_t cube) {
      const auto it = cubes_.find(cube);
      if (it == cubes_.end()) return;
      std::erase(it->second, index);
      if (it->second.empty()) cubes_.erase(it);
    });
  }
  /// Calls \p test(index) for the candidates of voxel \p k (a key in range) until one returns true;
  /// true if one did.
  template <class Test>
  bool any_at(const Key& k, Test&& test) const {
    for (std::uint32_t l = 0; l < kLevels; ++l) {
      if (!((levels_ >> l) & 1u)) continue;
      const auto it = cubes_.find(pack(l, cube_of(k.x, l), cube_of(k.y, l), cube_of(k.z, l)));
      if (it == cubes_.end()) continue;
      for (const std::uint32_t i : it->second)
        if (test(i)) return true;
    }
    return false;
  }
  /// Calls \p test(index) for the candidates of the key box [lo, hi] (keys in range), or returns
  /// nothing when the box overlaps more than \p max_cubes cubes at a level in use (then the caller
  /// tests every mirror, which costs less): true or false as any_at().
  template <class Test>
  std::optional<bool> any_in(const Key& lo, const Key& hi, std::int64_t max_cubes, Test&& test) const {
    for (std::uint32_t l = 0; l < kLevels; ++l) {
      if (!((levels_ >> l) & 1u)) continue;
      std::int64_t n = 1;
      for (int a = 0; a < 3; ++a) n *= cube_of(hi[a], l) - cube_of(lo[a], l) + 1;
      if (n > max_cubes) return std::nullopt;
    }
    for (std::uint32_t l = 0; l < kLevels; ++l) {
      if (!((levels_ >> l) & 1u)) continue;
      for (std::int64_t z = cube_of(lo.z, l); z <= cube_of(hi.z, l); ++z)
        for (std::int64_t y = cube_of(lo.y, l); y <= cube_of(hi.y, l); ++y)
          for (std::int64_t x = cube_of(lo.x, l); x <= cube_of(hi.x, l); ++x) {
            const auto it = cubes_.find(pack(l, x, y, z));
            if (it == cubes_.end()) continue;
            for (const std::uint32_t i : it->second)
              if (test(i)) return true;
          }
    }
    return false;
  }
  /// The key box around the centres a mirror may hold or a segment may pass, from a metric box:
  /// one voxel wider on each side, clamped to the key range (in double, before any conversion).
  static void key_box(const GridGeometry& g, const Point3& lo, const Point3& hi, Key& klo, Key& khi) noexcept {
    for (int a = 0; a < 3; ++a) {
      const double l = std::floor((lo[a] - g.origin()[a]) / g.resolution()) - 1.0;
      const double h = std::floor((hi[a] - g.origin()[a]) / g.resolution()) + 1.0;
      // NaN (not expected from finite patches) clamps to the whole range.
      klo[a] = l >= -double(kKeyLimit) ? static_cast<std::int32_t>(std::min(l, double(kKeyLimit) - 1)) : -kKeyLimit;
      khi[a] = h <= double(kKeyLimit) - 1 ? static_cast<std::int32_t>(std::max(h, -double(kKeyLimit))) : kKeyLimit - 1;
    }
  }

 private:
  static constexpr std::uint32_t kLevels = 19;  ///< level 18: a cube of 2^24 voxels holds the key range

  struct Footprint {
    std::uint32_t level = 0;
    std::int64_t lo[3], hi[3];  ///< cube coordinates at that level
  };

  /// The cube coordinate of key coordinate \p v (in range) at level \p l: in [0, 2^(18 - l)).
  static std::int64_t cube_of(std::int32_t v, std::uint32_t l) noexcept {
    return (std::int64_t{v} + kKeyLimit) >> (l + 6);
  }
  static std::uint64_t pack(std::uint32_t l, std::int64_t x, std::int64_t y, std::int64_t z) noexcept {
    return (std::uint64_t{l} << 57) | (static_cast<std::uint64_t>(z) << 38) | (static_cast<std::uint64_t>(y) << 19) |
           static_cast<std::uint64_t>(x);
  }
  static Footprint footprint(const PlanePatch& m, const GridGeometry& g) noexcept {
    const double t = (0.5 * m.normal.cwiseAbs().sum() + 1e-9) * g.resolution();
    const Point3 v = m.axis_v();
    Point3 e;
    for (int a = 0; a < 3; ++a)
      e[a] = (m.half_u * std::abs(m.axis_u[a]) + m.half_v * std::abs(v[a]) + t * std::abs(m.normal[a])) * (1.0 + 1e-9) +
             g.resolution();
    Key lo, hi;
    key_box(g, m.center - e, m.center + e, lo, hi);
    Footprint f;
    for (f.level = 0; f.level + 1 < kLevels; ++f.level) {
      bool fits = true;
      for (int a = 0; a < 3; ++a) fits = fits && cube_of(hi[a], f.level) - cube_of(lo[a], f.level) <= 1;
      if (fits) break;
    }
    for (int a = 0; a < 3; ++a) {
      f.lo[a] = cube_of(lo[a], f.level);
      f.hi[a] = cube_of(hi[a], f.level);
    }
    return f;
  }
  template <class F>
  static void for_each_cube(const Footprint& f, F&& visit) {
    for (std::int64_t z = f.lo[2]; z <= f.hi[2]; ++z)
      for (std::int64_t y = f.lo[1]; y <= f.hi[1]; ++y)
        for (std::int64_t x = f.lo[0]; x <= f.hi[0]; ++x) visit(pack(f.level, x, y, z));
  }

  std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> cubes_;
  std::uint32_t levels_ = 0;  ///< bit l: a mirror is registered at level l
};
}  // namespace detail

/// How ExplainedSpace::add_mirror() treats a mirror in the plane of a known one.
enum class MirrorMerge {
  Grow,  ///< the same mirror: the known rectangle grows to hold both (found mirrors)
  Keep   ///< kept as given, beside it (surfaces a user knows, e.g. walls on both sides of a doorway)
};

/// The explained-free-space evidence channel (see the file comment).
class ExplainedSpace {
 public:
  /// A count grid: one class's hits and misses.
  using CountGrid = VoxelGrid<HitMissCount, Entropy, SparseStorage>;

  /// The scratch one beam of a scan needs in the channel, beyond the plain insertion's: the
  /// scan's beams as the channel copies them (point clouds and depth frames become beams) and again
  /// split by class in add(), the beam's class, its record in the ledger (about 25 bytes) and its
  /// prepared ray when a class's beams are inserted into the count grids (kept for scans of up to
  /// 2^20 rays). A scan of n beams needs up to n times this; check_scan_scratch() holds it to the
  /// insertion budget.
  static constexpr std::uint64_t kScratchBytesPerBeam =
      2 * sizeof(Beam) + sizeof(BeamClass) + 25 + sizeof(detail::PreparedRay);

  /// Refuses a scan of \p beams beams whose scratch in the channel (beams x kScratchBytesPerBeam)
  /// exceeds the insertion budget \p insert.max_grid_bytes (nothing with kUnlimitedInsertBudget),
  /// as the insertion refuses a scan that may add more than the budget to a map. Every entry point
  /// that takes a scan calls it before allocating anything.
  /// \throws InvalidArgument naming the beams, the bytes and the budget.
  static void check_scan_scratch(std::uint64_t beams, const InsertOptions& insert) {
    if (insert.max_grid_bytes == kUnlimitedInsertBudget) return;
    if (beams <= insert.max_grid_bytes / kScratchBytesPerBeam) return;
    const auto mib = [](long double b) {
      std::string t = std::to_string(b / (1024.0L * 1024.0L));
      return t.substr(0, t.find('.') + 2);
    };
    throw InvalidArgument("intervox::ExplainedSpace: a scan of " + std::to_string(beams) + " beams needs up to " +
                          mib(static_cast<long double>(beams) * kScratchBytesPerBeam) +
                          " MiB of scratch in the explained channel (" + std::to_string(kScratchBytesPerBeam) +
                          " bytes per beam), more than the insertion budget of " + mib(insert.max_grid_bytes) +
                          " MiB (InsertOptions::max_grid_bytes). Insert the scan in parts, or raise max_grid_bytes.");
  }

  /// An empty channel.
  /// \param geometry the grid's geometry (copied); the insert functions check that the grid has it
  /// \throws InvalidArgument for invalid options.
  explicit ExplainedSpace(const GridGeometry& geometry, const ExplainOptions& options = {})
      : geometry_(geometry),
        trusted_(geometry, std::nullopt),
        suspect_(geometry, std::nullopt),
        no_return_(geometry, std::nullopt),
        scratch_{CountGrid(geometry, std::nullopt), CountGrid(geometry, std::nullopt), CountGrid(geometry, std::nullopt)} {
    set_options(options);
  }

  /// A channel holding saved evidence (io/explained_file.hpp loads one): the three count grids,
  /// the trusted extent (nothing: the box of the trusted voxels) and the known mirrors (kept as
  /// given, in order: not merged as add_mirror() merges). The blocks that hold a trusted hit are
  /// found again from the trusted counts. The ledger starts empty: saved evidence keeps its
  /// classes.
  /// \throws InvalidArgument for invalid options, count grids of different geometries, a bounded
  ///         count grid, an extent with min > max, or an invalid mirror (PlanePatch::validate()).
  ExplainedSpace(const ExplainOptions& options, CountGrid trusted, CountGrid suspect, CountGrid no_return,
                 const std::optional<KeyBox>& extent = std::nullopt, std::vector<PlanePatch> mirrors = {})
      : geometry_(trusted.geometry()),
        trusted_(std::move(trusted)),
        suspect_(std::move(suspect)),
        no_return_(std::move(no_return)),
        scratch_{CountGrid(geometry_, std::nullopt), CountGrid(geometry_, std::nullopt),
                 CountGrid(geometry_, std::nullopt)} {
    set_options(options);
    for (const CountGrid* g : {&suspect_, &no_return_})
      if (g->resolution() != geometry_.resolution() || g->geometry().origin() != geometry_.origin())
        throw InvalidArgument("intervox::ExplainedSpace: the count grids have different geometries");
    for (const CountGrid* g : {&trusted_, &suspect_, &no_return_})
      if (g->key_box()) throw InvalidArgument("intervox::ExplainedSpace: count grids must be unbounded");
    trusted_.for_each_observed([&](const Key& k, const HitMissCount::Cell& c) {
      if (c.hits > 0) surface_blocks_.insert(block_of(k));
      if (!extent) grow_extent(k);
    });
    if (extent) {
      for (int a = 0; a < 3; ++a)
        if (extent->min[a] > extent->max[a]) throw InvalidArgument("intervox::ExplainedSpace: the trusted extent has min > max");
      trusted_extent_ = extent;
    }
    for (const PlanePatch& m : mirrors) m.validate();
    mirrors_ = std::move(mirrors);
    for (std::size_t i = 0; i < mirrors_.size(); ++i) mirror_index_.add(mirrors_[i], static_cast<std::uint32_t>(i), geometry_);
  }

  const GridGeometry& geometry() const noexcept { return geometry_; }
  const ExplainOptions& options() const noexcept { return options_; }
  /// Changes thresholds and model; the evidence is kept (the belief is computed from counts on
  /// every query, so a new model applies to all of it at once). New thresholds apply to the
  /// classes of later scans and revisions; a smaller ledger budget forgets the oldest scans now.
  /// \throws InvalidArgument for invalid options.
  void set_options(const ExplainOptions& options) {
    options.validate();
    options_ = options;
    ledger_.set_budget(options.ledger_bytes);
  }

  // ---- classification and evidence ----------------------------------------------------------

  /// The class of \p beam against the evidence so far, with the insertion's rules of \p insert
  /// (min and max range: a beam the insertion skips is Skipped).
  BeamClass classify(const Beam& beam, const InsertOptions& insert) const noexcept {
    InsideCache cache;
    return classify(beam, insert, cache);
  }

  /// The classes of \p beams (one scan) against the evidence so far, on insert.threads threads
  /// (the same result for any count).
  /// \throws InvalidArgument for invalid insert options.
  std::vector<BeamClass> classify(std::span<const Beam> beams, const InsertOptions& insert) const {
    insert.validate();
    std::vector<BeamClass> out(beams.size());
    parallel_for_chunks(
        beams.size(), insert.threads,
        [&](std::size_t b, std::size_t e) {
          InsideCache cache;
          for (std::size_t i = b; i < e; ++i) out[i] = classify(beams[i], insert, cache);
        },
        1024);
    return out;
  }

  /// Adds one scan's evidence: each beam's voxels (as the insertion under \p insert walks them)
  /// get its class's hit and misses, at most one of each per class and voxel in the scan.
  /// Skipped beams (and beams the insertion would skip) add nothing. Then, with a ledger
  /// (ExplainOptions::ledger_bytes > 0), keeps the scan in it and revises the kept scans (see the
  /// file comment; revision_stats() counts what moved). Returns the beams per class as given in
  /// InsertStats::beams_trusted, beams_suspect and beams_no_return (nothing else set).
  /// \throws InvalidArgument if the sizes differ or the insert options are invalid, or if the
  ///         insertion budget refuses the scan: its scratch (check_scan_scratch()) or what it adds
  ///         to a count grid (then nothing changed).
  InsertStats add(std::span<const Beam> beams, std::span<const BeamClass> classes, const InsertOptions& insert) {
    insert.validate();
    check_scan_scratch(beams.size(), insert);
    if (beams.size() != classes.size())
      throw InvalidArgument("intervox::ExplainedSpace::add: " + std::to_string(beams.size()) + " beams but " +
                            std::to_string(classes.size()) + " classes");
    std::vector<Beam> by_class[3];
    for (std::size_t i = 0; i < beams.size(); ++i)
      if (classes[i] != BeamClass::Skipped) by_class[static_cast<int>(classes[i])].push_back(beams[i]);
    // What the scan adds to each class, into the scratch grids first: a scan the budget refuses
    // changes nothing.
    inserter_.set_options(insert);
    InsertStats st;
    std::uint64_t* counted[3] = {&st.beams_trusted, &st.beams_suspect, &st.beams_no_return};
    for (int c = 0; c < 3; ++c) {
      scratch_[c].clear();
      *counted[c] = inserter_.insert_beams(scratch_[c], std::span<const Beam>(by_class[c])).rays;
    }
    // The trusted extent grows by the key box of each trusted ray (its walk stays in it).
    grow_extent_by(by_class[0], insert);
    const bool revise_on = ledger_.budget() > 0;
    if (!revise_on) changed_.clear();
    merge(scratch_[0], trusted_, true, revise_on);
    merge(scratch_[1], suspect_, true, false);
    merge(scratch_[2], no_return_, true, false);
    if (revise_on) {
      LedgerScan scan(beams, classes, insert);
      scan.set_footprint(BeamClass::Trusted, ScanFootprint::of(scratch_[0]));
      scan.set_footprint(BeamClass::Suspect, ScanFootprint::of(scratch_[1]));
      const bool kept = ledger_.push(std::move(scan));
      // The newest scan was classed against all evidence but its own: until other scans come, it
      // needs no second look.
      if (++since_revision_ >= options_.revision_interval) revise_kept(since_revision_ == 1 && kept);
    }
    return st;
  }

  /// One scan of beams: classes them (classify()), inserts them into \p grid with \p inserter
  /// (its options; the grid's update is unchanged, bit for bit), then adds their evidence (add()).
  /// \p classes, if given, receives each beam's class. Returns the insertion's statistics with the
  /// class counts filled in.
  /// \tparam G any OccupancyGrid with this channel's geometry
  /// \throws InvalidArgument if the grid's geometry differs, if the channel's scratch for the scan
  ///         exceeds the insertion budget (check_scan_scratch()), or as the insertion throws (then the
  ///         grid and the channel are unchanged). The channel's count grids are unbounded sparse
  ///         grids under the same insertion budget (InsertOptions::max_grid_bytes); a scan into a
  ///         bounded grid (not budgeted) whose rays the count grids' budget refuses throws
  ///         InvalidArgument after the grid was updated, with the channel unchanged.
  template <OccupancyGrid G>
  InsertStats insert_beams(ScanInserter& inserter, G& grid, std::span<const Beam> beams,
                           std::vector<BeamClass>* classes = nullptr) {
    check_geometry(grid.geometry());
    check_scan_scratch(beams.size(), inserter.options());
    std::vector<BeamClass> c = classify(beams, inserter.options());
    InsertStats st = inserter.insert_beams(grid, beams);
    const InsertStats counted = add(beams, c, inserter.options());
    st.beams_trusted = counted.beams_trusted;
    st.beams_suspect = counted.beams_suspect;
    st.beams_no_return = counted.beams_no_return;
    if (classes) *classes = std::move(c);
    return st;
  }

  /// A point cloud seen from \p origin (every point a return), as insert_beams().
  /// \tparam G an OccupancyGrid; \tparam O PointLike; \tparam R a PointRange
  /// \throws InvalidArgument as insert_beams() (the scratch is checked before the beams are made).
  template <OccupancyGrid G, PointLike O, PointRange R>
  InsertStats insert_point_cloud(ScanInserter& inserter, G& grid, const O& origin, const R& points,
                                 std::vector<BeamClass>* classes = nullptr) {
    check_scan_scratch(static_cast<std::uint64_t>(std::ranges::size(points)), inserter.options());
    const Point3 o = to_point(origin);
    std::vector<Beam> beams;
    beams.reserve(static_cast<std::size_t>(std::ranges::size(points)));
    for (const auto& p : points) beams.push_back(Beam{o, to_point(p), true});
    return insert_beams(inserter, grid, std::span<const Beam>(beams), classes);
  }

  /// A depth frame (ScanInserter::insert_depth_image(G&, const DepthFrame&)'s pixel rule and max
  /// range: the smaller of the frame's and the inserter's), as insert_beams(); \p classes, if
  /// given, is row-major per pixel.
  /// \tparam G an OccupancyGrid
  /// \throws InvalidArgument for an invalid frame, or as insert_beams().
  template <OccupancyGrid G>
  InsertStats insert_depth_image(ScanInserter& inserter, G& grid, const DepthFrame& frame,
                                 std::vector<BeamClass>* classes = nullptr) {
    frame.validate();
    const InsertOptions o = inserter.options().for_frame(frame.max_range);
    o.validate();
    check_scan_scratch(frame.image.depth.size(), o);
    std::vector<Beam> beams = depth_frame_beams(frame);
    // A pixel without a return saw nothing within the range: its end there (the crossing test's
    // window; the insertion marks free space up to the max range whatever the end).
    if (o.has_max_range())
      for (Beam& b : beams)
        if (!b.hit) b.end = b.origin + (b.end - b.origin).normalized() * o.max_range;
    ScanInserter capped(o);  // the frame's range for this scan only; the caller's inserter is untouched
    ScanInserter& use = o.max_range == inserter.options().max_range ? inserter : capped;
    return insert_beams(use, grid, std::span<const Beam>(beams), classes);
  }

  // ---- queries ------------------------------------------------------------------------------

  /// The evidence of voxel \p k (all zero if none).
  EvidenceCell evidence(const Key& k) const noexcept {
    const HitMissCount::Cell t = count(trusted_, k), s = count(suspect_, k), n = count(no_return_, k);
    return {t.hits, t.misses, s.hits, s.misses, n.misses};
  }
  /// The combined belief of voxel \p k (EvidenceModel::combine()).
  ExplainedBelief belief(const Key& k) const noexcept { return options_.model.combine(evidence(k)); }
  /// The explained state of voxel \p k: Occupied on a known mirror (on_mirror()) whatever its
  /// evidence, else the belief model's state of its evidence.
  ExplainedState state(const Key& k) const noexcept {
    if (on_mirror(k)) return ExplainedState::Occupied;
    return options_.model.state(evidence(k));
  }
  /// True if \p k is explained free (the only space a safe planner may drive through).
  bool explained_free(const Key& k) const noexcept { return state(k) == ExplainedState::Free; }
  /// True if \p k is free only if beams that lie told the truth: unexplained, with at least
  /// ExplainOptions::min_lying_misses suspect misses (beams that passed a supported surface or
  /// ended in explained mid-air, returned or not), and
  /// free were its suspect and no-return evidence trusted (EvidenceModel::state() of the counts
  /// pooled as trusted). Space a mirror's phantom or a black surface's missing returns carved; not
  /// a voxel whose trusted evidence merely conflicts (a surface's edge), and not one that only
  /// beams without a return crossed which met no supported surface within their range (space
  /// beyond the range of what was seen: unknown, not lied about).
  bool free_only_by_lying_beams(const Key& k) const noexcept {
    const EvidenceCell c = evidence(k);
    if (c.suspect_misses < options_.min_lying_misses || options_.model.state(c) != ExplainedState::Unexplained || on_mirror(k))
      return false;
    const auto pooled = [](unsigned a, unsigned b, unsigned d = 0) {
      return static_cast<std::uint16_t>(std::min<unsigned>(a + b + d, 0xffffu));
    };
    EvidenceCell all;
    all.trusted_hits = pooled(c.trusted_hits, c.suspect_hits);
    all.trusted_misses = pooled(c.trusted_misses, c.suspect_misses, c.no_return_misses);
    return options_.model.state(all) == ExplainedState::Free;
  }
  /// True if \p k is a supported surface for the crossing test (see the file comment).
  bool supported_surface(const Key& k) const noexcept { return supported(count(trusted_, k)); }
  /// The same rule on a voxel's trusted counts (a cell of counts(BeamClass::Trusted)), for callers
  /// that walk the counts themselves: supported_surface(k) is supported_counts(the cell at k).
  bool supported_counts(const HitMissCount::Cell& trusted) const noexcept { return supported(trusted); }
  /// The unit normal of the least-squares plane through the supported surface voxels within one
  /// voxel of \p k (the 3x3x3 block, \p k included; sign: largest component positive), or nothing
  /// if fewer than 3 of them are supported or they lie (nearly) on a line (plane_normal() with a
  /// minimum spread of 0.05). The local surface the crossing test and find_lying_surfaces() use.
  std::optional<Point3> surface_normal(const Key& k) const {
    return detail::local_surface(k, [&](const Key& q) { return supported_surface(q); }).normal;
  }

  // ---- known mirrors ------------------------------------------------------------------------

  /// Tells the channel of a mirror (found by find_lying_surfaces(), analysis/lying_surfaces.hpp,
  /// or known to the user): from now on a returned beam that crosses \p mirror more than
  /// crossing_tolerance before its end, and a beam without a return that crosses it within the
  /// sensor's range, is suspect (what lies behind a mirror cannot be seen through it), and the
  /// voxels on it are explained occupied (on_mirror()). The ledger's kept returned beams that
  /// cross it move to suspect now, and the revision rounds follow what that changes (as in
  /// revise()); without a ledger (ledger_bytes 0) only later scans are concerned. A mirror in the
  /// plane of a known one (normals within 2 degrees, the new centre within one voxel of the known
  /// plane) is the same mirror: the known rectangle grows, in its own axes, to hold both, unless the
  /// grown rectangle would not be a valid patch (PlanePatch::validate(): its extent beyond the
  /// largest double), in which case the new one is kept beside it as given. The mirrors are
  /// saved by io/explained_file.hpp (from its version 2): a loaded channel knows them.
  ///
  /// With \p merge MirrorMerge::Keep the patch is kept as given, beside any known one in its plane
  /// (as a loaded channel keeps its mirrors): what a user who knows the surfaces tells, e.g. a
  /// floor plan's walls on both sides of a doorway, which merging would join across the doorway.
  /// A mirror added later with MirrorMerge::Grow may still grow a kept patch of its plane.
  /// Thread safety: needs exclusive access, like add().
  /// \throws InvalidArgument for an invalid patch (PlanePatch::validate()).
  void add_mirror(const PlanePatch& mirror_in, MirrorMerge merge = MirrorMerge::Grow) {
    mirror_in.validate();
    PlanePatch mirror = mirror_in;
    // The plane of a known mirror: one mirror, grown to hold both rectangles.
    const double cos_same = std::cos(2.0 * std::numbers::pi / 180.0);
    const auto same = merge == MirrorMerge::Keep ? mirrors_.end() : std::find_if(mirrors_.begin(), mirrors_.end(), [&](const PlanePatch& m) {
      return std::abs(m.normal.dot(mirror.normal)) >= cos_same &&
             std::abs(m.normal.dot(mirror.center - m.center)) <= geometry_.resolution();
    });
    std::optional<PlanePatch> grown;
    if (same != mirrors_.end()) {
      PlanePatch m = *same;
      const Point3 v = m.axis_v(), mv = mirror.axis_v();
      const Point3 d = mirror.center - m.center;
      // the new rectangle's reach along the known one's axes
      const double ru = std::abs(mirror.axis_u.dot(m.axis_u)) * mirror.half_u + std::abs(mv.dot(m.axis_u)) * mirror.half_v;
      const double rv = std::abs(mirror.axis_u.dot(v)) * mirror.half_u + std::abs(mv.dot(v)) * mirror.half_v;
      const double u0 = std::min(-m.half_u, d.dot(m.axis_u) - ru), u1 = std::max(m.half_u, d.dot(m.axis_u) + ru);
      const double v0 = std::min(-m.half_v, d.dot(v) - rv), v1 = std::max(m.half_v, d.dot(v) + rv);
      m.center += m.axis_u * (0.5 * (u0 + u1)) + v * (0.5 * (v0 + v1));
      m.half_u = 0.5 * (u1 - u0);
      m.half_v = 0.5 * (v1 - v0);
      // Two valid rectangles can grow into one that is not (an extent beyond the largest double):
      // never keep, or save, what cannot be read back.
      try {
        m.validate();
        grown = m;
      } catch (const InvalidArgument&) {
      }
    }
    if (grown) {
      const auto index = static_cast<std::uint32_t>(same - mirrors_.begin());
      mirror_index_.remove(*same, index, geometry_);
      *same = *grown;
      mirror_index_.add(*same, index, geometry_);
      mirror = *grown;
    } else {
      mirrors_.push_back(mirror);
      mirror_index_.add(mirror, static_cast<std::uint32_t>(mirrors_.size() - 1), geometry_);
    }
    if (ledger_.budget() == 0) return;
    bool demoted = false;
    for (LedgerScan& scan : ledger_.scans()) {
      std::vector<std::size_t> candidates;
      scan.for_each([&](std::size_t i, const Beam& b, BeamClass c) {
        if (b.hit && c == BeamClass::Trusted && crosses(mirror, b)) candidates.push_back(i);
      });
      if (!candidates.empty()) demoted |= revise_scan(scan, candidates);
    }
    revise_kept(false);
    if (demoted) recompute_extent();
  }
  /// The mirrors the channel was told of, in order.
  const std::vector<PlanePatch>& mirrors() const noexcept { return mirrors_; }
  /// True if voxel \p k lies on a known mirror: the plane meets the voxel's closed box (its centre
  /// within 0.5 x resolution x (|n.x| + |n.y| + |n.z|) of the plane, so a plane on a voxel face
  /// holds the voxels on both sides), and the centre lies within the rectangle.
  /// The mirrors are indexed by where they lie (detail::MirrorIndex): a query tests the few whose
  /// box holds the voxel, not every mirror.
  bool on_mirror(const Key& k) const noexcept {
    if (mirrors_.empty()) return false;
    const Point3 c = geometry_.center(k);
    const auto holds = [&](std::uint32_t i) {
      const PlanePatch& m = mirrors_[i];
      return m.contains(c, (0.5 * m.normal.cwiseAbs().sum() + 1e-9) * geometry_.resolution());
    };
    if (in_key_range(k)) return mirror_index_.any_at(k, holds);
    for (std::uint32_t i = 0; i < mirrors_.size(); ++i)
      if (holds(i)) return true;
    return false;
  }

  /// The key box of the trusted beams' walks (it holds every voxel with trusted evidence, and may
  /// exceed them by the one voxel of a cut beam's end), or nothing before the first trusted beam:
  /// the observed extent that planners and viewers of an unbounded map should use, which suspect
  /// and no-return evidence never grows.
  const std::optional<KeyBox>& trusted_extent() const noexcept { return trusted_extent_; }

  /// What revision did since the channel was made (or cleared).
  struct RevisionStats {
    std::uint64_t rounds = 0;            ///< rounds run that had changed voxels to look at
    std::uint64_t scans_revisited = 0;   ///< kept scans classed again (a beam passed a changed voxel)
    std::uint64_t beams_revisited = 0;   ///< returned beams classed again
    std::uint64_t to_suspect = 0;        ///< beams moved from trusted to suspect
    std::uint64_t to_trusted = 0;        ///< beams moved from suspect to trusted
    std::uint64_t unsettled = 0;         ///< scans after whose revision the last round still moved beams
  };
  /// Revises the kept scans now against the changes since the last revision (add() does it every
  /// ExplainOptions::revision_interval scans; call this before planning with a larger interval).
  /// Thread safety: needs exclusive access, like add().
  void revise() {
    if (ledger_.budget() > 0) revise_kept(false);
  }
  /// What revision did so far (see the file comment).
  const RevisionStats& revision_stats() const noexcept { return revision_; }
  /// The ledger of kept scans (their beams and classes now; see explain/beam_ledger.hpp).
  const BeamLedger& ledger() const noexcept { return ledger_; }

  /// Calls f(key, const EvidenceCell&) once for every voxel with evidence, in a deterministic
  /// order: those with trusted evidence first, then those with suspect evidence, then the rest.
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

  /// The count grid of one class (Trusted, Suspect or NoReturn; the no-return grid has misses
  /// only), e.g. to save or draw it like any grid.
  /// \throws InvalidArgument for BeamClass::Skipped.
  const CountGrid& counts(BeamClass c) const {
    switch (c) {
      case BeamClass::Trusted: return trusted_;
      case BeamClass::Suspect: return suspect_;
      case BeamClass::NoReturn: return no_return_;
      case BeamClass::Skipped: break;
    }
    throw InvalidArgument("intervox::ExplainedSpace::counts: skipped beams leave no evidence");
  }

  /// The voxels with evidence.
  std::size_t size() const {
    std::size_t n = 0;
    for_each([&](const Key&, const EvidenceCell&) { ++n; });
    return n;
  }
  /// Bytes held: the three count grids, the ledger (BeamLedger::bytes()), the scratch count
  /// grids and the inserter's scratch (ScanInserter::scratch_bytes()).
  std::size_t memory_bytes() const noexcept {
    std::size_t n = trusted_.memory_bytes() + suspect_.memory_bytes() + no_return_.memory_bytes() +
                    inserter_.scratch_bytes() + ledger_.bytes();
    for (const CountGrid& g : scratch_) n += g.memory_bytes();
    return n + changed_.size() * (sizeof(ChangeBlock) + 32) + look_.size() * (sizeof(ChangeBlock) + 32);
  }
  /// Forgets all evidence and the ledger (and frees the scratch).
  void clear() {
    trusted_.clear();
    suspect_.clear();
    no_return_.clear();
    for (CountGrid& g : scratch_) g.clear();
    inserter_.release_scratch();
    surface_blocks_.clear();
    trusted_extent_.reset();
    ledger_.clear();
    revision_ = {};
    changed_.clear();
    since_revision_ = 0;
    mirrors_.clear();
    mirror_index_.clear();
  }

  /// Checks that a grid of geometry \p g has the channel's voxels (same resolution and origin),
  /// as every call that pairs a grid with the channel does.
  /// \throws InvalidArgument naming \p who if the resolution or the origin differs.
  void check_geometry(const GridGeometry& g, const char* who = "intervox::ExplainedSpace") const {
    if (g.resolution() != geometry_.resolution() || g.origin() != geometry_.origin())
      throw InvalidArgument(std::string(who) + ": the grid's geometry (resolution " + std::to_string(g.resolution()) +
                            ") differs from the explained channel's (resolution " +
                            std::to_string(geometry_.resolution()) + "), or their origins differ");
  }

 private:

  /// What inside_met_steeply() found at supported voxels, kept while the beams of one chunk of a
  /// scan are classed (the trusted evidence they are read against does not change meanwhile).
  struct InsideCache {
    struct Entry {
      Point3 normal;  ///< the local plane's normal (zero if the supported voxels span none)
      bool inside;    ///< a plane, and every neighbour across it supported
    };
    std::unordered_map<Key, Entry, KeyHash> at;
  };

  BeamClass classify(const Beam& beam, const InsertOptions& insert, InsideCache& cache) const noexcept {
    InsertStats ignored;
    const std::optional<detail::PreparedRay> p = detail::prepare_ray(geometry_, insert, beam, ignored);
    if (!p) return BeamClass::Skipped;
    if (!beam.hit) return classify_no_return(beam, *p, insert.max_range, cache);
    return classify_returned(beam, *p, nullptr, &cache);
  }

  static HitMissCount::Cell count(const CountGrid& g, const Key& k) noexcept {
    const HitMissCount::Cell* c = g.storage().find(k);
    return c ? *c : HitMissCount::Cell{};
  }

  bool supported(const HitMissCount::Cell& c) const noexcept {
    return c.hits >= options_.min_surface_hits && double(c.hits) >= options_.surface_hit_ratio * double(c.misses);
  }

  /// The block coordinate (8^3 blocks) of a key.
  static Key block_of(const Key& k) noexcept { return Key{k.x >> 3, k.y >> 3, k.z >> 3}; }

  /// Walks the voxels of the prepared ray \p p inside block \p b (the part of its segment in the
  /// block's box, its keys clamped into the block); true as soon as \p f(key) is.
  template <class F>
  static bool walk_block(const detail::PreparedRay& p, const Key& b, F& f) noexcept {
    const Point3 d = p.v1 - p.v0;
    double t0 = 0.0, t1 = 1.0;
    for (int a = 0; a < 3; ++a) {
      const double lo = 8.0 * b[a], hi = lo + 8.0;
      if (d[a] == 0.0) continue;  // the segment lies in the block's slab (its block walk got here)
      double ta = (lo - p.v0[a]) / d[a], tb = (hi - p.v0[a]) / d[a];
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
    }
    if (t0 > t1) t0 = t1 = std::clamp(0.5 * (t0 + t1), 0.0, 1.0);  // grazes an edge or a corner
    const Point3 e0 = p.v0 + t0 * d, e1 = p.v0 + t1 * d;
    Key k0, k1;
    for (int a = 0; a < 3; ++a) {
      const auto clamp_key = [&](double v) {
        return std::clamp(static_cast<std::int32_t>(std::floor(v)), 8 * b[a], 8 * b[a] + 7);
      };
      k0[a] = clamp_key(e0[a]);
      k1[a] = clamp_key(e1[a]);
    }
    detail::SegmentDda dda(e0, e1, k0, k1);
    for (;;) {
      if (f(dda.key)) return true;
      if (dda.remaining == 0) return false;
      dda.advance();
    }
  }

  /// Walks the voxels of \p p that lie in blocks of \p blocks, block by block; true as soon as
  /// \p f(key) is.
  template <class F>
  static bool walk_blocks(const detail::PreparedRay& p, const KeySet& blocks, F& f) noexcept {
    if (blocks.size() == 0) return false;
    detail::SegmentDda dda(p.v0 / 8.0, p.v1 / 8.0, block_of(p.k0), block_of(p.k1));
    for (;;) {
      if (blocks.contains(dda.key) && walk_block(p, dda.key, f)) return true;
      if (dda.remaining == 0) return false;
      dda.advance();
    }
  }

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

  /// Reads cells along a walk, remembering the last block (a walk stays in a block for several
  /// steps, so most reads skip the hash lookup); with \p own, the counts without that scan's
  /// evidence (a kept scan classed again).
  struct CellReader {
    using Blocks = detail::SparseBlocks<HitMissCount::Cell>;
    const Blocks& cells;
    const ScanFootprint* own = nullptr;
    std::uint64_t id = ~std::uint64_t{0};
    const Blocks::Block* block = nullptr;
    const ScanFootprint::Block* own_block = nullptr;

    HitMissCount::Cell operator()(const Key& k) noexcept {
      if (!in_key_range(k)) return {};
      const std::uint64_t b = detail::block_id_of(k);
      if (b != id) {
        id = b;
        block = cells.find_block(b);
        if (own) own_block = own->find(b);
      }
      HitMissCount::Cell c = block ? (*block)[Blocks::cell_index(k)] : HitMissCount::Cell{};
      if (own_block) {
        const HitMissCount::Cell m = ScanFootprint::mark(own_block, k);
        c.hits = static_cast<std::uint16_t>(c.hits - std::min(c.hits, m.hits));
        c.misses = static_cast<std::uint16_t>(c.misses - std::min(c.misses, m.misses));
      }
      return c;
    }
  };

  /// The crossing test of a returned, prepared beam (reads through \p read): a supported voxel
  /// whose centre projects more than crossing_tolerance before the end; with \p inside, only one
  /// of a surface's inside met steeply (inside_met_steeply()). Supported voxels lie in blocks
  /// that hold a trusted hit (surface_blocks_): the walk steps block by block and walks voxels
  /// only inside those.
  bool crosses_support(const Beam& beam, const detail::PreparedRay& p, CellReader& read, bool inside,
                       InsideCache* cache) const noexcept {
    const Point3 d = beam.end - beam.origin;
    const double len = d.norm();
    const Point3 u = d / len;
    const double limit = len - options_.crossing_tolerance - 0.5 * geometry_.resolution();
    const double min_sine = inside ? std::sin(options_.no_return_crossing_angle * std::numbers::pi / 180.0) : 0.0;
    const auto crosses = [&](const Key& k) {
      return (geometry_.center(k) - beam.origin).dot(u) < limit && supported(read(k)) &&
             (!inside || inside_met_steeply(k, u, min_sine, read, cache));
    };
    return limit > 0.0 && walk_blocks(p, surface_blocks_, crosses);
  }

  /// True if supported voxel \p k (read through \p read) lies inside a surface that direction
  /// \p u meets at an angle whose sine is \p min_sine or more: around it the supported voxels
  /// within one voxel span a plane (their least-squares plane), \p u meets it that steeply, and
  /// every one of the 8 neighbours across the plane (along the two axes other than the normal's
  /// largest, one voxel up or down along it for an oblique surface) is supported: an edge, a
  /// corner, a thin rod or a lone voxel is none. With \p cache, what a voxel's neighbours say is
  /// looked at once per cache.
  bool inside_met_steeply(const Key& k, const Point3& u, double min_sine, CellReader& read, InsideCache* cache) const {
    if (cache) {
      auto it = cache->at.find(k);
      if (it == cache->at.end()) it = cache->at.emplace(k, inside_of(k, read)).first;
      return it->second.inside && std::abs(it->second.normal.dot(u)) >= min_sine;
    }
    const InsideCache::Entry e = inside_of(k, read);
    return e.inside && std::abs(e.normal.dot(u)) >= min_sine;
  }

  /// The local plane of supported voxel \p k and whether it lies inside it (inside_met_steeply()).
  InsideCache::Entry inside_of(const Key& k, CellReader& read) const {
    const detail::LocalSurface local = detail::local_surface(k, [&](const Key& q) { return supported(read(q)); });
    const std::optional<Point3>& normal = local.normal;
    const std::array<bool, 27>& on = local.on;
    if (!normal) return {Point3::Zero(), false};
    int a = 0;
    for (int i = 1; i < 3; ++i)
      if (std::abs((*normal)[i]) > std::abs((*normal)[a])) a = i;
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    for (int i = -1; i <= 1; ++i)
      for (int j = -1; j <= 1; ++j) {
        if (i == 0 && j == 0) continue;
        bool any = false;
        for (int t = -1; t <= 1 && !any; ++t) {
          int off[3];
          off[a] = t;
          off[b] = i;
          off[c] = j;
          any = on[static_cast<std::size_t>((off[2] + 1) * 9 + (off[1] + 1) * 3 + off[0] + 1)];
        }
        if (!any) return {*normal, false};
      }
    return {*normal, true};
  }

  /// The crossing test of a beam that returned nothing, prepared (cut at \p max_range): Suspect
  /// if, more than crossing_tolerance before the sensor's range (the nearer of its `end` and
  /// \p max_range), its walk enters a run of supported surface voxels at a voxel of the surface's
  /// inside met steeply (below) and leaves the run into a voxel that no trusted beam crossed (it
  /// went through a surface the sensor should have seen, into the space behind it, as a black
  /// surface's beams do once the wall behind is known); else NoReturn (nothing within the
  /// sensor's range: space beyond what was seen).
  BeamClass classify_no_return(const Beam& beam, const detail::PreparedRay& p, double max_range, InsideCache& cache) const noexcept {
    CellReader read{trusted_.storage(), nullptr};
    const Point3 d = beam.end - beam.origin;
    const double len = d.norm();
    const double range = std::min(len, max_range);
    const Beam cut{beam.origin, beam.origin + d * (range / len), false};
    if (crosses_mirror(cut)) return BeamClass::Suspect;
    if (!crosses_support(cut, p, read, false, nullptr)) return BeamClass::NoReturn;  // the cheap test first: no supported voxel at all
    const double limit = range - options_.crossing_tolerance - 0.5 * geometry_.resolution();
    const Point3 u = d / len;
    const double min_sine = std::sin(options_.no_return_crossing_angle * std::numbers::pi / 180.0);
    // A crossing needs a surface's inside, met steeply (inside_met_steeply()).
    const auto steep = [&](const Key& k) { return inside_met_steeply(k, u, min_sine, read, &cache); };
    int run = 0;  // 0 outside a supported run, 1 in a run met steeply enough, 2 in one met grazing
    bool through = false;
    traverse(geometry_, beam.origin, Point3(beam.origin + u * limit), [&](const Key& k) {
      const HitMissCount::Cell c = read(k);
      if (supported(c)) {
        if (run == 0) run = steep(k) ? 1 : 2;
      } else if (run != 0) {
        if (run == 1 && c.misses == 0) through = true;  // behind the surface: space no trusted beam crossed
        run = 0;
      }
      return !through;
    });
    return through ? BeamClass::Suspect : BeamClass::NoReturn;
  }

  /// The crossing and mid-air tests of a returned, prepared beam; with \p own, against the
  /// evidence without that scan's.
  BeamClass classify_returned(const Beam& beam, const detail::PreparedRay& p, const ScanFootprint* own,
                              InsideCache* cache) const noexcept {
    if (crosses_mirror(beam)) return BeamClass::Suspect;
    CellReader read{trusted_.storage(), own};
    const Point3 u = (beam.end - beam.origin).normalized();
    const double tol = options_.crossing_tolerance;
    const bool crossing = crosses_support(beam, p, read, options_.returned_crossing_inside, cache);
    // Around the end, along the beam: any supported voxel (then the beam grazed or met a known
    // surface), and whether every voxel is established trusted free space (mid-air). Only looked
    // at when it can change the class: after a crossing, or when the end voxel itself is
    // trusted free.
    const auto around_end = [&](bool& near_support, bool& mid_air) {
      near_support = false;
      mid_air = true;
      const TraverseResult r = traverse(geometry_, beam.end - tol * u, beam.end + tol * u, [&](const Key& k) {
        const HitMissCount::Cell c = read(k);
        if (supported(c)) near_support = true;
        if (c.hits != 0 || c.misses < options_.mid_air_misses) mid_air = false;
        return !near_support;
      });
      if (r.status == TraverseStatus::Invalid) mid_air = false;  // the end's surroundings leave the key range
    };
    bool near_support = false, mid_air = false;
    if (crossing) {
      around_end(near_support, mid_air);
      if (!near_support) return BeamClass::Suspect;
    }
    if (p.hit) {
      const HitMissCount::Cell end = read(p.k1);
      if (end.hits == 0 && end.misses >= options_.mid_air_misses) {
        around_end(near_support, mid_air);
        if (mid_air) return BeamClass::Suspect;
      }
    }
    return BeamClass::Trusted;
  }

  // ---- revision -----------------------------------------------------------------------------

  /// What the tests read of a trusted cell: bit 0 a supported surface, bit 1 a voxel of mid-air.
  unsigned reading(const HitMissCount::Cell& c) const noexcept {
    return (supported(c) ? 1u : 0u) | (c.hits == 0 && c.misses >= options_.mid_air_misses ? 2u : 0u);
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

  /// Adds (\p add) or takes out the counts \p visit lists (it calls its argument with (key,
  /// cell)) into \p dst. Into the trusted grid: notes the blocks of trusted hits and, with
  /// \p track, how the voxels' reading() changed.
  template <class Visit>
  void apply(Visit&& visit, CountGrid& dst, bool add, bool track) {
    const bool trusted = &dst == &trusted_;
    auto& cells = dst.storage();
    visit([&](const Key& k, const HitMissCount::Cell& d) {
      HitMissCount::Cell* c = cells.touch(k);
      if (!c) return;  // unreachable: the same unbounded geometry
      const unsigned before = reading(*c);
      if (add) {
        c->hits = add_saturated(c->hits, d.hits);
        c->misses = add_saturated(c->misses, d.misses);
      } else {
        take(*c, d);
      }
      if (!trusted) return;
      if (c->hits > 0) surface_blocks_.insert(block_of(k));
      if (track) note_change(k, before, reading(*c));
    });
  }
  void merge(const CountGrid& src, CountGrid& dst, bool add, bool track) {
    apply([&](const auto& f) { src.for_each_observed(f); }, dst, add, track);
  }

  /// Changes \p dst from holding a scan's evidence \p was to holding \p now, touching only the
  /// voxels where the two differ; into the trusted grid, notes how their reading() changed.
  void apply_difference(const ScanFootprint& was, const ScanFootprint& now, CountGrid& dst) {
    const bool trusted = &dst == &trusted_;
    auto& cells = dst.storage();
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
          const std::size_t c = w * 64 + static_cast<std::size_t>(std::countr_zero(m));
          const std::uint64_t bit = std::uint64_t{1} << (c & 63);
          const Key k = detail::key_in_block(base, c);
          HitMissCount::Cell* cell = cells.touch(k);
          if (!cell) continue;  // unreachable: the same unbounded geometry
          const unsigned before = reading(*cell);
          take(*cell, {static_cast<std::uint16_t>((x.hit[w] & bit) ? 1 : 0), static_cast<std::uint16_t>((x.miss[w] & bit) ? 1 : 0)});
          cell->hits = add_saturated(cell->hits, (y.hit[w] & bit) ? 1 : 0);
          cell->misses = add_saturated(cell->misses, (y.miss[w] & bit) ? 1 : 0);
          if (!trusted) continue;
          if (cell->hits > 0) surface_blocks_.insert(block_of(k));
          note_change(k, before, reading(*cell));
        }
      i += take_a;
      j += take_b;
    }
  }

  /// How a voxel's reading() changed: bit 0 support gained, 1 support lost, 2 mid-air gained,
  /// 3 mid-air lost.
  static unsigned transition(unsigned before, unsigned after) noexcept {
    return ((~before & after & 1u) ? 1u : 0u) | ((before & ~after & 1u) ? 2u : 0u) | ((~before & after & 2u) ? 4u : 0u) |
           ((before & ~after & 2u) ? 8u : 0u);
  }

  /// The changes of one 8^3 block: per kind of transition() a bit per cell.
  struct ChangeBlock {
    std::array<std::array<std::uint64_t, 8>, 4> bits{};
  };
  using Changes = std::unordered_map<std::uint64_t, ChangeBlock>;

  void note_change(const Key& k, unsigned before, unsigned after) {
    const unsigned t = transition(before, after);
    if (t == 0) return;
    ChangeBlock& b = changed_[detail::block_id_of(k)];
    const std::size_t i = detail::cell_index_of(k);
    for (int kind = 0; kind < 4; ++kind)
      if (t & (1u << kind)) b.bits[kind][i >> 6] |= std::uint64_t{1} << (i & 63);
  }

  void grow_extent_by(const std::vector<Beam>& trusted, const InsertOptions& insert) {
    InsertStats ignored;
    for (const Beam& b : trusted)
      if (const std::optional<detail::PreparedRay> p = detail::prepare_ray(geometry_, insert, b, ignored)) {
        grow_extent(p->k0);
        grow_extent(p->k1);
      }
  }

  /// True if a change this round looks at (look_) could change the class \p c of returned beam
  /// \p b (prepared as \p p; classify_returned() reads): a voxel more than crossing_tolerance
  /// before its end that became a supported surface (a trusted beam may now cross one) or stopped
  /// being one (a suspect beam may no longer), walked through the blocks that hold such a change
  /// only; or, voxel by voxel within reach of its end, a support or mid-air reading that changed
  /// the way that can turn the end tests' verdict. A trusted beam whose only such change is a
  /// support lost near its end counts only if it crosses a supported voxel (without the evidence
  /// of \p own, its scan's): else near support does not matter to it.
  bool may_change(const Beam& b, const detail::PreparedRay& p, BeamClass c, const ScanFootprint& own) const noexcept {
    const Point3 d = b.end - b.origin;
    const double len = d.norm();
    const Point3 u = d / len;
    const double tol = options_.crossing_tolerance, res = geometry_.resolution();
    const bool trusted = c == BeamClass::Trusted;
    // Support gained (trusted) or lost (suspect) before the end; with the inside rule either,
    // anywhere within one voxel of the path (a neighbour decides whether a voxel is inside).
    const bool inside = options_.returned_crossing_inside;
    const unsigned before_end = inside ? 3u : trusted ? 1u : 2u;
    const unsigned near_end = trusted ? 4u : 1u | 8u;  // what can change the end tests' verdict
    std::uint64_t cached_id = ~std::uint64_t{0};
    const ChangeBlock* cached = nullptr;
    const auto changes = [&](const Key& key) {
      const std::uint64_t id = detail::block_id_of(key);
      if (id != cached_id) {
        cached_id = id;
        const auto it = look_.find(id);
        cached = it == look_.end() ? nullptr : &it->second;
      }
      unsigned t = 0;
      if (!cached) return t;
      const std::size_t i = detail::cell_index_of(key);
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
      const std::uint64_t id = detail::block_id_of(key);
      if (id != near_id) {
        near_id = id;
        const auto it = look_near_.find(id);
        near_block = it == look_near_.end() ? nullptr : &it->second;
      }
      const std::size_t i = detail::cell_index_of(key);
      return near_block && ((near_block->bits[0][i >> 6] >> (i & 63)) & 1u) ? 3u : 0u;
    };
    const auto before = [&](const Key& key) {
      return (changes_near(key) & before_end) && (geometry_.center(key) - b.origin).dot(u) < limit;
    };
    if (limit > 0.0 && walk_blocks(p, inside ? look_near_blocks_ : trusted ? look_gain_blocks_ : look_lost_blocks_, before))
      return true;
    // Around the end, voxel by voxel.
    Point3 v0, v1;
    Key k0, k1;
    const Point3 from = len > tol + res ? Point3(b.end - u * (tol + res)) : b.origin;
    if (!detail::voxel_of(geometry_, from, v0, k0) || !detail::voxel_of(geometry_, b.end + u * tol, v1, k1)) return true;
    bool support_lost_near_end = false;
    for (detail::SegmentDda dda(v0, v1, k0, k1);; dda.advance()) {
      const unsigned t = changes(dda.key);
      if (t & near_end) return true;
      if (trusted && (t & 2u)) support_lost_near_end = true;
      if (dda.remaining == 0) break;
    }
    if (!support_lost_near_end) return false;
    CellReader read{trusted_.storage(), &own};
    return crosses_support(b, p, read, inside, nullptr);
  }

  /// Revision after a scan was added (see the file comment); \p newest_kept: the ledger's newest
  /// scan is the one just added, classed against all other evidence already, so the first round
  /// skips it.
  void revise_kept(bool newest_kept) {
    since_revision_ = 0;
    bool extent_dirty = false;
    for (int round = 0; round < options_.revision_rounds && !changed_.empty(); ++round) {
      ++revision_.rounds;
      // This round looks at the changes so far (look_); its own moves go to changed_.
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
        const Key base = detail::block_base_of(entry.first);
        const auto any = [&](int kind) {
          for (const std::uint64_t w : block.bits[kind])
            if (w) return true;
          return false;
        };
        if (any(0)) look_gain_blocks_.insert(block_of(base));
        if (any(1)) look_lost_blocks_.insert(block_of(base));
        if (options_.returned_crossing_inside)  // every voxel within one voxel of a support change
          for (std::size_t w = 0; w < 8; ++w)
            for (std::uint64_t m = block.bits[0][w] | block.bits[1][w]; m != 0; m &= m - 1) {
              const Key k = detail::key_in_block(base, w * 64 + static_cast<std::size_t>(std::countr_zero(m)));
              for (int dz = -1; dz <= 1; ++dz)
                for (int dy = -1; dy <= 1; ++dy)
                  for (int dx = -1; dx <= 1; ++dx)
                    if (const Key q{k.x + dx, k.y + dy, k.z + dz}; in_key_range(q)) {
                      const std::size_t i = detail::cell_index_of(q);
                      look_near_[detail::block_id_of(q)].bits[0][i >> 6] |= std::uint64_t{1} << (i & 63);
                      look_near_blocks_.insert(block_of(q));
                    }
            }
        lo = lo.cwiseMin(geometry_.center(base));
        hi = hi.cwiseMax(geometry_.center(Key{base.x + 7, base.y + 7, base.z + 7}));
      }
      const double reach = options_.crossing_tolerance + geometry_.resolution();
      auto& scans = ledger_.scans();
      const std::size_t last = scans.size() - (round == 0 && newest_kept ? 1 : 0);
      // Which kept scans have beams a change may concern (on the threads of their options).
      std::vector<std::vector<std::size_t>> candidates(last);
      for (std::size_t s = 0; s < last; ++s) {
        const LedgerScan& scan = scans[s];
        bool apart = false;
        for (int a = 0; a < 3; ++a)
          apart = apart || scan.min_corner()[a] > hi[a] + reach || scan.max_corner()[a] < lo[a] - reach;
        if (apart) continue;
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
                const std::optional<detail::PreparedRay> p = detail::prepare_ray(geometry_, scan.insert(), beams[i], ignored);
                if (p && may_change(beams[i], *p, cls[i], scan.footprint(BeamClass::Trusted)))
                  flag[i] = 1;
              }
            },
            1024);
        for (std::size_t i = 0; i < flag.size(); ++i)
          if (flag[i]) candidates[s].push_back(i);
      }
      for (std::size_t s = 0; s < last; ++s)
        if (!candidates[s].empty()) extent_dirty |= revise_scan(scans[s], candidates[s]);
      if (round + 1 == options_.revision_rounds && !changed_.empty()) ++revision_.unsettled;
    }
    changed_.clear();
    ledger_.refit();
    if (extent_dirty) recompute_extent();  // a trusted beam became suspect: the trusted voxels' box again
  }

  void recompute_extent() {
    trusted_extent_.reset();
    trusted_.for_each_observed([&](const Key& k, const HitMissCount::Cell&) { grow_extent(k); });
  }

  /// True if \p beam crosses \p m more than crossing_tolerance before its end.
  bool crosses(const PlanePatch& m, const Beam& beam) const noexcept {
    const std::optional<double> t = m.crossing(beam.origin, beam.end);
    return t && (1.0 - *t) * (beam.end - beam.origin).norm() > options_.crossing_tolerance;
  }
  /// True if \p beam crosses a known mirror (crosses()): with a few mirrors, each is tested; with
  /// more, those whose box the beam's key box overlaps (detail::MirrorIndex), unless the beam
  /// overlaps so many of the index's cubes (a long beam) that testing every mirror costs less.
  bool crosses_mirror(const Beam& beam) const noexcept {
    const auto crossed = [&](std::uint32_t i) { return crosses(mirrors_[i], beam); };
    const auto n = static_cast<std::int64_t>(mirrors_.size());
    if (n > 64) {
      Key lo, hi;
      detail::MirrorIndex::key_box(geometry_, beam.origin.cwiseMin(beam.end), beam.origin.cwiseMax(beam.end), lo, hi);
      // (a cube's lookup costs about what four mirrors' tests cost)
      if (const std::optional<bool> any = mirror_index_.any_in(lo, hi, std::max<std::int64_t>(64, n / 4), crossed))
        return *any;
    }
    for (std::uint32_t i = 0; i < mirrors_.size(); ++i)
      if (crossed(i)) return true;
    return false;
  }

  /// Classes the \p candidates of \p scan again against all evidence but the scan's own (its
  /// trusted footprint left out of every read), and moves the evidence of those whose class
  /// changed. True if a trusted beam became suspect.
  bool revise_scan(LedgerScan& scan, const std::vector<std::size_t>& candidates) {
    ++revision_.scans_revisited;
    revision_.beams_revisited += candidates.size();
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
    parallel_for_chunks(
        beams.size(), scan.insert().threads,
        [&](std::size_t from, std::size_t to) {
          InsertStats ignored;
          InsideCache cache;  // the evidence without this scan's, fixed while it is classed again
          for (std::size_t j = from; j < to; ++j) {
            const std::optional<detail::PreparedRay> p = detail::prepare_ray(geometry_, scan.insert(), beams[j], ignored);
            now[j] = p ? classify_returned(beams[j], *p, &own, &cache) : scan.beam_class(candidates[j]);
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
        ++revision_.to_suspect;
        demoted = true;
      } else {
        ++revision_.to_trusted;
        promoted.push_back(beams[j]);
      }
    }
    inserter_.set_options(scan.insert());
    for (const BeamClass c : {BeamClass::Trusted, BeamClass::Suspect}) {
      CountGrid& part = scratch_[static_cast<int>(c)];
      part.clear();
      inserter_.insert_beams(part, std::span<const Beam>(scan.beams_of(c)));
      ScanFootprint fresh = ScanFootprint::of(part);
      apply_difference(scan.footprint(c), fresh, c == BeamClass::Trusted ? trusted_ : suspect_);
      scan.set_footprint(c, std::move(fresh));
    }
    grow_extent_by(promoted, scan.insert());
    return demoted;
  }

  GridGeometry geometry_;
  ExplainOptions options_;
  ScanInserter inserter_;
  CountGrid trusted_, suspect_, no_return_;
  KeySet surface_blocks_;  ///< blocks (block_of()) that hold a trusted hit: every supported voxel lies in one
  std::optional<KeyBox> trusted_extent_;
  std::array<CountGrid, 3> scratch_;  ///< one scan's contribution per class (add() and revision)
  BeamLedger ledger_;
  RevisionStats revision_;
  int since_revision_ = 0;  ///< scans added since the last revision
  Changes changed_;     ///< how voxels' reading() changed (by add() or this round's moves)
  Changes look_;        ///< the changes a revision round looks at
  KeySet look_gain_blocks_, look_lost_blocks_;  ///< their blocks (block_of()) with a support gained, lost
  Changes look_near_;        ///< with returned_crossing_inside: bits[0] marks every voxel within one voxel of a support change
  KeySet look_near_blocks_;  ///< ... and their blocks (block_of())
  std::vector<PlanePatch> mirrors_;  ///< known mirrors (add_mirror())
  detail::MirrorIndex mirror_index_;  ///< where they lie, by their index in mirrors_
};

}  // namespace intervox
