#pragma once
/// \file
/// The known mirrors of the explained channel (ExplainedSpace::add_mirror(), on_mirror();
/// explain/explained_space.hpp): the mirrors a region analysis found (analysis/lying_surfaces.hpp)
/// or a user knows, merged when they lie in one plane (MirrorMerge), indexed by where they lie
/// (detail::MirrorIndex) so that a voxel's or a beam's test looks at the few mirrors near it, and
/// the mirror test of the classes: a beam that crosses a known mirror more than
/// crossing_tolerance before its end is suspect (detail::KnownMirrors::crossed_by()).
///
/// Thread safety: the const members may run concurrently with each other; add(), assign() and
/// clear() need exclusive access.

#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/plane_patch.hpp>
#include <intervox/core/point.hpp>
#include <intervox/core/sensor_data.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numbers>
#include <optional>
#include <unordered_map>
#include <utility>
#include <vector>

namespace intervox {

/// How ExplainedSpace::add_mirror() treats a mirror in the plane of a known one.
enum class MirrorMerge {
  Grow,  ///< the same mirror: the known rectangle grows to hold both (found mirrors)
  Keep   ///< kept as given, beside it (surfaces a user knows, e.g. walls on both sides of a doorway)
};

namespace detail {
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

/// The mirrors an ExplainedSpace was told of, in order, with their index (ExplainedSpace's
/// add_mirror(), mirrors(), on_mirror() and the mirror test of its classes). It holds no
/// geometry: every call that needs the voxels takes the channel's.
class KnownMirrors {
 public:
  /// The mirrors, in order.
  const std::vector<PlanePatch>& all() const noexcept { return mirrors_; }
  /// Forgets every mirror.
  void clear() noexcept {
    mirrors_.clear();
    index_.clear();
  }
  /// Takes \p mirrors as given, in order (not merged: a loaded channel's), in place of none.
  /// \throws InvalidArgument for an invalid mirror (PlanePatch::validate()); then nothing changed.
  void assign(std::vector<PlanePatch> mirrors, const GridGeometry& g) {
    for (const PlanePatch& m : mirrors) m.validate();
    mirrors_ = std::move(mirrors);
    for (std::size_t i = 0; i < mirrors_.size(); ++i) index_.add(mirrors_[i], static_cast<std::uint32_t>(i), g);
  }

  /// Adds \p mirror_in as ExplainedSpace::add_mirror() tells (a mirror in the plane of a known one
  /// grows it, unless \p merge is MirrorMerge::Keep or the grown rectangle would be invalid) and
  /// returns the mirror as now known: the grown one, or \p mirror_in.
  /// \throws InvalidArgument for an invalid patch (PlanePatch::validate()).
  PlanePatch add(const PlanePatch& mirror_in, MirrorMerge merge, const GridGeometry& g) {
    mirror_in.validate();
    const auto same = merge == MirrorMerge::Keep ? mirrors_.end() : same_plane(mirror_in, g);
    std::optional<PlanePatch> grown;
    if (same != mirrors_.end()) grown = grown_to_hold(*same, mirror_in);
    if (grown) {
      const auto index = static_cast<std::uint32_t>(same - mirrors_.begin());
      index_.remove(*same, index, g);
      *same = *grown;
      index_.add(*same, index, g);
      return *grown;
    }
    mirrors_.push_back(mirror_in);
    index_.add(mirror_in, static_cast<std::uint32_t>(mirrors_.size() - 1), g);
    return mirror_in;
  }

  /// True if voxel \p k of a channel of geometry \p g lies on a known mirror
  /// (ExplainedSpace::on_mirror()).
  bool holds(const Key& k, const GridGeometry& g) const noexcept {
    if (mirrors_.empty()) return false;
    const Point3 c = g.center(k);
    const auto holds = [&](std::uint32_t i) {
      const PlanePatch& m = mirrors_[i];
      return m.contains(c, (0.5 * m.normal.cwiseAbs().sum() + 1e-9) * g.resolution());
    };
    if (in_key_range(k)) return index_.any_at(k, holds);
    for (std::uint32_t i = 0; i < mirrors_.size(); ++i)
      if (holds(i)) return true;
    return false;
  }

  /// True if \p beam crosses \p m more than \p tolerance (ExplainOptions::crossing_tolerance)
  /// before its end.
  static bool crosses(const PlanePatch& m, const Beam& beam, double tolerance) noexcept {
    const std::optional<double> t = m.crossing(beam.origin, beam.end);
    return t && (1.0 - *t) * (beam.end - beam.origin).norm() > tolerance;
  }
  /// True if \p beam crosses a known mirror (crosses()): with a few mirrors, each is tested; with
  /// more, those whose box the beam's key box overlaps (MirrorIndex), unless the beam overlaps so
  /// many of the index's cubes (a long beam) that testing every mirror costs less.
  bool crossed_by(const Beam& beam, const GridGeometry& g, double tolerance) const noexcept {
    const auto crossed = [&](std::uint32_t i) { return crosses(mirrors_[i], beam, tolerance); };
    const auto n = static_cast<std::int64_t>(mirrors_.size());
    if (n > 64) {
      Key lo, hi;
      MirrorIndex::key_box(g, beam.origin.cwiseMin(beam.end), beam.origin.cwiseMax(beam.end), lo, hi);
      // (a cube's lookup costs about what four mirrors' tests cost)
      if (const std::optional<bool> any = index_.any_in(lo, hi, std::max<std::int64_t>(64, n / 4), crossed))
        return *any;
    }
    for (std::uint32_t i = 0; i < mirrors_.size(); ++i)
      if (crossed(i)) return true;
    return false;
  }

 private:
  /// The known mirror in the plane of \p mirror (normals within 2 degrees, its centre within one
  /// voxel of the known plane), or end().
  std::vector<PlanePatch>::iterator same_plane(const PlanePatch& mirror, const GridGeometry& g) {
    const double cos_same = std::cos(2.0 * std::numbers::pi / 180.0);
    return std::find_if(mirrors_.begin(), mirrors_.end(), [&](const PlanePatch& m) {
      return std::abs(m.normal.dot(mirror.normal)) >= cos_same &&
             std::abs(m.normal.dot(mirror.center - m.center)) <= g.resolution();
    });
  }

  /// Known mirror \p m grown, in its own axes, to hold \p mirror as well; nothing if the grown
  /// rectangle is not a valid patch (PlanePatch::validate(): an extent beyond the largest double).
  static std::optional<PlanePatch> grown_to_hold(PlanePatch m, const PlanePatch& mirror) {
    const Point3 v = m.axis_v(), mv = mirror.axis_v();
    const Point3 d = mirror.center - m.center;
    // the new rectangle's reach along the known one's axes
    const double ru =
        std::abs(mirror.axis_u.dot(m.axis_u)) * mirror.half_u + std::abs(mv.dot(m.axis_u)) * mirror.half_v;
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
      return m;
    } catch (const InvalidArgument&) {
      return std::nullopt;
    }
  }

  std::vector<PlanePatch> mirrors_;  ///< known mirrors (ExplainedSpace::add_mirror())
  MirrorIndex index_;                ///< where they lie, by their index in mirrors_
};
}  // namespace detail

}  // namespace intervox
