#pragma once
/// \file
/// Internal: where things may stand in a random apartment. Keeps the floor raster with every
/// piece placed so far, the stretches of wall already taken, and the rule that no piece may leave a
/// room unreachable for the robot or stand in front of a doorway. Not public API.

#include <intervox/core/key.hpp>
#include <intervox/core/plane_patch.hpp>
#include <intervox/sim/detail/apartment_draw.hpp>
#include <intervox/sim/detail/apartment_floor_plan.hpp>
#include <intervox/sim/detail/floor_raster.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <optional>
#include <vector>

namespace intervox::sim::detail {

/// A floor footprint: a rectangle centred at `center` with half extents hx along the unit x-y
/// direction u and hy across it.
struct Footprint {
  Point3 center = Point3::Zero();
  Point3 u = Point3::UnitX();
  double hx = 0, hy = 0;
};

/// The x-y footprint of an axis-aligned box.
inline Footprint footprint_of(const Bounds& b) {
  return {0.5 * (b.min + b.max), Point3::UnitX(), 0.5 * (b.max.x() - b.min.x()), 0.5 * (b.max.y() - b.min.y())};
}

/// True if two footprints grown by \p gap overlap (separating axes of two rectangles).
inline bool overlap(const Footprint& a, const Footprint& b, double gap) {
  const Point3 av(-a.u.y(), a.u.x(), 0.0), bv(-b.u.y(), b.u.x(), 0.0);
  const Point3 d = b.center - a.center;
  for (const Point3& axis : {a.u, av, b.u, bv}) {
    const double ra = a.hx * std::abs(a.u.dot(axis)) + a.hy * std::abs(av.dot(axis));
    const double rb = b.hx * std::abs(b.u.dot(axis)) + b.hy * std::abs(bv.dot(axis));
    if (std::abs(d.dot(axis)) > ra + rb + gap) return false;
  }
  return true;
}

/// A spot against a wall: room, side (RoomSide numbering) and where along the side it starts.
struct WallSpot {
  int room = 0, side = 0;
  double at = 0;
};

/// Where things may stand (see the file comment).
class Placer {
 public:
  /// \p passage: the robot's radius plus margin that must stay passable.
  Placer(const FloorPlan& plan, Draws& draws, double passage)
      : plan_(plan), draws_(draws), passage_(passage), raster_(plan.wall_raster()) {}

  /// Every room reachable from \p from (default: the most open cell of room 0) through cells
  /// farther than the passage from every blocked cell (at least 1 m² of each), and no such cell
  /// (beyond 0.5 m² in all) cut off from them.
  bool rooms_reachable(const FloorRaster& raster, const std::optional<Point3>& from = std::nullopt) const {
    const std::vector<double> dist = raster.distances();
    const std::vector<char> reach = raster.reachable(dist, from ? *from : most_open(raster, dist, 0), passage_);
    const std::vector<Bounds>& rooms = plan_.rooms();
    std::vector<double> area(rooms.size(), 0.0);
    double pockets = 0;
    const double cell_area = raster.cell() * raster.cell();
    for (int y = 0; y < raster.height(); ++y)
      for (int x = 0; x < raster.width(); ++x) {
        const std::size_t i = raster.index(x, y);
        if (!(dist[i] > passage_)) continue;
        if (!reach[i]) {
          pockets += cell_area;
          continue;
        }
        for (std::size_t r = 0; r < rooms.size(); ++r)
          if (inside_xy(rooms[r], raster.center(x, y))) area[r] += cell_area;
      }
    return pockets <= 0.5 && std::ranges::all_of(area, [](double a) { return a >= 1.0; });
  }

  /// True if \p f keeps clear of the doorways' zones and of every piece placed (by \p gap), and
  /// the rooms stay reachable with it.
  bool fits(const Footprint& f, double gap) const {
    for (const ApartmentDoorway& d : plan_.doorways()) {
      // No furniture in front of a doorway: 1.1 m on both sides, 0.3 m beyond its jambs.
      Bounds z = d.opening;
      const int t = FloorPlan::along_wall(z);
      z.min[t] -= 0.3;
      z.max[t] += 0.3;
      z.min[1 - t] -= 1.1;
      z.max[1 - t] += 1.1;
      if (overlap(f, footprint_of(z), 0.0)) return false;
    }
    for (const Footprint& p : pieces_)
      if (overlap(f, p, gap)) return false;
    FloorRaster trial = raster_;
    trial.block_rectangle(f.center, f.u, f.hx, f.hy);
    return rooms_reachable(trial);
  }

  /// Places \p f: blocks it in the raster.
  void commit(const Footprint& f) {
    pieces_.push_back(f);
    raster_.block_rectangle(f.center, f.u, f.hx, f.hy);
  }

  /// Marks [at, at + width] of a side as taken (\p spot's side).
  void take(const WallSpot& spot, double width) { used_.push_back({spot.room, spot.side, spot.at, spot.at + width}); }

  /// A spot of \p width against a random side of a random room (\p room >= 0: that room), away
  /// from corners, openings and what stands there already.
  std::optional<WallSpot> wall_spot(double width, int room = -1) {
    for (int tries = 0; tries < 12; ++tries) {
      const int r = room >= 0 ? room : static_cast<int>(draws_.below(plan_.rooms().size()));
      const int side = static_cast<int>(draws_.below(4));
      Intervals free = plan_.free_of_openings(r, side);
      for (const Used& u : used_)
        if (u.room == r && u.side == side) subtract(free, u.lo - 0.05, u.hi + 0.05);
      if (const auto at = draws_.pick(free, width)) return WallSpot{r, side, *at};
    }
    return std::nullopt;
  }

  /// A free-standing footprint of half extents \p hx x \p hy in a random room (\p room >= 0: that
  /// room), \p wall_gap from its walls and 0.9 m from every piece; any yaw with \p any_yaw, else
  /// along or across the axes (then centred on 5 cm).
  std::optional<Footprint> free_standing(double hx, double hy, bool any_yaw, double wall_gap, int room = -1) {
    for (int tries = 0; tries < (room >= 0 ? 8 : 12); ++tries) {
      const Bounds& r = plan_.rooms()[room >= 0 ? static_cast<std::size_t>(room) : draws_.below(plan_.rooms().size())];
      Footprint f;
      if (any_yaw) {
        const double yaw = draws_.uniform(0.0, 3.141592653589793);
        f.u = Point3(std::cos(yaw), std::sin(yaw), 0.0);
        f.hx = hx;
        f.hy = hy;
      } else {
        const bool turn = draws_.chance(0.5);
        f.hx = turn ? hy : hx;
        f.hy = turn ? hx : hy;
      }
      const double rx = std::abs(f.u.x()) * f.hx + std::abs(f.u.y()) * f.hy,
                   ry = std::abs(f.u.y()) * f.hx + std::abs(f.u.x()) * f.hy;
      const double x0 = r.min.x() + wall_gap + rx, x1 = r.max.x() - wall_gap - rx;
      const double y0 = r.min.y() + wall_gap + ry, y1 = r.max.y() - wall_gap - ry;
      if (x0 > x1 || y0 > y1) continue;
      const double x = draws_.uniform(x0, x1), y = draws_.uniform(y0, y1);
      f.center = any_yaw ? Point3(x, y, 0.0) : Point3(snap(x), snap(y), 0.0);
      if (fits(f, 0.9)) return f;
    }
    return std::nullopt;
  }

  /// The box of depth \p depth from \p zlo to \p zhi against the side at \p spot.
  Bounds against(const WallSpot& spot, double width, double depth, double zlo, double zhi) const {
    const RoomSide s = room_side(plan_.rooms()[static_cast<std::size_t>(spot.room)], spot.side);
    Bounds b;
    b.min[s.along] = spot.at;
    b.max[s.along] = spot.at + width;
    b.min[s.normal_axis] = s.sign > 0 ? s.at + 0.001 : s.at - depth;
    b.max[s.normal_axis] = s.sign > 0 ? s.at + depth : s.at - 0.001;
    b.min.z() = zlo;
    b.max.z() = zhi;
    return b;
  }

  /// A quad facing into the room of \p spot, \p offset in front of the side's wall face, over
  /// [at, at + width] along it and [zlo, zhi] in height; its plane in \p plane.
  ObjectSpec face_quad(const WallSpot& spot, double offset, double width, double zlo, double zhi,
                       PlanePatch& plane) const {
    const RoomSide s = room_side(plan_.rooms()[static_cast<std::size_t>(spot.room)], spot.side);
    ObjectSpec q;
    q.shape = ObjectSpec::Shape::Quad;
    q.corner = Point3::Zero();
    q.corner[s.along] = spot.at;
    q.corner[s.normal_axis] = s.at + s.sign * offset;
    q.corner.z() = zlo;
    q.edge_u = width * Point3::Unit(s.along);
    q.edge_v = (zhi - zlo) * Point3::UnitZ();
    plane.normal = s.sign * Point3::Unit(s.normal_axis);
    plane.axis_u = PlanePatch::floor_axis(plane.normal);
    plane.center = q.corner + 0.5 * q.edge_u + 0.5 * q.edge_v;
    plane.half_u = 0.5 * width;
    plane.half_v = 0.5 * (zhi - zlo);
    return q;
  }

  /// A start: a random cell \p clearance from every blocked cell, in a random room (the next
  /// room if that one has none), from which every room is reachable; the room in \p room.
  std::optional<Point3> start(double clearance, int& room) {
    const std::vector<double> dist = raster_.distances();
    const std::vector<Bounds>& rooms = plan_.rooms();
    const std::size_t first = draws_.below(rooms.size());
    for (std::size_t k = 0; k < rooms.size(); ++k) {
      const std::size_t r = (first + k) % rooms.size();
      std::vector<Point3> spots;
      for (int y = 0; y < raster_.height(); ++y)
        for (int x = 0; x < raster_.width(); ++x)
          if (inside_xy(rooms[r], raster_.center(x, y)) && dist[raster_.index(x, y)] >= clearance)
            spots.push_back(raster_.center(x, y));
      for (int tries = 0; tries < 8 && !spots.empty(); ++tries) {
        const std::size_t pick = draws_.below(spots.size());
        if (!rooms_reachable(raster_, spots[pick])) {
          spots.erase(spots.begin() + static_cast<std::ptrdiff_t>(pick));
          continue;
        }
        room = static_cast<int>(r);
        return Point3(spots[pick].x(), spots[pick].y(), 0.0);
      }
    }
    return std::nullopt;
  }

  const FloorRaster& raster() const noexcept { return raster_; }

 private:
  struct Used {
    int room = 0, side = 0;
    double lo = 0, hi = 0;
  };

  /// The centre of the most open cell of room \p room (largest distance to a blocked cell).
  Point3 most_open(const FloorRaster& raster, const std::vector<double>& dist, std::size_t room) const {
    double best = -1;
    Point3 seed = Point3::Zero();
    for (int y = 0; y < raster.height(); ++y)
      for (int x = 0; x < raster.width(); ++x)
        if (inside_xy(plan_.rooms()[room], raster.center(x, y)) && dist[raster.index(x, y)] > best) {
          best = dist[raster.index(x, y)];
          seed = raster.center(x, y);
        }
    return seed;
  }

  const FloorPlan& plan_;
  Draws& draws_;
  double passage_;
  FloorRaster raster_;
  std::vector<Footprint> pieces_;
  std::vector<Used> used_;
};

}  // namespace intervox::sim::detail
