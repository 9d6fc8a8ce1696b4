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
    case LyingKind::Mirror: return "mirror";
    case LyingKind::Opening: return "opening";
    case LyingKind::Black: return "black";
    case LyingKind::Unresolved: return "unresolved";
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
      out.emplace_back(std::cos(tilt * deg) * std::cos(a * deg), std::cos(tilt * deg) * std::sin(a * deg), std::sin(tilt * deg));
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

}  // namespace detail

/// The lying regions of \p space, named (see the file comment), in the order of their smallest
/// voxel key.
/// \throws InvalidArgument for invalid parameters.
inline std::vector<LyingSurface> find_lying_surfaces(const ExplainedSpace& space, const LyingSurfaceParams& params = {}) {
  params.validate();
  const GridGeometry& g = space.geometry();
  const double res = g.resolution();
  const double tol = space.options().crossing_tolerance;

  // The voxels only lying beams made free, and their 26-connected regions.
  std::vector<Key> lying;
  space.counts(BeamClass::Suspect).for_each_observed([&](const Key& k, const HitMissCount::Cell&) {
    if (space.free_only_by_lying_beams(k)) lying.push_back(k);
  });
  std::sort(lying.begin(), lying.end());
  std::unordered_map<Key, int, KeyHash> region_of;
  region_of.reserve(lying.size());
  for (const Key& k : lying) region_of.emplace(k, -1);
  std::vector<std::vector<Key>> regions;
  for (const Key& seed : lying) {
    if (region_of[seed] >= 0) continue;
    const int id = static_cast<int>(regions.size());
    std::vector<Key> members{seed};
    region_of[seed] = id;
    for (std::size_t i = 0; i < members.size(); ++i) {
      const Key c = members[i];
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const auto it = region_of.find(Key{c.x + dx, c.y + dy, c.z + dz});
            if (it == region_of.end() || it->second >= 0) continue;
            it->second = id;
            members.push_back(it->first);
          }
    }
    regions.push_back(std::move(members));
  }
  // Regions too small are dropped (their voxels count as none).
  std::vector<int> kept_index(regions.size(), -1);
  std::vector<LyingSurface> out;
  for (std::size_t r = 0; r < regions.size(); ++r) {
    if (regions[r].size() < params.min_region_voxels) continue;
    kept_index[r] = static_cast<int>(out.size());
    LyingSurface s;
    s.voxels = regions[r].size();
    s.extent = KeyBox{regions[r].front(), regions[r].front()};
    for (const Key& k : regions[r]) {
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
  if (out.empty()) return out;

  // The ledger's suspect beams, each to the region it enters first.
  struct Entry {
    Beam beam;
    Point3 at;  // where it enters the region
  };
  std::vector<std::vector<Entry>> returned(out.size()), silent(out.size());
  for (const LedgerScan& scan : space.ledger().scans())
    scan.for_each([&](std::size_t, const Beam& b, BeamClass c) {
      if (c != BeamClass::Suspect) return;
      int hit_region = -1;
      Key at{};
      traverse(g, b.origin, b.end, [&](const Key& k) {
        const auto it = region_of.find(k);
        if (it != region_of.end() && kept_index[static_cast<std::size_t>(it->second)] >= 0) {
          hit_region = kept_index[static_cast<std::size_t>(it->second)];
          at = k;
          return false;
        }
        return true;
      });
      if (hit_region < 0) return;
      const Point3 u = (b.end - b.origin).normalized();
      const Point3 entry = b.origin + u * (g.center(at) - b.origin).dot(u);
      (b.hit ? returned : silent)[static_cast<std::size_t>(hit_region)].push_back(Entry{b, entry});
    });

  const std::vector<Point3> normals = detail::lying_normals(params);
  const auto supported_at = [&](const Point3& p) {
    const std::optional<Key> k = g.try_key(p);
    return k && space.supported_surface(*k);
  };
  const auto& trusted = space.counts(BeamClass::Trusted).storage();
  // What the votes ask of the trusted counts, and per thread a reader of it with the local
  // surface normals asked so far (the same voxels come back for every candidate normal).
  const detail::TrustedBits bits(space);
  struct Lookup {
    detail::TrustedBits::Reader read;
    std::unordered_map<Key, std::optional<Point3>, KeyHash> normals{};
    detail::FreeCache free{};
  };
  const double min_facing = std::sin(20.0 * std::numbers::pi / 180.0);
  // The surface at supported voxel k faces normal n: the least-squares plane of the supported
  // voxels within one voxel of it (ExplainedSpace::surface_normal()) has a normal within 70
  // degrees of n (a floor, or any surface a reflection slides along, is found by every vertical
  // plane and tells nothing).
  const auto faces = [&](Lookup& at, const Key& k, const Point3& n) {
    auto it = at.normals.find(k);
    if (it == at.normals.end())
      it = at.normals.emplace(k, detail::local_surface(k, [&](const Key& q) { return at.read.supported(q); }).normal).first;
    const std::optional<Point3>& nu = it->second;
    return nu && std::abs(nu->dot(n)) >= min_facing;
  };
  // A vote for the plane at offset d along n from beam b (se = n . end) that enters its region
  // at the fraction \p entry of its length (negative: not asked): it crosses the plane no later
  // than one voxel after it enters the region (the lying space begins behind a mirror) and at
  // least 2 tol from its origin, its end reflected about the plane lands on a supported voxel
  // that faces the plane, the reflected path from the mirror point to it runs through space the
  // map explains (up to tol before it: no supported voxel, and at least half its voxels crossed
  // by trusted beams), and behind the plane it ran mostly through space not explained free.
  const auto votes_for = [&](Lookup& lk, const Beam& b, const Point3& n, double d, double se, double entry) {
    if (std::abs(se - d) < tol) return false;  // the end moves at least 2 tol: not onto its own surface
    const double so = n.dot(b.origin);
    const double at = (d - so) / (se - so);
    const double length = (b.end - b.origin).norm();
    if (entry >= 0.0 && at > entry + res / length) return false;
    if (at * length < 2.0 * tol) return false;  // a mirror within 2 tol of the sensor: none
    const Point3 reflected = b.end - 2.0 * (se - d) * n;
    if (!bits.near_support(reflected)) return false;
    const std::optional<Key> rk = g.try_key(reflected);
    if (!rk || !lk.read.supported(*rk) || !faces(lk, *rk, n)) return false;
    const Point3 m = b.origin + (b.end - b.origin) * at;
    const Point3 dir = reflected - m;
    const double len = dir.norm();
    if (len <= tol + res) return true;
    std::size_t seen = 0, known = 0;
    bool blocked = false;
    const Point3 stop = m + dir * ((len - tol) / len);
    traverse(g, m, stop, [&](const Key& k) {
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
    traverse(g, m, Point3(m + behind * ((blen - tol) / blen)), [&](const Key& k) {
      ++walked;
      free += lk.free(space, k);
      return true;
    });
    return 4 * free <= 3 * walked;
  };
  const double h = 0.5 * res;  // offset bins: the reflected end moves one voxel per bin

  for (std::size_t r = 0; r < out.size(); ++r) {
    LyingSurface& s = out[r];
    s.returned_beams = returned[r].size();
    s.silent_beams = silent[r].size();
    for (const Entry& e : returned[r]) s.real_ends += supported_at(e.beam.end);
    Point3 mean_origin = Point3::Zero();
    for (const auto* list : {&returned[r], &silent[r]})
      for (const Entry& e : *list) mean_origin += e.beam.origin;
    if (s.returned_beams + s.silent_beams > 0) mean_origin /= static_cast<double>(s.returned_beams + s.silent_beams);

    // The mirror hypothesis: the plane search over the (thinned) returned suspect beams.
    std::vector<std::pair<Beam, double>> search;  // the beam, the fraction of its length where it enters the region
    const std::size_t stride = (returned[r].size() + params.max_search_beams - 1) / params.max_search_beams;
    for (std::size_t i = 0; i < returned[r].size(); i += std::max<std::size_t>(stride, 1)) {
      const Entry& e = returned[r][i];
      search.emplace_back(e.beam, (e.at - e.beam.origin).norm() / (e.beam.end - e.beam.origin).norm());
    }
    s.searched_beams = search.size();
    std::vector<detail::LyingPlaneScore> scores(normals.size());
    // The range of offsets a beam can cross the plane at, more than tol before its end: (lo, hi)
    // in metres along n, or empty.
    const auto window = [&](const Beam& b, const Point3& n, double& lo, double& hi, double& se) {
      const double so = n.dot(b.origin);
      se = n.dot(b.end);
      const double len = (b.end - b.origin).norm();
      if (std::abs(se - so) < res || len <= tol) return false;
      const double last = se - (se - so) * tol / len;  // the offset tol before the end
      lo = std::min(so, last);
      hi = std::max(so, last);
      return true;
    };
    if (!search.empty())
      parallel_for_chunks(
          normals.size(), params.threads,
          [&](std::size_t from, std::size_t to) {
            Lookup lk{detail::TrustedBits::Reader(bits)};
            std::vector<std::uint32_t> votes;
            std::vector<std::int64_t> crossing;
            for (std::size_t i = from; i < to; ++i) {
              const Point3& n = normals[i];
              double lo_all = std::numeric_limits<double>::infinity(), hi_all = -lo_all;
              for (const auto& [b, entry] : search)
                for (const Point3* p : {&b.origin, &b.end}) {
                  lo_all = std::min(lo_all, n.dot(*p));
                  hi_all = std::max(hi_all, n.dot(*p));
                }
              const std::int64_t first = static_cast<std::int64_t>(std::floor(lo_all / h)) - 1;
              const std::size_t bins = static_cast<std::size_t>(std::ceil(hi_all / h) - std::floor(lo_all / h)) + 3;
              votes.assign(bins, 0);
              // The crossings, counted as ranges: +1 at a beam's first bin, -1 after its last.
              crossing.assign(bins + 1, 0);
              const auto mid = [&](std::int64_t bin) { return (static_cast<double>(bin) + 0.5) * h; };
              for (const auto& [b, entry] : search) {
                double lo = 0, hi = 0, se = 0;
                if (!window(b, n, lo, hi, se)) continue;
                // The bins with lo < d < hi: [a, e).
                const std::int64_t start = static_cast<std::int64_t>(std::ceil(lo / h - 0.5));
                std::int64_t a = start;
                while (mid(a) <= lo && mid(a) < hi) ++a;
                std::int64_t e = std::max(start, static_cast<std::int64_t>(std::ceil(hi / h - 0.5)));
                while (e > start && mid(e - 1) >= hi) --e;
                while (mid(e) < hi) ++e;
                if (a >= e) continue;
                ++crossing[static_cast<std::size_t>(a - first)];
                --crossing[static_cast<std::size_t>(e - first)];
                // Votes only where the beam can vote: it crosses the plane at a fraction of its
                // length in [2 tol / length, entry + res / length] (entry >= 0 here; votes_for()
                // tests it again, exactly; two bins of margin on either side).
                const double so = n.dot(b.origin), length = (b.end - b.origin).norm();
                const double d0 = so + (2.0 * tol / length) * (se - so), d1 = so + (entry + res / length) * (se - so);
                const std::int64_t v0 = std::max(a, static_cast<std::int64_t>(std::floor(std::min(d0, d1) / h - 0.5)) - 2);
                const std::int64_t v1 = std::min(e, static_cast<std::int64_t>(std::ceil(std::max(d0, d1) / h - 0.5)) + 3);
                for (std::int64_t bin = v0; bin < v1; ++bin)
                  if (votes_for(lk, b, n, mid(bin), se, entry)) ++votes[static_cast<std::size_t>(bin - first)];
              }
              detail::LyingPlaneScore best;
              std::int64_t crossing_here = 0;
              for (std::size_t at = 0; at < bins; ++at) {
                crossing_here += crossing[at];
                if (votes[at] > best.votes) best = {first + static_cast<std::int64_t>(at), votes[at], static_cast<std::size_t>(crossing_here)};
              }
              scores[i] = best;
            }
          },
          1);
    std::size_t best = 0;
    for (std::size_t i = 1; i < scores.size(); ++i)
      if (scores[i].votes > scores[best].votes) best = i;
    if (!scores.empty() && scores[best].votes > 0) {
      s.mirror_votes = scores[best].votes;
      s.mirror_crossing = scores[best].crossing;
      s.best_normal = normals[best];
      s.best_offset = (static_cast<double>(scores[best].bin) + 0.5) * h;
    }
    const auto span_patch = [&](const std::vector<Point3>& pts, const Point3& n, double offset) {
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
      p.half_u = 0.5 * (u1 - u0) + 0.5 * res;
      p.half_v = 0.5 * (v1 - v0) + 0.5 * res;
      return p;
    };
    bool mirror = !scores.empty() && scores[best].votes >= params.min_mirror_votes &&
                  static_cast<double>(scores[best].votes) >= params.min_mirror_share * static_cast<double>(scores[best].crossing);
    if (mirror) {  // (its votes come from the region's beams, so the crossings below are never empty)
      // The patch: the crossings of the region's returned suspect beams that vote for the plane
      // (at its offset or the bins beside it), grown below.
      const Point3& n = normals[best];
      const double offset = (static_cast<double>(scores[best].bin) + 0.5) * h;
      Lookup lk{detail::TrustedBits::Reader(bits)};
      const auto votes_near = [&](const Beam& b, double entry) {
        double lo = 0, hi = 0, se = 0;
        if (!window(b, n, lo, hi, se)) return false;
        for (const double d : {offset, offset - h, offset + h})
          if (d > lo && d < hi && votes_for(lk, b, n, d, se, entry)) return true;
        return false;
      };
      const auto crossing_of = [&](const Beam& b) {
        const double so = n.dot(b.origin), se = n.dot(b.end);
        return Point3(b.origin + (b.end - b.origin) * ((offset - so) / (se - so)));
      };
      std::vector<Point3> crossings;
      for (const Entry& e : returned[r])
        if (votes_near(e.beam, (e.at - e.beam.origin).norm() / (e.beam.end - e.beam.origin).norm()))
          crossings.push_back(crossing_of(e.beam));
      // Grown over the plane: cells of one voxel in the plane, 8-connected to those crossings and
      // within grow_reach of them, where the ledger's returned beams (any class: a phantom that
      // crossed only unseen space is trusted) that cross the cell are this plane's phantoms:
      // reflected about it, the ends of at least 3 land on a supported voxel (consistent; a floor
      // counts now that the plane is fixed), at least one of them on a surface that faces the
      // plane (a floor alone would let the patch run on beside the mirror, where real beams end
      // on the floor behind its plane), and at most one in 10 lands in space trusted beams
      // crossed and never hit (inconsistent).
      const Point3 au = PlanePatch::floor_axis(n), av = n.cross(au);
      using Cell = std::pair<std::int64_t, std::int64_t>;
      const auto cell_of = [&](const Point3& q) {
        return Cell{static_cast<std::int64_t>(std::floor(q.dot(au) / res)), static_cast<std::int64_t>(std::floor(q.dot(av) / res))};
      };
      std::vector<Cell> grown;
      for (const Point3& q : crossings) grown.push_back(cell_of(q));
      std::sort(grown.begin(), grown.end());
      grown.erase(std::unique(grown.begin(), grown.end()), grown.end());
      struct CellCount {
        std::uint32_t consistent = 0, inconsistent = 0, facing = 0;
      };
      std::unordered_map<std::int64_t, CellCount> cells;
      const auto cell_id = [](const Cell& c) { return c.first * 4294967311LL + c.second; };
      if (!crossings.empty()) {
        const PlanePatch seed = span_patch(crossings, n, offset);
        const Point3 sv = seed.axis_v();
        for (const LedgerScan& scan : space.ledger().scans())
          scan.for_each([&](std::size_t, const Beam& b, BeamClass c) {
            if (!b.hit || c == BeamClass::Skipped) return;
            double lo = 0, hi = 0, se = 0;
            if (!window(b, n, lo, hi, se) || offset <= lo || offset >= hi || std::abs(se - offset) < tol) return;
            const Point3 dq = crossing_of(b) - seed.center;
            if (std::abs(dq.dot(seed.axis_u)) > seed.half_u + params.grow_reach ||
                std::abs(dq.dot(sv)) > seed.half_v + params.grow_reach)
              return;
            const std::optional<Key> rk = g.try_key(b.end - 2.0 * (se - offset) * n);
            if (!rk) return;
            CellCount& cc = cells[cell_id(cell_of(crossing_of(b)))];
            if (lk.read.supported(*rk)) {
              ++cc.consistent;
              cc.facing += faces(lk, *rk, n) ? 1u : 0u;
            } else if (const HitMissCount::Cell* t = trusted.find(*rk); t && t->hits == 0 && t->misses > 0) {
              ++cc.inconsistent;
            }
          });
      }
      std::unordered_set<std::int64_t> in;
      for (const Cell& c : grown) in.insert(cell_id(c));
      // A mirror is opaque and its phantoms land on real surfaces: where its votes cross the
      // plane, the beams that cross it there must reflect onto supported voxels, not into space
      // the map explains as free (a plane through open space that folds a few surfaces onto
      // each other passes the vote, while most beams through it end on real surfaces beyond).
      for (const Cell& c : grown)
        if (const auto it = cells.find(cell_id(c)); it != cells.end()) {
          s.consistent_ends += it->second.consistent;
          s.inconsistent_ends += it->second.inconsistent;
        }
      if (static_cast<double>(s.inconsistent_ends) >
          params.max_inconsistent_share * static_cast<double>(s.consistent_ends + s.inconsistent_ends))
        mirror = false;
      if (mirror) {
        for (std::size_t i = 0; i < grown.size() && params.grow_reach > 0.0; ++i)
          for (std::int64_t du = -1; du <= 1; ++du)
            for (std::int64_t dv = -1; dv <= 1; ++dv) {
              const Cell c{grown[i].first + du, grown[i].second + dv};
              const auto it = cells.find(cell_id(c));
              if (it == cells.end() || in.count(cell_id(c))) continue;
              const CellCount& k = it->second;
              if (k.consistent < 3 || k.consistent < 9 * k.inconsistent || k.facing == 0) continue;
              in.insert(cell_id(c));
              grown.push_back(c);
            }
        std::vector<Point3> corners;
        for (const auto& [cu, cv] : grown)
          for (const double fu : {0.0, 1.0})
            for (const double fv : {0.0, 1.0})
              corners.push_back(au * ((static_cast<double>(cu) + fu) * res) + av * ((static_cast<double>(cv) + fv) * res));
        s.kind = LyingKind::Mirror;
        s.surface = span_patch(corners, n, offset);
        s.has_plane = true;
        continue;
      }
    }
    // The other kinds: the plane of the entry points.
    std::vector<Point3> entries;
    for (const auto* list : {&returned[r], &silent[r]})
      for (const Entry& e : *list) entries.push_back(e.at);
    if (entries.size() >= 3) {
      Point3 c = Point3::Zero();
      for (const Point3& p : entries) c += p;
      c /= static_cast<double>(entries.size());
      if (const std::optional<Point3> n = plane_normal(std::span<const Point3>(entries))) {
        s.surface = span_patch(entries, *n, n->dot(c));
        s.has_plane = true;
      }
    }
    if (s.returned_beams >= params.min_opening_beams &&
        static_cast<double>(s.real_ends) >= params.opening_share * static_cast<double>(s.returned_beams))
      s.kind = LyingKind::Opening;
    else if (s.silent_beams > s.returned_beams)
      s.kind = LyingKind::Black;
    else
      s.kind = LyingKind::Unresolved;
  }
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
