#pragma once
/// \file
/// Explained free space, part 2: a second evidence channel beside any grid, fed by classed beams.
///
/// A beam is evidence only as far as the map can explain it. ExplainedSpace classes each beam of
/// a scan against its own trusted evidence *as it stood before the scan* (so a scan's beams never
/// vouch for each other, and the result does not depend on their order or on the thread count):
///
///  - **no return** (Beam::hit false): free up to the max range as in the insertion, but of
///    reliability 0 by default: such space is never explained free;
///  - **suspect** if it returned and
///    1. *crossing*: its walk passes a *supported surface* voxel (at least `min_surface_hits`
///       trusted hits and trusted hits >= `surface_hit_ratio` x trusted misses) more than
///       `crossing_tolerance` before its end, and no supported voxel lies within
///       `crossing_tolerance` of its end along the beam (a beam that grazes a surface and ends
///       on it is not a crossing): a mirror's phantom passing the wall behind the mirror, or
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
/// What is not (yet) done: beams are classed once, against the map of their arrival; a phantom
/// that arrives before the wall behind the mirror is known keeps its class (no revision ledger),
/// and no region analysis names mirrors or openings. docs/concepts.md, "Explained free space",
/// lists what this finds and what it misses, with measurements.
///
/// How: the evidence lives in three count grids (VoxelGrid<HitMissCount>, one per class), and a
/// scan's beams of each class are inserted into their class's grid by the ray insertion itself,
/// so the per-scan rules (one update per voxel, a hit winning) and the walks are the insertion's
/// own.
///
/// Memory: three sparse grids of 4-byte cells (2 KiB per 8^3 block and class) over the voxels the
/// beams of each class crossed, plus an inserter's scratch (ScanInserter). Unbounded within the
/// key range; the insertion's budget (InsertOptions::max_grid_bytes) bounds what a scan adds to
/// each.
///
/// Thread safety: the const queries may run concurrently with each other; add() and the insert
/// functions need exclusive access. classify() runs on InsertOptions::threads threads with the
/// same result for any count.

#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/key_set.hpp>
#include <intervox/core/parallel.hpp>
#include <intervox/core/point.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/explain/evidence.hpp>
#include <intervox/grid/occupancy_grid.hpp>
#include <intervox/grid/sparse_storage.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/raycast/detail/prepare_ray.hpp>
#include <intervox/raycast/insert.hpp>
#include <intervox/raycast/insert_options.hpp>
#include <intervox/raycast/traversal.hpp>
#include <intervox/update/hit_miss_count.hpp>
#include <intervox/utility/utility.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
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

  /// \throws InvalidArgument naming the first invalid parameter.
  void validate() const {
    model.validate();
    const ParamCheck check("intervox::ExplainOptions");
    check.at_least("min_surface_hits", min_surface_hits, 1);
    check.nonnegative("surface_hit_ratio", surface_hit_ratio);
    check.nonnegative("crossing_tolerance", crossing_tolerance);
    check.at_least("mid_air_misses", mid_air_misses, 1);
  }
};

/// The explained-free-space evidence channel (see the file comment).
class ExplainedSpace {
 public:
  /// A count grid: one class's hits and misses.
  using CountGrid = VoxelGrid<HitMissCount, Entropy, SparseStorage>;

  /// An empty channel.
  /// \param geometry the grid's geometry (copied); the insert functions check that the grid has it
  /// \throws InvalidArgument for invalid options.
  explicit ExplainedSpace(const GridGeometry& geometry, const ExplainOptions& options = {})
      : geometry_(geometry),
        trusted_(geometry, std::nullopt),
        suspect_(geometry, std::nullopt),
        no_return_(geometry, std::nullopt) {
    set_options(options);
  }

  /// A channel holding saved evidence (io/explained_file.hpp loads one): the three count grids,
  /// and the trusted extent (nothing: the box of the trusted voxels). The blocks that hold a
  /// trusted hit are found again from the trusted counts.
  /// \throws InvalidArgument for invalid options, count grids of different geometries, a bounded
  ///         count grid, or an extent with min > max.
  ExplainedSpace(const ExplainOptions& options, CountGrid trusted, CountGrid suspect, CountGrid no_return,
                 const std::optional<KeyBox>& extent = std::nullopt)
      : geometry_(trusted.geometry()),
        trusted_(std::move(trusted)),
        suspect_(std::move(suspect)),
        no_return_(std::move(no_return)) {
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
  }

  const GridGeometry& geometry() const noexcept { return geometry_; }
  const ExplainOptions& options() const noexcept { return options_; }
  /// Changes thresholds and model; the evidence is kept (the belief is computed from counts on
  /// every query, so a new model applies to all of it at once).
  /// \throws InvalidArgument for invalid options.
  void set_options(const ExplainOptions& options) {
    options.validate();
    options_ = options;
  }

  // ---- classification and evidence ----------------------------------------------------------

  /// The class of \p beam against the evidence so far, with the insertion's rules of \p insert
  /// (min and max range: a beam the insertion skips is Skipped).
  BeamClass classify(const Beam& beam, const InsertOptions& insert) const noexcept {
    InsertStats ignored;
    const std::optional<detail::PreparedRay> p = detail::prepare_ray(geometry_, insert, beam, ignored);
    if (!p) return BeamClass::Skipped;
    if (!beam.hit) return BeamClass::NoReturn;
    return classify_returned(beam, *p);
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
          for (std::size_t i = b; i < e; ++i) out[i] = classify(beams[i], insert);
        },
        1024);
    return out;
  }

  /// Adds one scan's evidence: each beam's voxels (as the insertion under \p insert walks them)
  /// get its class's hit and misses, at most one of each per class and voxel in the scan.
  /// Skipped beams (and beams the insertion would skip) add nothing. Returns the beams per class
  /// in InsertStats::beams_trusted, beams_suspect and beams_no_return (nothing else set).
  /// \throws InvalidArgument if the sizes differ or the insert options are invalid.
  InsertStats add(std::span<const Beam> beams, std::span<const BeamClass> classes, const InsertOptions& insert) {
    insert.validate();
    if (beams.size() != classes.size())
      throw InvalidArgument("intervox::ExplainedSpace::add: " + std::to_string(beams.size()) + " beams but " +
                            std::to_string(classes.size()) + " classes");
    std::vector<Beam> by_class[3];
    for (std::size_t i = 0; i < beams.size(); ++i)
      if (classes[i] != BeamClass::Skipped) by_class[static_cast<int>(classes[i])].push_back(beams[i]);
    inserter_.set_options(insert);
    // The trusted extent grows by the key box of each trusted ray (its walk stays in it).
    InsertStats ignored;
    for (const Beam& b : by_class[0])
      if (const std::optional<detail::PreparedRay> p = detail::prepare_ray(geometry_, insert, b, ignored)) {
        grow_extent(p->k0);
        grow_extent(p->k1);
        if (p->hit) surface_blocks_.insert(block_of(p->k1));
      }
    const InsertStats t = inserter_.insert_beams(trusted_, std::span<const Beam>(by_class[0]));
    const InsertStats s = inserter_.insert_beams(suspect_, std::span<const Beam>(by_class[1]));
    const InsertStats n = inserter_.insert_beams(no_return_, std::span<const Beam>(by_class[2]));
    InsertStats st;
    st.beams_trusted = t.rays;
    st.beams_suspect = s.rays;
    st.beams_no_return = n.rays;
    return st;
  }

  /// One scan of beams: classes them (classify()), inserts them into \p grid with \p inserter
  /// (its options; the grid's update is unchanged, bit for bit), then adds their evidence (add()).
  /// \p classes, if given, receives each beam's class. Returns the insertion's statistics with the
  /// class counts filled in.
  /// \tparam G any OccupancyGrid with this channel's geometry
  /// \throws InvalidArgument if the grid's geometry differs, or as the insertion throws (then the
  ///         grid and the channel are unchanged). The channel's count grids are unbounded sparse
  ///         grids under the same insertion budget (InsertOptions::max_grid_bytes); a scan into a
  ///         bounded grid (not budgeted) whose rays the count grids' budget refuses throws
  ///         InvalidArgument after the grid was updated, with the channel unchanged.
  template <OccupancyGrid G>
  InsertStats insert_beams(ScanInserter& inserter, G& grid, std::span<const Beam> beams,
                           std::vector<BeamClass>* classes = nullptr) {
    check_geometry(grid.geometry());
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
  template <OccupancyGrid G, PointLike O, PointRange R>
  InsertStats insert_point_cloud(ScanInserter& inserter, G& grid, const O& origin, const R& points,
                                 std::vector<BeamClass>* classes = nullptr) {
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
    const std::vector<Beam> beams = depth_frame_beams(frame);
    const InsertOptions o = inserter.options().for_frame(frame.max_range);
    o.validate();
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
  /// The explained state of voxel \p k.
  ExplainedState state(const Key& k) const noexcept { return options_.model.state(evidence(k)); }
  /// True if \p k is explained free (the only space a safe planner may drive through).
  bool explained_free(const Key& k) const noexcept { return state(k) == ExplainedState::Free; }
  /// True if \p k is a supported surface for the crossing test (see the file comment).
  bool supported_surface(const Key& k) const noexcept { return supported(count(trusted_, k)); }

  /// The key box of the trusted beams' walks (it holds every voxel with trusted evidence, and may
  /// exceed them by the one voxel of a cut beam's end), or nothing before the first trusted beam:
  /// the observed extent that planners and viewers of an unbounded map should use, which suspect
  /// and no-return evidence never grows.
  const std::optional<KeyBox>& trusted_extent() const noexcept { return trusted_extent_; }

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
  /// Bytes held: the three count grids and the inserter's scratch (ScanInserter::scratch_bytes()).
  std::size_t memory_bytes() const noexcept {
    return trusted_.memory_bytes() + suspect_.memory_bytes() + no_return_.memory_bytes() + inserter_.scratch_bytes();
  }
  /// Forgets all evidence (and frees the inserter's scratch).
  void clear() {
    trusted_.clear();
    suspect_.clear();
    no_return_.clear();
    inserter_.release_scratch();
    surface_blocks_.clear();
    trusted_extent_.reset();
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
  /// steps, so most reads skip the hash lookup).
  struct CellReader {
    using Blocks = detail::SparseBlocks<HitMissCount::Cell>;
    const Blocks& cells;
    std::uint64_t id = ~std::uint64_t{0};
    const Blocks::Block* block = nullptr;

    HitMissCount::Cell operator()(const Key& k) noexcept {
      if (!in_key_range(k)) return {};
      const std::uint64_t b = detail::block_id_of(k);
      if (b != id) {
        id = b;
        block = cells.find_block(b);
      }
      return block ? (*block)[Blocks::cell_index(k)] : HitMissCount::Cell{};
    }
  };

  /// The crossing and mid-air tests of a returned, prepared beam.
  BeamClass classify_returned(const Beam& beam, const detail::PreparedRay& p) const noexcept {
    CellReader read{trusted_.storage()};
    const Point3 d = beam.end - beam.origin;
    const double len = d.norm();
    const Point3 u = d / len;
    const double tol = options_.crossing_tolerance;
    const double half = 0.5 * geometry_.resolution();
    // Crossing: a supported voxel whose centre projects more than tol before the end. Supported
    // voxels lie in blocks that hold a trusted hit (surface_blocks_): the walk steps block by
    // block and walks voxels only inside those.
    const double limit = len - tol - half;
    const auto crosses = [&](const Key& k) {
      return (geometry_.center(k) - beam.origin).dot(u) < limit && supported(read(k));
    };
    bool crossing = false;
    if (limit > 0.0 && surface_blocks_.size() > 0) {
      const Point3 b0 = p.v0 / 8.0, b1 = p.v1 / 8.0;
      detail::SegmentDda blocks(b0, b1, block_of(p.k0), block_of(p.k1));
      for (;;) {
        if (surface_blocks_.contains(blocks.key) && walk_block(p, blocks.key, crosses)) {
          crossing = true;
          break;
        }
        if (blocks.remaining == 0) break;
        blocks.advance();
      }
    }
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

  GridGeometry geometry_;
  ExplainOptions options_;
  ScanInserter inserter_;
  CountGrid trusted_, suspect_, no_return_;
  KeySet surface_blocks_;  ///< blocks (block_of()) that hold a trusted hit: every supported voxel lies in one
  std::optional<KeyBox> trusted_extent_;
};

}  // namespace intervox
