#pragma once
/// \file
/// Internal part of ray insertion: the first step of every input ray, its check against the
/// insertion options (prepare_ray()) into the segment the walks take (PreparedRay).
///
/// Thread safety: reentrant.

#include <intervox/core/key.hpp>
#include <intervox/core/point.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/raycast/insert_options.hpp>
#include <intervox/raycast/traversal.hpp>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <optional>

namespace intervox::detail {

/// One input ray that passed prepare_ray(): its segment in voxel coordinates and keys, and
/// whether its end voxel gets a hit.
struct PreparedRay {
  Point3 v0, v1;
  Key k0, k1;
  bool hit;

  /// The voxels its walk enumerates (the work it takes): the key distance plus one.
  std::uint64_t cost() const noexcept {
    std::uint64_t n = 1;
    for (int a = 0; a < 3; ++a) n += static_cast<std::uint64_t>(std::abs(std::int64_t{k1[a]} - k0[a]));
    return n;
  }
};

/// Checks one input ray (Beam::hit false: no return, `end` anywhere along the beam) against the
/// options: the segment to walk, or nothing, with the reason counted in \p st (a ray taken is
/// counted in `rays`, and in `truncated` if cut at max range).
inline std::optional<PreparedRay> prepare_ray(const GridGeometry& g, const InsertOptions& o, const Beam& r,
                                              InsertStats& st) noexcept {
  if (!is_finite(r.origin) || !is_finite(r.end)) {
    ++st.skipped_invalid;
    return std::nullopt;
  }
  const Point3 d = r.end - r.origin;
  const double len = d.norm();
  if (len == 0.0) {
    ++st.skipped_zero_length;
    return std::nullopt;
  }
  if (!std::isfinite(len)) {  // coordinates near the double limit: far outside the key range
    ++st.skipped_key_range;
    return std::nullopt;
  }
  Point3 end = r.end;
  bool hit = r.hit;
  bool cut = false;
  if (hit) {
    if (len < o.min_range) {
      ++st.skipped_min_range;
      return std::nullopt;
    }
    if (o.has_max_range() && len > o.max_range) {
      end = r.origin + d * (o.max_range / len);
      hit = false;
      cut = true;
    }
  } else {
    if (!o.has_max_range()) {
      ++st.skipped_no_max_range;
      return std::nullopt;
    }
    end = r.origin + d * (o.max_range / len);
    cut = true;
  }
  PreparedRay p;
  if (!voxel_of(g, r.origin, p.v0, p.k0) || !voxel_of(g, end, p.v1, p.k1)) {
    ++st.skipped_key_range;
    return std::nullopt;
  }
  p.hit = hit;
  ++st.rays;
  if (cut) ++st.truncated;
  return p;
}

/// Cuts the walk of \p p short where it leaves \p box (a bounded grid's key box), so that a ray
/// that runs far past a bounded grid is not walked out there (a 64 x 48 frame at 1000 m range into
/// a dense room took 17 s). The end key is clamped, per axis, to one voxel past the box's far face
/// in the direction of travel; v0 and v1 stay, and with them every face crossing of the walk
/// (SegmentDda), so the walk is the same voxel for voxel until the first axis reaches its clamped
/// end, which is the step that leaves the box: every voxel after it lies outside the box, and the
/// updates inside the box are exactly those of the whole walk. A hit beyond the box is dropped. A
/// ray that cannot enter the box (outside it on an axis it does not move towards) is not walked:
/// false. \p outside gets the updates so left out, all beyond the box: per ray, the voxels the whole
/// walk would have taken after the cut walk's end, and its hit (the cut walk's own voxels outside
/// the box are counted where they are dropped, apply_marks()).
inline bool clip_to_box(PreparedRay& p, const KeyBox& box, std::uint64_t& outside) noexcept {
  if (box.contains(p.k1)) return true;  // the walk ends inside: it leaves the box nowhere
  Key end = p.k1;
  std::uint64_t before = 0, after = 0;
  for (int a = 0; a < 3; ++a) {
    const std::int32_t k0 = p.k0[a];
    if (p.k1[a] > k0) {
      if (k0 > box.max[a])
        end[a] = k0;  // beyond the box, moving away: never enters (below)
      else
        end[a] = std::min(p.k1[a], box.max[a] + 1);
    } else if (p.k1[a] < k0) {
      if (k0 < box.min[a])
        end[a] = k0;
      else
        end[a] = std::max(p.k1[a], box.min[a] - 1);
    }
    before += static_cast<std::uint64_t>(std::abs(std::int64_t{p.k1[a]} - k0));
    after += static_cast<std::uint64_t>(std::abs(std::int64_t{end[a]} - k0));
  }
  bool enters = true;
  for (int a = 0; a < 3; ++a) {
    const std::int32_t k0 = p.k0[a];
    const bool away = (k0 > box.max[a] && p.k1[a] >= k0) || (k0 < box.min[a] && p.k1[a] <= k0);
    enters = enters && !away;
  }
  if (!enters) {
    outside += before + (p.hit ? 1 : 0);
    return false;
  }
  outside += before - after + (p.hit ? 1 : 0);
  p.k1 = end;
  p.hit = false;
  return true;
}

}  // namespace intervox::detail
