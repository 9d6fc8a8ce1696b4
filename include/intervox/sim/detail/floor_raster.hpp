#pragma once
/// \file
/// Internal: a raster of a floor plan at a fixed cell size, with footprints blocked, the distance
/// of every cell to the nearest blocked cell, and the cells a round robot can reach from a start.
/// The apartment generator (sim/apartment.hpp) keeps its worlds passable with it. Not public API.

#include <intervox/core/key.hpp>
#include <intervox/core/point.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace intervox::sim::detail {

/// A floor raster over [origin, origin + size) in x-y, cells of `cell` metres.
///
/// Thread safety: a value type.
class FloorRaster {
 public:
  FloorRaster(const Point3& origin, double width, double depth, double cell)
      : origin_(origin),
        cell_(cell),
        nx_(std::max(1, static_cast<int>(std::ceil(width / cell)))),
        ny_(std::max(1, static_cast<int>(std::ceil(depth / cell)))),
        blocked_(static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_), 0) {}

  int width() const noexcept { return nx_; }
  int height() const noexcept { return ny_; }
  double cell() const noexcept { return cell_; }
  /// The centre of cell (x, y) on the floor (z = origin's).
  Point3 center(int x, int y) const noexcept { return origin_ + Point3((x + 0.5) * cell_, (y + 0.5) * cell_, 0.0); }
  /// The cell that holds \p p (clamped to the raster).
  std::pair<int, int> cell_of(const Point3& p) const noexcept {
    const int x = static_cast<int>(std::floor((p.x() - origin_.x()) / cell_));
    const int y = static_cast<int>(std::floor((p.y() - origin_.y()) / cell_));
    return {std::clamp(x, 0, nx_ - 1), std::clamp(y, 0, ny_ - 1)};
  }
  bool blocked(int x, int y) const noexcept { return blocked_[index(x, y)] != 0; }

  /// Blocks (or, with \p value false, unblocks) every cell whose centre lies in the x-y extent of
  /// \p box grown by half a cell (a thin footprint still blocks the cells it crosses).
  void set_box(const Bounds& box, bool value = true) {
    const double h = 0.5 * cell_;
    for_cells(box.min.x() - h, box.min.y() - h, box.max.x() + h, box.max.y() + h,
              [&](int x, int y, const Point3&) { blocked_[index(x, y)] = value ? 1 : 0; });
  }

  /// Blocks every cell whose centre lies within half a cell of the rectangle centred at \p c
  /// with half extents \p hx along \p u (a unit x-y direction) and \p hy across it.
  void block_rectangle(const Point3& c, const Point3& u, double hx, double hy) {
    const Point3 v(-u.y(), u.x(), 0.0);
    const double h = 0.5 * cell_, rx = std::abs(u.x()) * hx + std::abs(v.x()) * hy,
                 ry = std::abs(u.y()) * hx + std::abs(v.y()) * hy;
    for_cells(c.x() - rx - h, c.y() - ry - h, c.x() + rx + h, c.y() + ry + h, [&](int x, int y, const Point3& p) {
      const Point3 d = p - c;
      if (std::abs(d.x() * u.x() + d.y() * u.y()) <= hx + h && std::abs(d.x() * v.x() + d.y() * v.y()) <= hy + h)
        blocked_[index(x, y)] = 1;
    });
  }

  /// The distance from every cell's centre to the nearest blocked cell's centre (0 on blocked
  /// cells; a raster without a blocked cell gives about 2^20 cells everywhere), by a two-pass
  /// propagation of the nearest blocked cell (8SSEDT; exact but for rare corner cases
  /// where it overestimates by a fraction of a cell).
  std::vector<double> distances() const {
    const int big = 1 << 20;
    std::vector<std::pair<int, int>> near(blocked_.size(), {big, big});  // offset to the nearest blocked cell
    for (int y = 0; y < ny_; ++y)
      for (int x = 0; x < nx_; ++x)
        if (blocked(x, y)) near[index(x, y)] = {0, 0};
    const auto relax = [&](int x, int y, int dx, int dy) {
      const int qx = x + dx, qy = y + dy;
      if (qx < 0 || qy < 0 || qx >= nx_ || qy >= ny_) return;
      const auto& o = near[index(qx, qy)];
      const std::pair<int, int> cand{o.first + dx, o.second + dy};
      if (norm2(cand) < norm2(near[index(x, y)])) near[index(x, y)] = cand;
    };
    for (int y = 0; y < ny_; ++y) {
      for (int x = 0; x < nx_; ++x) {
        relax(x, y, -1, 0);
        relax(x, y, 0, -1);
        relax(x, y, -1, -1);
        relax(x, y, 1, -1);
      }
      for (int x = nx_ - 1; x >= 0; --x) relax(x, y, 1, 0);
    }
    for (int y = ny_ - 1; y >= 0; --y) {
      for (int x = nx_ - 1; x >= 0; --x) {
        relax(x, y, 1, 0);
        relax(x, y, 0, 1);
        relax(x, y, 1, 1);
        relax(x, y, -1, 1);
      }
      for (int x = 0; x < nx_; ++x) relax(x, y, -1, 0);
    }
    std::vector<double> out(blocked_.size());
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = std::sqrt(static_cast<double>(norm2(near[i]))) * cell_;
    return out;
  }

  /// The cells whose centre lies farther than \p radius from every blocked cell's centre and that
  /// are 8-connected to \p start through such cells (1 = reachable), given distances().
  std::vector<char> reachable(const std::vector<double>& dist, const Point3& start, double radius) const {
    std::vector<char> seen(blocked_.size(), 0);
    const auto [sx, sy] = cell_of(start);
    if (!(dist[index(sx, sy)] > radius)) return seen;
    std::vector<std::pair<int, int>> stack{{sx, sy}};
    seen[index(sx, sy)] = 1;
    while (!stack.empty()) {
      const auto [x, y] = stack.back();
      stack.pop_back();
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int qx = x + dx, qy = y + dy;
          if (qx < 0 || qy < 0 || qx >= nx_ || qy >= ny_) continue;
          const std::size_t q = index(qx, qy);
          if (seen[q] || !(dist[q] > radius)) continue;
          // No corner cutting: a diagonal step needs both side cells passable.
          if (dx != 0 && dy != 0 && (!(dist[index(x + dx, y)] > radius) || !(dist[index(x, y + dy)] > radius)))
            continue;
          seen[q] = 1;
          stack.push_back({qx, qy});
        }
    }
    return seen;
  }

  std::size_t index(int x, int y) const noexcept {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(nx_) + static_cast<std::size_t>(x);
  }

 private:
  static long long norm2(const std::pair<int, int>& v) noexcept {
    return static_cast<long long>(v.first) * v.first + static_cast<long long>(v.second) * v.second;
  }

  template <class F>
  void for_cells(double x0, double y0, double x1, double y1, F&& f) {
    const int cx0 = std::max(0, static_cast<int>(std::ceil((x0 - origin_.x()) / cell_ - 0.5)));
    const int cy0 = std::max(0, static_cast<int>(std::ceil((y0 - origin_.y()) / cell_ - 0.5)));
    const int cx1 = std::min(nx_ - 1, static_cast<int>(std::floor((x1 - origin_.x()) / cell_ - 0.5)));
    const int cy1 = std::min(ny_ - 1, static_cast<int>(std::floor((y1 - origin_.y()) / cell_ - 0.5)));
    for (int y = cy0; y <= cy1; ++y)
      for (int x = cx0; x <= cx1; ++x) f(x, y, center(x, y));
  }

  Point3 origin_;
  double cell_;
  int nx_, ny_;
  std::vector<char> blocked_;
};

}  // namespace intervox::sim::detail
