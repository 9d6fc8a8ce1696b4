// The region analysis of explained free space (analysis/lying_surfaces.hpp): a planted mirror is
// found in its plane and, told to the channel, makes its phantoms suspect; the same panel painted
// diffuse is no mirror; beams without a return make a black region; the result is the same on 1
// and 2 threads; bad parameters are refused. Planted scenes with closed-form phantoms (a ray
// tracer of boxes and one mirror rectangle, below), no simulator.
#include <intervox/analysis/lying_surfaces.hpp>
#include <intervox/explain/explain.hpp>
#include <intervox/raycast/insert.hpp>

#include "../common/grid_types.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <vector>

namespace iv = intervox;

namespace lying_surfaces_test {

struct Box {
  iv::Point3 lo, hi;
};

// Where the ray o + t d (t > 0) enters the box, or nothing (also from inside).
std::optional<double> enter(const Box& b, const iv::Point3& o, const iv::Point3& d) {
  double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (std::abs(d[a]) < 1e-12) {
      if (o[a] < b.lo[a] || o[a] > b.hi[a]) return std::nullopt;
      continue;
    }
    double ta = (b.lo[a] - o[a]) / d[a], tb = (b.hi[a] - o[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  if (t0 > t1 || t0 <= 1e-9) return std::nullopt;
  return t0;
}

// A room 4.5 x 5 x 2.5 m with two boxes whose faces look along x, and a free-standing panel in
// the plane x = 1 (y in [1.8, 3.2], z in [0, 1.6]), a perfect mirror on its east face or, with
// mirror false, a diffuse slab x in [0.98, 1].
struct Room {
  bool mirror = true;
  std::vector<Box> boxes{
      {{-0.1, -0.1, -0.1}, {4.6, 5.1, 0.0}},  // floor
      {{-0.1, -0.1, 2.5}, {4.6, 5.1, 2.6}},   // ceiling
      {{-0.1, -0.1, 0.0}, {0.0, 5.1, 2.5}},   // west wall
      {{4.5, -0.1, 0.0}, {4.6, 5.1, 2.5}},    // east wall
      {{-0.1, -0.1, 0.0}, {4.6, 0.0, 2.5}},   // south wall
      {{-0.1, 5.0, 0.0}, {4.6, 5.1, 2.5}},    // north wall
      {{3.0, 0.5, 0.0}, {3.4, 1.5, 1.2}},     // shelf
      {{2.5, 3.5, 0.0}, {2.9, 4.5, 0.9}},     // crate
  };
  static constexpr double kPanelX = 1.0, kY0 = 1.8, kY1 = 3.2, kZ1 = 1.6;

  // The first surface along o + t d: its distance and whether it is the mirror's face.
  std::pair<double, bool> first(const iv::Point3& o, const iv::Point3& d, bool may_mirror) const {
    double best = std::numeric_limits<double>::infinity();
    bool at_mirror = false;
    for (const Box& b : boxes)
      if (const auto t = enter(b, o, d); t && *t < best) best = *t;
    if (mirror && may_mirror && d.x() < -1e-12) {
      const double t = (kPanelX - o.x()) / d.x();
      const iv::Point3 p = o + t * d;
      if (t > 1e-9 && t < best && p.y() >= kY0 && p.y() <= kY1 && p.z() >= 0.0 && p.z() <= kZ1) {
        best = t;
        at_mirror = true;
      }
    }
    if (!mirror)
      if (const auto t = enter(Box{{0.98, kY0, 0.0}, {kPanelX, kY1, kZ1}}, o, d); t && *t < best) best = *t;
    return {best, at_mirror};
  }

  // One beam: a direct return, or the mirror's phantom (reported at the folded range along the
  // beam's own direction), or no return beyond max_range (its end at the range).
  iv::Beam beam(const iv::Point3& o, const iv::Point3& d, double max_range, bool& phantom) const {
    auto [t, at_mirror] = first(o, d, true);
    phantom = false;
    if (at_mirror) {
      const iv::Point3 m = o + t * d;
      const iv::Point3 r(-d.x(), d.y(), d.z());
      t += first(m, r, false).first;
      phantom = true;
    }
    if (t > max_range) return {o, o + d * max_range, false};
    return {o, o + d * t, true};
  }

  std::vector<iv::Point3> origins() const {
    return {{3.5, 2.5, 0.5}, {4.0, 1.5, 0.5}, {4.0, 3.8, 0.5}, {2.2, 2.5, 0.5},
            {4.2, 2.5, 0.8}, {2.0, 1.0, 0.5}, {2.0, 4.2, 0.5}, {1.6, 0.6, 0.5}};
  }

  // One scan per origin, all around (azimuth every degree, elevation -30..30 every degree);
  // phantom[s][i] tells which beams are the mirror's.
  std::vector<std::vector<iv::Beam>> scans(double max_range, std::vector<std::vector<bool>>& phantom) const {
    std::vector<std::vector<iv::Beam>> out;
    phantom.clear();
    const double deg = std::numbers::pi / 180.0;
    for (const iv::Point3& o : origins()) {
      std::vector<iv::Beam> s;
      std::vector<bool> ph;
      for (int az = 0; az < 360; ++az)
        for (int el = -30; el <= 30; ++el) {
          const double a = az * deg, e = el * deg;
          bool p = false;
          s.push_back(beam(o, iv::Point3(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e)), max_range, p));
          ph.push_back(p);
        }
      out.push_back(std::move(s));
      phantom.push_back(std::move(ph));
    }
    return out;
  }
};

constexpr double kRes = 0.05, kRange = 6.0;

template <class G>
G room_grid() {
  return test::make_grid_for<G>(kRes, iv::Bounds{{-4.5, -0.5, -0.5}, {5.0, 5.5, 3.0}});
}

// Inserts the room's scans (classed) into grid and channel.
template <class G>
std::vector<std::vector<bool>> survey(const Room& room, G& grid, iv::ExplainedSpace& space) {
  iv::InsertOptions io;
  io.max_range = kRange;
  iv::ScanInserter inserter(io);
  std::vector<std::vector<bool>> phantom;
  for (const auto& s : room.scans(kRange, phantom)) space.insert_beams(inserter, grid, std::span<const iv::Beam>(s));
  space.revise();
  return phantom;
}

// The share of the ledger's returned beams of one kind (phantoms or direct returns) classed suspect now.
double suspect_share(const iv::ExplainedSpace& space, const std::vector<std::vector<bool>>& phantom, bool of_phantoms) {
  std::size_t n = 0, suspect = 0;
  const auto& kept = space.ledger().scans();
  REQUIRE(kept.size() == phantom.size());  // the ledger keeps every scan (no skipped beams here)
  for (std::size_t s = 0; s < kept.size(); ++s)
    kept[s].for_each([&](std::size_t i, const iv::Beam& b, iv::BeamClass c) {
      if (!b.hit || phantom[s][i] != of_phantoms) return;
      ++n;
      suspect += c == iv::BeamClass::Suspect;
    });
  REQUIRE(n > 0);
  return double(suspect) / double(n);
}

}  // namespace lying_surfaces_test

using namespace lying_surfaces_test;

TEMPLATE_TEST_CASE("a planted mirror is found in its plane, and told to the channel its phantoms become suspect",
                   "[analysis][lying]", test::BayesSparse, test::MeanDense, test::CompactBoundedSparse) {
  Room room;
  TestType grid = room_grid<TestType>();
  iv::ExplainedSpace space(grid.geometry());
  const auto phantom = survey(room, grid, space);
  const double phantoms_before = suspect_share(space, phantom, true);

  const std::vector<iv::LyingSurface> found = iv::find_lying_surfaces(space);
  std::size_t mirrors = 0;
  for (const iv::LyingSurface& s : found) {
    INFO("region of " << s.voxels << " voxels, kind " << iv::to_string(s.kind) << ", votes " << s.mirror_votes << " of "
                      << s.mirror_crossing);
    CHECK(s.voxels >= iv::LyingSurfaceParams{}.min_region_voxels);
    if (s.kind != iv::LyingKind::Mirror) continue;
    ++mirrors;
    REQUIRE(s.has_plane);
    // The panel's plane x = 1, its normal towards the room (+x), the patch on the panel.
    CHECK(s.surface.normal.x() >= std::cos(3.0 * std::numbers::pi / 180.0));
    CHECK(std::abs(s.surface.center.x() - Room::kPanelX) <= kRes);
    const iv::Point3 v = s.surface.axis_v();
    CHECK(std::abs(s.surface.axis_u.y()) * s.surface.half_u + std::abs(v.y()) * s.surface.half_v <= 0.5 * (Room::kY1 - Room::kY0) + 2 * kRes);
    CHECK(s.surface.center.y() >= Room::kY0 - kRes);
    CHECK(s.surface.center.y() <= Room::kY1 + kRes);
    CHECK(s.mirror_votes >= iv::LyingSurfaceParams{}.min_mirror_votes);
  }
  REQUIRE(mirrors >= 1);

  const double direct_before = suspect_share(space, phantom, false);
  REQUIRE(iv::resolve_mirrors(space, found) == mirrors);
  const double phantoms_after = suspect_share(space, phantom, true);
  INFO("phantoms suspect " << phantoms_before << " -> " << phantoms_after << ", direct returns " << direct_before
                           << " -> " << suspect_share(space, phantom, false));
  // Measured: 51 % of the phantoms suspect by the crossing and mid-air tests alone, 77 % with
  // the mirror known (the patch spans the panel's width and the heights where reflections land
  // on surfaces facing it: z 0.2..1.0 of 0..1.6).
  CHECK(phantoms_before < 0.6);
  CHECK(phantoms_after >= 0.7);
  CHECK(phantoms_after >= phantoms_before + 0.2);
  CHECK(suspect_share(space, phantom, false) <= direct_before + 0.01);
  // The panel's face is explained occupied, the space right behind it not explained free.
  const iv::GridGeometry& g = grid.geometry();
  CHECK(space.state(g.key(iv::Point3(Room::kPanelX, 2.5, 0.5))) == iv::ExplainedState::Occupied);
  CHECK(space.state(g.key(iv::Point3(0.6, 2.5, 0.5))) != iv::ExplainedState::Free);
}

TEST_CASE("the same panel painted diffuse is no mirror, and nothing is told to the channel", "[analysis][lying]") {
  Room room;
  room.mirror = false;
  iv::VoxelGrid<iv::BayesLogOdds> grid(kRes);
  iv::ExplainedSpace space(grid.geometry());
  survey(room, grid, space);
  const std::vector<iv::LyingSurface> found = iv::find_lying_surfaces(space);
  for (const iv::LyingSurface& s : found) CHECK(s.kind != iv::LyingKind::Mirror);
  CHECK(iv::resolve_mirrors(space, found) == 0);
  CHECK(space.mirrors().empty());
}

TEST_CASE("a region carved by suspect beams without a return is a black surface", "[analysis][lying]") {
  // A wall x = 2 seen from three places, then beams from (0, 0, 0) that return nothing and pass
  // through it (a black patch on the wall would do this) into the space behind.
  iv::VoxelGrid<iv::BayesLogOdds> grid(kRes);
  iv::ExplainedSpace space(grid.geometry());
  iv::InsertOptions io;
  io.max_range = 5.0;
  iv::ScanInserter inserter(io);
  for (const double y0 : {-1.0, 0.0, 1.0}) {
    std::vector<iv::Beam> wall;
    for (double y = -1.5; y <= 1.5; y += 0.02)
      for (double z = -0.5; z <= 0.5; z += 0.02) wall.push_back({{0.0, y0, 0.0}, {2.0, y, z}, true});
    space.insert_beams(inserter, grid, std::span<const iv::Beam>(wall));
  }
  std::vector<iv::Beam> silent;
  for (double y = -0.3; y <= 0.3; y += 0.02)
    for (double z = -0.3; z <= 0.3; z += 0.02) silent.push_back({{0.0, 0.0, 0.0}, iv::Point3(2.0, y, z).normalized() * 4.0, false});
  std::vector<iv::BeamClass> classes;
  space.insert_beams(inserter, grid, std::span<const iv::Beam>(silent), &classes);
  REQUIRE(std::count(classes.begin(), classes.end(), iv::BeamClass::Suspect) > 100);
  space.revise();
  const std::vector<iv::LyingSurface> found = iv::find_lying_surfaces(space);
  REQUIRE(found.size() == 1);
  const iv::LyingSurface& s = found.front();
  CHECK(s.kind == iv::LyingKind::Black);
  CHECK(s.returned_beams == 0);
  CHECK(s.silent_beams > 100);
  CHECK(s.no_return_misses == 0);  // suspect misses, not no-return ones: the beams passed a supported surface
  CHECK(s.suspect_misses > 0);
  // They enter the region right behind the wall: its plane is x = 2, facing the sensor.
  REQUIRE(s.has_plane);
  CHECK(s.surface.normal.x() <= -0.99);
  CHECK(std::abs(s.surface.center.x() - 2.0) <= 2 * kRes);
  // Nothing else of the map is lying: every region voxel lies behind the wall.
  CHECK(grid.geometry().center(s.extent.min).x() > 2.0);
}

TEST_CASE("the lying surfaces are the same on one and two threads", "[analysis][lying][threaded]") {
  Room room;
  iv::VoxelGrid<iv::BayesLogOdds> grid(kRes);
  iv::ExplainedSpace space(grid.geometry());
  survey(room, grid, space);
  test::ThreadCap cap(2);
  iv::LyingSurfaceParams one;
  one.max_search_beams = 300;  // a shorter search: the same code, less time under the thread sanitizer
  iv::LyingSurfaceParams two = one;
  two.threads = 2;
  const auto a = iv::find_lying_surfaces(space, one), b = iv::find_lying_surfaces(space, two);
  REQUIRE(a.size() == b.size());
  REQUIRE_FALSE(a.empty());
  for (std::size_t i = 0; i < a.size(); ++i) {
    CHECK(a[i].kind == b[i].kind);
    CHECK(a[i].voxels == b[i].voxels);
    CHECK(a[i].mirror_votes == b[i].mirror_votes);
    CHECK(a[i].best_offset == b[i].best_offset);
    CHECK(a[i].surface.center == b[i].surface.center);
    CHECK(a[i].surface.half_u == b[i].surface.half_u);
  }
}

TEST_CASE("invalid lying-surface parameters are refused with the parameter's name", "[analysis][lying][errors]") {
  iv::VoxelGrid<iv::BayesLogOdds> grid(kRes);
  const iv::ExplainedSpace space(grid.geometry());
  CHECK(iv::find_lying_surfaces(space).empty());  // no evidence, no region
  const auto refused = [&](auto change, const char* name) {
    iv::LyingSurfaceParams p;
    change(p);
    CHECK_THROWS_WITH(iv::find_lying_surfaces(space, p), Catch::Contains(name));
  };
  refused([](iv::LyingSurfaceParams& p) { p.min_region_voxels = 0; }, "min_region_voxels");
  refused([](iv::LyingSurfaceParams& p) { p.min_mirror_votes = 0; }, "min_mirror_votes");
  refused([](iv::LyingSurfaceParams& p) { p.min_mirror_share = 1.5; }, "min_mirror_share");
  refused([](iv::LyingSurfaceParams& p) { p.normal_step_deg = 0.0; }, "normal_step_deg");
  refused([](iv::LyingSurfaceParams& p) { p.max_tilt_deg = std::nan(""); }, "max_tilt_deg");
  refused([](iv::LyingSurfaceParams& p) { p.tilt_step_deg = -1.0; }, "tilt_step_deg");
  refused([](iv::LyingSurfaceParams& p) { p.max_search_beams = 0; }, "max_search_beams");
  refused([](iv::LyingSurfaceParams& p) { p.min_opening_beams = 0; }, "min_opening_beams");
  refused([](iv::LyingSurfaceParams& p) { p.opening_share = -0.1; }, "opening_share");
  refused([](iv::LyingSurfaceParams& p) { p.grow_reach = -1.0; }, "grow_reach");
}
