// Exploration map (thesis 3.3.3) on hand-drawn maps: '#' occupied, '.' free, '?' unknown.
// Rows are written top first; cell (x, y) counts y from the bottom row.
#include <catch2/catch.hpp>
#include <intervox/intervox.hpp>
#include <intervox/plan/exploration_map.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace iv = intervox;
using Approx = Catch::Detail::Approx;
using L = iv::MapLabel;

namespace {
iv::ExplorationMap analyse(const std::vector<std::string>& rows, iv::Cell2 robot, double radius) {
  iv::ExplorationMapParams p;
  p.robot_radius = radius;
  return iv::ExplorationMap(iv::ColumnMap::from_rows(rows, 0.1), robot, p);
}
}  // namespace

TEST_CASE("the closest frontier is the border cell with the shortest path, not the nearest in a line", "[plan][map]") {
  // The robot stands at (1, 1). The unknown cell at (3, 1) is 0.2 m away in a line but its border
  // cell (4, 1) is 1.7 m away along the corridor; the unknown cell at (9, 4) is reached in 1.0 m.
  const auto m =
      analyse({"##########", "#........?", "#.######.#", "#.######.#", "#.#?.....#", "##########"}, {1, 1}, 0.0);
  REQUIRE(m.closest_frontier().has_value());
  CHECK(*m.closest_frontier() == iv::Cell2{8, 4});
  CHECK(m.path_distance({8, 4}) == Approx(1.0));
  CHECK(m.label({4, 1}) == L::Border);
  CHECK(m.path_distance({4, 1}) == Approx(1.7));
  CHECK(m.label({8, 3}) == L::Border);  // touches (9, 4) diagonally
  CHECK(m.label({5, 1}) == L::ReachableFree);
  // Borders come sorted by path distance.
  const auto& b = m.borders();
  REQUIRE(b.size() == 3);
  for (std::size_t i = 1; i < b.size(); ++i) CHECK(m.path_distance(b[i - 1]) <= m.path_distance(b[i]));
  CHECK(b.back() == iv::Cell2{4, 1});
}

TEST_CASE("free space behind a wall is unreachable and offers no frontier", "[plan][map]") {
  const auto m = analyse({"#########", "#...#...?", "#...#...#", "#########"}, {1, 1}, 0.0);
  CHECK(m.label({2, 2}) == L::ReachableFree);
  CHECK(m.label({6, 2}) == L::Unreachable);
  CHECK(m.label({7, 2}) == L::Unreachable);  // next to unknown, but not reachable: not a border
  CHECK(m.label({4, 1}) == L::Occupied);
  CHECK_FALSE(m.closest_frontier().has_value());
  CHECK(m.count(L::Border) == 0);
  CHECK_FALSE(m.reachable({6, 2}));
  CHECK(m.path_distance({6, 2}) == iv::ExplorationMap::kUnreachable);
}

TEST_CASE("a door narrower than the robot blocks the frontier behind it", "[plan][map]") {
  const std::vector<std::string> rows{"###########", "#...#.....?", "#.........?", "#...#.....?", "###########"};
  SECTION("a point robot passes") {
    const auto m = analyse(rows, {2, 2}, 0.0);
    REQUIRE(m.closest_frontier().has_value());
    CHECK(*m.closest_frontier() == iv::Cell2{9, 2});
  }
  SECTION("a robot of one cell radius does not: the door is collision space") {
    const auto m = analyse(rows, {2, 2}, 0.1);
    CHECK(m.radius_cells() == 1);
    CHECK(m.label({4, 2}) == L::CollisionSpace);
    CHECK(m.label({1, 1}) == L::CollisionSpace);
    CHECK(m.label({2, 2}) == L::ReachableFree);
    CHECK(m.label({7, 2}) == L::Unreachable);
    CHECK_FALSE(m.closest_frontier().has_value());
  }
}

TEST_CASE("an unknown column in collision space gets a maybe-collision space when it is in reach", "[plan][map]") {
  const auto m = analyse({"#########", "#.......#", "#.......#", "#.......#", "#...?...#", "#...#...#", "#.......#",
                          "#.......#", "#########"},
                         {2, 6}, 0.1);
  CHECK(m.label({4, 4}) == L::UnknownInCollision);
  CHECK(m.label({4, 5}) == L::MaybeCollision);
  CHECK(m.label({5, 4}) == L::MaybeCollision);
  CHECK(m.label({3, 4}) == L::MaybeCollision);
  CHECK(m.label({4, 3}) == L::Occupied);
  CHECK(m.label({3, 3}) == L::CollisionSpace);
  CHECK_FALSE(m.reachable({3, 4}));
  CHECK(m.reachable({2, 4}));
  CHECK(m.label({3, 5}) == L::Border);  // touches the unknown column diagonally
}

TEST_CASE("unknown space behind a wall does not narrow the room", "[plan][map]") {
  // The unknown column behind the wall is in collision space, but no open free cell is within the
  // robot radius of it, so no maybe-collision space spills into the room.
  const auto m = analyse({"?????", "#####", "#...#", "#...#", "#...#", "#####"}, {2, 2}, 0.1);
  CHECK(m.label({2, 5}) == L::UnknownInCollision);
  CHECK(m.label({2, 2}) == L::ReachableFree);
  CHECK(m.label({2, 3}) == L::CollisionSpace);
  CHECK(m.count(L::MaybeCollision) == 0);
  CHECK_FALSE(m.closest_frontier().has_value());
}

TEST_CASE("the robot's known footprint counts as free", "[plan][map]") {
  auto cols = iv::ColumnMap::from_rows({"#####", "#???#", "#...#", "#####"}, 0.1);
  iv::ExplorationMap without(cols, {2, 1}, {0.0});
  CHECK(without.label({2, 2}) == L::Unknown);
  iv::ExplorationMap with(cols, {2, 1}, {0.0}, {iv::Cell2{1, 2}, iv::Cell2{2, 2}, iv::Cell2{3, 2}});
  CHECK(with.label({2, 2}) == L::ReachableFree);
  CHECK_FALSE(with.closest_frontier().has_value());
}

TEST_CASE("bad exploration map input throws", "[plan][map]") {
  auto cols = iv::ColumnMap::from_rows({"...", "..."}, 0.1);
  CHECK_THROWS_AS(iv::ExplorationMap(cols, {5, 0}), iv::InvalidArgument);
  CHECK_THROWS_AS(iv::ExplorationMap(cols, {0, 0}, {-1.0}), iv::InvalidArgument);
  CHECK_THROWS_AS(iv::ColumnMap::from_rows({"...", ".."}), iv::InvalidArgument);
  CHECK_THROWS_AS(iv::ColumnMap(0, 3, 0.1), iv::InvalidArgument);
  CHECK_THROWS_AS(iv::ColumnMap(3, 3, 0.0), iv::InvalidArgument);
}

TEST_CASE("projection along z: any occupied voxel occupies, all free frees, the floor is excluded", "[plan][map]") {
  iv::VoxelGrid<iv::BayesLogOdds, iv::Entropy> g(0.1);
  // Column (0, 0): occupied floor voxel (z = 0) and free above (z = 1..3).
  for (int i = 0; i < 5; ++i) {
    g.update(iv::Key{0, 0, 0}, iv::Observation::Hit);
    for (int z = 1; z <= 3; ++z) g.update(iv::Key{0, 0, z}, iv::Observation::Miss);
    // Column (1, 0): free, one occupied voxel at z = 2.
    for (int z = 1; z <= 3; ++z) g.update(iv::Key{1, 0, z}, z == 2 ? iv::Observation::Hit : iv::Observation::Miss);
    // Column (2, 0): free except an unobserved voxel at z = 3.
    for (int z = 1; z <= 2; ++z) g.update(iv::Key{2, 0, z}, iv::Observation::Miss);
  }
  const iv::Bounds region{{0.0, 0.0, 0.1}, {0.3, 0.1, 0.4}};  // z voxel centres 0.15, 0.25, 0.35
  const auto m = iv::project_columns(g, region);
  CHECK(m.width() == 3);
  CHECK(m.height() == 1);
  CHECK(m.at({0, 0}) == iv::Occupancy::Free);
  CHECK(m.at({1, 0}) == iv::Occupancy::Occupied);
  CHECK(m.at({2, 0}) == iv::Occupancy::Unknown);
  CHECK(m.key_of({2, 0}) == iv::Key{2, 0, 0});
  const iv::Bounds with_floor{{0.0, 0.0, 0.0}, {0.3, 0.1, 0.4}};
  CHECK(iv::project_columns(g, with_floor).at({0, 0}) == iv::Occupancy::Occupied);
  CHECK_THROWS_AS(iv::project_columns(g, iv::Bounds{{0, 0, 0.11}, {0.3, 0.1, 0.12}}), iv::InvalidArgument);
}

TEST_CASE("with the thesis' classification the lower rule projects never-observed columns free, the upper occupied",
          "[plan][map]") {
  iv::IntervalParams p;
  p.classify_unobserved = true;
  const iv::Bounds region{{0.0, 0.0, 0.1}, {0.3, 0.1, 0.4}};
  const iv::VoxelGrid<iv::IntervalUpdate<iv::LowerState>, iv::MaxEntropy> lower(0.1,
                                                                                iv::IntervalUpdate<iv::LowerState>(p));
  const iv::VoxelGrid<iv::IntervalUpdate<iv::UpperState>, iv::MaxEntropy> upper(0.1,
                                                                                iv::IntervalUpdate<iv::UpperState>(p));
  const iv::VoxelGrid<iv::IntervalUpdate<iv::MeanState>, iv::MaxEntropy> mean(0.1,
                                                                              iv::IntervalUpdate<iv::MeanState>(p));
  for (int x = 0; x < 3; ++x) {
    CHECK(iv::project_columns(lower, region).at({x, 0}) == iv::Occupancy::Free);
    CHECK(iv::project_columns(upper, region).at({x, 0}) == iv::Occupancy::Occupied);
    CHECK(iv::project_columns(mean, region).at({x, 0}) == iv::Occupancy::Unknown);
  }
  // The default keeps never-observed columns unknown under every rule.
  const iv::VoxelGrid<iv::IntervalUpdate<iv::LowerState>, iv::MaxEntropy> lower_default(0.1);
  CHECK(iv::project_columns(lower_default, region).at({0, 0}) == iv::Occupancy::Unknown);
}

TEST_CASE("a robot standing in maybe-collision space can drive out over known free cells", "[plan][map]") {
  // A ring of unknown columns (radius 2-3 cells) around the robot, walled in by occupied columns
  // (radius 3-4 cells): the robot's cell and its free neighbours all lie in maybe-collision space,
  // as in the blind zone of the mobile base's cameras next to furniture.
  iv::ColumnMap cols(21, 21, 0.1);
  const iv::Cell2 robot{10, 10};
  for (int y = 0; y < 21; ++y)
    for (int x = 0; x < 21; ++x) {
      const double d = std::hypot(x - robot.x, y - robot.y);
      cols.set({x, y}, d < 2.0    ? iv::Occupancy::Free
                       : d <= 3.0 ? iv::Occupancy::Unknown
                       : d <= 4.0 ? iv::Occupancy::Occupied
                                  : iv::Occupancy::Free);
    }
  iv::ExplorationMapParams p;
  p.robot_radius = 0.2;
  const iv::ExplorationMap m(cols, robot, p);
  CHECK(m.label({11, 10}) != L::CollisionSpace);
  // Without the escape zone only the robot's own cell would be reachable and no frontier would exist.
  CHECK(m.reachable({11, 10}));
  CHECK(m.reachable({10, 9}));
  CHECK(m.path_distance({11, 10}) == Approx(0.1));
  REQUIRE(m.closest_frontier().has_value());
  CHECK(m.label(*m.closest_frontier()) == L::Border);
  // The escape zone never crosses collision space or unknown columns.
  CHECK_FALSE(m.reachable({11, 11}));  // free, but within the robot radius of the occupied ring
  CHECK_FALSE(m.reachable({12, 10}));  // unknown
  CHECK_FALSE(m.reachable({20, 20}));  // free, outside the walls
}

TEST_CASE("the escape zone lets a robot leave maybe-collision space but never drive along unseen columns",
          "[plan][map]") {
  // A wall (row 9) with an unseen strip in front of it (row 8, unknown): row 7 is collision space,
  // row 6 lies within the robot radius (2 cells) of the strip and is maybe-collision space, rows
  // 0-5 are open floor. Before the escape zone was bounded, a robot standing in row 6 could plan
  // along the whole row, its body sweeping over the unseen strip (the demo's table edge).
  std::vector<std::string> rows{std::string(30, '#'), std::string(30, '?')};
  rows.resize(10, std::string(30, '.'));
  iv::ExplorationMapParams p;
  p.robot_radius = 0.2;
  p.edge_is_unknown = false;
  const iv::ColumnMap cols = iv::ColumnMap::from_rows(rows, 0.1);
  {
    const iv::ExplorationMap m(cols, {3, 6}, p);
    REQUIRE(m.label({10, 6}) == L::MaybeCollision);  // the zone as analysed when the robot stands elsewhere
    CHECK(m.reachable({5, 6}));                      // within its own footprint: it may move there
    CHECK(m.reachable({3, 5}));                      // out of the zone
    CHECK(m.reachable({20, 3}));                     // and on over open floor
    for (int x = 6; x < 30; ++x) {
      INFO("cell (" << x << ", 6)");
      CHECK_FALSE(m.reachable({x, 6}));  // along the strip beyond the footprint: never
    }
  }
  {
    // A robot next to the zone (row 5) does not enter it at all.
    const iv::ExplorationMap m(cols, {3, 5}, p);
    for (int x = 0; x < 30; ++x) {
      INFO("cell (" << x << ", 6)");
      CHECK_FALSE(m.reachable({x, 6}));
      CHECK(m.reachable({x, 5}));
    }
  }
}

TEST_CASE("the path to a cell runs through reachable neighbours, around walls, without cutting corners",
          "[plan][map]") {
  // The robot at (1, 1) must go up the left corridor, along the top and down to (4, 1).
  const auto m =
      analyse({"##########", "#........?", "#.######.#", "#.######.#", "#.#?.....#", "##########"}, {1, 1}, 0.0);
  const std::vector<iv::Cell2> path = m.path_to({4, 1});
  REQUIRE(path.size() >= 2);
  CHECK(path.front() == iv::Cell2{1, 1});
  CHECK(path.back() == iv::Cell2{4, 1});
  double length = 0;
  for (std::size_t i = 1; i < path.size(); ++i) {
    const int dx = path[i].x - path[i - 1].x, dy = path[i].y - path[i - 1].y;
    CHECK(std::max(std::abs(dx), std::abs(dy)) == 1);
    CHECK(m.reachable(path[i]));
    if (dx != 0 && dy != 0) {  // no corner cutting: both cells beside a diagonal step are reachable
      CHECK(m.reachable({path[i - 1].x + dx, path[i - 1].y}));
      CHECK(m.reachable({path[i - 1].x, path[i - 1].y + dy}));
    }
    length += 0.1 * std::sqrt(double(dx * dx + dy * dy));
  }
  CHECK(length == Approx(m.path_distance({4, 1})));
  CHECK(m.path_to({1, 1}) == std::vector<iv::Cell2>{{1, 1}});
  CHECK(m.path_to({3, 1}).empty());  // unknown: not reachable
  CHECK(m.path_to({0, 0}).empty());  // a wall
}

TEST_CASE("the clearance widens the collision disk by exactly its length", "[plan][map]") {
  // One obstacle at (10, 10) in an open 21 x 21 map at 0.1 m; the robot far from it at (1, 1).
  // Cells whose centre lies within robot_radius (+ clearance) of the obstacle's are collision space.
  std::vector<std::string> rows(21, std::string(21, '.'));
  rows[21 - 1 - 10][10] = '#';
  for (const double clearance : {0.0, 0.071}) {
    iv::ExplorationMapParams p;
    p.robot_radius = 0.35;
    p.clearance = clearance;
    const iv::ExplorationMap m(iv::ColumnMap::from_rows(rows, 0.1), {1, 1}, p);
    const double r = (p.robot_radius + clearance) / 0.1;
    for (int y = 0; y < 21; ++y)
      for (int x = 0; x < 21; ++x) {
        if (x == 10 && y == 10) continue;
        const double d = std::hypot(x - 10.0, y - 10.0);
        INFO("clearance " << clearance << ", cell (" << x << ", " << y << "), distance " << d << " cells");
        CHECK((m.label({x, y}) == L::CollisionSpace) == (d <= r + 1e-9));
      }
  }
  iv::ExplorationMapParams bad;
  bad.clearance = -0.1;
  CHECK_THROWS_AS(iv::ExplorationMap(iv::ColumnMap::from_rows(rows, 0.1), {1, 1}, bad), iv::InvalidArgument);
}

TEST_CASE("space outside the map is not known free: the robot keeps its radius from the map's edge", "[plan][map]") {
  // An all-free 15 x 11 map at 0.1 m, robot radius 0.2 m (2 cells): cells within 2 cells of a
  // centre just outside (x or y in {0, 1} or at the far sides) are maybe-collision space.
  const std::vector<std::string> rows(11, std::string(15, '.'));
  iv::ExplorationMapParams p;
  p.robot_radius = 0.2;
  const iv::ExplorationMap m(iv::ColumnMap::from_rows(rows, 0.1), {7, 5}, p);
  for (int y = 0; y < 11; ++y)
    for (int x = 0; x < 15; ++x) {
      const int out = std::min(std::min(x + 1, 15 - x), std::min(y + 1, 11 - y));
      INFO("cell (" << x << ", " << y << ")");
      CHECK(m.reachable({x, y}) == (out > 2));
      CHECK((m.label({x, y}) == L::MaybeCollision) == (out <= 2));
    }
  // A robot standing in the edge zone leaves it over cells no closer to the edge.
  const iv::ExplorationMap at_edge(iv::ColumnMap::from_rows(rows, 0.1), {7, 1}, p);
  CHECK(at_edge.reachable({7, 5}));
  CHECK(at_edge.reachable({3, 1}));        // as close as the robot (2 cells)
  CHECK_FALSE(at_edge.reachable({7, 0}));  // closer
  // Off: the first edition's rule, every free cell reachable.
  p.edge_is_unknown = false;
  const iv::ExplorationMap open(iv::ColumnMap::from_rows(rows, 0.1), {7, 5}, p);
  CHECK(open.reachable({0, 0}));
  CHECK(open.reachable({14, 10}));
}

TEST_CASE("an open hazard's zone keeps the robot off but does not hide an unknown hazard column from the frontier",
          "[plan][map][hazard]") {
  // All free, but for one unknown column in the middle: the robot keeps its radius from it either
  // way as a hazard; listed as `cells` its zone hides it, listed as `open` the zone's rim is border.
  std::vector<std::string> rows(11, std::string(11, '.'));
  rows[5][5] = '?';
  const auto cols = iv::ColumnMap::from_rows(rows, 0.1);
  iv::ExplorationMapParams p;
  p.robot_radius = 0.2;
  p.edge_is_unknown = false;
  const iv::Cell2 hazard{5, 5}, robot{0, 0};
  iv::MapHazards hidden, open;
  hidden.cells = {hazard};
  open.open = {hazard};
  const iv::ExplorationMap plain(cols, robot, p), mh(cols, robot, p, {}, hidden), mo(cols, robot, p, {}, open);
  // Without hazards the unknown column is outside collision space: its neighbours are border.
  CHECK(plain.label({4, 5}) == L::Border);
  for (const iv::ExplorationMap* m : {&mh, &mo}) {
    CHECK_FALSE(m->reachable({4, 5}));  // 0.1 m from it
    CHECK_FALSE(m->reachable({3, 5}));  // 0.2 m: within the radius
    CHECK(m->reachable({2, 5}));        // 0.3 m
  }
  CHECK(mh.borders().empty());
  CHECK(mh.label({2, 5}) == L::ReachableFree);
  CHECK(mo.label({2, 5}) == L::Border);
  CHECK(mo.label({5, 2}) == L::Border);
  CHECK(mo.label({0, 0}) == L::ReachableFree);
  // An open hazard on a free column hides nothing and borders nothing.
  iv::MapHazards free_open;
  free_open.open = {{2, 8}};
  const iv::ExplorationMap mf(cols, robot, p, {}, free_open);
  CHECK_FALSE(mf.reachable({2, 8}));
  CHECK(mf.label({2, 5}) == plain.label({2, 5}));
}

TEST_CASE("an open hazard's zone that reaches past a wall into its collision space makes no border there",
          "[plan][map][hazard]") {
  // A wall across the map at y = 6 and an unknown column right behind it (5, 7): its zone (0.3 m)
  // reaches (5, 4), in the wall's collision space, next to the reachable cell (5, 3). The robot
  // cannot look behind the wall from there, so the cell is no border; without the wall it is.
  std::vector<std::string> walled(12, std::string(11, '.')), open_floor = walled;  // top row (y = 11) first
  walled[11 - 6] = std::string(11, '#');
  walled[11 - 7][5] = open_floor[11 - 7][5] = '?';
  iv::ExplorationMapParams p;
  p.robot_radius = 0.2;
  p.edge_is_unknown = false;
  iv::MapHazards hz;
  hz.open = {{5, 7}};
  hz.margin = 0.1;
  const iv::Cell2 robot{0, 0};
  const iv::ExplorationMap with_wall(iv::ColumnMap::from_rows(walled, 0.1), robot, p, {}, hz);
  const iv::ExplorationMap without(iv::ColumnMap::from_rows(open_floor, 0.1), robot, p, {}, hz);
  REQUIRE(with_wall.reachable({5, 3}));
  REQUIRE_FALSE(with_wall.reachable({5, 4}));  // collision space of the wall, and the zone
  CHECK(with_wall.label({5, 3}) == L::ReachableFree);
  CHECK(with_wall.borders().empty());
  REQUIRE(without.reachable({5, 3}));
  REQUIRE_FALSE(without.reachable({5, 4}));  // the zone alone
  CHECK(without.label({5, 3}) == L::Border);
}

TEST_CASE(
    "the column map's flood fill enters each accepted 8-connected cell once and never a cell an earlier fill marked",
    "[plan][map]") {
  // A pocket at the top left that reaches (1, 1) by a diagonal step, and two pockets apart.
  const iv::ColumnMap m = iv::ColumnMap::from_rows({
      "#######",
      "#..#..#",
      "#..#.##",
      "##.####",
      "#.##..#",
      "#######",
  });
  const auto free = [&](const iv::Cell2& q, std::size_t, std::size_t) { return m.at(q) == iv::Occupancy::Free; };
  std::vector<std::uint8_t> reached(m.size(), 0);
  std::vector<std::size_t> visited;
  m.flood_fill(m.index({1, 4}), reached, free, [&](std::size_t i) { visited.push_back(i); });
  // Brute force: grow the set by any free cell with an 8-neighbour in it until nothing changes.
  std::vector<std::uint8_t> in(m.size(), 0);
  in[m.index({1, 4})] = 1;
  for (bool grew = true; grew;) {
    grew = false;
    for (std::size_t i = 0; i < m.size(); ++i) {
      const iv::Cell2 c = m.cell_of(i);
      if (in[i] || m.at(c) != iv::Occupancy::Free) continue;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
          if (m.contains({c.x + dx, c.y + dy}) && in[m.index({c.x + dx, c.y + dy})] && !in[i]) in[i] = 1, grew = true;
    }
  }
  std::vector<std::size_t> expected;
  for (std::size_t i = 0; i < m.size(); ++i)
    if (in[i]) expected.push_back(i);
  std::sort(visited.begin(), visited.end());
  CHECK(expected.size() == 6);  // the top-left pocket, (2, 2) and, diagonally, (1, 1)
  CHECK(visited == expected);
  CHECK(std::adjacent_find(visited.begin(), visited.end()) == visited.end());
  CHECK(reached[m.index({4, 1})] == 0);
  // A second fill from the other pocket with the same flags enters only its own cells.
  std::vector<std::size_t> second;
  m.flood_fill(m.index({4, 1}), reached, free, [&](std::size_t i) { second.push_back(i); });
  CHECK(second.size() == 2);
  // Bad arguments throw.
  std::vector<std::uint8_t> small(3, 0);
  CHECK_THROWS_AS(m.flood_fill(0, small, free, [](std::size_t) {}), iv::InvalidArgument);
  CHECK_THROWS_AS(m.flood_fill(m.size(), reached, free, [](std::size_t) {}), iv::InvalidArgument);
}

namespace {
// Room A (x 1-9) and room B (x 11-17) joined by a doorway of seven cells in the wall at x = 10
// (y 3-9). A is seen free, B unknown; the robot (radius 0.3 m, three cells) stands in A.
const std::vector<std::string> kDoorway = {
    "###################", "#.........#???????#", "#.........#???????#", "#.........????????#", "#.........????????#",
    "#.........????????#", "#.........????????#", "#.........????????#", "#.........????????#", "#.........????????#",
    "#.........#???????#", "#.........#???????#", "###################"};

iv::ExplorationMap doorway_map(bool passages, double min_area = 0.0, const std::vector<std::string>& rows = kDoorway) {
  iv::ExplorationMapParams p;
  p.robot_radius = 0.3;
  p.passages = passages;
  p.passage_min_hidden_area = min_area;
  return iv::ExplorationMap(iv::ColumnMap::from_rows(rows, 0.1), {3, 6}, p);
}
}  // namespace

TEST_CASE("a doorway whose far side is unknown closes the frontier, and the passage cells in front of it say so",
          "[plan][map][passage]") {
  const iv::ExplorationMap off = doorway_map(false), on = doorway_map(true);
  // The unknown columns beside the jambs are in reach of the doorway's open cell: their
  // maybe-collision disks close the passage, so no reachable cell touches B's unknown space.
  CHECK(off.label({10, 6}) == L::MaybeCollision);
  CHECK(off.borders().empty());
  CHECK(off.passages().empty());  // not computed unless asked for
  // With the option the labels and borders are the same, and the passages are listed.
  for (int y = 0; y < on.height(); ++y)
    for (int x = 0; x < on.width(); ++x) REQUIRE(on.label({x, y}) == off.label({x, y}));
  CHECK(on.borders().empty());
  const std::vector<iv::Cell2>& pass = on.passages();
  REQUIRE(!pass.empty());
  for (std::size_t i = 0; i < pass.size(); ++i) {
    const iv::Cell2& c = pass[i];
    CHECK(on.reachable(c));
    CHECK(c.x < 10);  // in room A, before the door
    CHECK(std::abs(c.y - 6) <= 3);
    bool beside_zone = false;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) beside_zone = beside_zone || on.label({c.x + dx, c.y + dy}) == L::MaybeCollision;
    CHECK(beside_zone);
    if (i > 0) CHECK(on.path_distance(pass[i - 1]) <= on.path_distance(c));
  }
  // Brute force: every reachable cell with a maybe-collision neighbour is a passage here (the
  // doorway's zone is the map's only one, and it hides B).
  std::size_t expected = 0;
  for (int y = 0; y < on.height(); ++y)
    for (int x = 0; x < on.width(); ++x) {
      if (!on.reachable({x, y})) continue;
      bool next = false;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) next = next || ((dx || dy) && on.label({x + dx, y + dy}) == L::MaybeCollision);
      expected += next;
    }
  CHECK(pass.size() == expected);
}

TEST_CASE("a passage counts only if the unknown floor it hides reaches the minimum area", "[plan][map][passage]") {
  // The unknown floor hidden: B's unknown columns outside collision space (labelled Unknown, or
  // maybe-collision in the doorway's zone), all joined to the zone here.
  const iv::ExplorationMap m = doorway_map(true);
  std::size_t hidden = 0;
  for (int y = 0; y < m.height(); ++y)
    for (int x = 0; x < m.width(); ++x)
      hidden += m.columns().at({x, y}) == iv::Occupancy::Unknown &&
                (m.label({x, y}) == L::Unknown || m.label({x, y}) == L::MaybeCollision);
  REQUIRE(hidden > 10);
  const double area = 0.01 * double(hidden);
  CHECK(doorway_map(true, area).passages() == m.passages());
  CHECK(doorway_map(true, area + 0.01).passages().empty());
  // Bad input: a negative or NaN minimum.
  CHECK_THROWS_AS(doorway_map(true, -0.1), iv::InvalidArgument);
  CHECK_THROWS_AS(doorway_map(true, std::nan("")), iv::InvalidArgument);
}

TEST_CASE("an unknown column against a wall closes no passage: its zone hides no unknown floor",
          "[plan][map][passage]") {
  // The door walled up, B with it, and one unknown column in A against the wall: a maybe-collision
  // zone in front of it, but nothing unknown outside collision space behind the zone.
  std::vector<std::string> rows = kDoorway;
  for (std::size_t y = 1; y + 1 < rows.size(); ++y) rows[y].replace(10, 8, "########");
  rows[6][9] = '?';
  const iv::ExplorationMap m = doorway_map(true, 0.0, rows);
  CHECK(m.label({9, 6}) == L::UnknownInCollision);
  CHECK(m.count(L::MaybeCollision) > 0);
  CHECK(m.passages().empty());
  CHECK(m.borders().empty());
}

namespace {
// Two rooms joined by a corridor one traversable cell wide (y = 4 for a 0.1 m robot radius) through
// the wall block x 8-12.
const std::vector<std::string> kCorridor{"#####################",  //
                                         "#.......#####.......#",  //
                                         "#.......#####.......#",  //
                                         "#...................#",  //
                                         "#...................#",  //
                                         "#...................#",  //
                                         "#.......#####.......#",  //
                                         "#.......#####.......#",  //
                                         "#####################"};
}  // namespace

TEST_CASE("the way back: free cells the robot drove stay passable through zones evidence put there since, but no place "
          "to stand",
          "[plan][map][way-back]") {
  iv::ExplorationMapParams p;
  p.robot_radius = 0.1;
  p.edge_is_unknown = false;
  const iv::Cell2 robot{3, 4}, far{15, 4}, gate{10, 4};
  // A hazard column in the corridor's wall row: its zone (one cell) takes the corridor's cell
  // below it, which cuts the rooms apart.
  iv::MapHazards hazards;
  hazards.cells = {{10, 5}};
  std::vector<iv::Cell2> driven;
  for (int x = 3; x <= 17; ++x) driven.push_back({x, 4});  // the path the robot came along
  driven.push_back({-5, 40});                              // outside the map: ignored
  const auto cols = iv::ColumnMap::from_rows(kCorridor, 0.1);
  const iv::ExplorationMap open(cols, robot, p), cut(cols, robot, p, {}, hazards),
      back(cols, robot, p, {}, hazards, driven);
  REQUIRE(open.reachable(far));
  CHECK(open.path_distance(far) == Approx(1.2));
  // The hazard's zone shuts the robot into the left room ...
  CHECK_FALSE(cut.passable(gate));
  CHECK_FALSE(cut.reachable(far));
  CHECK(cut.way_back_cells() == 0);
  // ... and the way back opens it again, through the one cell of the zone on the path.
  CHECK(back.reachable(far));
  CHECK(back.path_distance(far) == Approx(1.2));
  CHECK(back.way_back_cells() == 1);
  CHECK(back.passable(gate));
  CHECK_FALSE(back.reachable(gate));  // never a place to stand for a view
  CHECK(back.label(gate) == cut.label(gate));
  CHECK(back.label(gate) == L::MaybeCollision);
  const std::vector<iv::Cell2> path = back.path_to(far);
  REQUIRE(path.size() == 13);
  CHECK(path.front() == robot);
  CHECK(path.back() == far);
  CHECK(std::count(path.begin(), path.end(), gate) == 1);
  // Every other cell has the label it would have were the rooms not cut apart.
  for (int y = 0; y < open.height(); ++y)
    for (int x = 0; x < open.width(); ++x)
      if (!(iv::Cell2{x, y} == gate) && !(iv::Cell2{x, y} == hazards.cells.front()))
        CHECK(back.label({x, y}) == open.label({x, y}));
  // An obstacle seen next to the path since (collision space at the gate) closes the way back.
  std::vector<std::string> blocked = kCorridor;
  blocked[5][10] = '#';  // (10, 3)
  const iv::ExplorationMap shut(iv::ColumnMap::from_rows(blocked, 0.1), robot, p, {}, hazards, driven);
  CHECK_FALSE(shut.passable(gate));
  CHECK_FALSE(shut.reachable(far));
  CHECK(shut.path_to(far).empty());
  // So does a driven column that is no longer free: unknown at the gate (its drive there may have
  // been on evidence found to lie since).
  std::vector<std::string> unknown_gate = kCorridor;
  unknown_gate[4][10] = '?';  // (10, 4)
  const iv::ExplorationMap questioned(iv::ColumnMap::from_rows(unknown_gate, 0.1), robot, p, {}, hazards, driven);
  CHECK_FALSE(questioned.passable(gate));
  CHECK_FALSE(questioned.reachable(far));
  // Without hazards the driven cells are ordinary reachable cells.
  const iv::ExplorationMap plain_back(cols, robot, p, {}, {}, driven);
  CHECK(plain_back.way_back_cells() == 0);
  CHECK(plain_back.reachable(gate));
}
