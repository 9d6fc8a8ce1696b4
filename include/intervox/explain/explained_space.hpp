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
/// Files, by job (this header includes them all, so including it is enough):
///  - explain/explain_options.hpp: ExplainOptions, the thresholds, the belief model and the
///    ledger's budget and rhythm;
///  - explain/explained_counts.hpp: the count store (detail::ExplainedCounts): the three count
///    grids, the blocks that hold a trusted hit, the trusted extent;
///  - explain/beam_crossing.hpp: the crossing test (detail::BeamCrossing): supported surfaces, a
///    surface's inside (detail::local_surface()), mid-air, and the known mirrors' test;
///  - explain/known_mirrors.hpp: the known mirrors (MirrorMerge, detail::KnownMirrors,
///    detail::MirrorIndex);
///  - explain/ledger_revision.hpp: the ledger revision (detail::LedgerRevision,
///    ExplainRevisionStats), with the ledger itself in explain/beam_ledger.hpp;
///  - this file: ExplainedSpace, the insertion driver (classing a scan's beams and inserting them
///    per class) and the queries.
///
/// Memory: three sparse grids of 4-byte cells (2 KiB per 8^3 block and class) over the voxels the
/// beams of each class crossed, plus an inserter's scratch (ScanInserter) and three scratch count
/// grids of one scan's voxels. Unbounded within the key range; the insertion's budget
/// (InsertOptions::max_grid_bytes) bounds what a scan adds to each, and the channel's per-scan
/// scratch (ExplainedSpace::kScratchBytesPerBeam per beam: its copies of the beams, their classes,
/// the ledger's record and the count grids' prepared rays), checked before anything is allocated. The ledger holds at
/// most ExplainOptions::ledger_bytes (about 25 bytes per beam kept and 136 bytes per 8^3 block a kept scan's trusted or
/// suspect beams touched), and the changes awaiting a revision 256 bytes per block that holds one.
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
#include <intervox/explain/beam_crossing.hpp>
#include <intervox/explain/beam_ledger.hpp>
#include <intervox/explain/evidence.hpp>
#include <intervox/explain/explain_options.hpp>
#include <intervox/explain/explained_counts.hpp>
#include <intervox/explain/known_mirrors.hpp>
#include <intervox/explain/ledger_revision.hpp>
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

/// The explained-free-space evidence channel (see the file comment).
class ExplainedSpace {
 public:
  /// A count grid: one class's hits and misses.
  using CountGrid = detail::ExplainedCounts::CountGrid;

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
    ParamCheck("intervox::ExplainedSpace")
        .fail("a scan of " + std::to_string(beams) + " beams needs up to " +
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
        counts_(geometry),
        scratch_{CountGrid(geometry, std::nullopt), CountGrid(geometry, std::nullopt),
                 CountGrid(geometry, std::nullopt)} {
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
        counts_(std::move(trusted), std::move(suspect), std::move(no_return)),
        scratch_{CountGrid(geometry_, std::nullopt), CountGrid(geometry_, std::nullopt),
                 CountGrid(geometry_, std::nullopt)} {
    set_options(options);
    counts_.load(extent);
    mirrors_.assign(std::move(mirrors), geometry_);
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
    revision_.set_budget(options.ledger_bytes);
  }

  // ---- classification and evidence ----------------------------------------------------------

  /// The class of \p beam against the evidence so far, with the insertion's rules of \p insert
  /// (min and max range: a beam the insertion skips is Skipped).
  BeamClass classify(const Beam& beam, const InsertOptions& insert) const noexcept {
    detail::BeamCrossing::InsideCache cache;
    return crossing().classify(beam, insert, cache);
  }

  /// The classes of \p beams (one scan) against the evidence so far, on insert.threads threads
  /// (the same result for any count).
  /// \throws InvalidArgument for invalid insert options.
  std::vector<BeamClass> classify(std::span<const Beam> beams, const InsertOptions& insert) const {
    insert.validate();
    std::vector<BeamClass> out(beams.size());
    const detail::BeamCrossing test = crossing();
    parallel_for_chunks(
        beams.size(), insert.threads,
        [&](std::size_t b, std::size_t e) {
          detail::BeamCrossing::InsideCache cache;
          for (std::size_t i = b; i < e; ++i) out[i] = test.classify(beams[i], insert, cache);
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
      ParamCheck("intervox::ExplainedSpace::add")
          .fail(std::to_string(beams.size()) + " beams but " + std::to_string(classes.size()) + " classes");
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
    counts_.grow_extent_by(by_class[0], geometry_, insert);
    const bool revise_on = revision_.on();
    if (!revise_on) revision_.forget_changes();
    const auto untracked = [](const Key&, const HitMissCount::Cell&, const HitMissCount::Cell&) {};
    if (revise_on)
      counts_.merge(scratch_[0], BeamClass::Trusted,
                    [&](const Key& k, const HitMissCount::Cell& before, const HitMissCount::Cell& after) {
                      revision_.note(options_, k, before, after);
                    });
    else
      counts_.merge(scratch_[0], BeamClass::Trusted, untracked);
    counts_.merge(scratch_[1], BeamClass::Suspect, untracked);
    counts_.merge(scratch_[2], BeamClass::NoReturn, untracked);
    if (revise_on) {
      LedgerScan scan(beams, classes, insert);
      scan.set_footprint(BeamClass::Trusted, ScanFootprint::of(scratch_[0]));
      scan.set_footprint(BeamClass::Suspect, ScanFootprint::of(scratch_[1]));
      revision_.scan_added(context(), std::move(scan));
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
  EvidenceCell evidence(const Key& k) const noexcept { return counts_.evidence(k); }
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
    if (c.suspect_misses < options_.min_lying_misses || options_.model.state(c) != ExplainedState::Unexplained ||
        on_mirror(k))
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
  bool supported_surface(const Key& k) const noexcept {
    return supported(detail::ExplainedCounts::count(counts_.trusted(), k));
  }
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
    const PlanePatch mirror = mirrors_.add(mirror_in, merge, geometry_);
    revision_.mirror_added(context(), mirror);
  }
  /// The mirrors the channel was told of, in order.
  const std::vector<PlanePatch>& mirrors() const noexcept { return mirrors_.all(); }
  /// True if voxel \p k lies on a known mirror: the plane meets the voxel's closed box (its centre
  /// within 0.5 x resolution x (|n.x| + |n.y| + |n.z|) of the plane, so a plane on a voxel face
  /// holds the voxels on both sides), and the centre lies within the rectangle.
  /// The mirrors are indexed by where they lie (detail::MirrorIndex): a query tests the few whose
  /// box holds the voxel, not every mirror.
  bool on_mirror(const Key& k) const noexcept { return mirrors_.holds(k, geometry_); }

  /// The key box of the trusted beams' walks (it holds every voxel with trusted evidence, and may
  /// exceed them by the one voxel of a cut beam's end), or nothing before the first trusted beam:
  /// the observed extent that planners and viewers of an unbounded map should use, which suspect
  /// and no-return evidence never grows.
  const std::optional<KeyBox>& trusted_extent() const noexcept { return counts_.trusted_extent(); }

  /// What revision did since the channel was made (or cleared): explain/ledger_revision.hpp.
  using RevisionStats = ExplainRevisionStats;
  /// Revises the kept scans now against the changes since the last revision (add() does it every
  /// ExplainOptions::revision_interval scans; call this before planning with a larger interval).
  /// Thread safety: needs exclusive access, like add().
  void revise() { revision_.revise(context()); }
  /// What revision did so far (see the file comment).
  const RevisionStats& revision_stats() const noexcept { return revision_.stats(); }
  /// The ledger of kept scans (their beams and classes now; see explain/beam_ledger.hpp).
  const BeamLedger& ledger() const noexcept { return revision_.ledger(); }

  /// Calls f(key, const EvidenceCell&) once for every voxel with evidence, in a deterministic
  /// order: those with trusted evidence first, then those with suspect evidence, then the rest.
  template <class F>
  void for_each(F&& f) const {
    counts_.for_each(f);
  }

  /// The count grid of one class (Trusted, Suspect or NoReturn; the no-return grid has misses
  /// only), e.g. to save or draw it like any grid.
  /// \throws InvalidArgument for BeamClass::Skipped.
  const CountGrid& counts(BeamClass c) const {
    switch (c) {
      case BeamClass::Trusted:
        return counts_.trusted();
      case BeamClass::Suspect:
        return counts_.suspect();
      case BeamClass::NoReturn:
        return counts_.no_return();
      case BeamClass::Skipped:
        break;
    }
    ParamCheck("intervox::ExplainedSpace::counts").fail("skipped beams leave no evidence");
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
    std::size_t n = counts_.memory_bytes() + inserter_.scratch_bytes() + revision_.bytes();
    for (const CountGrid& g : scratch_) n += g.memory_bytes();
    return n;
  }
  /// Forgets all evidence and the ledger (and frees the scratch).
  void clear() {
    counts_.clear();
    for (CountGrid& g : scratch_) g.clear();
    inserter_.release_scratch();
    revision_.clear();
    mirrors_.clear();
  }

  /// Checks that a grid of geometry \p g has the channel's voxels (same resolution and origin),
  /// as every call that pairs a grid with the channel does.
  /// \throws InvalidArgument naming \p who if the resolution or the origin differs.
  void check_geometry(const GridGeometry& g, const char* who = "intervox::ExplainedSpace") const {
    if (g.resolution() != geometry_.resolution() || g.origin() != geometry_.origin())
      ParamCheck(who).fail("the grid's geometry (resolution " + std::to_string(g.resolution()) +
                           ") differs from the explained channel's (resolution " +
                           std::to_string(geometry_.resolution()) + "), or their origins differ");
  }

 private:
  detail::BeamCrossing crossing() const noexcept {
    return detail::BeamCrossing(geometry_, options_, counts_, mirrors_);
  }
  bool supported(const HitMissCount::Cell& c) const noexcept { return crossing().supported(c); }

  detail::RevisionContext context() noexcept { return {geometry_, options_, counts_, mirrors_, inserter_, scratch_}; }

  GridGeometry geometry_;
  ExplainOptions options_;
  ScanInserter inserter_;
  detail::ExplainedCounts counts_;    ///< the count grids per class, the trusted hits' blocks, the trusted extent
  std::array<CountGrid, 3> scratch_;  ///< one scan's contribution per class (add() and revision)
  detail::LedgerRevision revision_;   ///< the ledger, the changes awaiting a revision, the revision's statistics
  detail::KnownMirrors mirrors_;      ///< known mirrors (add_mirror()), indexed by where they lie
};

}  // namespace intervox
