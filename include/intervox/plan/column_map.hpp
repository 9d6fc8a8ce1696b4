#pragma once
/// \file
/// The 2D column map of the mobile platform (thesis 3.3.3): map cells (Cell2), the voxel grid
/// projected along z into one occupancy class per column (ColumnMap, project_columns), and the
/// metric centre of a map cell (cell_center). The exploration map (plan/exploration_map.hpp)
/// analyses a ColumnMap; the view samplers (plan/view_sampling.hpp) place candidates on its cells.

#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/point.hpp>
#include <intervox/core/types.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/grid/occupancy_grid.hpp>

#include <cmath>
#include <compare>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace intervox {

/// A cell of a 2D map: column (x, y) of the 3D grid, in map coordinates (0-based).
struct Cell2 {
  int x = 0;
  int y = 0;
  friend constexpr bool operator==(const Cell2&, const Cell2&) = default;
  friend constexpr auto operator<=>(const Cell2&, const Cell2&) = default;
};

/// A 2D occupancy map: one class per column of voxels. Cell (i, j) covers the voxel column with
/// keys x = key_origin.x + i, y = key_origin.y + j.
///
/// Thread safety: a plain value type.
class ColumnMap {
 public:
  ColumnMap() = default;
  /// A \p width x \p height map of Unknown cells.
  /// \throws InvalidArgument for a non-positive size or a resolution that is not finite and > 0.
  ColumnMap(int width, int height, double resolution, Key key_origin = {})
      : width_(width), height_(height), resolution_(resolution), key_origin_(key_origin) {
    if (width <= 0 || height <= 0 || static_cast<long long>(width) * height > (1LL << 28))
      ParamCheck("intervox::ColumnMap")
          .fail("size must be positive and at most 2^28 cells, got " + std::to_string(width) + "x" +
                std::to_string(height));
    ParamCheck("intervox::ColumnMap").positive("resolution", resolution);
    cells_.assign(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), Occupancy::Unknown);
  }

  /// Builds a map from rows of characters, top row first (so the picture reads as drawn):
  /// '#' occupied, '.' free, anything else unknown. Meant for tests and hand-drawn maps.
  /// \throws InvalidArgument if the rows are empty or of different lengths.
  static ColumnMap from_rows(const std::vector<std::string>& rows, double resolution = 0.1) {
    if (rows.empty() || rows.front().empty()) ParamCheck("intervox::ColumnMap::from_rows").fail("empty picture");
    const int w = static_cast<int>(rows.front().size());
    const int h = static_cast<int>(rows.size());
    ColumnMap m(w, h, resolution);
    for (int r = 0; r < h; ++r) {
      if (static_cast<int>(rows[r].size()) != w)
        ParamCheck("intervox::ColumnMap::from_rows").fail("row " + std::to_string(r) + " has a different length");
      for (int x = 0; x < w; ++x) {
        const char c = rows[r][x];
        m.set({x, h - 1 - r}, c == '#' ? Occupancy::Occupied : (c == '.' ? Occupancy::Free : Occupancy::Unknown));
      }
    }
    return m;
  }

  int width() const noexcept { return width_; }
  int height() const noexcept { return height_; }
  double resolution() const noexcept { return resolution_; }
  const Key& key_origin() const noexcept { return key_origin_; }
  bool contains(const Cell2& c) const noexcept { return c.x >= 0 && c.y >= 0 && c.x < width_ && c.y < height_; }
  std::size_t index(const Cell2& c) const noexcept {
    return static_cast<std::size_t>(c.y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(c.x);
  }
  Cell2 cell_of(std::size_t i) const noexcept {
    return {static_cast<int>(i % static_cast<std::size_t>(width_)),
            static_cast<int>(i / static_cast<std::size_t>(width_))};
  }
  /// The 8-connected flood fill over the map's cells: from the cell of index \p seed, every cell
  /// q inside the map, not yet marked in \p reached, entered by a step from an entered cell c for
  /// which `accept(q, index of q, index of c)` is true. Each entered cell (the seed always is) is
  /// marked in \p reached (one flag per cell; it may carry marks of earlier fills, which are not
  /// entered again) and passed to `visit(index)`. Depth first, each cell entered once.
  /// \tparam Accept callable as `bool(const Cell2&, std::size_t, std::size_t)`
  /// \tparam Visit callable as `void(std::size_t)`
  /// \throws InvalidArgument if \p reached does not hold size() flags or \p seed lies outside.
  template <class Accept, class Visit>
  void flood_fill(std::size_t seed, std::vector<std::uint8_t>& reached, Accept&& accept, Visit&& visit) const {
    if (reached.size() != cells_.size() || seed >= cells_.size())
      ParamCheck("intervox::ColumnMap::flood_fill").fail("need one flag per cell and a seed inside the map");
    std::vector<std::size_t> stack{seed};
    reached[seed] = 1;
    while (!stack.empty()) {
      const std::size_t ci = stack.back();
      const Cell2 c = cell_of(ci);
      stack.pop_back();
      visit(ci);
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const Cell2 q{c.x + dx, c.y + dy};
          if (!contains(q)) continue;
          const std::size_t qi = index(q);
          if (reached[qi] || !accept(q, qi, ci)) continue;
          reached[qi] = 1;
          stack.push_back(qi);
        }
    }
  }
  /// The class of a cell; Unknown outside the map.
  Occupancy at(const Cell2& c) const noexcept { return contains(c) ? cells_[index(c)] : Occupancy::Unknown; }
  /// Sets a cell; ignored outside the map.
  void set(const Cell2& c, Occupancy o) noexcept {
    if (contains(c)) cells_[index(c)] = o;
  }
  /// The map cell of the column holding key \p k (may lie outside the map).
  Cell2 cell_of_key(const Key& k) const noexcept { return {k.x - key_origin_.x, k.y - key_origin_.y}; }
  /// The x, y key of a map cell's column.
  Key key_of(const Cell2& c, std::int32_t z = 0) const noexcept {
    return {key_origin_.x + c.x, key_origin_.y + c.y, z};
  }
  std::size_t size() const noexcept { return cells_.size(); }

 private:
  int width_ = 0;
  int height_ = 0;
  double resolution_ = 1.0;
  Key key_origin_{};
  std::vector<Occupancy> cells_;
};

/// Projects a voxel grid along z (thesis 3.3.3): for each column of \p region (x, y extent), the
/// voxels whose centres lie in [region.min.z, region.max.z] decide the cell: any occupied voxel
/// makes it Occupied, all free makes it Free, otherwise Unknown. Exclude the floor by starting
/// region.min.z above it.
///
/// \tparam Grid a VoxelGrid, or any OccupancyView of one (geometry() and occupancy(Key)).
/// \throws InvalidArgument if region is not valid or holds no voxel centre in z.
template <OccupancyView Grid>
ColumnMap project_columns(const Grid& grid, const Bounds& region) {
  ParamCheck("intervox::project_columns").valid_bounds("region", region);
  const GridGeometry& g = grid.geometry();
  const KeyBox box = g.key_box(region);
  // Voxels whose centre lies inside [min.z, max.z].
  std::int32_t z0 = box.min.z, z1 = box.max.z;
  while (z0 <= z1 && g.center(Key{0, 0, z0}).z() < region.min.z()) ++z0;
  while (z1 >= z0 && g.center(Key{0, 0, z1}).z() > region.max.z()) --z1;
  if (z0 > z1) ParamCheck("intervox::project_columns").fail("the region's z range holds no voxel centre");
  ColumnMap map(static_cast<int>(box.extent(0)), static_cast<int>(box.extent(1)), g.resolution(),
                Key{box.min.x, box.min.y, 0});
  for (int y = 0; y < map.height(); ++y) {
    for (int x = 0; x < map.width(); ++x) {
      bool all_free = true;
      Occupancy cls = Occupancy::Free;
      for (std::int32_t z = z0; z <= z1; ++z) {
        const Occupancy o = grid.occupancy(Key{box.min.x + x, box.min.y + y, z});
        if (o == Occupancy::Occupied) {
          cls = Occupancy::Occupied;
          break;
        }
        if (o != Occupancy::Free) all_free = false;
      }
      if (cls != Occupancy::Occupied && !all_free) cls = Occupancy::Unknown;
      map.set({x, y}, cls);
    }
  }
  return map;
}

/// Offsets (dx, dy) of the cells whose centre lies within \p radius cells of a cell's centre,
/// (0, 0) included, row by row from (-r, -r) (a robot's footprint or zone on a ColumnMap).
inline std::vector<Cell2> disk_offsets(double radius) {
  std::vector<Cell2> d;
  if (!(radius >= 0)) return d;
  const int rc = static_cast<int>(std::floor(radius + 1e-9));
  const double r2 = radius * radius + 1e-9;
  for (int dy = -rc; dy <= rc; ++dy)
    for (int dx = -rc; dx <= rc; ++dx)
      if (double(dx * dx + dy * dy) <= r2) d.push_back({dx, dy});
  return d;
}

/// Metric centre (x, y, 0) of a map cell, given the grid geometry the map was projected from.
inline Point3 cell_center(const ColumnMap& m, const GridGeometry& g, const Cell2& c) {
  const Point3 p = g.center(m.key_of(c));
  return {p.x(), p.y(), 0.0};
}

}  // namespace intervox
