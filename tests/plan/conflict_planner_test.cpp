// Conflict-aware mobile planning on hand-built worlds (no simulator): a synthetic "sensor" writes
// a fixed room into the grid at every view, with a strip of voxels that stays conflicting however
// often it is seen (a mirror), or a closet whose inside is wrongly free behind a conflicting front.
#include <catch2/catch.hpp>
#include <intervox/grid/named_grids.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/plan/mobile_planner.hpp>

#include <cmath>
#include <algorithm>
#include <functional>
#include <string>
#include <vector>
#include <string_view>

namespace iv = intervox;

namespace {
constexpr std::string_view kConflict = "HHHHHHMMMMMMHH";  // stays [0.55, 0.55] when repeated
constexpr std::string_view kOccupied = "HHHHHHHHHH";
constexpr std::string_view kFree = "MMMMMMMMMM";
enum class Kind { Free, Occupied, Conflict };

void feed(iv::IntervalGrid& g, const iv::Key& k, std::string_view seq) {
  for (const char c : seq) g.update(k, c == 'H' ? iv::Observation::Hit : iv::Observation::Miss);
}

// A 6 m x 4 m room at 0.1 m (keys x 0..59, y 0..39, z 0..9): walls on the border, floor at z = 0;
// `kind` decides the rest (x, y, z keys). Every call "senses" the whole room once.
void sense(iv::IntervalGrid& g, const std::function<Kind(int, int, int)>& kind) {
  for (int z = 0; z < 10; ++z)
    for (int y = 0; y < 40; ++y)
      for (int x = 0; x < 60; ++x) {
        const bool wall = x == 0 || y == 0 || x == 59 || y == 39 || z == 0;
        const Kind k = wall ? Kind::Occupied : kind(x, y, z);
        feed(g, {x, y, z}, k == Kind::Occupied ? kOccupied : k == Kind::Conflict ? kConflict : kFree);
      }
}

// The mirror: a free-standing strip 0.3 m deep, 2 m long, in the robot's height band, centred
// at (1.6, 2.0).
Kind mirror_room(int x, int y, int z) {
  return x >= 15 && x <= 17 && y >= 10 && y <= 29 && z >= 2 && z <= 7 ? Kind::Conflict : Kind::Free;
}

iv::MobilePlannerParams room_params(bool aware, int max_steps, unsigned threads) {
  iv::MobilePlannerParams p;
  p.region = iv::Bounds{{0.0, 0.0, 0.2}, {6.0, 4.0, 0.8}};
  p.max_steps = max_steps;
  p.threads = threads;
  p.gain_stride = 8;
  p.conflicts.enabled = aware;
  // A plain planner that never gives a frontier up by itself (no visit limit, no gain floor):
  // only the conflict rules can end the episode before the budget.
  p.max_visits_per_frontier = 1000;
  p.min_relative_gain = 0;
  // The thesis' map: the strip's conflicting voxels stay unknown, not obstacles, whatever their
  // hits (with hits_block, the default, the plain planner treats the strip as an obstacle too).
  p.hits_block = false;
  return p;
}

struct Run {
  iv::Termination termination = iv::Termination::Running;
  std::vector<iv::ViewReason> reasons;
  std::vector<iv::Pose> views;
  int steps = 0;
  std::size_t retired = 0;
  std::size_t unresolvable = 0;  // regions of the last plan given up
};

// Plan, "drive", sense until the planner ends the episode.
Run run_room(bool aware, int max_steps, unsigned threads) {
  iv::IntervalGrid g(0.1);
  iv::MobilePlanner planner(iv::SensorRig::mobile_base(), room_params(aware, max_steps, threads));
  iv::Pose pose = iv::planar_pose({4.5, 2.0, 0.0}, 0.0);
  Run r;
  for (int i = 0; i < 100; ++i) {
    const iv::MobilePlan plan = planner.plan(g, pose);
    r.retired += plan.retired;
    r.unresolvable = static_cast<std::size_t>(std::count_if(plan.regions.begin(), plan.regions.end(),
                                                            [](const iv::PlannedRegion& x) { return x.unresolvable; }));
    if (plan.termination != iv::Termination::Running) {
      r.termination = plan.termination;
      break;
    }
    r.reasons.push_back(plan.reason);
    if (!plan.scans.empty()) pose = plan.scans.front();
    r.views.push_back(pose);
    sense(g, mirror_room);
  }
  r.steps = planner.steps();
  return r;
}
}  // namespace

TEST_CASE("the conflict-aware planner gives a mirror up after three directions where the plain one runs to its budget",
          "[plan][conflicts][slow]") {
  const Run plain = run_room(false, 10, 2);
  CHECK(plain.termination == iv::Termination::Budget);
  const Run aware = run_room(true, 10, 2);
  CHECK(aware.termination == iv::Termination::Explored);
  CHECK(aware.steps <= 6);
  CHECK(aware.unresolvable == 1);
  // The look-around, then views of the strip from new directions (not frontier views).
  REQUIRE(aware.reasons.size() >= 3);
  CHECK(aware.reasons[0] == iv::ViewReason::Initial);
  CHECK(std::count(aware.reasons.begin(), aware.reasons.end(), iv::ViewReason::Conflict) >= 2);
  // Three views at least 30° apart as seen from the strip's centre.
  std::vector<iv::Point3> dirs;
  const iv::Point3 centre(1.65, 2.0, 0.0);
  for (const auto& v : aware.views) {
    iv::Point3 d = v.translation() - centre;
    d.z() = 0;
    dirs.push_back(d.normalized());
  }
  int distinct = 0;
  for (std::size_t i = 0; i < dirs.size(); ++i) {
    bool fresh = true;
    for (std::size_t j = 0; j < i; ++j) fresh = fresh && dirs[i].dot(dirs[j]) < std::cos(0.5);  // ~29°: allow rounding
    distinct += fresh;
  }
  CHECK(distinct >= 3);
}

TEST_CASE("conflict-aware planning gives the same views for any thread count", "[plan][conflicts][threaded][slow]") {
  const Run a = run_room(true, 10, 1);
  const Run b = run_room(true, 10, 3);
  REQUIRE(a.views.size() == b.views.size());
  for (std::size_t i = 0; i < a.views.size(); ++i) CHECK(a.views[i].matrix() == b.views[i].matrix());
  CHECK(a.reasons == b.reasons);
}

TEST_CASE("the safety margin keeps every candidate out of a wrongly free pocket behind a conflict front",
          "[plan][conflicts]") {
  // A closet (keys x 0..9, y 10..19) whose inside is free in the map (wrongly: it is a solid
  // closet) behind a front at x = 9 that conflicts at even y and looks free at odd y.
  auto closet = [](int x, int y, int z) {
    if (x <= 9 && (y == 10 || y == 19)) return Kind::Occupied;
    if (x == 9 && y > 10 && y < 19 && y % 2 == 0 && z >= 2 && z <= 7) return Kind::Conflict;
    return Kind::Free;
  };
  iv::IntervalGrid g(0.1);
  sense(g, closet);
  auto params = [](bool aware) {
    iv::MobilePlannerParams p = room_params(aware, 5, 2);
    p.map.robot_radius = 0.15;  // a small robot fits through the gaps of the front
    p.start_free_radius = 0.3;
    return p;
  };
  const iv::Pose start = iv::planar_pose({4.5, 2.0, 0.0}, 0.0);
  const iv::Cell2 inside{4, 14};
  // The plain planner's map lets the robot into the pocket (so the check below can fail).
  {
    iv::MobilePlanner plain(iv::SensorRig::mobile_base(), params(false));
    plain.plan(g, start);
    CHECK(plain.exploration_map(g, start).reachable(inside));
  }
  iv::MobilePlanner aware(iv::SensorRig::mobile_base(), params(true));
  aware.plan(g, start);
  const double keep = 0.15 + aware.params().conflicts.safety_margin;
  std::size_t candidates = 0;
  for (int step = 0; step < 4; ++step) {
    const iv::MobilePlan plan = aware.plan(g, start);
    REQUIRE(plan.map.has_value());
    CHECK_FALSE(plan.map->reachable(inside));
    const iv::MapLabel front = plan.map->label({9, 12});
    CHECK((front == iv::MapLabel::UnknownInCollision || front == iv::MapLabel::Unresolvable));
    for (const auto& c : plan.candidates) {
      ++candidates;
      const iv::Point3& p = c.position;
      CHECK_FALSE((p.x() < 1.0 && p.y() > 1.0 && p.y() < 2.0));  // never in the pocket
      for (int y = 12; y <= 18; y += 2) {
        const double d = std::hypot(p.x() - 0.95, p.y() - (y + 0.5) * 0.1);
        CHECK(d > keep);
      }
    }
    for (const iv::Pose& q : plan.path)
      CHECK_FALSE((q.translation().x() < 1.0 && q.translation().y() > 1.0 && q.translation().y() < 2.0));
    if (plan.termination != iv::Termination::Running) break;
  }
  CHECK(candidates > 0);
}

TEST_CASE("conflict-aware planning on a Bayes grid is refused", "[plan][conflicts]") {
  iv::BayesGrid g(0.1);
  iv::MobilePlanner planner(iv::SensorRig::mobile_base(), room_params(true, 5, 1));
  CHECK_THROWS_AS(planner.plan(g, iv::planar_pose({4.5, 2.0, 0.0}, 0.0)), iv::InvalidArgument);
  iv::MobilePlannerParams bad = room_params(true, 5, 1);
  bad.conflicts.resolve_directions = 0;
  CHECK_THROWS_AS(iv::MobilePlanner(iv::SensorRig::mobile_base(), bad), iv::InvalidArgument);
}

TEST_CASE("hazards make a free pocket maybe-collision space and unresolvable columns get their label", "[plan][map]") {
  const std::vector<std::string> rows(9, std::string(12, '.'));
  const auto cols = iv::ColumnMap::from_rows(rows, 0.1);
  iv::MapHazards h;
  h.cells = {{2, 6}};
  h.unresolvable = {{9, 6}};
  h.margin = 0.1;
  iv::ExplorationMapParams p;
  p.robot_radius = 0.1;
  p.edge_is_unknown = false;  // an open hand-drawn map: only the hazards matter here
  const iv::ExplorationMap m(cols, {5, 0}, p, {}, h);
  CHECK(m.label({9, 6}) == iv::MapLabel::Unresolvable);
  CHECK(m.label({2, 6}) == iv::MapLabel::UnknownInCollision);  // a free column, but a hazard
  CHECK(m.label({2, 8}) == iv::MapLabel::MaybeCollision);      // 0.2 m: within radius + margin
  CHECK(m.label({4, 6}) == iv::MapLabel::MaybeCollision);
  CHECK(m.label({3, 7}) == iv::MapLabel::MaybeCollision);  // 0.141 m
  CHECK(m.label({0, 4}) == iv::MapLabel::ReachableFree);   // 0.283 m
  CHECK(m.label({2, 3}) == iv::MapLabel::ReachableFree);   // 0.3 m
  CHECK_FALSE(m.reachable({2, 4}));
  CHECK_FALSE(m.reachable({2, 6}));
  // A robot standing next to a hazard may leave, but only over cells no closer to it.
  const iv::ExplorationMap near(cols, {4, 6}, p, {}, h);
  CHECK(near.reachable({5, 0}));
  CHECK(near.reachable({4, 7}));        // as far from the hazard as the robot (0.2 m)
  CHECK_FALSE(near.reachable({3, 6}));  // closer
  CHECK_FALSE(near.reachable({2, 6}));
  h.margin = -1;
  CHECK_THROWS_AS(iv::ExplorationMap(cols, {5, 0}, p, {}, h), iv::InvalidArgument);
}

TEST_CASE("free space only beams without a return crossed is unknown to the conflict-aware planner's map",
          "[plan][conflicts][no-return]") {
  // The open room, all free in the grid. A fan of beams without a return from the robot towards
  // -x (an absorbing surface ahead) crosses the band; the conflict-aware map must not trust it.
  iv::IntervalGrid g(0.1);
  sense(g, [](int, int, int) { return Kind::Free; });
  const iv::Pose pose = iv::planar_pose({4.5, 2.0, 0.0}, 0.0);
  std::vector<iv::Beam> lost;
  for (int i = -3; i <= 3; ++i)
    for (const double z : {0.35, 0.55})
      lost.push_back(
          {{4.5, 2.0, z}, iv::Point3(4.5, 2.0, z) + 10.0 * iv::Point3(-1.0, 0.05 * i, 0.0).normalized(), false});
  iv::MobilePlanner plain(iv::SensorRig::mobile_base(), room_params(false, 10, 1));
  iv::MobilePlanner aware(iv::SensorRig::mobile_base(), room_params(true, 10, 1));
  // Each planner's map of the grid, the beams given as evidence only (the grid is as sensed).
  auto plain_map = plain.make_map(g), aware_map = aware.make_map(g);
  plain_map.add_evidence(lost);
  aware_map.add_evidence(lost);
  CHECK_FALSE(plain_map.no_returns());
  REQUIRE(aware_map.no_returns());
  // A cell 1.5 m ahead on the fan's axis, in the band.
  const iv::ExplorationMap pm = plain.exploration_map(plain_map, pose), am = aware.exploration_map(aware_map, pose);
  const iv::Cell2 ahead = pm.columns().cell_of_key(g.key(iv::Point3(3.0, 2.0, 0.5)));
  CHECK(pm.label(ahead) == iv::MapLabel::ReachableFree);
  CHECK(am.columns().at(ahead) == iv::Occupancy::Unknown);
  CHECK(am.label(ahead) != iv::MapLabel::ReachableFree);
  // Returns along the same lines confirm the space: the cell is free again.
  std::vector<iv::Beam> back;
  for (const auto& b : lost) back.push_back({b.origin, b.origin + 5.0 * (b.end - b.origin).normalized(), true});
  aware_map.add_evidence(back);
  CHECK(aware.exploration_map(aware_map, pose).label(ahead) == iv::MapLabel::ReachableFree);
}
