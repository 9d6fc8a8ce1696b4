// Any rig on the mobile planner (plan/look_around.hpp): the look-around covers the full circle
// whatever the rig (checked with SensorRig::sees, not with the function's own arithmetic), the
// blind zone follows its closed form, and a robot that must face along its path only ever drives
// forward. The world of the path test is a box room with a pillar measured analytically (no
// simulator).
#include <catch2/catch.hpp>
#include <intervox/grid/named_grids.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/plan/look_around.hpp>
#include <intervox/plan/mobile_planner.hpp>
#include <intervox/raycast/insert.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <span>
#include <vector>

namespace iv = intervox;

namespace {
constexpr double kDeg = std::numbers::pi / 180.0;

/// One O3D-100 at (x, 0, height) of the body, looking along the body's x axis, pitched up by \p pitch.
iv::SensorRig single_camera_rig(double x = 0.3, double height = 0.5, double pitch = 0.0) {
  iv::SensorRig rig;
  const iv::Point3 at(x, 0.0, height);
  rig.add(iv::DepthCamera::o3d100(), iv::look_at(at, at + iv::Point3(std::cos(pitch), 0.0, std::sin(pitch))), "front");
  return rig;
}

/// Distance along the unit ray (o, d) to the first surface of a 6 x 4 x 2.5 m room with a 0.6 m
/// square pillar at (3.5, 1.9) (the ray starts inside the room, outside the pillar).
double look_room_distance(const iv::Point3& o, const iv::Point3& d) {
  const iv::Point3 lo(0, 0, 0), hi(6, 4, 2.5), plo(3.2, 1.6, 0), phi(3.8, 2.2, 2.5);
  double wall = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i) {
    if (d[i] > 0) wall = std::min(wall, (hi[i] - o[i]) / d[i]);
    if (d[i] < 0) wall = std::min(wall, (lo[i] - o[i]) / d[i]);
  }
  double t0 = 0, t1 = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i) {
    if (d[i] == 0) {
      if (o[i] < plo[i] || o[i] > phi[i]) t0 = std::numeric_limits<double>::infinity();
      continue;
    }
    double a = (plo[i] - o[i]) / d[i], b = (phi[i] - o[i]) / d[i];
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
  }
  return t0 <= t1 ? std::min(wall, t0) : wall;
}

std::vector<iv::Beam> look_room_beams(const iv::SensorRig& rig, const iv::Pose& body) {
  std::vector<iv::Beam> beams;
  for (const iv::SensorRay& s : rig.rays(body, 2)) {
    const double t = look_room_distance(s.ray.origin, s.ray.direction);
    if (t < s.min_range) continue;
    beams.push_back({s.ray.origin, s.ray.at(std::min(t, s.ray.range)), t <= s.ray.range});
  }
  return beams;
}

/// The planner's first plan at \p start (the look-around), its scans measured in the box room and
/// inserted into \p grid out to the planner's range.
template <class Grid>
iv::MobilePlan look_around_in_room(iv::MobilePlanner& planner, Grid& grid, const iv::SensorRig& rig,
                                   const iv::Pose& start) {
  iv::MobilePlan first = planner.plan(grid, start);
  iv::ScanInserter inserter({.max_range = planner.max_range()});
  for (const iv::Pose& scan : first.scans) {
    const std::vector<iv::Beam> beams = look_room_beams(rig, scan);
    inserter.insert_beams(grid, std::span<const iv::Beam>(beams));
  }
  return first;
}
}  // namespace

TEST_CASE("the thesis rig's look-around keeps the thesis' four turns of 11.25 degrees", "[plan][look-around]") {
  const iv::MobilePlanner planner;
  const std::vector<double>& yaws = planner.look_around_yaws();
  REQUIRE(yaws.size() == 4);
  for (std::size_t i = 0; i < 4; ++i) CHECK(yaws[i] == Approx(11.25 * kDeg * double(i)).margin(1e-12));
  // Far away the eight 40° cameras, 45° apart, leave seams of about 5°; 1 m out the mounts'
  // offsets narrow each arc, and the widest gap is still closed by the thesis' 33.75° of turn.
  const iv::RigCoverage far = iv::rig_coverage(iv::SensorRig::mobile_base(), 1e6);
  CHECK(far.arcs.size() == 8);
  CHECK(far.largest_gap > 0.0);
  CHECK(far.largest_gap < 6.0 * kDeg);
  const iv::RigCoverage near = iv::rig_coverage(iv::SensorRig::mobile_base());
  CHECK(near.largest_gap > far.largest_gap);
  CHECK(near.largest_gap < 33.75 * kDeg);
  CHECK_THROWS_AS(iv::rig_coverage(iv::SensorRig::mobile_base(), 0.0), iv::InvalidArgument);
}

TEST_CASE("a single camera's look-around sees every direction around the base", "[plan][look-around]") {
  for (const double mount_x : {0.0, 0.3}) {
    const iv::SensorRig rig = single_camera_rig(mount_x);
    iv::MobilePlanner planner(rig);
    iv::VoxelGrid<iv::BayesLogOdds> grid(0.1);
    const iv::Pose start = iv::planar_pose(iv::Point3(1.0, 2.0, 0.0), 0.7);
    const iv::MobilePlan first = planner.plan(grid, start);
    REQUIRE(first.reason == iv::ViewReason::Initial);
    CHECK(first.scans.size() == planner.look_around_yaws().size());
    CHECK(first.scans.size() > 4);
    // The oracle: a point 2 m out at camera height, every degree around the start, lies in the
    // camera's field of view at some scan of the look-around.
    int unseen = 0;
    for (int a = 0; a < 360; ++a) {
      const iv::Point3 p = start.translation() + iv::Point3(2.0 * std::cos(a * kDeg), 2.0 * std::sin(a * kDeg), 0.5);
      bool seen = false;
      for (const iv::Pose& scan : first.scans) seen = seen || rig.sees(scan, p);
      unseen += seen ? 0 : 1;
    }
    CHECK(unseen == 0);
    // The thesis' 45° turn leaves most of the circle unseen with one camera: the oracle can fail.
    int unseen_thesis = 0;
    for (int a = 0; a < 360; ++a) {
      const iv::Point3 p = start.translation() + iv::Point3(2.0 * std::cos(a * kDeg), 2.0 * std::sin(a * kDeg), 0.5);
      bool seen = false;
      for (int i = 0; i < 4; ++i)
        seen = seen || rig.sees(start * iv::Pose(Eigen::AngleAxisd(std::numbers::pi / 16 * i, iv::Point3::UnitZ())), p);
      unseen_thesis += seen ? 0 : 1;
    }
    CHECK(unseen_thesis > 250);
  }
}

TEST_CASE("a given look-around span spreads the scans evenly from the start heading", "[plan][look-around]") {
  iv::MobilePlannerParams p;
  p.look_around_scans = 5;
  p.look_around_span = std::numbers::pi;
  p.start_free_radius = 1.0;
  const iv::MobilePlanner planner(single_camera_rig(), p);
  REQUIRE(planner.look_around_yaws().size() == 5);
  for (int i = 0; i < 5; ++i) CHECK(planner.look_around_yaws()[std::size_t(i)] == Approx(std::numbers::pi / 4 * i));
  CHECK(planner.start_free_radius() == 1.0);
  p.look_around_span = -0.1;
  CHECK_THROWS_AS(iv::MobilePlanner(single_camera_rig(), p), iv::InvalidArgument);
  p.look_around_span = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(iv::MobilePlanner(single_camera_rig(), p), iv::InvalidArgument);
}

TEST_CASE("the blind zone of a level camera is where its lowest pixel row reaches the band's floor",
          "[plan][look-around]") {
  // One camera at the axis, 0.5 m up, level; band [0.2, 0.8]: symmetric about the camera, so the
  // lowest and the highest row reach the band's edges at the same distance. Straight ahead that
  // distance is 0.3 / tan(angle of the lowest pixel row's centre); off the image's centre column
  // the row lies farther out by 1 / cos(azimuth), and the look-around puts every direction within
  // half a turn step (plus a 2° bin) of some scan's centre column.
  const iv::SensorRig rig = single_camera_rig(0.0);
  const auto& k = std::get<iv::DepthCamera>(rig.sensors().front().sensor).intrinsics;
  const double lowest = std::atan((k.height - 1 - k.cy) / k.fy);
  const double ahead = 0.3 / std::tan(lowest);
  const std::vector<double> yaws = iv::look_around_yaws(rig, 4);
  const double half_step = 0.5 * (yaws[1] - yaws[0]);
  const std::optional<double> blind = iv::blind_radius(rig, yaws, 0.2, 0.8);
  REQUIRE(blind);
  CHECK(*blind >= ahead - 1e-9);
  CHECK(*blind <= ahead / std::cos(half_step + 2 * kDeg));
  // Mounted 0.3 m forward: the same distances from the camera, 0.3 m farther from the axis ahead.
  const std::optional<double> forward = iv::blind_radius(single_camera_rig(0.3), yaws, 0.2, 0.8);
  REQUIRE(forward);
  CHECK(*forward > *blind);
  // The planner's default start-free radius is this blind zone; a given one is kept.
  CHECK(iv::MobilePlanner(rig).start_free_radius() == Approx(*blind));
}

TEST_CASE("a rig that never sees the band's floor has no blind zone to derive, and says so", "[plan][look-around]") {
  const iv::SensorRig up = single_camera_rig(0.0, 0.5, 60 * kDeg);  // pitched up: its lowest row climbs
  const std::vector<double> yaws = iv::look_around_yaws(up, 4);
  CHECK_FALSE(iv::blind_radius(up, yaws, 0.2, 0.8));
  CHECK_THROWS_AS(iv::MobilePlanner(up), iv::InvalidArgument);
  iv::MobilePlannerParams p;
  p.start_free_radius = 0.8;
  CHECK(iv::MobilePlanner(up, p).start_free_radius() == 0.8);
  CHECK_THROWS_AS(iv::blind_radius(up, std::vector<double>{}, 0.2, 0.8), iv::InvalidArgument);
  CHECK_THROWS_AS(iv::blind_radius(up, yaws, 0.8, 0.2), iv::InvalidArgument);
  CHECK_THROWS_AS(iv::look_around_yaws(up, 0), iv::InvalidArgument);
}

TEST_CASE("a robot that faces along its path turns on the spot and only drives forward", "[plan][look-around]") {
  const iv::SensorRig rig = single_camera_rig();
  iv::MobilePlannerParams p;
  p.face_along_path = true;
  p.threads = 1;
  p.max_steps = 6;
  iv::MobilePlanner planner(rig, p);
  iv::VoxelGrid<iv::BayesLogOdds> grid(0.1);
  iv::ScanInserter inserter({.max_range = planner.max_range()});
  iv::Pose pose = iv::planar_pose(iv::Point3(1.6, 1.6, 0.0), 0.0);
  int views = 0, translations = 0, turns = 0;
  for (;;) {
    const iv::MobilePlan plan = planner.plan(grid, pose);
    if (plan.termination != iv::Termination::Running) break;
    if (!plan.path.empty()) {
      CHECK(plan.path.front().isApprox(pose));
      CHECK(plan.path.back().isApprox(plan.view));
    }
    for (std::size_t i = 1; i < plan.path.size(); ++i) {
      const iv::Pose& a = plan.path[i - 1];
      const iv::Pose& b = plan.path[i];
      const iv::Point3 step = b.translation() - a.translation();
      if (step.norm() < 1e-9) {
        ++turns;
        continue;
      }
      ++translations;
      CHECK(a.linear().isApprox(b.linear(), 1e-9));                                 // no turning while driving
      CHECK(a.linear().col(0).dot(step.normalized()) == Approx(1.0).margin(1e-9));  // forward, never sideways
    }
    if (!plan.path.empty()) pose = plan.path.back();
    for (const iv::Pose& scan : plan.scans) {
      pose = scan;
      const std::vector<iv::Beam> beams = look_room_beams(rig, pose);
      inserter.insert_beams(grid, std::span<const iv::Beam>(beams));
    }
    ++views;
  }
  CHECK(views >= 3);
  CHECK(translations > 0);
  CHECK(turns > 0);
}

TEST_CASE("the start rule frees what the look-around cannot see and keeps the robot off what it hit",
          "[plan][look-around]") {
  // One camera in the box room, interval-mean (five misses to free, five hits to occupied).
  const iv::SensorRig rig = single_camera_rig();
  const iv::Pose start = iv::planar_pose(iv::Point3(1.55, 1.55, 0.0), 0.0);
  const iv::Point3 edge(2.75, 1.55, 0.75);  // 1.2 m ahead at the band's top: a table's edge
  auto explore_start = [&](const iv::MobilePlannerParams& p) {
    iv::MobilePlanner planner(rig, p);
    iv::IntervalGrid grid(0.1);
    look_around_in_room(planner, grid, rig, start);
    grid.update(grid.geometry().key(edge), iv::Observation::Hit);  // seen twice: not yet occupied
    grid.update(grid.geometry().key(edge), iv::Observation::Hit);
    REQUIRE(grid.occupancy(grid.geometry().key(edge)) == iv::Occupancy::Unknown);
    const iv::ExplorationMap map = planner.exploration_map(grid, start);
    const auto at = [&](double x, double y) {
      return map.columns().at(map.columns().cell_of_key(grid.geometry().key(iv::Point3(x, y, 0.5))));
    };
    struct Seen {
      iv::Occupancy near, edge;
      bool reachable_near;
    };
    const iv::Cell2 near_cell = map.columns().cell_of_key(grid.geometry().key(iv::Point3(2.05, 1.55, 0.5)));
    return Seen{at(2.05, 1.55), at(edge.x(), edge.y()), map.reachable(near_cell)};
  };
  iv::MobilePlannerParams p;
  p.region = iv::Bounds{{0.0, 0.0, 0.2}, {6.0, 4.0, 0.8}};
  const auto library = explore_start(p);
  CHECK(library.near == iv::Occupancy::Free);  // 0.5 m ahead: its low and high voxels are blind, the rest crossed
  CHECK(library.reachable_near);
  CHECK(library.edge == iv::Occupancy::Occupied);  // hits_block
  p.hits_block = false;
  CHECK(explore_start(p).edge == iv::Occupancy::Unknown);  // not assumed free: the rig could see it
  p.start_free_columns = true;  // the thesis' rule: the edge, within the radius, counts as free
  CHECK(explore_start(p).edge == iv::Occupancy::Free);
}

TEST_CASE("the exact start rule counts a voxel blind exactly when no beam of the look-around crosses its cube",
          "[plan][look-around][one-camera]") {
  // A coarse camera (16 x 12 pixels), so that its turns leave gaps; a start off the grid's lattice.
  iv::SensorRig rig;
  const iv::Point3 at(0.3, 0.0, 0.5);
  rig.add(iv::DepthCamera::make(16, 12, 40 * kDeg, 30 * kDeg, 0.1, 4.0), iv::look_at(at, at + iv::Point3::UnitX()),
          "front");
  const std::vector<double> yaws = iv::look_around_yaws(rig, 4);
  const double radius = 1.2;
  iv::BlindZone zone(rig, yaws, radius);
  CHECK_FALSE(zone.traced());
  const iv::GridGeometry g(0.1);
  const iv::Pose start = iv::planar_pose(iv::Point3(1.537, 2.071, 0.0), 0.31);
  zone.trace(g, start);
  REQUIRE(zone.traced());
  // The oracle: the beams' segments from min_range to range, tested against each voxel's cube
  // (slab test, interior).
  std::vector<std::pair<iv::Point3, iv::Point3>> segments;
  for (const double yaw : yaws)
    for (const iv::SensorRay& r : rig.rays(start * iv::Pose(Eigen::AngleAxisd(yaw, iv::Point3::UnitZ()))))
      segments.push_back({r.ray.at(r.min_range), r.ray.at(r.ray.range)});
  const auto crosses = [&](const iv::Point3& a, const iv::Point3& b, const iv::Point3& lo, const iv::Point3& hi) {
    double t0 = 0.0, t1 = 1.0;
    for (int i = 0; i < 3; ++i) {
      const double d = b[i] - a[i];
      if (d == 0.0) {
        if (a[i] <= lo[i] || a[i] >= hi[i]) return false;
        continue;
      }
      double u = (lo[i] - a[i]) / d, v = (hi[i] - a[i]) / d;
      if (u > v) std::swap(u, v);
      t0 = std::max(t0, u);
      t1 = std::min(t1, v);
    }
    return t0 < t1;
  };
  const iv::Pose to_start = start.inverse();
  const double half = 0.5 * g.resolution();
  std::size_t inside = 0, blind_exact = 0, blind_hull = 0, mismatches = 0, hull_not_exact = 0;
  const iv::Key c = g.key(start.translation());
  for (int dx = -14; dx <= 14; ++dx)
    for (int dy = -14; dy <= 14; ++dy)
      for (int z = 0; z <= 10; ++z) {
        const iv::Key k{c.x + dx, c.y + dy, z};
        const iv::Point3 p = to_start * g.center(k);
        if (!zone.contains(p, half)) continue;
        ++inside;
        const iv::Point3 lo = g.center(k) - iv::Point3::Constant(half), hi = g.center(k) + iv::Point3::Constant(half);
        bool crossed = false;
        for (const auto& [a, b] : segments) crossed = crossed || crosses(a, b, lo, hi);
        mismatches += crossed != zone.crossed(k) ? 1 : 0;
        blind_exact += zone.crossed(k) ? 0 : 1;
        const bool hull = zone.blind(p, half);
        blind_hull += hull ? 1 : 0;
        hull_not_exact += hull && zone.crossed(k) ? 1 : 0;
      }
  INFO(inside << " voxels in the zone, " << blind_exact << " blind exactly, " << blind_hull << " by the hull");
  REQUIRE(inside > 1000);
  CHECK(mismatches == 0);
  CHECK(hull_not_exact == 0);       // the hull is conservative: what it calls blind, no beam crosses
  CHECK(blind_exact > blind_hull);  // and the exact walk finds blind voxels it calls seen
  CHECK_THROWS_AS(zone.trace(g, iv::planar_pose(iv::Point3(std::nan(""), 0.0, 0.0), 0.0)), iv::InvalidArgument);
}

TEST_CASE("with the exact start rule a one-camera robot leaves its start at 5 cm", "[plan][look-around][one-camera]") {
  // One camera in the box room, interval-mean with five frames per heading (five misses free a
  // voxel): the hull leaves unknown the voxels between the camera's turns next to the base, the
  // exact walk frees them. The plan after the look-around is then a view; all its poses and the
  // path keep the robot's radius from the room's walls and pillar.
  const iv::SensorRig rig = single_camera_rig();
  const iv::Pose start = iv::planar_pose(iv::Point3(1.5, 2.0, 0.0), 0.0);
  auto after_look_around = [&](bool exact, std::size_t& unknown_near) {
    iv::MobilePlannerParams p;
    p.frames_per_scan = 5;
    p.threads = 1;
    p.exact_blind_zone = exact;
    p.region = iv::Bounds{{0.0, 0.0, 0.2}, {6.0, 4.0, 0.8}};
    iv::MobilePlanner planner(rig, p);
    iv::IntervalGrid grid(0.05);
    look_around_in_room(planner, grid, rig, start);
    const iv::ExplorationMap map = planner.exploration_map(grid, start);
    unknown_near = 0;
    for (int y = 0; y < map.height(); ++y)
      for (int x = 0; x < map.width(); ++x) {
        const iv::Cell2 cell{x, y};
        const iv::Point3 w = grid.geometry().center(map.columns().key_of(cell));
        if ((w.head<2>() - start.translation().head<2>()).norm() <= 0.6 &&
            map.columns().at(cell) == iv::Occupancy::Unknown)
          ++unknown_near;
      }
    return planner.plan(grid, start);
  };
  std::size_t unknown_hull = 0, unknown_exact = 0;
  const iv::MobilePlan hull = after_look_around(false, unknown_hull);
  const iv::MobilePlan exact = after_look_around(true, unknown_exact);
  INFO("unknown columns within 0.6 m of the start: hull " << unknown_hull << ", exact " << unknown_exact);
  CHECK(unknown_exact < unknown_hull);
  REQUIRE(exact.termination == iv::Termination::Running);
  REQUIRE_FALSE(exact.path.empty());
  for (const iv::Pose& q : exact.path) {
    const iv::Point3 t = q.translation();
    CHECK(std::min({t.x(), t.y(), 6.0 - t.x(), 4.0 - t.y()}) >= 0.36);
    const double px = std::clamp(t.x(), 3.2, 3.8), py = std::clamp(t.y(), 1.6, 2.2);
    CHECK(std::hypot(t.x() - px, t.y() - py) >= 0.36);
  }
}

TEST_CASE(
    "with frames per scan, each scan pose is listed that many times and a one-camera interval-mean map gets free space",
    "[plan][look-around][one-camera]") {
  const iv::SensorRig rig = single_camera_rig();
  const iv::Pose start = iv::planar_pose(iv::Point3(1.5, 2.0, 0.0), 0.0);
  std::size_t free_voxels[2] = {0, 0};
  for (const int frames : {1, 5}) {
    CAPTURE(frames);
    iv::MobilePlannerParams p;
    p.frames_per_scan = frames;
    p.threads = 1;
    iv::MobilePlanner planner(rig, p);
    iv::IntervalGrid grid(0.1);  // interval-mean: five consistent misses make a voxel free
    const iv::MobilePlan first = planner.plan(grid, start);
    const std::size_t yaws = planner.look_around_yaws().size();
    REQUIRE(first.scans.size() == yaws * std::size_t(frames));
    for (std::size_t i = 0; i < first.scans.size(); ++i)
      CHECK(first.scans[i].isApprox(first.scans[i - i % std::size_t(frames)], 0.0));  // in a row, the same pose
    for (std::size_t y = 1; y < yaws; ++y) CHECK_FALSE(first.scans[y * std::size_t(frames)].isApprox(first.scans[0]));
    iv::ScanInserter inserter;
    for (const iv::Pose& scan : first.scans) {
      const std::vector<iv::Beam> beams = look_room_beams(rig, scan);
      inserter.insert_beams(grid, std::span<const iv::Beam>(beams));
    }
    grid.for_each_observed(
        [&](const iv::Key& k, const auto&) { free_voxels[frames == 5] += grid.occupancy(k) == iv::Occupancy::Free; });
    const iv::MobilePlan view = planner.plan(grid, start);
    if (!view.scans.empty()) CHECK(view.scans.size() == std::size_t(p.scans_per_view * frames));
  }
  // One frame per heading leaves the room almost unclassified (each voxel has one or two misses);
  // five frames free what the camera crossed.
  CHECK(free_voxels[1] > 10 * std::max<std::size_t>(free_voxels[0], 1));
  CHECK(free_voxels[1] > 1000);
  iv::MobilePlannerParams bad;
  bad.frames_per_scan = 0;
  CHECK_THROWS_WITH(iv::MobilePlanner(rig, bad), Catch::Contains("frames_per_scan"));
}
