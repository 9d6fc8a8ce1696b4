#pragma once
/// \file
/// Internal: a binary bounding volume hierarchy over the scene's primitives, flattened into an
/// array. Built by the surface area heuristic (SAH) over 16 bins of the centroids per axis, leaves
/// of at most 8 primitives; below depth 48 by median splits on the longest centroid axis, so the
/// depth stays below 48 + 32 whatever the scene. Node boxes enclose the primitives' loose_bounds(),
/// so rounding never culls a hit.

#include <intervox/sim/detail/primitive.hpp>

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <vector>

namespace intervox::sim::detail {

struct BvhNode {
  Point3 lo, hi;
  std::uint32_t first = 0;  ///< leaf: first index into Bvh::order; inner: index of the right child
  std::uint32_t count = 0;  ///< leaf: number of primitives; inner: 0 (the left child follows)
};

class Bvh {
 public:
  void build(const std::vector<Prim>& prims) {
    nodes_.clear();
    order_.resize(prims.size());
    std::iota(order_.begin(), order_.end(), 0u);
    boxes_.resize(prims.size());
    centroids_.resize(prims.size());
    for (std::size_t i = 0; i < prims.size(); ++i) {
      boxes_[i] = loose_bounds(prims[i]);
      centroids_[i] = 0.5 * (boxes_[i].min + boxes_[i].max);
    }
    if (!prims.empty()) build_node(0, static_cast<std::uint32_t>(prims.size()), 0);
  }

  /// loose_bounds() of primitive \p i.
  const Bounds& loose(std::uint32_t i) const noexcept { return boxes_[i]; }

  /// Closest hit in (tmin, tmax]; returns the primitive index or -1, and writes t. Of hits at the
  /// same t the lowest primitive index wins: the hit of testing every primitive in index order.
  std::int64_t closest(const std::vector<Prim>& prims, const Point3& o, const Point3& d, double tmin, double tmax,
                       double& t_out) const noexcept {
    if (nodes_.empty()) return -1;
    const RayInverse ri(d);
    const Point3& inv = ri.inv;
    double best = tmax;
    std::int64_t best_i = -1;
    // Nodes are pushed with their entry parameter, the nearer child last (visited first), and
    // skipped when popped if a closer hit has been found meanwhile.
    std::uint32_t stack[kStack];
    double entry[kStack];
    int sp = 0;
    double t_root = 0;
    if (!node_hit(nodes_[0], o, inv, tmin, best, t_root)) return -1;
    stack[sp] = 0;
    entry[sp++] = t_root;
    while (sp > 0) {
      --sp;
      if (entry[sp] > best) continue;
      const BvhNode& n = nodes_[stack[sp]];
      if (n.count > 0) {
        for (std::uint32_t k = n.first; k < n.first + n.count; ++k) {
          const double t = intersect_fast(prims[order_[k]], boxes_[order_[k]], o, d, ri, tmin, best);
          // Ties go to the lower primitive index, as when testing every primitive in order.
          if (t < kInf && (t < best || (t == best && (best_i < 0 || static_cast<std::int64_t>(order_[k]) < best_i)))) {
            best = t;
            best_i = order_[k];
          }
        }
      } else {
        const std::uint32_t l = static_cast<std::uint32_t>(&n - nodes_.data()) + 1, r = n.first;
        double tl = 0, tr = 0;
        const bool hl = node_hit(nodes_[l], o, inv, tmin, best, tl);
        const bool hr = node_hit(nodes_[r], o, inv, tmin, best, tr);
        if (sp + 2 > kStack) continue;  // cannot happen: the depth stays below 48 + 32
        if (hl && hr) {
          const bool left_first = tl <= tr;
          stack[sp] = left_first ? r : l;
          entry[sp++] = left_first ? tr : tl;
          stack[sp] = left_first ? l : r;
          entry[sp++] = left_first ? tl : tr;
        } else if (hl) {
          stack[sp] = l;
          entry[sp++] = tl;
        } else if (hr) {
          stack[sp] = r;
          entry[sp++] = tr;
        }
      }
    }
    t_out = best;
    return best_i;
  }

  /// Calls f(prim index) for every primitive whose bounds meet the closed box [lo, hi]; stops
  /// when f returns true, and then returns true.
  template <class F>
  bool any_in_box(const Point3& lo, const Point3& hi, F&& f) const {
    if (nodes_.empty()) return false;
    std::uint32_t stack[kStack];
    int sp = 0;
    stack[sp++] = 0;
    while (sp > 0) {
      const BvhNode& n = nodes_[stack[--sp]];
      if ((n.lo.array() > hi.array()).any() || (lo.array() > n.hi.array()).any()) continue;
      if (n.count > 0) {
        for (std::uint32_t k = n.first; k < n.first + n.count; ++k)
          if (f(order_[k])) return true;
      } else {
        const std::uint32_t self = static_cast<std::uint32_t>(&n - nodes_.data());
        if (sp + 2 > kStack) continue;  // cannot happen: the depth stays below 48 + 32
        stack[sp++] = n.first;
        stack[sp++] = self + 1;
      }
    }
    return false;
  }

  /// Calls f(prim index) for every primitive whose bounds (and whose ancestors' node boxes) pass
  /// \p keep(lo, hi), a conservative test of an axis-aligned box.
  template <class Keep, class F>
  void for_each_kept(Keep&& keep, F&& f) const {
    if (nodes_.empty()) return;
    std::uint32_t stack[kStack];
    int sp = 0;
    stack[sp++] = 0;
    while (sp > 0) {
      const BvhNode& n = nodes_[stack[--sp]];
      if (!keep(n.lo, n.hi)) continue;
      if (n.count > 0) {
        for (std::uint32_t k = n.first; k < n.first + n.count; ++k)
          if (keep(boxes_[order_[k]].min, boxes_[order_[k]].max)) f(order_[k]);
      } else {
        const std::uint32_t self = static_cast<std::uint32_t>(&n - nodes_.data());
        if (sp + 2 > kStack) continue;  // cannot happen: the depth stays below 48 + 32
        stack[sp++] = n.first;
        stack[sp++] = self + 1;
      }
    }
  }

  std::size_t node_count() const noexcept { return nodes_.size(); }

 private:
  static bool node_hit(const BvhNode& n, const Point3& o, const Point3& inv, double tmin, double tmax,
                       double& t_entry) noexcept {
    double t0 = tmin, t1 = tmax;
    for (int i = 0; i < 3; ++i) {
      const double a = (n.lo[i] - o[i]) * inv[i], b = (n.hi[i] - o[i]) * inv[i];
      // NaN (0 * inf, a ray in a slab's face plane) is ignored by these comparisons: conservative.
      const double lo = std::min(a, b), hi = std::max(a, b);
      t0 = std::max(t0, lo);
      t1 = std::min(t1, hi);
    }
    t_entry = t0;
    return t0 <= t1;
  }

  static constexpr int kStack = 96;
  static constexpr std::uint32_t kDepthSah = 48, kBins = 16, kMaxLeaf = 8;

  static double half_area(const Point3& lo, const Point3& hi) noexcept {
    const Point3 e = (hi - lo).cwiseMax(Point3::Zero());
    return e.x() * e.y() + e.y() * e.z() + e.z() * e.x();
  }

  /// The bounds of primitives [begin, end) of order_: of their boxes (lo, hi) and of their
  /// centroids (clo, chi).
  struct RangeBounds {
    Point3 lo, hi, clo, chi;
  };
  RangeBounds range_bounds(std::uint32_t begin, std::uint32_t end) const noexcept {
    Point3 lo = Point3::Constant(kInf), hi = Point3::Constant(-kInf);
    Point3 clo = lo, chi = hi;
    for (std::uint32_t k = begin; k < end; ++k) {
      lo = lo.cwiseMin(boxes_[order_[k]].min);
      hi = hi.cwiseMax(boxes_[order_[k]].max);
      clo = clo.cwiseMin(centroids_[order_[k]]);
      chi = chi.cwiseMax(centroids_[order_[k]]);
    }
    return {lo, hi, clo, chi};
  }

  /// The best SAH split found so far: its cost (sum of area times count of both sides), its axis
  /// (-1: none) and the last bin of its left side.
  struct SahSplit {
    double cost = kInf;
    int axis = -1;
    std::uint32_t bin = 0;
  };

  /// SAH over bins of the centroids of [begin, end) along \p axis (centroid extent \p extent from
  /// \p c0): cost of a split, in units of one primitive test, 1 + (A_left n_left + A_right
  /// n_right) / A; \p best keeps the cheapest split so far (the first of equal costs).
  void sah_axis(std::uint32_t begin, std::uint32_t end, int axis, double c0, double extent, SahSplit& best) const {
    std::uint32_t count[kBins] = {};
    Point3 blo[kBins], bhi[kBins];
    for (std::uint32_t b = 0; b < kBins; ++b) blo[b] = Point3::Constant(kInf), bhi[b] = Point3::Constant(-kInf);
    for (std::uint32_t k = begin; k < end; ++k) {
      const std::uint32_t b = bin_of(centroids_[order_[k]][axis], c0, extent);
      ++count[b];
      blo[b] = blo[b].cwiseMin(boxes_[order_[k]].min);
      bhi[b] = bhi[b].cwiseMax(boxes_[order_[k]].max);
    }
    double right_area[kBins];
    std::uint32_t right_count[kBins];
    Point3 rlo = Point3::Constant(kInf), rhi = Point3::Constant(-kInf);
    std::uint32_t rc = 0;
    for (std::uint32_t b = kBins - 1; b > 0; --b) {
      rlo = rlo.cwiseMin(blo[b]);
      rhi = rhi.cwiseMax(bhi[b]);
      rc += count[b];
      right_area[b] = rc ? half_area(rlo, rhi) : 0.0;
      right_count[b] = rc;
    }
    Point3 llo = Point3::Constant(kInf), lhi = Point3::Constant(-kInf);
    std::uint32_t lc = 0;
    for (std::uint32_t b = 0; b + 1 < kBins; ++b) {  // split between bins b and b + 1
      llo = llo.cwiseMin(blo[b]);
      lhi = lhi.cwiseMax(bhi[b]);
      lc += count[b];
      if (lc == 0 || right_count[b + 1] == 0) continue;
      const double cost = lc * half_area(llo, lhi) + right_count[b + 1] * right_area[b + 1];
      if (cost < best.cost) best.cost = cost, best.axis = axis, best.bin = b;
    }
  }

  /// Partitions [begin, end) of order_ by \p split (centroid bins of \p r along its axis);
  /// returns the first primitive of the right side.
  std::uint32_t sah_partition(std::uint32_t begin, std::uint32_t end, const RangeBounds& r, const SahSplit& split) {
    const double c0 = r.clo[split.axis], extent = r.chi[split.axis] - r.clo[split.axis];
    const auto at = std::partition(order_.begin() + begin, order_.begin() + end, [&](std::uint32_t i) {
      return bin_of(centroids_[i][split.axis], c0, extent) <= split.bin;
    });
    return static_cast<std::uint32_t>(at - order_.begin());
  }

  /// Median split of [begin, end) (n primitives) on the longest centroid axis of \p r (also when
  /// all centroids coincide); returns the first primitive of the right side.
  std::uint32_t median_split(std::uint32_t begin, std::uint32_t end, std::uint32_t n, const RangeBounds& r) {
    int axis = 0;
    (r.chi - r.clo).maxCoeff(&axis);
    const std::uint32_t mid = begin + n / 2;
    std::nth_element(
        order_.begin() + begin, order_.begin() + mid, order_.begin() + end, [&](std::uint32_t x, std::uint32_t y) {
          return centroids_[x][axis] < centroids_[y][axis] || (centroids_[x][axis] == centroids_[y][axis] && x < y);
        });
    return mid;
  }

  std::uint32_t build_node(std::uint32_t begin, std::uint32_t end, std::uint32_t depth) {
    const std::uint32_t index = static_cast<std::uint32_t>(nodes_.size());
    nodes_.emplace_back();
    const RangeBounds r = range_bounds(begin, end);
    nodes_[index].lo = r.lo;
    nodes_[index].hi = r.hi;
    const std::uint32_t n = end - begin;
    const auto leaf = [&] {
      nodes_[index].first = begin;
      nodes_[index].count = n;
      return index;
    };
    if (n <= 2) return leaf();
    std::uint32_t mid = begin;
    if (depth < kDepthSah) {
      // SAH over bins of the centroids (sah_axis()); a leaf costs n.
      SahSplit best;
      for (int axis = 0; axis < 3; ++axis) {
        const double extent = r.chi[axis] - r.clo[axis];
        if (!(extent > 0)) continue;
        sah_axis(begin, end, axis, r.clo[axis], extent, best);
      }
      const double area = half_area(r.lo, r.hi);
      if (best.axis >= 0 && area > 0) {
        if (n <= kMaxLeaf && 1.0 + best.cost / area >= n) return leaf();
        mid = sah_partition(begin, end, r, best);
      }
    }
    if (mid <= begin || mid >= end) {
      // Median split on the longest centroid axis (also when all centroids coincide).
      if (n <= 4) return leaf();
      mid = median_split(begin, end, n, r);
    }
    build_node(begin, mid, depth + 1);
    const std::uint32_t right = build_node(mid, end, depth + 1);
    nodes_[index].first = right;
    nodes_[index].count = 0;
    return index;
  }

  static std::uint32_t bin_of(double c, double c0, double extent) noexcept {
    const double b = (c - c0) / extent * kBins;
    return b <= 0 ? 0u : std::min(kBins - 1, static_cast<std::uint32_t>(b));
  }

  std::vector<BvhNode> nodes_;
  std::vector<std::uint32_t> order_;
  std::vector<Bounds> boxes_;
  std::vector<Point3> centroids_;
};

}  // namespace intervox::sim::detail
