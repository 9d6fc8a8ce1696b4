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

}  // namespace intervox::detail
