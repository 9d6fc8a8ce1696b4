#pragma once
/// \file
/// Internal: the floor plan of a random apartment: the outer walls' rectangle split into rooms (a
/// binary partition, so that one open doorway in each split's wall makes every room reachable),
/// the walls between rooms with their doorways and windows, the floor raster the robot must pass,
/// and the objects of the structure (floor, ceiling, walls around their openings, door leaves).
/// Not public API.

#include <intervox/core/key.hpp>
#include <intervox/sim/apartment_parts.hpp>
#include <intervox/sim/detail/apartment_draw.hpp>
#include <intervox/sim/detail/floor_raster.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace intervox::sim::detail {

/// A wall between two rooms: it lies at `at` along axis `axis` (0: the plane x = at) and runs over
/// [from, to] along the other axis; its openings are doorways or windows.
struct InnerWall {
  int axis = 0;
  double at = 0, from = 0, to = 0;
  struct Opening {
    double lo = 0, hi = 0, zlo = 0, zhi = 0;
    int doorway = -1;  ///< index into the doorways, or -1 for a window
  };
  std::vector<Opening> openings;
};

/// A side of a room: 0 south (y = min, facing +y), 1 north, 2 west (x = min, facing +x), 3 east.
struct RoomSide {
  int normal_axis = 1;    ///< the axis the wall faces along
  int along = 0;          ///< the axis the wall runs along
  double at = 0;          ///< the wall face's coordinate along normal_axis
  double sign = 1;        ///< into the room along normal_axis
  double lo = 0, hi = 0;  ///< the side's extent along `along`
};

inline RoomSide room_side(const Bounds& room, int side) {
  RoomSide s;
  s.normal_axis = side < 2 ? 1 : 0;
  s.along = 1 - s.normal_axis;
  s.sign = side % 2 == 0 ? 1.0 : -1.0;
  s.at = side % 2 == 0 ? room.min[s.normal_axis] : room.max[s.normal_axis];
  s.lo = room.min[s.along];
  s.hi = room.max[s.along];
  return s;
}

/// True if \p c lies within \p room's x-y extent.
inline bool inside_xy(const Bounds& room, const Point3& c) {
  return c.x() >= room.min.x() && c.x() <= room.max.x() && c.y() >= room.min.y() && c.y() <= room.max.y();
}

/// The floor plan (see the file comment).
class FloorPlan {
 public:
  /// A piece of an inner wall two rooms share: [lo, hi] along the wall, 0.25 m from its ends.
  struct Shared {
    int low = 0, high = 0;  ///< the rooms on its low and high side
    double lo = 0, hi = 0;
  };

  FloorPlan(const ApartmentOptions& o, Draws& draws) : o_(o), draws_(draws) {}

  /// Draws the rectangle, splits it into rooms and joins them; false if this draw found no
  /// doorway for some split (the caller draws again).
  bool draw() {
    draw_footprint();
    split_rooms();
    return join_rooms();
  }

  /// Further doorways: on each shared wall piece, with the option's chance, open or closed.
  void add_further_doorways() {
    for (std::size_t wi = 0; wi < walls_.size(); ++wi)
      for (const Shared& piece : shared_pieces(walls_[wi])) {
        if (!draws_.chance(o_.extra_door_probability)) continue;
        const double width = snap(draws_.uniform(o_.door_width_min, o_.door_width_max));
        if (const auto at = free_spot(walls_[wi], piece, width))
          add_doorway(wi, piece, *at, width,
                      draws_.chance(o_.closed_door_share) ? DoorwayState::Closed : DoorwayState::Open, false);
      }
  }

  /// Every shared piece of every inner wall, with its wall's index.
  std::vector<std::pair<std::size_t, Shared>> shared_pieces() const {
    std::vector<std::pair<std::size_t, Shared>> out;
    for (std::size_t wi = 0; wi < walls_.size(); ++wi)
      for (const Shared& s : shared_pieces(walls_[wi])) out.push_back({wi, s});
    return out;
  }

  /// A random spot of \p width on \p piece of wall \p wi, 0.4 m from the wall's other openings.
  std::optional<double> free_spot(std::size_t wi, const Shared& piece, double width) {
    return free_spot(walls_[wi], piece, width);
  }

  /// Adds a doorway on wall \p wi between the rooms of \p piece over [at, at + width]; returns its index.
  int add_doorway(std::size_t wi, const Shared& piece, double at, double width, DoorwayState state, bool tree) {
    InnerWall& w = walls_[wi];
    const int a = w.axis, t = 1 - a;
    Bounds opening;
    opening.min[a] = w.at - 0.5 * kWall;
    opening.max[a] = w.at + 0.5 * kWall;
    opening.min[t] = at;
    opening.max[t] = at + width;
    opening.min.z() = 0.0;
    opening.max.z() = o_.door_height;
    w.openings.push_back({at, at + width, 0.0, o_.door_height, static_cast<int>(doorways_.size())});
    doorways_.push_back({opening, state, {piece.low, piece.high}, std::nullopt, tree});
    return static_cast<int>(doorways_.size()) - 1;
  }

  /// Adds a window on wall \p wi over [at, at + width] and [zlo, zhi].
  void add_window(std::size_t wi, double at, double width, double zlo, double zhi) {
    walls_[wi].openings.push_back({at, at + width, zlo, zhi, -1});
  }

  /// The stretches of side \p side of room \p room free of openings (0.5 m from them) and corners.
  Intervals free_of_openings(int room, int side) const {
    const RoomSide s = room_side(rooms_[static_cast<std::size_t>(room)], side);
    Intervals free{{s.lo + 0.05, s.hi - 0.05}};
    for (const InnerWall& w : walls_) {
      if (w.axis != s.normal_axis || std::abs(w.at - (s.at - s.sign * 0.5 * kWall)) > 1e-6) continue;
      for (const InnerWall::Opening& op : w.openings) subtract(free, op.lo - 0.5, op.hi + 0.5);
    }
    return free;
  }

  /// The floor raster (5 cm) with the walls blocked and the open doorways passable.
  FloorRaster wall_raster() const {
    const double m = 2 * kWall;
    FloorRaster r(Point3(-m, -m, 0.0), width_ + 2 * m, depth_ + 2 * m, 0.05);
    r.set_box({{-m, -m, 0.0}, {width_ + m, 0.0, 1.0}});
    r.set_box({{-m, depth_, 0.0}, {width_ + m, depth_ + m, 1.0}});
    r.set_box({{-m, -m, 0.0}, {0.0, depth_ + m, 1.0}});
    r.set_box({{width_, -m, 0.0}, {width_ + m, depth_ + m, 1.0}});
    for (const InnerWall& w : walls_) {
      Bounds b;
      b.min[w.axis] = w.at - 0.5 * kWall;
      b.max[w.axis] = w.at + 0.5 * kWall;
      b.min[1 - w.axis] = w.from;
      b.max[1 - w.axis] = w.to;
      r.set_box(b);
    }
    // Open doorways are passable: the cells whose centres lie inside the opening (along the wall)
    // and a whole cell beyond it across (no row of the wall's blocking left by rounding).
    for (const ApartmentDoorway& d : doorways_) {
      if (d.state != DoorwayState::Open) continue;
      Bounds in = d.opening;
      const int t = along_wall(in);
      in.min[t] += 0.5 * r.cell() + 1e-9;
      in.max[t] -= 0.5 * r.cell() + 1e-9;
      in.min[1 - t] -= r.cell();
      in.max[1 - t] += r.cell();
      for (int y = 0; y < r.height(); ++y)
        for (int x = 0; x < r.width(); ++x)
          if (inside_xy(in, r.center(x, y))) r.set_box({r.center(x, y), r.center(x, y)}, false);
    }
    return r;
  }

  /// The axis a doorway's opening runs along (its longer side in x-y).
  static int along_wall(const Bounds& opening) {
    return opening.max.x() - opening.min.x() < opening.max.y() - opening.min.y() ? 1 : 0;
  }

  /// The structure's objects: floor, ceiling, outer walls, inner walls around their openings and
  /// the closed doorways' leaves, in that order.
  std::vector<ObjectSpec> structure() const {
    std::vector<ObjectSpec> out;
    const double m = kWall, H = o_.wall_height;
    out.push_back(box_spec("floor", {{-m, -m, -m}, {width_ + m, depth_ + m, 0.0}}));
    out.push_back(box_spec("ceiling", {{-m, -m, H}, {width_ + m, depth_ + m, H + m}}));
    out.push_back(box_spec("wall_south", {{-m, -m, 0.0}, {width_ + m, 0.0, H}}));
    out.push_back(box_spec("wall_north", {{-m, depth_, 0.0}, {width_ + m, depth_ + m, H}}));
    out.push_back(box_spec("wall_west", {{-m, 0.0, 0.0}, {0.0, depth_, H}}));
    out.push_back(box_spec("wall_east", {{width_, 0.0, 0.0}, {width_ + m, depth_, H}}));
    for (std::size_t wi = 0; wi < walls_.size(); ++wi) inner_wall(walls_[wi], "wall_" + std::to_string(wi), out);
    for (std::size_t d = 0; d < doorways_.size(); ++d) {
      if (doorways_[d].state != DoorwayState::Closed) continue;
      Bounds leaf = doorways_[d].opening;
      const int across = 1 - along_wall(leaf);
      const double mid = 0.5 * (leaf.min[across] + leaf.max[across]);
      leaf.min[across] = mid - 0.02;
      leaf.max[across] = mid + 0.02;
      ObjectSpec s = box_spec("door_" + std::to_string(d), leaf);
      s.doorway = static_cast<int>(d);
      out.push_back(s);
    }
    return out;
  }

  double width() const noexcept { return width_; }
  double depth() const noexcept { return depth_; }
  const std::vector<Bounds>& rooms() const noexcept { return rooms_; }
  const std::vector<InnerWall>& walls() const noexcept { return walls_; }
  const std::vector<ApartmentDoorway>& doorways() const noexcept { return doorways_; }

 private:
  static double area(const Bounds& b) { return (b.max.x() - b.min.x()) * (b.max.y() - b.min.y()); }

  /// The outer walls' inside: width x depth of the drawn area (at most max_area), large enough for
  /// the rooms wanted (two need a long side of two rooms, three or four both sides).
  void draw_footprint() {
    rooms_wanted_ = draws_.integer(o_.min_rooms, o_.max_rooms);
    double area = 0;
    for (int i = 0; i < rooms_wanted_; ++i) area += draws_.uniform(o_.room_area_min, o_.room_area_max);
    const double aspect = draws_.uniform(1.0, 1.8);
    const double two = 2.0 * kMinRoomSide + 0.2;
    if (o_.max_area < two * two) rooms_wanted_ = std::min(rooms_wanted_, 2);  // no room for three
    const double long_min = rooms_wanted_ >= 2 ? two : kMinRoomSide,
                 short_min = rooms_wanted_ >= 3 ? two : kMinRoomSide;
    area = std::clamp(area, std::max(15.0, long_min * short_min), o_.max_area);
    const auto down = [](double v) { return std::floor(v / 0.05 + 1e-9) * 0.05; };
    width_ = down(std::clamp(std::sqrt(area * aspect), long_min, area / short_min));
    depth_ = down(area / width_);  // >= short_min; width x depth <= area
    if (draws_.chance(0.5)) std::swap(width_, depth_);
  }

  /// One split: the largest region that can be split is, across its longer side if it can be.
  bool split_once() {
    std::vector<std::size_t> order(regions_.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return area(regions_[a]) > area(regions_[b]); });
    for (const std::size_t i : order) {
      const Bounds r = regions_[i];
      const int longer = r.max.x() - r.min.x() >= r.max.y() - r.min.y() ? 0 : 1;
      for (const int axis : {longer, 1 - longer}) {
        const double lo = r.min[axis] + kMinRoomSide, hi = r.max[axis] - kMinRoomSide;
        if (lo > hi) continue;
        const double at =
            std::clamp(snap(r.min[axis] + draws_.uniform(0.35, 0.65) * (r.max[axis] - r.min[axis])), lo, hi);
        Bounds a = r, b = r;
        a.max[axis] = at;
        b.min[axis] = at;
        regions_[i] = a;
        regions_.push_back(b);
        walls_.push_back({axis, at, r.min[1 - axis], r.max[1 - axis], {}});
        return true;
      }
    }
    return false;
  }

  /// Splits until the rooms wanted (or nothing can be split), then the rooms' free insides.
  void split_rooms() {
    regions_ = {Bounds{{0.0, 0.0, 0.0}, {width_, depth_, o_.wall_height}}};
    while (static_cast<int>(regions_.size()) < rooms_wanted_ && split_once()) {
    }
    rooms_.clear();
    for (const Bounds& r : regions_) {
      Bounds in = r;
      for (int a = 0; a < 2; ++a) {
        if (in.min[a] > 1e-9) in.min[a] += 0.5 * kWall;
        if (in.max[a] < (a == 0 ? width_ : depth_) - 1e-9) in.max[a] -= 0.5 * kWall;
      }
      rooms_.push_back(in);
    }
  }

  std::vector<Shared> shared_pieces(const InnerWall& w) const {
    std::vector<Shared> out;
    const int a = w.axis, t = 1 - a;
    for (std::size_t i = 0; i < regions_.size(); ++i) {
      if (std::abs(regions_[i].max[a] - w.at) > 1e-9) continue;
      for (std::size_t j = 0; j < regions_.size(); ++j) {
        if (std::abs(regions_[j].min[a] - w.at) > 1e-9) continue;
        const double lo = std::max({regions_[i].min[t], regions_[j].min[t], w.from}) + 0.25;
        const double hi = std::min({regions_[i].max[t], regions_[j].max[t], w.to}) - 0.25;
        if (hi > lo) out.push_back({static_cast<int>(i), static_cast<int>(j), lo, hi});
      }
    }
    return out;
  }

  std::optional<double> free_spot(const InnerWall& w, const Shared& piece, double width) {
    Intervals free{{piece.lo, piece.hi}};
    for (const InnerWall::Opening& op : w.openings) subtract(free, op.lo - 0.4, op.hi + 0.4);
    return draws_.pick(free, width);
  }

  /// One open doorway per wall joins the two sides of its split: every room is reachable.
  bool join_rooms() {
    for (std::size_t wi = 0; wi < walls_.size(); ++wi) {
      const double width = snap(draws_.uniform(o_.door_width_min, o_.door_width_max));
      std::vector<Shared> pieces;
      for (const Shared& s : shared_pieces(walls_[wi]))
        if (s.hi - s.lo >= width) pieces.push_back(s);
      if (pieces.empty()) return false;
      const Shared& piece = pieces[draws_.below(pieces.size())];
      const std::optional<double> at = free_spot(walls_[wi], piece, width);
      if (!at) return false;
      add_doorway(wi, piece, *at, width, DoorwayState::Open, true);
    }
    return true;
  }

  void inner_wall(const InnerWall& w, const std::string& name, std::vector<ObjectSpec>& out) const {
    const int a = w.axis, t = 1 - a;
    const auto piece = [&](const std::string& part, double lo, double hi, double zlo, double zhi) {
      if (hi - lo < 1e-6 || zhi - zlo < 1e-6) return;
      Bounds b;
      b.min[a] = w.at - 0.5 * kWall;
      b.max[a] = w.at + 0.5 * kWall;
      b.min[t] = lo;
      b.max[t] = hi;
      b.min.z() = zlo;
      b.max.z() = zhi;
      out.push_back(box_spec(name + part, b));
    };
    // A piece's suffix, appended to a string that owns its characters (GCC 12 at -O3 warns,
    // falsely, of overlapping copies in `"literal" + std::string&&`: -Wrestrict).
    const auto tag = [](const char* prefix, int n) {
      std::string s(prefix);
      s += std::to_string(n);
      return s;
    };
    std::vector<InnerWall::Opening> ops = w.openings;
    std::sort(ops.begin(), ops.end(), [](const auto& x, const auto& y) { return x.lo < y.lo; });
    double at = w.from;
    int k = 0;
    for (const InnerWall::Opening& op : ops) {
      piece(tag("_", k++), at, op.lo, 0.0, o_.wall_height);
      piece(tag("_below", k), op.lo, op.hi, 0.0, op.zlo);
      piece(tag("_above", k), op.lo, op.hi, op.zhi, o_.wall_height);
      at = op.hi;
    }
    piece(tag("_", k), at, w.to, 0.0, o_.wall_height);
  }

  const ApartmentOptions& o_;
  Draws& draws_;
  int rooms_wanted_ = 1;
  double width_ = 0, depth_ = 0;
  std::vector<Bounds> regions_;  ///< rooms between wall centre lines
  std::vector<Bounds> rooms_;    ///< free insides
  std::vector<InnerWall> walls_;
  std::vector<ApartmentDoorway> doorways_;
};

}  // namespace intervox::sim::detail
