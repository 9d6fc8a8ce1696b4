#pragma once
/// \file
/// Surfaces that lie, found and named: the region analysis of explained free space (docs/concepts.md,
/// "Explained free space").
///
/// find_lying_surfaces() groups the voxels that only lying beams made free
/// (ExplainedSpace::free_only_by_lying_beams()) into 26-connected regions and, for each region
/// of at least `min_region_voxels`, looks at the suspect beams of the channel's ledger that enter
/// it (the first region voxel on a beam's walk is where it enters; beams through a mirror the
/// channel knows count too, so that a known mirror is found again, and grows, as its phantoms
/// come from new places: ExplainedSpace::add_mirror() merges a mirror in a known one's plane):
///
///  - **mirror hypothesis**: a mirror's phantom return lies where the real surface it lit lies,
///    reflected about the mirror's plane. For every candidate plane (normals every
///    `normal_step_deg` in the horizontal, i.e. vertical planes, and tilted up and down by
///    multiples of `tilt_step_deg` up to `max_tilt_deg`; offsets every half voxel) each returned
///    suspect beam that crosses the plane more than the channel's crossing_tolerance before its
///    end, at least 2 x crossing_tolerance from its origin (a plane through the sensor folds the
///    room onto itself) and no later than one voxel after it enters the region (the lying space
///    begins behind a mirror) has its end reflected about the plane; it *votes* for the plane if
///    the reflected end moved at least 2 x crossing_tolerance and lands on a supported surface
///    voxel (ExplainedSpace::supported_surface()) that faces the plane (the least-squares plane
///    of the supported voxels within one voxel has its normal within 70 degrees of the plane's:
///    a floor, or any surface the reflection slides along, is found by every vertical plane and
///    tells nothing), the reflected path from the mirror point to it runs through space the map
///    explains (no supported voxel up to crossing_tolerance before it, at least half its voxels
///    crossed by trusted beams), and behind the plane the beam ran mostly through space the map
///    does not explain as free (at most 3 in 4 of those voxels explained free: else the plane
///    folds real space onto real space, as the bisector of a box's corner folds its two faces).
///    The plane with the most votes is the region's mirror if it has at least `min_mirror_votes`
///    votes, they are at least `min_mirror_share` of the searched beams that cross it, and (the
///    opacity test, off by default) the plane is opaque where they cross it: of the ledger's
///    returned beams of any class that cross the plane in the voxel-sized cells of the voting
///    crossings (more than crossing_tolerance before their end), reflected about it, those whose
///    end lands in space trusted beams crossed and never hit are at most `max_inconsistent_share`
///    (1 by default: no test; 0.2 measured) of those that land there or on a supported voxel
///    (LyingSurface::consistent_ends, inconsistent_ends, counted either way). A real mirror's beams
///    are all phantoms, which reflect onto real surfaces; a plane through open space that folds
///    a few surfaces onto each other (a desk leg's faces, two closets' corners) gathers the votes
///    too, but most beams through it end on real surfaces beyond it, and their ends, reflected,
///    land in free space;
///  - **opening hypothesis** (a doorway or a window through which the ends are real space),
///    tried when no mirror is found: at least `min_opening_beams` returned suspect beams enter the region
///    and at least `opening_share` of them end on a supported surface (real space that trusted
///    beams saw too);
///  - **black surface**: more suspect beams without a return than returned ones enter the region
///    (space carved only by beams that came back with nothing);
///  - **unresolved** otherwise.
///
/// Each region is reported (LyingSurface) with its kind, a plane patch, its key box and its
/// evidence counts. A mirror's patch is the plane found, spanned by the crossing points of the
/// region's returned suspect beams that vote for it (all of them, not only those searched), and
/// grown over the plane, one voxel-sized cell at a time (8-connected, within `grow_reach`), over
/// the cells where the ledger's returned beams of any class (a phantom that crossed only unseen
/// space is trusted) reflect onto supported voxels (at least 3, at least one of them facing the
/// plane: a floor alone would let the patch run on beside the mirror) and at most one in 10 into
/// space trusted beams crossed and never hit. Any other kind's patch is the least-squares plane
/// of the points where the region's suspect beams enter it, spanned by those points.
/// resolve_mirrors() tells the channel of the mirrors found
/// (ExplainedSpace::add_mirror()): their beams become suspect and their surface explained
/// occupied. Openings and black surfaces are reported, not acted on: an opening's beams keep
/// their classes until revision, which trusts them once the surfaces they end on are seen
/// directly (a returned beam that ends on a supported surface is no crossing;
/// tests/analysis/planted_doorway_test.cpp).
///
/// Only the ledger's scans are looked at (ExplainOptions::ledger_bytes; a channel without a
/// ledger, or a loaded one, finds regions but no beams, so every region is unresolved). The
/// known hard case: two mirror-symmetric rooms joined by a doorway look like a mirror in the
/// doorway (docs/concepts.md measures it).
///
/// Cost: one walk per suspect beam of the ledger, and per region O(normals x searched beams x
/// offsets along a beam) lookups (about 180 x 2,000 x 150 at 5 cm with the defaults), spread over
/// `threads` (the same result for any count).
///
/// Thread safety: reads the channel only; it must not be written meanwhile.

#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/parallel.hpp>
#include <intervox/core/plane_fit.hpp>
#include <intervox/core/plane_patch.hpp>
#include <intervox/core/point.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/explain/explained_space.hpp>
#include <intervox/raycast/traversal.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numbers>
#include <optional>
#include <span>
#include <string_view>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

namespace intervox {

/// What a lying region is (see the file comment).
enum class LyingKind : std::uint8_t {
  Mirror = 0,      ///< its suspect returns are real surfaces reflected about a plane
  Opening = 1,     ///< its suspect returns end on surfaces the map supports: real space seen through an opening
  Black = 2,       ///< carved mostly by suspect beams without a return
  Unresolved = 3,  ///< none of these
};

/// Name of a lying kind ("mirror", "opening", "black", "unresolved").
constexpr std::string_view to_string(LyingKind k) noexcept {
  switch (k) {
    case LyingKind::Mirror:
      return "mirror";
    case LyingKind::Opening:
      return "opening";
    case LyingKind::Black:
      return "black";
    case LyingKind::Unresolved:
      return "unresolved";
  }
  return "?";
}

/// The thresholds of find_lying_surfaces() (see the file comment).
struct LyingSurfaceParams {
  /// Voxels a region needs to be analysed, >= 1 (smaller ones are not reported).
  std::size_t min_region_voxels = 27;
  /// Votes the best plane needs to be a mirror, >= 1.
  std::size_t min_mirror_votes = 60;
  /// ... and its share of the searched beams that cross it, in [0, 1].
  double min_mirror_share = 0.2;
  /// Degrees between two candidate normals in the horizontal, in (0, 90].
  double normal_step_deg = 1.0;
  /// Degrees the candidate normals are tilted up and down at most (0: vertical planes only), in
  /// [0, 90], in steps of tilt_step_deg (in (0, 90]).
  double max_tilt_deg = 0.0;
  double tilt_step_deg = 5.0;
  /// Returned suspect beams a region's plane search looks at at most, >= 1 (more are thinned
  /// evenly, in the ledger's order).
  std::size_t max_search_beams = 2000;
  /// Returned suspect beams a region needs for the opening test, >= 1, and the share of them that
  /// must end on a supported surface, in [0, 1].
  std::size_t min_opening_beams = 20;
  double opening_share = 0.5;
  /// m: how far beyond the voting crossings a mirror's patch may grow over the plane (see the file
  /// comment; 0: not at all), >= 0.
  double grow_reach = 2.0;
  /// The opacity test, off by default (1): the share, in [0, 1], of the ledger's returned beams
  /// crossing the plane where its votes cross it that may reflect into space trusted beams crossed
  /// and never hit; more, and the plane is no mirror (see the file comment). 0.2 was measured
  /// (docs/concepts.md, "Surfaces that lie, found and named"): it removes most planes through open
  /// space, and also the helpful planes beside a closet whose every face is a mirror.
  double max_inconsistent_share = 1.0;
  /// Threads of the plane search (0: all hardware threads); the result is the same for any count.
  unsigned threads = 1;

  /// \throws InvalidArgument naming the first invalid parameter.
  void validate() const {
    const ParamCheck check("intervox::LyingSurfaceParams");
    check.at_least("min_region_voxels", min_region_voxels, std::size_t{1});
    check.at_least("min_mirror_votes", min_mirror_votes, std::size_t{1});
    check.in_range("min_mirror_share", min_mirror_share, 0.0, 1.0);
    check.in_range("normal_step_deg", normal_step_deg, 0.0, 90.0, RangeEnds::OpenClosed);
    check.in_range("max_tilt_deg", max_tilt_deg, 0.0, 90.0);
    check.in_range("tilt_step_deg", tilt_step_deg, 0.0, 90.0, RangeEnds::OpenClosed);
    check.at_least("max_search_beams", max_search_beams, std::size_t{1});
    check.at_least("min_opening_beams", min_opening_beams, std::size_t{1});
    check.in_range("opening_share", opening_share, 0.0, 1.0);
    check.nonnegative("grow_reach", grow_reach);
    check.in_range("max_inconsistent_share", max_inconsistent_share, 0.0, 1.0);
  }
};

/// One lying region, named (see the file comment).
struct LyingSurface {
  LyingKind kind = LyingKind::Unresolved;
  /// The plane patch (mirror: the plane found; else the plane of the entry points), its normal
  /// turned towards the mean origin of the region's beams. Meaningless when has_plane is false.
  PlanePatch surface;
  /// False if the region's beams gave no plane (fewer than 3 entry points, or collinear ones).
  bool has_plane = false;
  std::size_t voxels = 0;              ///< the region's voxels (free only by lying beams)
  KeyBox extent;                       ///< their key box
  std::uint64_t suspect_misses = 0;    ///< suspect misses summed over the region's voxels
  std::uint64_t no_return_misses = 0;  ///< misses of beams without a return, summed likewise
  std::size_t returned_beams = 0;      ///< returned suspect beams of the ledger that enter the region
  std::size_t silent_beams = 0;        ///< suspect beams without a return that enter it
  std::size_t searched_beams = 0;      ///< returned ones the plane search looked at
  std::size_t mirror_votes = 0;        ///< of those, the votes for the best plane
  std::size_t mirror_crossing = 0;     ///< of those, the ones that cross the best plane
  std::size_t real_ends = 0;           ///< returned suspect beams that end on a supported surface
  /// The ledger's returned beams (any class) that cross the best plane in the cells of its voting
  /// crossings, reflected about it: onto a supported voxel (consistent with a mirror) or into space
  /// trusted beams crossed and never hit (inconsistent). Zero unless the plane had the votes.
  std::size_t consistent_ends = 0;
  std::size_t inconsistent_ends = 0;
  /// The plane search's best plane whatever the verdict: points p with best_normal . p = best_offset
  /// (a zero normal when nothing was searched).
  Point3 best_normal = Point3::Zero();
  double best_offset = 0.0;
};

namespace detail {

/// The candidate normals of the plane search, in a fixed order.
inline std::vector<Point3> lying_normals(const LyingSurfaceParams& p) {
  std::vector<double> tilts{0.0};
  for (double t = p.tilt_step_deg; t <= p.max_tilt_deg + 1e-9; t += p.tilt_step_deg) {
    tilts.push_back(t);
    tilts.push_back(-t);
  }
  std::vector<Point3> out;
  const double deg = std::numbers::pi / 180.0;
  for (const double tilt : tilts)
    for (double a = 0.0; a < 180.0 - 1e-9; a += p.normal_step_deg) {
      if (std::abs(tilt) >= 90.0 - 1e-9 && a > 0.0) break;  // one horizontal plane
      out.emplace_back(std::cos(tilt * deg) * std::cos(a * deg), std::cos(tilt * deg) * std::sin(a * deg),
                       std::sin(tilt * deg));
    }
  return out;
}

/// What the plane search asks of the trusted counts millions of times, one bit per voxel in 8^3
/// blocks: is the voxel a supported surface (ExplainedSpace::supported_surface()), did a trusted
/// beam cross it (a miss). Built once per find_lying_surfaces() call; read through a Reader,
/// which keeps the last block it looked at (one per thread: the walks stay in a block for a while).
class TrustedBits {
  struct Block {
    std::array<std::uint64_t, 8> supported{}, crossed{};
  };

 public:
  explicit TrustedBits(const ExplainedSpace& space) {
    std::optional<KeyBox> supported_box;
    space.counts(BeamClass::Trusted).for_each_observed([&](const Key& k, const HitMissCount::Cell& c) {
      const std::size_t i = cell_index_of(k);
      Block& b = blocks_[block_id_of(k)];
      const std::uint64_t bit = std::uint64_t{1} << (i & 63);
      if (space.supported_counts(c)) {
        b.supported[i >> 6] |= bit;
        if (!supported_box) supported_box = KeyBox{k, k};
        for (int a = 0; a < 3; ++a) {
          supported_box->min[a] = std::min(supported_box->min[a], k[a]);
          supported_box->max[a] = std::max(supported_box->max[a], k[a]);
        }
      }
      if (c.misses > 0) b.crossed[i >> 6] |= bit;
    });
    if (supported_box) {  // the box of the supported voxels' cubes, half a voxel wider on every side
      const GridGeometry& g = space.geometry();
      lo_ = g.center(supported_box->min) - Point3::Constant(g.resolution());
      hi_ = g.center(supported_box->max) + Point3::Constant(g.resolution());
    }
  }

  /// False if no supported voxel can hold \p p (it lies outside their box): a test before the key.
  bool near_support(const Point3& p) const noexcept {
    return (p.array() >= lo_.array()).all() && (p.array() <= hi_.array()).all();
  }

  /// Reads the bits; not thread-safe (its cache), so one per thread.
  class Reader {
   public:
    explicit Reader(const TrustedBits& bits) : bits_(&bits) {}
    bool supported(const Key& k) { return test(k, &Block::supported); }
    bool crossed(const Key& k) { return test(k, &Block::crossed); }

   private:
    bool test(const Key& k, std::array<std::uint64_t, 8> Block::*which) {
      const std::uint64_t id = block_id_of(k);
      if (id != id_) {
        id_ = id;
        const auto it = bits_->blocks_.find(id);
        block_ = it == bits_->blocks_.end() ? nullptr : &it->second;
      }
      if (!block_) return false;
      const std::size_t i = cell_index_of(k);
      return ((block_->*which)[i >> 6] >> (i & 63)) & 1u;
    }
    const TrustedBits* bits_;
    std::uint64_t id_ = ~std::uint64_t{0};
    const Block* block_ = nullptr;
  };

 private:
  std::unordered_map<std::uint64_t, Block> blocks_;
  // Empty (lo > hi) while no voxel is supported.
  Point3 lo_ = Point3::Constant(std::numeric_limits<double>::infinity()), hi_ = -lo_;
};

/// Whether voxels are explained free (ExplainedSpace::state()), remembered in a direct-mapped
/// table of 2^13 entries (a voxel asked again is answered from it unless another took its slot).
/// One per thread.
class FreeCache {
 public:
  bool operator()(const ExplainedSpace& space, const Key& k) {
    if (slots_.empty()) slots_.assign(kSize, Slot{});
    Slot& s = slots_[KeyHash{}(k) & (kSize - 1)];
    if (!(s.key == k)) s = Slot{k, space.state(k) == ExplainedState::Free};
    return s.free;
  }

 private:
  static constexpr std::size_t kSize = std::size_t{1} << 13;
  struct Slot {
    // No voxel has this key (keys lie within +-2^23).
    Key key{std::numeric_limits<std::int32_t>::min(), 0, 0};
    bool free = false;
  };
  std::vector<Slot> slots_;
};

/// The plane search's verdict for one normal: its best offset bin, votes and crossing beams.
struct LyingPlaneScore {
  std::int64_t bin = 0;
  std::size_t votes = 0, crossing = 0;
};

/// What the votes ask per thread: a reader of the trusted bits, with the local surface normals
/// asked so far (the same voxels come back for every candidate normal) and a cache of the
/// explained-free test.
struct LyingLookup {
  TrustedBits::Reader read;
  std::unordered_map<Key, std::optional<Point3>, KeyHash> normals{};
  FreeCache free{};
};

/// What every phase of find_lying_surfaces() reads: the channel, the thresholds, the quantities
/// derived from them once, the trusted bits and the candidate normals of the plane search.
struct LyingSurfaceContext {
  const ExplainedSpace& space;
  const LyingSurfaceParams& params;
  const GridGeometry& g;
  double res = 0.0;
  double tol = 0.0;         ///< the channel's crossing_tolerance
  double h = 0.0;           ///< offset bins: the reflected end moves one voxel per bin
  double min_facing = 0.0;  ///< sin 20 degrees: a surface within 70 degrees of a plane faces it
  const TrustedBits& bits;
  const std::vector<Point3>& normals;
};

/// The voxels only lying beams made free, their 26-connected regions in the order of their
/// smallest key (each voxel mapped to its region), and each region's index among those reported
/// (-1: too small).
struct LyingVoxelRegions {
  std::unordered_map<Key, int, KeyHash> region_of;
  std::vector<std::vector<Key>> regions;
  std::vector<int> kept_index;
};

/// Regions: the voxels only lying beams made free, grouped 26-connected.
inline LyingVoxelRegions lying_regions(const ExplainedSpace& space) {
  LyingVoxelRegions lr;
  std::vector<Key> lying;
  space.counts(BeamClass::Suspect).for_each_observed([&](const Key& k, const HitMissCount::Cell&) {
    if (space.free_only_by_lying_beams(k)) lying.push_back(k);
  });
  std::sort(lying.begin(), lying.end());
  lr.region_of.reserve(lying.size());
  for (const Key& k : lying) lr.region_of.emplace(k, -1);
  for (const Key& seed : lying) {
    if (lr.region_of[seed] >= 0) continue;
    const int id = static_cast<int>(lr.regions.size());
    std::vector<Key> members{seed};
    lr.region_of[seed] = id;
    for (std::size_t i = 0; i < members.size(); ++i) {
      const Key c = members[i];
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const auto it = lr.region_of.find(Key{c.x + dx, c.y + dy, c.z + dz});
            if (it == lr.region_of.end() || it->second >= 0) continue;
            it->second = id;
            members.push_back(it->first);
          }
    }
    lr.regions.push_back(std::move(members));
  }
  return lr;
}

/// Regions, reported: one LyingSurface (voxels, key box, evidence) per region of at least
/// min_region_voxels; smaller ones are dropped (their voxels count as none).
inline std::vector<LyingSurface> report_regions(const ExplainedSpace& space, const LyingSurfaceParams& params,
                                                LyingVoxelRegions& lr) {
  lr.kept_index.assign(lr.regions.size(), -1);
  std::vector<LyingSurface> out;
  for (std::size_t r = 0; r < lr.regions.size(); ++r) {
    const std::vector<Key>& region = lr.regions[r];
    if (region.size() < params.min_region_voxels) continue;
    lr.kept_index[r] = static_cast<int>(out.size());
    LyingSurface s;
    s.voxels = region.size();
    s.extent = KeyBox{region.front(), region.front()};
    for (const Key& k : region) {
      for (int a = 0; a < 3; ++a) {
        s.extent.min[a] = std::min(s.extent.min[a], k[a]);
        s.extent.max[a] = std::max(s.extent.max[a], k[a]);
      }
      const EvidenceCell e = space.evidence(k);
      s.suspect_misses += e.suspect_misses;
      s.no_return_misses += e.no_return_misses;
    }
    out.push_back(s);
  }
  return out;
}

/// A suspect beam of the ledger and where it enters its region.
struct LyingEntry {
  Beam beam;
  Point3 at;
};

/// The ledger's suspect beams of each reported region (the first it enters), returned and silent.
struct RegionBeams {
  std::vector<std::vector<LyingEntry>> returned, silent;
};

/// Regions, their beams: the ledger's suspect beams, each to the reported region it enters first.
inline RegionBeams region_beams(const ExplainedSpace& space, const LyingVoxelRegions& lr, std::size_t reported) {
  const GridGeometry& g = space.geometry();
  RegionBeams rb{std::vector<std::vector<LyingEntry>>(reported), std::vector<std::vector<LyingEntry>>(reported)};
  for (const LedgerScan& scan : space.ledger().scans())
    scan.for_each([&](std::size_t, const Beam& b, BeamClass c) {
      if (c != BeamClass::Suspect) return;
      int hit_region = -1;
      Key at{};
      traverse(g, b.origin, b.end, [&](const Key& k) {
        const auto it = lr.region_of.find(k);
        if (it != lr.region_of.end() && lr.kept_index[static_cast<std::size_t>(it->second)] >= 0) {
          hit_region = lr.kept_index[static_cast<std::size_t>(it->second)];
          at = k;
          return false;
        }
        return true;
      });
      if (hit_region < 0) return;
      const Point3 u = (b.end - b.origin).normalized();
      const Point3 entry = b.origin + u * (g.center(at) - b.origin).dot(u);
      (b.hit ? rb.returned : rb.silent)[static_cast<std::size_t>(hit_region)].push_back(LyingEntry{b, entry});
    });
  return rb;
}

/// The surface at supported voxel k faces normal n: the least-squares plane of the supported
/// voxels within one voxel of it (ExplainedSpace::surface_normal()) has a normal within 70
/// degrees of n (a floor, or any surface a reflection slides along, is found by every vertical
/// plane and tells nothing).
inline bool lying_faces(const LyingSurfaceContext& ctx, LyingLookup& at, const Key& k, const Point3& n) {
  auto it = at.normals.find(k);
  if (it == at.normals.end())
    it = at.normals.emplace(k, local_surface(k, [&](const Key& q) { return at.read.supported(q); }).normal).first;
  const std::optional<Point3>& nu = it->second;
  return nu && std::abs(nu->dot(n)) >= ctx.min_facing;
}

/// The plane vote, the one test of every plane the analysis weighs (the plane search and the
/// patch's crossings): a vote for the plane at offset d along n from beam b (se = n . end) that
/// enters its region at the fraction \p entry of its length (negative: not asked): it crosses the
/// plane no later than one voxel after it enters the region (the lying space begins behind a
/// mirror) and at least 2 tol from its origin, its end reflected about the plane lands on a
/// supported voxel that faces the plane, the reflected path from the mirror point to it runs
/// through space the map explains (up to tol before it: no supported voxel, and at least half its
/// voxels crossed by trusted beams), and behind the plane it ran mostly through space not
/// explained free.
inline bool lying_votes_for(const LyingSurfaceContext& ctx, LyingLookup& lk, const Beam& b, const Point3& n, double d,
                            double se, double entry) {
  const double res = ctx.res, tol = ctx.tol;
  if (std::abs(se - d) < tol) return false;  // the end moves at least 2 tol: not onto its own surface
  const double so = n.dot(b.origin);
  const double at = (d - so) / (se - so);
  const double length = (b.end - b.origin).norm();
  if (entry >= 0.0 && at > entry + res / length) return false;
  if (at * length < 2.0 * tol) return false;  // a mirror within 2 tol of the sensor: none
  const Point3 reflected = b.end - 2.0 * (se - d) * n;
  if (!ctx.bits.near_support(reflected)) return false;
  const std::optional<Key> rk = ctx.g.try_key(reflected);
  if (!rk || !lk.read.supported(*rk) || !lying_faces(ctx, lk, *rk, n)) return false;
  const Point3 m = b.origin + (b.end - b.origin) * at;
  const Point3 dir = reflected - m;
  const double len = dir.norm();
  if (len <= tol + res) return true;
  std::size_t seen = 0, known = 0;
  bool blocked = false;
  const Point3 stop = m + dir * ((len - tol) / len);
  traverse(ctx.g, m, stop, [&](const Key& k) {
    ++seen;
    known += lk.read.crossed(k);
    blocked = lk.read.supported(k);
    return !blocked;
  });
  if (blocked || 2 * known < seen) return false;
  // Behind the plane the beam ran mostly through space the map does not explain as free (a
  // phantom's path): at most 3 in 4 of the voxels from the mirror point to tol before the end
  // explained free. Else the plane folds real space onto real space: one through the sensor
  // folds the room onto itself, the bisector of a box's corner folds its two faces.
  const Point3 behind = b.end - m;
  const double blen = behind.norm();
  if (blen <= tol + res) return true;
  std::size_t walked = 0, free = 0;
  traverse(ctx.g, m, Point3(m + behind * ((blen - tol) / blen)), [&](const Key& k) {
    ++walked;
    free += lk.free(ctx.space, k);
    return true;
  });
  return 4 * free <= 3 * walked;
}

/// The range of offsets beam b can cross a plane of normal n at, more than tol before its end:
/// (lo, hi) in metres along n, and se = n . end; false if empty.
inline bool lying_window(const LyingSurfaceContext& ctx, const Beam& b, const Point3& n, double& lo, double& hi,
                         double& se) {
  const double so = n.dot(b.origin);
  se = n.dot(b.end);
  const double len = (b.end - b.origin).norm();
  if (std::abs(se - so) < ctx.res || len <= ctx.tol) return false;
  const double last = se - (se - so) * ctx.tol / len;  // the offset tol before the end
  lo = std::min(so, last);
  hi = std::max(so, last);
  return true;
}

/// The middle of offset bin \p bin, in metres along the normal.
inline double lying_bin_mid(const LyingSurfaceContext& ctx, std::int64_t bin) {
  return (static_cast<double>(bin) + 0.5) * ctx.h;
}

/// A searched beam: the beam and the fraction of its length where it enters the region.
using SearchBeam = std::pair<Beam, double>;

/// Plane search, its beams: the region's returned suspect beams, thinned evenly to at most
/// max_search_beams.
inline std::vector<SearchBeam> search_beams(const LyingSurfaceContext& ctx, const std::vector<LyingEntry>& returned) {
  std::vector<SearchBeam> search;
  const std::size_t stride = (returned.size() + ctx.params.max_search_beams - 1) / ctx.params.max_search_beams;
  for (std::size_t i = 0; i < returned.size(); i += std::max<std::size_t>(stride, 1)) {
    const LyingEntry& e = returned[i];
    search.emplace_back(e.beam, (e.at - e.beam.origin).norm() / (e.beam.end - e.beam.origin).norm());
  }
  return search;
}

/// Plane search, one beam for normal n: counts it in the crossings of the offset bins it crosses
/// (as a range: +1 at its first bin, -1 after its last) and adds its votes (bins counted from
/// \p first).
inline void vote_beam(const LyingSurfaceContext& ctx, LyingLookup& lk, const SearchBeam& sb, const Point3& n,
                      std::int64_t first, std::vector<std::uint32_t>& votes, std::vector<std::int64_t>& crossing) {
  const auto& [b, entry] = sb;
  const double h = ctx.h, res = ctx.res, tol = ctx.tol;
  double lo = 0, hi = 0, se = 0;
  if (!lying_window(ctx, b, n, lo, hi, se)) return;
  // The bins with lo < d < hi: [a, e).
  const std::int64_t start = static_cast<std::int64_t>(std::ceil(lo / h - 0.5));
  std::int64_t a = start;
  while (lying_bin_mid(ctx, a) <= lo && lying_bin_mid(ctx, a) < hi) ++a;
  std::int64_t e = std::max(start, static_cast<std::int64_t>(std::ceil(hi / h - 0.5)));
  while (e > start && lying_bin_mid(ctx, e - 1) >= hi) --e;
  while (lying_bin_mid(ctx, e) < hi) ++e;
  if (a >= e) return;
  ++crossing[static_cast<std::size_t>(a - first)];
  --crossing[static_cast<std::size_t>(e - first)];
  // Votes only where the beam can vote: it crosses the plane at a fraction of its length in
  // [2 tol / length, entry + res / length] (entry >= 0 here; lying_votes_for() tests it again,
  // exactly; two bins of margin on either side).
  const double so = n.dot(b.origin), length = (b.end - b.origin).norm();
  const double d0 = so + (2.0 * tol / length) * (se - so), d1 = so + (entry + res / length) * (se - so);
  const std::int64_t v0 = std::max(a, static_cast<std::int64_t>(std::floor(std::min(d0, d1) / h - 0.5)) - 2);
  const std::int64_t v1 = std::min(e, static_cast<std::int64_t>(std::ceil(std::max(d0, d1) / h - 0.5)) + 3);
  for (std::int64_t bin = v0; bin < v1; ++bin)
    if (lying_votes_for(ctx, lk, b, n, lying_bin_mid(ctx, bin), se, entry))
      ++votes[static_cast<std::size_t>(bin - first)];
}

/// Plane search, one normal: the votes of the searched beams over the offset bins every beam's
/// ends span; its best bin (the first with the most votes) with the beams that cross it.
inline LyingPlaneScore score_normal(const LyingSurfaceContext& ctx, LyingLookup& lk,
                                    const std::vector<SearchBeam>& search, const Point3& n,
                                    std::vector<std::uint32_t>& votes, std::vector<std::int64_t>& crossing) {
  const double h = ctx.h;
  double lo_all = std::numeric_limits<double>::infinity(), hi_all = -lo_all;
  for (const auto& [b, entry] : search)
    for (const Point3* p : {&b.origin, &b.end}) {
      lo_all = std::min(lo_all, n.dot(*p));
      hi_all = std::max(hi_all, n.dot(*p));
    }
  const std::int64_t first = static_cast<std::int64_t>(std::floor(lo_all / h)) - 1;
  const std::size_t bins = static_cast<std::size_t>(std::ceil(hi_all / h) - std::floor(lo_all / h)) + 3;
  votes.assign(bins, 0);
  crossing.assign(bins + 1, 0);
  for (const SearchBeam& sb : search) vote_beam(ctx, lk, sb, n, first, votes, crossing);
  LyingPlaneScore best;
  std::int64_t crossing_here = 0;
  for (std::size_t at = 0; at < bins; ++at) {
    crossing_here += crossing[at];
    if (votes[at] > best.votes)
      best = {first + static_cast<std::int64_t>(at), votes[at], static_cast<std::size_t>(crossing_here)};
  }
  return best;
}

/// Plane search: every candidate normal scored over the searched beams, spread over the threads
/// in chunks of normals (the same scores for any count); all zero if no beam is searched.
inline std::vector<LyingPlaneScore> plane_search(const LyingSurfaceContext& ctx,
                                                 const std::vector<SearchBeam>& search) {
  std::vector<LyingPlaneScore> scores(ctx.normals.size());
  if (!search.empty())
    parallel_for_chunks(
        ctx.normals.size(), ctx.params.threads,
        [&](std::size_t from, std::size_t to) {
          LyingLookup lk{TrustedBits::Reader(ctx.bits)};
          std::vector<std::uint32_t> votes;
          std::vector<std::int64_t> crossing;
          for (std::size_t i = from; i < to; ++i)
            scores[i] = score_normal(ctx, lk, search, ctx.normals[i], votes, crossing);
        },
        1);
  return scores;
}

/// A plane patch in the plane n . p = offset spanning \p pts (half a voxel wider), its normal
/// turned towards \p mean_origin.
inline PlanePatch span_patch(const LyingSurfaceContext& ctx, const std::vector<Point3>& pts, const Point3& n,
                             double offset, const Point3& mean_origin) {
  PlanePatch p;
  p.normal = n.dot(mean_origin) - offset >= 0.0 ? n : Point3(-n);
  p.axis_u = PlanePatch::floor_axis(p.normal);
  const Point3 v = p.axis_v();
  double u0 = std::numeric_limits<double>::infinity(), u1 = -u0, v0 = u0, v1 = -u0;
  for (const Point3& q : pts) {
    u0 = std::min(u0, q.dot(p.axis_u));
    u1 = std::max(u1, q.dot(p.axis_u));
    v0 = std::min(v0, q.dot(v));
    v1 = std::max(v1, q.dot(v));
  }
  p.center = n * offset + p.axis_u * (0.5 * (u0 + u1)) + v * (0.5 * (v0 + v1));
  p.half_u = 0.5 * (u1 - u0) + 0.5 * ctx.res;
  p.half_v = 0.5 * (v1 - v0) + 0.5 * ctx.res;
  return p;
}

/// A voxel-sized cell of a mirror's plane, (u, v) along its in-plane axes.
using LyingCell = std::pair<std::int64_t, std::int64_t>;
inline std::int64_t lying_cell_id(const LyingCell& c) noexcept { return c.first * 4294967311LL + c.second; }

/// A cell's reflected ends: onto a supported voxel (consistent; facing: on a surface that faces
/// the plane) or into space trusted beams crossed and never hit (inconsistent).
struct LyingCellCount {
  std::uint32_t consistent = 0, inconsistent = 0, facing = 0;
};

/// The plane a mirror's patch grows over: n . p = offset, its in-plane axes (u along the floor).
struct MirrorPlane {
  Point3 n;
  double offset = 0.0;
  Point3 au, av;

  LyingCell cell_of(const Point3& q, double res) const {
    return LyingCell{static_cast<std::int64_t>(std::floor(q.dot(au) / res)),
                     static_cast<std::int64_t>(std::floor(q.dot(av) / res))};
  }
  /// Where beam b crosses the plane.
  Point3 crossing_of(const Beam& b) const {
    const double so = n.dot(b.origin), se = n.dot(b.end);
    return Point3(b.origin + (b.end - b.origin) * ((offset - so) / (se - so)));
  }
};

/// Patch growth, its seed: the crossings of the region's returned suspect beams that vote for the
/// plane (at its offset or the bins beside it).
inline std::vector<Point3> voting_crossings(const LyingSurfaceContext& ctx, LyingLookup& lk, const MirrorPlane& pl,
                                            const std::vector<LyingEntry>& returned) {
  const auto votes_near = [&](const Beam& b, double entry) {
    double lo = 0, hi = 0, se = 0;
    if (!lying_window(ctx, b, pl.n, lo, hi, se)) return false;
    for (const double d : {pl.offset, pl.offset - ctx.h, pl.offset + ctx.h})
      if (d > lo && d < hi && lying_votes_for(ctx, lk, b, pl.n, d, se, entry)) return true;
    return false;
  };
  std::vector<Point3> crossings;
  for (const LyingEntry& e : returned)
    if (votes_near(e.beam, (e.at - e.beam.origin).norm() / (e.beam.end - e.beam.origin).norm()))
      crossings.push_back(pl.crossing_of(e.beam));
  return crossings;
}

/// Opacity test and patch growth, their evidence: the ledger's returned beams (any class: a
/// phantom that crossed only unseen space is trusted) that cross the plane within grow_reach of
/// the \p seed patch, counted per cell they cross by where their ends land, reflected about it.
inline std::unordered_map<std::int64_t, LyingCellCount> plane_cells(const LyingSurfaceContext& ctx, LyingLookup& lk,
                                                                    const MirrorPlane& pl, const PlanePatch& seed) {
  const auto& trusted = ctx.space.counts(BeamClass::Trusted).storage();
  std::unordered_map<std::int64_t, LyingCellCount> cells;
  const Point3 sv = seed.axis_v();
  for (const LedgerScan& scan : ctx.space.ledger().scans())
    scan.for_each([&](std::size_t, const Beam& b, BeamClass c) {
      if (!b.hit || c == BeamClass::Skipped) return;
      double lo = 0, hi = 0, se = 0;
      if (!lying_window(ctx, b, pl.n, lo, hi, se) || pl.offset <= lo || pl.offset >= hi ||
          std::abs(se - pl.offset) < ctx.tol)
        return;
      const Point3 dq = pl.crossing_of(b) - seed.center;
      if (std::abs(dq.dot(seed.axis_u)) > seed.half_u + ctx.params.grow_reach ||
          std::abs(dq.dot(sv)) > seed.half_v + ctx.params.grow_reach)
        return;
      const std::optional<Key> rk = ctx.g.try_key(b.end - 2.0 * (se - pl.offset) * pl.n);
      if (!rk) return;
      LyingCellCount& cc = cells[lying_cell_id(pl.cell_of(pl.crossing_of(b), ctx.res))];
      if (lk.read.supported(*rk)) {
        ++cc.consistent;
        cc.facing += lying_faces(ctx, lk, *rk, pl.n) ? 1u : 0u;
      } else if (const HitMissCount::Cell* t = trusted.find(*rk); t && t->hits == 0 && t->misses > 0) {
        ++cc.inconsistent;
      }
    });
  return cells;
}

/// Patch growth: the cells 8-connected to \p grown (appended to it, breadth first) where the
/// ledger's beams are this plane's phantoms: at least 3 reflected ends consistent, at least one
/// on a surface that faces the plane, at most one in 10 inconsistent.
inline void grow_patch(const LyingSurfaceContext& ctx, std::vector<LyingCell>& grown,
                       std::unordered_set<std::int64_t>& in,
                       const std::unordered_map<std::int64_t, LyingCellCount>& cells) {
  for (std::size_t i = 0; i < grown.size() && ctx.params.grow_reach > 0.0; ++i)
    for (std::int64_t du = -1; du <= 1; ++du)
      for (std::int64_t dv = -1; dv <= 1; ++dv) {
        const LyingCell c{grown[i].first + du, grown[i].second + dv};
        const auto it = cells.find(lying_cell_id(c));
        if (it == cells.end() || in.count(lying_cell_id(c))) continue;
        const LyingCellCount& k = it->second;
        if (k.consistent < 3 || k.consistent < 9 * k.inconsistent || k.facing == 0) continue;
        in.insert(lying_cell_id(c));
        grown.push_back(c);
      }
}

/// Opacity test and patch growth for the plane n . p = offset that has a mirror's votes: the
/// patch seeded by the voting crossings, the opacity test over its cells (LyingSurface::
/// consistent_ends, inconsistent_ends), and if it holds, the patch grown and \p s named a mirror.
/// False if the plane is no mirror.
inline bool grow_mirror(const LyingSurfaceContext& ctx, LyingSurface& s, const std::vector<LyingEntry>& returned,
                        const Point3& n, double offset, const Point3& mean_origin) {
  // (its votes come from the region's beams, so the crossings are never empty)
  LyingLookup lk{TrustedBits::Reader(ctx.bits)};
  const Point3 au = PlanePatch::floor_axis(n);
  const MirrorPlane pl{n, offset, au, n.cross(au)};
  const std::vector<Point3> crossings = voting_crossings(ctx, lk, pl, returned);
  std::vector<LyingCell> grown;
  for (const Point3& q : crossings) grown.push_back(pl.cell_of(q, ctx.res));
  std::sort(grown.begin(), grown.end());
  grown.erase(std::unique(grown.begin(), grown.end()), grown.end());
  std::unordered_map<std::int64_t, LyingCellCount> cells;
  if (!crossings.empty()) cells = plane_cells(ctx, lk, pl, span_patch(ctx, crossings, n, offset, mean_origin));
  std::unordered_set<std::int64_t> in;
  for (const LyingCell& c : grown) in.insert(lying_cell_id(c));
  // A mirror is opaque and its phantoms land on real surfaces: where its votes cross the plane,
  // the beams that cross it there must reflect onto supported voxels, not into space the map
  // explains as free (a plane through open space that folds a few surfaces onto each other
  // passes the vote, while most beams through it end on real surfaces beyond).
  for (const LyingCell& c : grown)
    if (const auto it = cells.find(lying_cell_id(c)); it != cells.end()) {
      s.consistent_ends += it->second.consistent;
      s.inconsistent_ends += it->second.inconsistent;
    }
  if (static_cast<double>(s.inconsistent_ends) >
      ctx.params.max_inconsistent_share * static_cast<double>(s.consistent_ends + s.inconsistent_ends))
    return false;
  grow_patch(ctx, grown, in, cells);
  std::vector<Point3> corners;
  for (const auto& [cu, cv] : grown)
    for (const double fu : {0.0, 1.0})
      for (const double fv : {0.0, 1.0})
        corners.push_back(au * ((static_cast<double>(cu) + fu) * ctx.res) +
                          pl.av * ((static_cast<double>(cv) + fv) * ctx.res));
  s.kind = LyingKind::Mirror;
  s.surface = span_patch(ctx, corners, n, offset, mean_origin);
  s.has_plane = true;
  return true;
}

/// Naming, the other kinds: the patch is the plane of the points where the region's suspect
/// beams enter it; the region is an opening, a black surface or unresolved (see the file comment).
inline void name_by_entries(const LyingSurfaceContext& ctx, LyingSurface& s, const std::vector<LyingEntry>& returned,
                            const std::vector<LyingEntry>& silent, const Point3& mean_origin) {
  std::vector<Point3> entries;
  for (const auto* list : {&returned, &silent})
    for (const LyingEntry& e : *list) entries.push_back(e.at);
  if (entries.size() >= 3) {
    Point3 c = Point3::Zero();
    for (const Point3& p : entries) c += p;
    c /= static_cast<double>(entries.size());
    if (const std::optional<Point3> n = plane_normal(std::span<const Point3>(entries))) {
      s.surface = span_patch(ctx, entries, *n, n->dot(c), mean_origin);
      s.has_plane = true;
    }
  }
  if (s.returned_beams >= ctx.params.min_opening_beams &&
      static_cast<double>(s.real_ends) >= ctx.params.opening_share * static_cast<double>(s.returned_beams))
    s.kind = LyingKind::Opening;
  else if (s.silent_beams > s.returned_beams)
    s.kind = LyingKind::Black;
  else
    s.kind = LyingKind::Unresolved;
}

/// One region's beams counted into \p s (returned, silent, real ends); returns their mean origin.
inline Point3 count_region_beams(const LyingSurfaceContext& ctx, LyingSurface& s,
                                 const std::vector<LyingEntry>& returned, const std::vector<LyingEntry>& silent) {
  const auto supported_at = [&](const Point3& p) {
    const std::optional<Key> k = ctx.g.try_key(p);
    return k && ctx.space.supported_surface(*k);
  };
  s.returned_beams = returned.size();
  s.silent_beams = silent.size();
  for (const LyingEntry& e : returned) s.real_ends += supported_at(e.beam.end);
  Point3 mean_origin = Point3::Zero();
  for (const auto* list : {&returned, &silent})
    for (const LyingEntry& e : *list) mean_origin += e.beam.origin;
  if (s.returned_beams + s.silent_beams > 0) mean_origin /= static_cast<double>(s.returned_beams + s.silent_beams);
  return mean_origin;
}

/// One region named: the plane search over its (thinned) returned suspect beams (the mirror
/// hypothesis), the best plane's votes and, if they suffice, the opacity test and patch growth;
/// else the other kinds.
inline void name_region(const LyingSurfaceContext& ctx, LyingSurface& s, const std::vector<LyingEntry>& returned,
                        const std::vector<LyingEntry>& silent) {
  const Point3 mean_origin = count_region_beams(ctx, s, returned, silent);
  const std::vector<SearchBeam> search = search_beams(ctx, returned);
  s.searched_beams = search.size();
  const std::vector<LyingPlaneScore> scores = plane_search(ctx, search);
  std::size_t best = 0;
  for (std::size_t i = 1; i < scores.size(); ++i)
    if (scores[i].votes > scores[best].votes) best = i;
  if (!scores.empty() && scores[best].votes > 0) {
    s.mirror_votes = scores[best].votes;
    s.mirror_crossing = scores[best].crossing;
    s.best_normal = ctx.normals[best];
    s.best_offset = lying_bin_mid(ctx, scores[best].bin);
  }
  const bool votes = !scores.empty() && scores[best].votes >= ctx.params.min_mirror_votes &&
                     static_cast<double>(scores[best].votes) >=
                         ctx.params.min_mirror_share * static_cast<double>(scores[best].crossing);
  if (votes && grow_mirror(ctx, s, returned, ctx.normals[best], lying_bin_mid(ctx, scores[best].bin), mean_origin))
    return;
  name_by_entries(ctx, s, returned, silent, mean_origin);
}

}  // namespace detail

/// The lying regions of \p space, named (see the file comment), in the order of their smallest
/// voxel key.
/// \throws InvalidArgument for invalid parameters.
inline std::vector<LyingSurface> find_lying_surfaces(const ExplainedSpace& space,
                                                     const LyingSurfaceParams& params = {}) {
  params.validate();
  // The regions: the voxels only lying beams made free, 26-connected; those large enough reported.
  detail::LyingVoxelRegions regions = detail::lying_regions(space);
  std::vector<LyingSurface> out = detail::report_regions(space, params, regions);
  if (out.empty()) return out;
  // The ledger's suspect beams, each to the region it enters first.
  const detail::RegionBeams beams = detail::region_beams(space, regions, out.size());
  // Each region named: plane search, opacity test, patch growth, or the other kinds.
  const GridGeometry& g = space.geometry();
  const std::vector<Point3> normals = detail::lying_normals(params);
  const detail::TrustedBits bits(space);
  const detail::LyingSurfaceContext ctx{space,
                                        params,
                                        g,
                                        g.resolution(),
                                        space.options().crossing_tolerance,
                                        0.5 * g.resolution(),
                                        std::sin(20.0 * std::numbers::pi / 180.0),
                                        bits,
                                        normals};
  for (std::size_t r = 0; r < out.size(); ++r) detail::name_region(ctx, out[r], beams.returned[r], beams.silent[r]);
  return out;
}

/// Tells \p space of every mirror in \p surfaces (ExplainedSpace::add_mirror()); returns how many.
/// Thread safety: needs exclusive access to \p space.
inline std::size_t resolve_mirrors(ExplainedSpace& space, std::span<const LyingSurface> surfaces) {
  std::size_t n = 0;
  for (const LyingSurface& s : surfaces)
    if (s.kind == LyingKind::Mirror && s.has_plane) {
      space.add_mirror(s.surface);
      ++n;
    }
  return n;
}

}  // namespace intervox
