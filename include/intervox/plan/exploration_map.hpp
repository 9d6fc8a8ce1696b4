#pragma once
/// \file
/// The 2D exploration map of the mobile platform (thesis 3.3.3): collision space, maybe-collision
/// space, reachable free space, borders and the closest frontier of a ColumnMap (the voxel grid
/// projected along z, plan/column_map.hpp).

#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/types.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/grid/occupancy_grid.hpp>
#include <intervox/plan/column_map.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <queue>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace intervox {

/// What a cell of the exploration map is, in the order of Table 3.2 of the thesis.
enum class MapLabel : std::uint8_t {
  Unknown = 0,         ///< unknown column, not in collision space (white)
  Occupied,            ///< an obstacle (black)
  CollisionSpace,      ///< within the robot radius of an obstacle (gray)
  ReachableFree,       ///< free, outside every collision space, reachable from the robot (blue)
  UnknownInCollision,  ///< unknown column inside the collision space (dark red)
  MaybeCollision,      ///< within the robot radius of an unknown column in reach (light green)
  Unreachable,         ///< free and outside collision spaces, but not reachable (dark green)
  Border,              ///< reachable and next to an unknown column (light red)
  /// A column of a lying region given up: a conflict region, or an unexplained group (explained
  /// planning), seen from enough directions or without a view from a new direction
  /// (MapHazards::unresolvable; teal, an addition to Table 3.2).
  Unresolvable,
};

/// Number of MapLabel values (arrays indexed by label).
inline constexpr std::size_t kMapLabelCount = static_cast<std::size_t>(MapLabel::Unresolvable) + 1;

/// Name of a label, as in the exploration map picture's legend (view/exploration_image.hpp).
constexpr std::string_view to_string(MapLabel l) noexcept {
  switch (l) {
    case MapLabel::Unknown:
      return "unknown";
    case MapLabel::Occupied:
      return "occupied";
    case MapLabel::CollisionSpace:
      return "collision space";
    case MapLabel::ReachableFree:
      return "reachable free";
    case MapLabel::UnknownInCollision:
      return "unknown in collision";
    case MapLabel::MaybeCollision:
      return "maybe collision";
    case MapLabel::Unreachable:
      return "unreachable";
    case MapLabel::Border:
      return "border";
    case MapLabel::Unresolvable:
      return "unresolvable";
  }
  return "?";
}

/// Columns the robot must keep away from although the projection may call them free, e.g. the
/// columns of conflict regions (thesis 5.5: space wrongly seen as free). Each hazard column and every cell within
/// robot_radius + margin of it is maybe-collision space: never traversable, except that a robot standing in it may
/// drive out over free cells that take it no closer to a hazard.
struct MapHazards {
  std::vector<Cell2> cells;         ///< hazard columns (map cells; outside the map: ignored)
  std::vector<Cell2> unresolvable;  ///< hazard columns labelled Unresolvable (hazards too)
  /// Hazard columns whose zone does not hide the frontier: a reachable cell next to the zone of
  /// such a column that is unknown is a border, so the unknown space can still be looked at from
  /// outside the zone (explained planning's unexplained columns). Zone cells in the collision
  /// space of an occupied column make no border: a real obstacle, not the hazard, keeps the robot
  /// off them (such columns behind a wall cannot be looked at from beside it).
  std::vector<Cell2> open;
  double margin = 0.0;  ///< m of safety margin beyond the robot radius, finite and >= 0
  bool empty() const noexcept { return cells.empty() && unresolvable.empty() && open.empty(); }
};

/// Parameters of the exploration map.
struct ExplorationMapParams {
  double robot_radius = 0.35;  ///< m; radius of the cylinder the robot needs to turn in place
  /// m kept beyond robot_radius from occupied and unknown columns (and hazards), finite, >= 0.
  /// The disks are measured between cell centres, while an obstacle may reach half a cell's
  /// diagonal beyond the centre of the cell that holds it: 0.71 cells here make the map as safe
  /// as the robot's true radius (the conflict-aware mobile planner sets that).
  double clearance = 0.0;
  /// The radius of the collision and maybe-collision disks: robot_radius + clearance.
  double keep_out() const noexcept { return robot_radius + clearance; }
  /// Space outside the map is not known to be free: cells within keep_out() of the map's edge
  /// (measured to the centres of the cells just outside) are maybe-collision space. A map cut at
  /// the faces of a room's walls then keeps the robot off walls whose voxels fell outside it or
  /// were mapped as mixed free voxels. Off: the edge is ignored (the first edition's rule).
  bool edge_is_unknown = true;
  /// Also find the passages (ExplorationMap::passages()): reachable cells beside maybe-collision
  /// space that hides unknown space, such as a doorway whose far side was seen by too few scans.
  /// Off (the default): not computed, passages() is empty. MobilePlannerParams::passage_views
  /// sets it.
  bool passages = false;
  /// m²; a hiding zone makes passages only if the unknown space it hides covers at least this
  /// much floor: its own unknown columns and the cells of every 8-connected set of cells labelled
  /// Unknown it touches (so small pockets beside furniture do not count). Finite, >= 0.
  double passage_min_hidden_area = 0.0;
};

/// The analysed exploration map: labels, path distances from the robot and borders.
///
/// Rules:
///  - collision space: cells (not occupied) whose centre lies within robot_radius of an occupied
///    cell's centre;
///  - an unknown cell in collision space is "in reach" if a free cell outside collision space lies
///    within robot_radius of it; maybe-collision space is every non-occupied, non-collision cell
///    within robot_radius of an unknown cell in reach (unknown space behind a wall is not in reach
///    and does not narrow the room);
///  - traversable: free cells (or cells listed as known free, e.g. the robot's own footprint)
///    outside collision and maybe-collision space; reachable: connected to the robot's cell through
///    traversable cells (8-connected, no corner cutting); the robot's own cell always counts as
///    traversable, and so does its escape zone when it stands in maybe-collision space: the free,
///    non-collision cells of that space connected to the robot's cell, within keep_out() of it or
///    reached by steps that each move farther from the nearest unknown column in reach (a robot
///    standing next to unknown columns, such as its cameras' blind zone, may drive out over known
///    free cells instead of being trapped, but never along unknown columns it has not seen);
///  - the map's edge (`edge_is_unknown`): non-occupied, non-collision cells whose centre lies
///    within robot_radius (+ clearance) of the centre of a cell just outside the map are
///    maybe-collision space too; a robot standing there may leave over cells no closer to the edge;
///  - path distance: shortest 8-connected path length in metres (Dijkstra, diagonal = sqrt 2 cells);
///  - border: a reachable cell with an Unknown cell among its 8 neighbours, or with an unreachable
///    cell of the zone of an unknown MapHazards::open column that is not in collision space;
///  - passage (ExplorationMapParams::passages): a reachable cell with an 8-neighbour in a
///    hiding zone. A hiding zone is an 8-connected set of cells labelled MaybeCollision for an
///    unknown column in reach (not for a hazard or the map's edge) that holds an unknown column or
///    touches a cell labelled Unknown, at least passage_min_hidden_area of floor in all (its
///    unknown columns and the Unknown components it touches): unknown space the maybe-collision
///    rule keeps the frontier rule from (a doorway whose far side was seen by too few scans
///    closes this way);
///  - hazards (MapHazards, optional): hazard columns and the cells within robot_radius + margin of
///    them are not traversable (labelled MaybeCollision unless occupied or in collision space; the
///    hazard columns themselves Unresolvable, or UnknownInCollision); the robot's escape from
///    them only passes cells no closer to a hazard than its own cell;
///  - the way back (`driven`, optional): cells the robot's centre passed on paths it drove are
///    passable while their column is free (known free cells included) and outside collision
///    space, whatever maybe-collision, hazard or edge zone evidence gathered since puts them in:
///    the robot's turning cylinder was clear there by the map it drove on, and its body passed. A
///    driven column that is no longer free (unknown, unexplained, occupied) closes it: the drive
///    there may have been on evidence found to lie since. Paths run through these cells
///    (path_to(), path_distance()), but a robot never stands on one for a view: such a cell keeps
///    the label the other rules give it, is not reachable() and no border; passable() is true.
///
/// Thread safety: immutable after construction; const members may be called concurrently.
class ExplorationMap {
 public:
  static constexpr double kUnreachable = std::numeric_limits<double>::infinity();

  /// Analyses \p columns for a robot standing in cell \p robot.
  /// \param known_free cells to treat as free whatever the projection says (the robot's footprint
  ///        at every position it stood on: the robot was there, so nothing is there).
  /// \throws InvalidArgument if robot lies outside the map or robot_radius is negative / not finite.
  /// \param hazards columns to keep away from (see the class comment).
  /// \param driven cells the robot's centre passed on paths it drove (the way back, see the class
  ///        comment); cells outside the map are ignored.
  /// \throws InvalidArgument also for a negative or non-finite hazard margin.
  ExplorationMap(ColumnMap columns, Cell2 robot, const ExplorationMapParams& params = {},
                 const std::vector<Cell2>& known_free = {}, const MapHazards& hazards = {},
                 const std::vector<Cell2>& driven = {})
      : columns_(std::move(columns)), robot_(robot), params_(params) {
    const ParamCheck check("intervox::ExplorationMap");
    check.nonnegative("hazards.margin", hazards.margin);
    if (!columns_.contains(robot))
      check.fail("robot cell (" + std::to_string(robot.x) + ", " + std::to_string(robot.y) + ") lies outside the map");
    check.nonnegative("robot_radius", params.robot_radius);
    check.nonnegative("clearance", params.clearance);
    check.nonnegative("passage_min_hidden_area", params.passage_min_hidden_area);
    for (const Cell2& c : known_free)
      if (columns_.contains(c) && columns_.at(c) != Occupancy::Occupied) columns_.set(c, Occupancy::Free);
    std::vector<std::uint8_t> driven_mask(columns_.size(), 0);
    for (const Cell2& c : driven)
      if (columns_.contains(c)) driven_mask[columns_.index(c)] = 1;
    analyse(hazards, driven_mask);
  }

  const ColumnMap& columns() const noexcept { return columns_; }
  int width() const noexcept { return columns_.width(); }
  int height() const noexcept { return columns_.height(); }
  double resolution() const noexcept { return columns_.resolution(); }
  const Cell2& robot() const noexcept { return robot_; }
  const ExplorationMapParams& params() const noexcept { return params_; }

  /// The label of a cell (Unknown outside the map).
  MapLabel label(const Cell2& c) const noexcept {
    return columns_.contains(c) ? labels_[columns_.index(c)] : MapLabel::Unknown;
  }
  /// True for ReachableFree and Border cells: connected to the robot's cell, and a place to stand.
  bool reachable(const Cell2& c) const noexcept { return passable(c) && !way_back_[columns_.index(c)]; }
  /// True if a path from the robot's cell reaches \p c: reachable() cells and the cells of the way
  /// back (driven paths) connected to it.
  bool passable(const Cell2& c) const noexcept {
    return columns_.contains(c) && std::isfinite(distance_[columns_.index(c)]);
  }
  /// Number of cells a path passes only as the way back (passable, not reachable).
  std::size_t way_back_cells() const noexcept {
    return static_cast<std::size_t>(std::count(way_back_.begin(), way_back_.end(), std::uint8_t{1}));
  }
  /// Path length in metres from the robot over passable cells; kUnreachable if not passable.
  double path_distance(const Cell2& c) const noexcept {
    return columns_.contains(c) ? distance_[columns_.index(c)] : kUnreachable;
  }
  /// A shortest drivable path from the robot's cell to \p c: cells (8-connected, no corner
  /// cutting, through passable cells only: reachable ones and the way back), the robot's cell first
  /// and \p c last; empty if \p c is not passable. Its length (straight steps one cell, diagonal
  /// steps sqrt 2 cells) is path_distance(c).
  std::vector<Cell2> path_to(const Cell2& c) const {
    if (!passable(c)) return {};
    std::vector<Cell2> path{c};
    const double res = columns_.resolution();
    const double diag = res * std::sqrt(2.0);
    Cell2 cur = c;
    while (!(cur == robot_)) {
      const double d = distance_[columns_.index(cur)];
      std::optional<Cell2> best;
      double best_d = kUnreachable;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          if (dx == 0 && dy == 0) continue;
          const Cell2 q{cur.x + dx, cur.y + dy};
          if (!passable(q)) continue;
          if (dx != 0 && dy != 0 && !(passable({cur.x + dx, cur.y}) && passable({cur.x, cur.y + dy}))) continue;
          const double dq = distance_[columns_.index(q)];
          const double step = (dx != 0 && dy != 0) ? diag : res;
          // A predecessor on a shortest path: its distance plus the step gives ours.
          if (std::abs(dq + step - d) <= 1e-9 * std::max(1.0, d) && dq < best_d) {
            best = q;
            best_d = dq;
          }
        }
      if (!best) break;  // cannot happen for distances computed by analyse()
      cur = *best;
      path.push_back(cur);
    }
    std::reverse(path.begin(), path.end());
    return path;
  }
  /// Every border cell, by increasing path distance (ties: lower y, then lower x).
  const std::vector<Cell2>& borders() const noexcept { return borders_; }
  /// Every passage cell (ExplorationMapParams::passages; see the class comment), by increasing
  /// path distance (ties: lower y, then lower x); empty unless that option is on.
  const std::vector<Cell2>& passages() const noexcept { return passages_; }
  /// The closest border cell by path distance (the next frontier), if any.
  std::optional<Cell2> closest_frontier() const {
    if (borders_.empty()) return std::nullopt;
    return borders_.front();
  }
  /// Number of cells with label \p l.
  std::size_t count(MapLabel l) const noexcept {
    return static_cast<std::size_t>(std::count(labels_.begin(), labels_.end(), l));
  }
  /// Radius in cells used for the collision and maybe-collision disks.
  int radius_cells() const noexcept { return radius_cells_; }

 private:
  // Offsets (dx, dy) of the cells whose centre lies within the robot radius (excluding (0, 0)).
  std::vector<Cell2> disk() const {
    std::vector<Cell2> d = disk_offsets(params_.keep_out() / columns_.resolution());
    std::erase(d, Cell2{0, 0});
    return d;
  }

  /// The escape zones' flood fill (ColumnMap::flood_fill, each zone with its own predicate):
  /// one flag per cell of the map (1: reached from the cell of index \p seed; the seed always is).
  template <class Accept>
  std::vector<std::uint8_t> flood_fill(std::size_t seed, Accept&& accept) const {
    std::vector<std::uint8_t> reached(columns_.size(), 0);
    columns_.flood_fill(seed, reached, accept, [](std::size_t) {});
    return reached;
  }

  /// What analyse() derives per cell (index) before the paths: the hazard zone, collision and
  /// maybe-collision space, the edge zone and the escape zones.
  struct Zones {
    std::vector<std::uint8_t> hazard;  ///< 1: a hazard column (cells, open), 2: an unresolvable one
    std::vector<long long>
        hazard_d2;  ///< squared distance (cells) to the nearest hazard column within its zone; -1 outside
    std::vector<std::uint8_t> open_zone;  ///< in the zone of an unknown MapHazards::open column
    std::vector<std::uint8_t> collision;  ///< collision space of the occupied columns
    std::vector<std::uint8_t> maybe;      ///< maybe-collision space of unknown columns in reach
    std::vector<long long> maybe_d2;  ///< squared distance (cells) to the nearest unknown column in reach; -1 outside
    std::vector<int> edge_out;  ///< distance (cells) to the nearest centre outside the map, 0 outside the edge zone
    std::vector<std::uint8_t> escape;         ///< the escape zone from maybe-collision space
    std::vector<std::uint8_t> hazard_escape;  ///< the escape zone from the hazard zone
    std::size_t robot_index = 0;
    int robot_edge = 0;  ///< edge_out of the robot's cell
  };

  /// The phases of the analysis: zones, shortest paths, labels, passages.
  void analyse(const MapHazards& hazards, const std::vector<std::uint8_t>& driven) {
    Zones z;
    hazard_zone(hazards, z);
    radius_cells_ = static_cast<int>(std::floor(params_.keep_out() / columns_.resolution() + 1e-9));
    collision_zones(z);
    edge_zone(z);
    escape_zones(z);
    shortest_paths(z, driven);
    label_cells(z, driven);
    sort_by_distance(borders_);
    if (!params_.passages) return;
    find_passages(z);
  }

  /// Hazard zone: squared distance (cells) to the nearest hazard column within robot_radius +
  /// margin; -1 outside the zone.
  void hazard_zone(const MapHazards& hazards, Zones& z) const {
    const std::size_t n = columns_.size();
    z.hazard.assign(n, 0);
    z.hazard_d2.assign(n, -1);
    z.open_zone.assign(n, 0);
    if (hazards.empty()) return;
    const double hr = (params_.keep_out() + hazards.margin) / columns_.resolution();
    const int hc = static_cast<int>(std::floor(hr + 1e-9));
    for (int pass = 0; pass < 3; ++pass)
      for (const Cell2& c : pass == 0 ? hazards.cells : pass == 1 ? hazards.unresolvable : hazards.open) {
        if (!columns_.contains(c)) continue;
        z.hazard[columns_.index(c)] = pass == 1 ? 2 : std::max<std::uint8_t>(z.hazard[columns_.index(c)], 1);
        const bool see_through = pass == 2 && columns_.at(c) == Occupancy::Unknown;
        for (int dy = -hc; dy <= hc; ++dy)
          for (int dx = -hc; dx <= hc; ++dx) {
            const long long d2 = 1LL * dx * dx + 1LL * dy * dy;
            const Cell2 q{c.x + dx, c.y + dy};
            if (double(d2) > hr * hr + 1e-9 || !columns_.contains(q)) continue;
            long long& cur = z.hazard_d2[columns_.index(q)];
            if (cur < 0 || d2 < cur) cur = d2;
            if (see_through) z.open_zone[columns_.index(q)] = 1;
          }
      }
  }

  /// Collision space (the robot's disk around every occupied column) and maybe-collision space
  /// (the disk around every unknown column in collision space that open free space reaches).
  void collision_zones(Zones& z) const {
    const std::size_t n = columns_.size();
    const std::vector<Cell2> offsets = disk();
    z.collision.assign(n, 0);
    z.maybe.assign(n, 0);
    z.maybe_d2.assign(n, -1);
    for (std::size_t i = 0; i < n; ++i) {
      if (columns_.at(columns_.cell_of(i)) != Occupancy::Occupied) continue;
      const Cell2 c = columns_.cell_of(i);
      for (const Cell2& o : offsets) {
        const Cell2 q{c.x + o.x, c.y + o.y};
        if (columns_.contains(q)) z.collision[columns_.index(q)] = 1;
      }
    }
    // Unknown cells in collision space that are in reach of open free space get a maybe-collision disk.
    for (std::size_t i = 0; i < n; ++i) {
      const Cell2 c = columns_.cell_of(i);
      if (columns_.at(c) != Occupancy::Unknown || !z.collision[i]) continue;
      bool in_reach = false;
      for (const Cell2& o : offsets) {
        const Cell2 q{c.x + o.x, c.y + o.y};
        if (columns_.contains(q) && is_open_free(z, columns_.index(q))) {
          in_reach = true;
          break;
        }
      }
      if (!in_reach) continue;
      for (const Cell2& o : offsets) {
        const Cell2 q{c.x + o.x, c.y + o.y};
        if (!columns_.contains(q)) continue;
        const std::size_t qi = columns_.index(q);
        z.maybe[qi] = 1;
        const long long d2 = 1LL * o.x * o.x + 1LL * o.y * o.y;
        if (z.maybe_d2[qi] < 0 || d2 < z.maybe_d2[qi]) z.maybe_d2[qi] = d2;
      }
    }
  }

  /// The map's edge: the cells just outside count as unknown columns in reach (edge_is_unknown).
  void edge_zone(Zones& z) const {
    const int w = columns_.width(), h = columns_.height();
    const std::size_t n = columns_.size();
    z.edge_out.assign(n, 0);
    if (!params_.edge_is_unknown) return;
    const double r = params_.keep_out() / columns_.resolution() + 1e-9;
    for (std::size_t i = 0; i < n; ++i) {
      const Cell2 c = columns_.cell_of(i);
      const int out = std::min(std::min(c.x + 1, w - c.x), std::min(c.y + 1, h - c.y));
      if (double(out) <= r) z.edge_out[i] = out;
    }
  }

  /// The escape zones of a robot standing in maybe-collision space or in a hazard zone.
  void escape_zones(Zones& z) const {
    const std::size_t n = columns_.size();
    z.robot_index = columns_.index(robot_);
    const std::size_t robot_index = z.robot_index;
    // A robot standing in the edge zone may leave it over cells no closer to the edge.
    z.robot_edge = z.edge_out[robot_index];
    // Escape zone: a robot standing in maybe-collision space (unknown columns close by, e.g. the
    // blind zone of its own cameras) may drive out of it over open free cells of that space: within
    // keep_out() of its own cell (the footprint it stands on) any connected one, beyond it only
    // cells farther from the nearest unknown column in reach than the cell they are entered from
    // (it drives away, never along unseen columns). A robot merely next to that space never
    // enters it.
    z.escape.assign(n, 0);
    if (z.maybe[robot_index]) {
      const double foot = params_.keep_out() / columns_.resolution();
      const double foot2 = foot * foot + 1e-9;
      z.escape = flood_fill(robot_index, [&](const Cell2& q, std::size_t qi, std::size_t ci) {
        if (!z.maybe[qi] || !is_open_free(z, qi)) return false;
        const double fx = q.x - robot_.x, fy = q.y - robot_.y;
        return !(z.maybe_d2[qi] <= z.maybe_d2[ci] && fx * fx + fy * fy > foot2);
      });
    }
    // Escape from the hazard zone: open free cells of the zone connected to the robot's cell that
    // lie no closer to a hazard than the robot's cell.
    z.hazard_escape.assign(n, 0);
    if (z.hazard_d2[robot_index] >= 0) {
      const long long own = z.hazard_d2[robot_index];
      z.hazard_escape = flood_fill(robot_index, [&](const Cell2&, std::size_t qi, std::size_t) {
        return !(z.hazard_d2[qi] < own || z.hazard[qi] || !is_open_free(z, qi));
      });
    }
  }

  /// A free column outside collision space.
  bool is_open_free(const Zones& z, std::size_t i) const {
    return columns_.at(columns_.cell_of(i)) == Occupancy::Free && !z.collision[i];
  }
  /// A cell the robot may stand on: its own, or an open free one outside maybe-collision, hazard
  /// and edge zones but for their escape zones.
  bool standable(const Zones& z, std::size_t i) const {
    return i == z.robot_index ||
           (is_open_free(z, i) && (!z.maybe[i] || z.escape[i]) && (z.hazard_d2[i] < 0 || z.hazard_escape[i]) &&
            (z.edge_out[i] == 0 || (z.robot_edge > 0 && z.edge_out[i] >= z.robot_edge)));
  }
  /// The way back: a driven cell whose column is free and outside collision space.
  bool way_back_cell(const Zones& z, const std::vector<std::uint8_t>& driven, std::size_t i) const {
    return driven[i] && is_open_free(z, i) && !standable(z, i);
  }

  /// Dijkstra from the robot's cell over 8-connected standable and way-back cells, no corner cutting.
  void shortest_paths(const Zones& z, const std::vector<std::uint8_t>& driven) {
    const std::size_t n = columns_.size();
    auto traversable = [&](const Cell2& c) {
      if (!columns_.contains(c)) return false;
      const std::size_t i = columns_.index(c);
      return standable(z, i) || way_back_cell(z, driven, i);
    };
    distance_.assign(n, kUnreachable);
    using Item = std::pair<double, std::size_t>;
    std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
    distance_[z.robot_index] = 0.0;
    queue.push({0.0, z.robot_index});
    const double res = columns_.resolution();
    const double diag = res * std::sqrt(2.0);
    while (!queue.empty()) {
      const auto [d, i] = queue.top();
      queue.pop();
      if (d > distance_[i]) continue;
      const Cell2 c = columns_.cell_of(i);
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          if (dx == 0 && dy == 0) continue;
          const Cell2 q{c.x + dx, c.y + dy};
          if (!traversable(q)) continue;
          if (dx != 0 && dy != 0 && !(traversable({c.x + dx, c.y}) && traversable({c.x, c.y + dy}))) continue;
          const double nd = d + ((dx != 0 && dy != 0) ? diag : res);
          const std::size_t qi = columns_.index(q);
          if (nd < distance_[qi]) {
            distance_[qi] = nd;
            queue.push({nd, qi});
          }
        }
      }
    }
  }

  /// The way back's cells and every cell's label; the border cells (unsorted).
  void label_cells(const Zones& z, const std::vector<std::uint8_t>& driven) {
    const std::size_t n = columns_.size();
    labels_.assign(n, MapLabel::Unknown);
    way_back_.assign(n, 0);
    for (std::size_t i = 0; i < n; ++i)
      way_back_[i] = std::isfinite(distance_[i]) && way_back_cell(z, driven, i) ? 1 : 0;
    for (std::size_t i = 0; i < n; ++i) {
      const Cell2 c = columns_.cell_of(i);
      const Occupancy o = columns_.at(c);
      MapLabel& l = labels_[i];
      if (std::isfinite(distance_[i]) && !way_back_[i]) {
        l = MapLabel::ReachableFree;
        bool next_to_unknown = false;
        for (int dy = -1; dy <= 1 && !next_to_unknown; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const Cell2 q{c.x + dx, c.y + dy};
            if ((dx != 0 || dy != 0) && columns_.contains(q) &&
                (columns_.at(q) == Occupancy::Unknown ||
                 (z.open_zone[columns_.index(q)] && !z.collision[columns_.index(q)] && !reachable(q)))) {
              next_to_unknown = true;
              break;
            }
          }
        if (next_to_unknown) {
          l = MapLabel::Border;
          borders_.push_back(c);
        }
      } else if (z.hazard[i] == 2) {
        l = MapLabel::Unresolvable;
      } else if (o == Occupancy::Occupied) {
        l = MapLabel::Occupied;
      } else if (z.hazard[i] == 1) {
        l = MapLabel::UnknownInCollision;
      } else if (z.collision[i]) {
        l = o == Occupancy::Unknown ? MapLabel::UnknownInCollision : MapLabel::CollisionSpace;
      } else if (z.maybe[i] || z.hazard_d2[i] >= 0 || z.edge_out[i] > 0) {
        l = MapLabel::MaybeCollision;
      } else if (o == Occupancy::Free) {
        l = MapLabel::Unreachable;
      } else {
        l = MapLabel::Unknown;
      }
    }
  }

  /// Sorts \p cells by increasing path distance (stable: ties keep their order).
  void sort_by_distance(std::vector<Cell2>& cells) const {
    const auto by_distance = [&](const Cell2& a, const Cell2& b) {
      return distance_[columns_.index(a)] < distance_[columns_.index(b)];
    };
    std::stable_sort(cells.begin(), cells.end(), by_distance);
  }

  static constexpr std::uint32_t kNoSet = std::numeric_limits<std::uint32_t>::max();
  /// The 8-connected sets of cells labelled Unknown: each cell's set (kNoSet if none) and each
  /// set's number of cells.
  struct UnknownSets {
    std::vector<std::uint32_t> of;
    std::vector<std::size_t> cells;
  };
  UnknownSets unknown_sets() const {
    const std::size_t n = columns_.size();
    UnknownSets u{std::vector<std::uint32_t>(n, kNoSet), {}};
    std::vector<std::uint8_t> reached(n, 0);
    for (std::size_t s = 0; s < n; ++s) {
      if (reached[s] || labels_[s] != MapLabel::Unknown) continue;
      const auto id = static_cast<std::uint32_t>(u.cells.size());
      u.cells.push_back(0);
      columns_.flood_fill(
          s, reached, [&](const Cell2&, std::size_t qi, std::size_t) { return labels_[qi] == MapLabel::Unknown; },
          [&](std::size_t i) {
            u.of[i] = id;
            ++u.cells[id];
          });
    }
    return u;
  }

  /// Hiding zones: sets of maybe-collision cells of unknown columns in reach (not hazard or edge
  /// zones) whose unknown columns and touched Unknown sets cover passage_min_hidden_area.
  std::vector<std::uint8_t> hiding_zones(const Zones& z) const {
    const std::size_t n = columns_.size();
    const UnknownSets unknown = unknown_sets();
    const auto zone_cell = [&](std::size_t i) {
      return labels_[i] == MapLabel::MaybeCollision && z.maybe[i] && z.hazard_d2[i] < 0 && z.edge_out[i] == 0;
    };
    const double cell_area = columns_.resolution() * columns_.resolution();
    std::vector<std::uint8_t> seen(n, 0), hiding(n, 0);
    std::vector<std::size_t> zone;
    std::vector<std::uint32_t> touched;
    for (std::size_t s = 0; s < n; ++s) {
      if (seen[s] || !zone_cell(s)) continue;
      zone.clear();
      touched.clear();
      std::size_t hidden = 0;
      columns_.flood_fill(
          s, seen, [&](const Cell2&, std::size_t qi, std::size_t) { return zone_cell(qi); },
          [&](std::size_t i) {
            zone.push_back(i);
            const Cell2 c = columns_.cell_of(i);
            if (columns_.at(c) == Occupancy::Unknown) ++hidden;
            for (int dy = -1; dy <= 1; ++dy)
              for (int dx = -1; dx <= 1; ++dx) {
                const Cell2 q{c.x + dx, c.y + dy};
                if (!columns_.contains(q)) continue;
                const std::uint32_t id = unknown.of[columns_.index(q)];
                if (id != kNoSet && std::find(touched.begin(), touched.end(), id) == touched.end()) {
                  touched.push_back(id);
                  hidden += unknown.cells[id];
                }
              }
          });
      if (hidden > 0 && double(hidden) * cell_area >= params_.passage_min_hidden_area - 1e-12)
        for (const std::size_t i : zone) hiding[i] = 1;
    }
    return hiding;
  }

  /// The passage cells: reachable cells next to a hiding zone, by path distance.
  void find_passages(const Zones& z) {
    const std::size_t n = columns_.size();
    const std::vector<std::uint8_t> hiding = hiding_zones(z);
    for (std::size_t i = 0; i < n; ++i) {
      if (!std::isfinite(distance_[i]) || way_back_[i]) continue;
      const Cell2 c = columns_.cell_of(i);
      bool next_to = false;
      for (int dy = -1; dy <= 1 && !next_to; ++dy)
        for (int dx = -1; dx <= 1 && !next_to; ++dx) {
          const Cell2 q{c.x + dx, c.y + dy};
          next_to = (dx != 0 || dy != 0) && columns_.contains(q) && hiding[columns_.index(q)];
        }
      if (next_to) passages_.push_back(c);
    }
    sort_by_distance(passages_);
  }

  ColumnMap columns_;
  Cell2 robot_;
  ExplorationMapParams params_;
  int radius_cells_ = 0;
  std::vector<MapLabel> labels_;
  std::vector<double> distance_;
  std::vector<std::uint8_t> way_back_;  ///< 1: passable only as the way back (see the class comment)
  std::vector<Cell2> borders_;
  std::vector<Cell2> passages_;
};

}  // namespace intervox
