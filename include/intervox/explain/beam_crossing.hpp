#pragma once
/// \file
/// The beam crossing test of the explained channel (ExplainedSpace, explain/explained_space.hpp,
/// whose file comment states the classes): the class of a beam against the channel's trusted
/// evidence and known mirrors. A beam that crosses a known mirror (explain/known_mirrors.hpp) is
/// suspect; a returned beam is suspect if it crosses a *supported surface* (trusted hits >=
/// min_surface_hits and >= surface_hit_ratio x trusted misses) more than crossing_tolerance
/// before its end with no supported voxel near its end, or if it ends in *mid-air* (every voxel
/// near its end crossed by mid_air_misses trusted scans and hit by none); a beam without a return
/// is suspect if, within the sensor's range, it enters a surface's inside steeply and leaves it
/// into space no trusted beam crossed. The *inside* of a surface: around a supported voxel the
/// supported voxels within one voxel span a plane (detail::local_surface()) and every neighbour
/// across the plane is supported.
///
/// Supported voxels lie in the blocks that hold a trusted hit (ExplainedCounts::surface_blocks()),
/// so the walks step block by block (walk_blocks()) and look at voxels only inside those. The
/// reads go through a CellReader, which can leave out one kept scan's own trusted footprint
/// (a kept scan classed again by the revision, explain/ledger_revision.hpp).
///
/// Uses the ray insertion's preparation (raycast/detail/prepare_ray.hpp: detail::prepare_ray,
/// detail::PreparedRay, detail::SegmentDda) and the sparse grid's blocks (grid/sparse_storage.hpp:
/// detail::SparseBlocks, detail::block_id_of), so that its walks are the insertion's own.
///
/// Thread safety: a BeamCrossing only reads; several may run at once on one channel while nothing
/// changes it. An InsideCache belongs to one thread.

#include <intervox/core/key.hpp>
#include <intervox/core/key_set.hpp>
#include <intervox/core/plane_fit.hpp>
#include <intervox/core/point.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/explain/beam_ledger.hpp>
#include <intervox/explain/evidence.hpp>
#include <intervox/explain/explain_options.hpp>
#include <intervox/explain/explained_counts.hpp>
#include <intervox/explain/known_mirrors.hpp>
#include <intervox/grid/sparse_storage.hpp>
#include <intervox/raycast/detail/prepare_ray.hpp>
#include <intervox/raycast/insert_options.hpp>
#include <intervox/raycast/traversal.hpp>
#include <intervox/update/hit_miss_count.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numbers>
#include <optional>
#include <span>
#include <unordered_map>
#include <utility>

namespace intervox::detail {

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

/// The crossing test of one ExplainedSpace: its geometry, options, counts and known mirrors, by
/// reference (made for a call, never kept: the channel may move).
class BeamCrossing {
 public:
  /// What inside_met_steeply() found at supported voxels, kept while the beams of one chunk of a
  /// scan are classed (the trusted evidence they are read against does not change meanwhile).
  struct InsideCache {
    struct Entry {
      Point3 normal;  ///< the local plane's normal (zero if the supported voxels span none)
      bool inside;    ///< a plane, and every neighbour across it supported
    };
    std::unordered_map<Key, Entry, KeyHash> at;
  };

  /// Reads cells along a walk, remembering the last block (a walk stays in a block for several
  /// steps, so most reads skip the hash lookup); with \p own, the counts without that scan's
  /// evidence (a kept scan classed again).
  struct CellReader {
    using Blocks = SparseBlocks<HitMissCount::Cell>;
    const Blocks& cells;
    const ScanFootprint* own = nullptr;
    std::uint64_t id = ~std::uint64_t{0};
    const Blocks::Block* block = nullptr;
    const ScanFootprint::Block* own_block = nullptr;

    HitMissCount::Cell operator()(const Key& k) noexcept {
      if (!in_key_range(k)) return {};
      const std::uint64_t b = block_id_of(k);
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

  BeamCrossing(const GridGeometry& geometry, const ExplainOptions& options, const ExplainedCounts& counts,
               const KnownMirrors& mirrors) noexcept
      : geometry_(geometry), options_(options), counts_(counts), mirrors_(mirrors) {}

  /// True if trusted counts \p c make a supported surface under \p options (at least
  /// min_surface_hits hits, and hits >= surface_hit_ratio x misses; ExplainedSpace::supported_counts()).
  static bool supported(const ExplainOptions& options, const HitMissCount::Cell& c) noexcept {
    return c.hits >= options.min_surface_hits && double(c.hits) >= options.surface_hit_ratio * double(c.misses);
  }
  /// The same under the channel's options.
  bool supported(const HitMissCount::Cell& c) const noexcept { return supported(options_, c); }

  /// The class of \p beam against the evidence, with the insertion's rules of \p insert
  /// (ExplainedSpace::classify()).
  BeamClass classify(const Beam& beam, const InsertOptions& insert, InsideCache& cache) const noexcept {
    InsertStats ignored;
    const std::optional<PreparedRay> p = prepare_ray(geometry_, insert, beam, ignored);
    if (!p) return BeamClass::Skipped;
    if (!beam.hit) return classify_no_return(beam, *p, insert.max_range, cache);
    return classify_returned(beam, *p, nullptr, &cache);
  }

  /// Walks the voxels of the prepared ray \p p inside block \p b (the part of its segment in the
  /// block's box, its keys clamped into the block); true as soon as \p f(key) is.
  template <class F>
  static bool walk_block(const PreparedRay& p, const Key& b, F& f) noexcept {
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
    SegmentDda dda(e0, e1, k0, k1);
    for (;;) {
      if (f(dda.key)) return true;
      if (dda.remaining == 0) return false;
      dda.advance();
    }
  }

  /// Walks the voxels of \p p that lie in blocks of \p blocks, block by block; true as soon as
  /// \p f(key) is.
  template <class F>
  static bool walk_blocks(const PreparedRay& p, const KeySet& blocks, F& f) noexcept {
    if (blocks.size() == 0) return false;
    SegmentDda dda(p.v0 / 8.0, p.v1 / 8.0, ExplainedCounts::block_of(p.k0), ExplainedCounts::block_of(p.k1));
    for (;;) {
      if (blocks.contains(dda.key) && walk_block(p, dda.key, f)) return true;
      if (dda.remaining == 0) return false;
      dda.advance();
    }
  }

  /// The crossing test of a returned, prepared beam (reads through \p read): a supported voxel
  /// whose centre projects more than crossing_tolerance before the end; with \p inside, only one
  /// of a surface's inside met steeply (inside_met_steeply()). Supported voxels lie in blocks
  /// that hold a trusted hit (ExplainedCounts::surface_blocks()): the walk steps block by
  /// block and walks voxels only inside those.
  bool crosses_support(const Beam& beam, const PreparedRay& p, CellReader& read, bool inside,
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
    return limit > 0.0 && walk_blocks(p, counts_.surface_blocks(), crosses);
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
    const LocalSurface local = local_surface(k, [&](const Key& q) { return supported(read(q)); });
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
  BeamClass classify_no_return(const Beam& beam, const PreparedRay& p, double max_range,
                               InsideCache& cache) const noexcept {
    CellReader read{counts_.trusted().storage(), nullptr};
    const Point3 d = beam.end - beam.origin;
    const double len = d.norm();
    const double range = std::min(len, max_range);
    const Beam cut{beam.origin, beam.origin + d * (range / len), false};
    if (mirrors_.crossed_by(cut, geometry_, options_.crossing_tolerance)) return BeamClass::Suspect;
    if (!crosses_support(cut, p, read, false, nullptr))
      return BeamClass::NoReturn;  // the cheap test first: no supported voxel at all
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
  BeamClass classify_returned(const Beam& beam, const PreparedRay& p, const ScanFootprint* own,
                              InsideCache* cache) const noexcept {
    if (mirrors_.crossed_by(beam, geometry_, options_.crossing_tolerance)) return BeamClass::Suspect;
    CellReader read{counts_.trusted().storage(), own};
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

 private:
  const GridGeometry& geometry_;
  const ExplainOptions& options_;
  const ExplainedCounts& counts_;
  const KnownMirrors& mirrors_;
};

}  // namespace intervox::detail
