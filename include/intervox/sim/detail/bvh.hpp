#pragma once
/// \file
/// Internal: a binary bounding volume hierarchy over the scene's primitives (median split on the
/// longest axis of the centroid bounds, leaves of at most 4 primitives), flattened into an array.

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
      boxes_[i] = prim_bounds(prims[i]);
      centroids_[i] = 0.5 * (boxes_[i].min + boxes_[i].max);
    }
    if (!prims.empty()) build_node(0, static_cast<std::uint32_t>(prims.size()));
  }

  /// Closest hit in (tmin, tmax]; returns the primitive index or -1, and writes t. Of hits at the
  /// same t the highest primitive index wins: the hit of testing every primitive in index order.
  std::int64_t closest(const std::vector<Prim>& prims, const Point3& o, const Point3& d, double tmin,
                       double tmax, double& t_out) const noexcept {
    if (nodes_.empty()) return -1;
    const Point3 inv = d.cwiseInverse();
    double best = tmax;
    std::int64_t best_i = -1;
    // Nodes are pushed with their entry parameter, the nearer child last (visited first), and
    // skipped when popped if a closer hit has been found meanwhile.
    std::uint32_t stack[64];
    double entry[64];
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
          const double t = intersect(prims[order_[k]], o, d, tmin, best);
          // Ties go to the higher primitive index, as when testing every primitive in order.
          if (t < kInf && (t < best || (t == best && static_cast<std::int64_t>(order_[k]) > best_i))) {
            best = t;
            best_i = order_[k];
          }
        }
      } else {
        const std::uint32_t l = static_cast<std::uint32_t>(&n - nodes_.data()) + 1, r = n.first;
        double tl = 0, tr = 0;
        const bool hl = node_hit(nodes_[l], o, inv, tmin, best, tl);
        const bool hr = node_hit(nodes_[r], o, inv, tmin, best, tr);
        if (sp + 2 > 64) continue;  // cannot happen: the tree is balanced
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
    std::uint32_t stack[64];
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
        if (sp + 2 > 64) continue;
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
    std::uint32_t stack[64];
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
        if (sp + 2 > 64) continue;  // cannot happen: the tree is balanced
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

  std::uint32_t build_node(std::uint32_t begin, std::uint32_t end) {
    const std::uint32_t index = static_cast<std::uint32_t>(nodes_.size());
    nodes_.emplace_back();
    Point3 lo = Point3::Constant(kInf), hi = Point3::Constant(-kInf);
    Point3 clo = lo, chi = hi;
    for (std::uint32_t k = begin; k < end; ++k) {
      lo = lo.cwiseMin(boxes_[order_[k]].min);
      hi = hi.cwiseMax(boxes_[order_[k]].max);
      clo = clo.cwiseMin(centroids_[order_[k]]);
      chi = chi.cwiseMax(centroids_[order_[k]]);
    }
    nodes_[index].lo = lo;
    nodes_[index].hi = hi;
    if (end - begin <= 4) {
      nodes_[index].first = begin;
      nodes_[index].count = end - begin;
      return index;
    }
    int axis = 0;
    (chi - clo).maxCoeff(&axis);
    const std::uint32_t mid = begin + (end - begin) / 2;
    std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                     [&](std::uint32_t x, std::uint32_t y) {
                       return centroids_[x][axis] < centroids_[y][axis] ||
                              (centroids_[x][axis] == centroids_[y][axis] && x < y);
                     });
    build_node(begin, mid);
    const std::uint32_t right = build_node(mid, end);
    nodes_[index].first = right;
    nodes_[index].count = 0;
    return index;
  }

  std::vector<BvhNode> nodes_;
  std::vector<std::uint32_t> order_;
  std::vector<Bounds> boxes_;
  std::vector<Point3> centroids_;
};

}  // namespace intervox::sim::detail
