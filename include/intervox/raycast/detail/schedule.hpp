#pragma once
/// \file
/// Internal part of ray insertion: the scheduling of the marking pass. The prepared rays of a
/// scan (one list per thread of the first pass) are split into runs of equal walk length, one
/// per thread (balanced_runs()), and each thread reads its run through a RayCursor.
///
/// Thread safety: a RayCursor is used by one thread; the lists are only read.

#include <intervox/raycast/detail/prepare_ray.hpp>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace intervox::detail {

/// A position in a list of prepared-ray lists taken as one sequence (list, index).
struct RayPos {
  std::size_t list = 0, index = 0;
  friend bool operator==(const RayPos&, const RayPos&) = default;
};

/// Hands out the prepared rays from \p begin up to \p end of the lists, in order.
class RayCursor {
 public:
  RayCursor(const std::vector<std::vector<PreparedRay>>& lists, RayPos begin, RayPos end) noexcept
      : lists_(&lists), at_(begin), end_(end) {}
  /// The next ray, or nullptr after the last.
  const PreparedRay* next() noexcept {
    for (;;) {
      if (at_ == end_) return nullptr;
      const auto& l = (*lists_)[at_.list];
      if (at_.index < l.size()) return &l[at_.index++];
      ++at_.list;
      at_.index = 0;
    }
  }

 private:
  const std::vector<std::vector<PreparedRay>>* lists_;
  RayPos at_, end_;
};

/// Splits the first \p n lists of prepared rays, taken as one sequence, into \p n runs of
/// about equal cost (PreparedRay::cost()), given each list's total \p cost: run t is
/// [bounds[t], bounds[t + 1]), so that threads get equal work whatever the scan's layout (in an
/// image, rows that see the near floor and rows that see far walls differ several times in cost).
inline std::vector<RayPos> balanced_runs(const std::vector<std::vector<PreparedRay>>& lists,
                                         const std::vector<std::uint64_t>& cost, unsigned n) {
  std::vector<RayPos> bounds(n + 1);
  bounds[n] = RayPos{n, 0};
  std::uint64_t total = 0;
  for (unsigned t = 0; t < n; ++t) total += cost[t];
  std::size_t list = 0;
  std::uint64_t before = 0;  // cost of the lists before `list`
  for (unsigned t = 1; t < n; ++t) {
    const std::uint64_t target = total * t / n;
    while (list < n && before + cost[list] <= target) before += cost[list++];
    if (list == n) {
      bounds[t] = RayPos{n, 0};
      continue;
    }
    std::uint64_t acc = before;
    std::size_t i = 0;
    const auto& l = lists[list];
    while (i < l.size() && acc < target) acc += l[i++].cost();
    bounds[t] = RayPos{list, i};
  }
  return bounds;
}

}  // namespace intervox::detail
