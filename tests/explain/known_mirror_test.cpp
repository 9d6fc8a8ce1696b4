// Mirrors told to the explained channel (ExplainedSpace::add_mirror()): the beams through one are
// suspect and its surface is explained occupied; telling it late moves the kept beams as if it
// had been known first (oracle: the channel told first); a mirror in a known one's plane grows
// it, unless told to keep it apart (MirrorMerge::Keep); without a ledger only later scans are
// concerned; invalid patches are refused.
#include <intervox/explain/explain.hpp>
#include <intervox/io/explained_file.hpp>
#include <intervox/raycast/insert.hpp>
#include <intervox/update/bayes_log_odds.hpp>

#include "../common/explained_evidence.hpp"
#include "../common/grid_types.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <string>
#include <vector>

namespace iv = intervox;

namespace known_mirror_test {

// The rectangle x = 1, y and z in [-0.5, 0.5], facing -x.
iv::PlanePatch panel() {
  iv::PlanePatch p;
  p.center = iv::Point3(1.0, 0.0, 0.0);
  p.normal = -iv::Point3::UnitX();
  p.axis_u = iv::Point3::UnitY();
  p.half_u = 0.5;
  p.half_v = 0.5;
  return p;
}

// A fan of returns from (0, y0, 0) onto the wall x = 2 (y, z in [-1, 1]): those within the
// panel's shadow pass it.
std::vector<iv::Beam> fan(double y0) {
  std::vector<iv::Beam> out;
  for (double y = -1.0; y <= 1.0; y += 0.05)
    for (double z = -0.5; z <= 0.5; z += 0.1) out.push_back({{0.0, y0, 0.0}, {2.0, y, z}, true});
  return out;
}

}  // namespace known_mirror_test

using namespace known_mirror_test;

TEST_CASE("a beam through a known mirror is suspect, and the mirror's surface is explained occupied",
          "[explain][mirror]") {
  iv::VoxelGrid<iv::BayesLogOdds> grid(0.05);
  iv::ExplainedSpace space(grid.geometry());
  iv::InsertOptions io;
  io.max_range = 5.0;
  const iv::Point3 o(0.0, 0.0, 0.0);
  // Nothing is known yet: every return is trusted.
  CHECK(space.classify({o, {2.0, 0.0, 0.0}, true}, io) == iv::BeamClass::Trusted);
  space.add_mirror(panel());
  REQUIRE(space.mirrors().size() == 1);
  CHECK(space.classify({o, {2.0, 0.0, 0.0}, true}, io) == iv::BeamClass::Suspect);  // through it
  CHECK(space.classify({o, {2.0, 0.2, 0.3}, true}, io) == iv::BeamClass::Suspect);  // through it, slanted
  CHECK(space.classify({o, {0.9, 0.0, 0.0}, true}, io) == iv::BeamClass::Trusted);  // ends before it
  CHECK(space.classify({o, {1.1, 0.0, 0.0}, true}, io) == iv::BeamClass::Trusted);  // ends on it, within the tolerance
  CHECK(space.classify({o, {2.0, 1.5, 0.0}, true}, io) == iv::BeamClass::Trusted);  // passes beside it
  CHECK(space.classify({{2.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, true}, io) ==
        iv::BeamClass::Suspect);  // from behind: both faces count
  CHECK(space.classify({o, {4.0, 0.0, 0.0}, false}, io) ==
        iv::BeamClass::Suspect);  // no return, through it within the range
  CHECK(space.classify({o, {0.5, 0.0, 0.0}, false}, io) == iv::BeamClass::NoReturn);  // no return, cut before it
  const iv::GridGeometry& g = grid.geometry();
  for (const double y : {-0.45, 0.0, 0.45}) {
    CHECK(space.on_mirror(g.key(iv::Point3(1.0, y, 0.1))));
    CHECK(space.state(g.key(iv::Point3(1.0, y, 0.1))) == iv::ExplainedState::Occupied);
    CHECK_FALSE(space.free_only_by_lying_beams(g.key(iv::Point3(1.0, y, 0.1))));
  }
  CHECK_FALSE(space.on_mirror(g.key(iv::Point3(1.1, 0.0, 0.0))));  // a voxel behind it
  CHECK_FALSE(space.on_mirror(g.key(iv::Point3(1.0, 0.6, 0.0))));  // beside it
  CHECK(space.state(g.key(iv::Point3(1.0, 0.6, 0.0))) == iv::ExplainedState::Unknown);
  space.clear();
  CHECK(space.mirrors().empty());
  CHECK(space.classify({o, {2.0, 0.0, 0.0}, true}, io) == iv::BeamClass::Trusted);
}

TEMPLATE_TEST_CASE("telling the channel of a mirror late moves its kept beams as if it had been known first",
                   "[explain][mirror]", INTERVOX_TEST_GRIDS) {
  iv::InsertOptions io;
  io.max_range = 5.0;
  iv::ScanInserter inserter(io);
  const iv::Bounds box{{-1.0, -2.0, -1.0}, {3.0, 2.0, 1.0}};
  TestType grid_late = test::make_grid_for<TestType>(0.05, box), grid_first = test::make_grid_for<TestType>(0.05, box);
  iv::ExplainOptions eo;
  eo.revision_interval = 1;
  iv::ExplainedSpace late(grid_late.geometry(), eo), first(grid_first.geometry(), eo);
  first.add_mirror(panel());
  for (const double y0 : {-0.6, 0.0, 0.6}) {
    const std::vector<iv::Beam> f = fan(y0);
    late.insert_beams(inserter, grid_late, std::span<const iv::Beam>(f));
    first.insert_beams(inserter, grid_first, std::span<const iv::Beam>(f));
  }
  std::size_t trusted_through = 0;
  for (const iv::LedgerScan& s : late.ledger().scans())
    s.for_each([&](std::size_t, const iv::Beam& b, iv::BeamClass c) {
      trusted_through += c == iv::BeamClass::Trusted && panel().crossing(b.origin, b.end).has_value();
    });
  REQUIRE(trusted_through > 100);  // before: the panel's beams are trusted
  late.add_mirror(panel());
  // The classes and the evidence are those of the channel that knew the mirror from the start.
  const auto& a = late.ledger().scans();
  const auto& b = first.ledger().scans();
  REQUIRE(a.size() == b.size());
  std::size_t suspect = 0;
  for (std::size_t s = 0; s < a.size(); ++s) {
    std::vector<iv::BeamClass> ca, cb;
    a[s].for_each([&](std::size_t, const iv::Beam&, iv::BeamClass c) { ca.push_back(c); });
    b[s].for_each([&](std::size_t, const iv::Beam&, iv::BeamClass c) { cb.push_back(c); });
    CHECK(ca == cb);
    suspect += static_cast<std::size_t>(std::count(ca.begin(), ca.end(), iv::BeamClass::Suspect));
  }
  CHECK(suspect >= trusted_through);
  CHECK(test::evidence_map(late) == test::evidence_map(first));
  CHECK(late.trusted_extent() == first.trusted_extent());
}

TEST_CASE("a mirror in the plane of a known one grows it, and a parallel one is another mirror", "[explain][mirror]") {
  iv::VoxelGrid<iv::BayesLogOdds> grid(0.05);
  iv::ExplainedSpace space(grid.geometry());
  space.add_mirror(panel());
  iv::PlanePatch beside = panel();
  beside.center = iv::Point3(1.02, 1.2, 0.3);  // within a voxel of the plane, further along y and up
  beside.normal = iv::Point3::UnitX();         // the other face: the same plane
  beside.axis_u = -iv::Point3::UnitY();
  beside.half_u = 0.3;
  beside.half_v = 0.2;
  space.add_mirror(beside);
  REQUIRE(space.mirrors().size() == 1);
  const iv::PlanePatch& m = space.mirrors().front();
  // One rectangle in the first one's axes that holds both: y in [-0.5, 1.5], z in [-0.5, 0.5].
  CHECK(m.center.y() == Approx(0.5));
  CHECK(m.center.z() == Approx(0.0).margin(1e-12));
  CHECK(m.half_u == Approx(1.0));
  CHECK(m.half_v == Approx(0.5));
  CHECK(m.center.x() == Approx(1.0));
  iv::PlanePatch parallel = panel();
  parallel.center.x() = 1.3;
  space.add_mirror(parallel);
  CHECK(space.mirrors().size() == 2);
}

TEST_CASE("a surface told with MirrorMerge::Keep stays apart from a known one in its plane, so the gap between them "
          "stays open",
          "[explain][mirror]") {
  // Two walls in the plane x = 1 with a doorway between them (y in [0.5, 0.9]); a beam through
  // the doorway onto the wall x = 2 is trusted when the walls are kept apart, and suspect when the
  // second grows the first across the doorway (the default for found mirrors).
  iv::PlanePatch beside = panel();
  beside.center = iv::Point3(1.0, 1.2, 0.0);
  beside.half_u = 0.3;  // y in [0.9, 1.5]
  const iv::Beam through{{0.0, 0.7, 0.0}, {2.0, 0.7, 0.0}, true};
  const iv::Beam wall_hit{{0.0, 0.0, 0.0}, {2.0, 0.0, 0.0}, true};  // through the first wall
  iv::InsertOptions io;
  io.max_range = 5.0;
  for (const iv::MirrorMerge merge : {iv::MirrorMerge::Keep, iv::MirrorMerge::Grow}) {
    iv::VoxelGrid<iv::BayesLogOdds> grid(0.05);
    iv::ExplainedSpace space(grid.geometry());
    space.add_mirror(panel(), merge);
    space.add_mirror(beside, merge);
    const bool kept = merge == iv::MirrorMerge::Keep;
    INFO((kept ? "keep" : "grow"));
    REQUIRE(space.mirrors().size() == (kept ? 2u : 1u));
    if (kept) {  // as given
      CHECK(space.mirrors()[1].center == beside.center);
      CHECK(space.mirrors()[1].half_u == beside.half_u);
    }
    CHECK(space.classify(through, io) == (kept ? iv::BeamClass::Trusted : iv::BeamClass::Suspect));
    CHECK(space.classify(wall_hit, io) == iv::BeamClass::Suspect);
    CHECK(space.on_mirror(grid.geometry().key(iv::Point3(1.0, 0.7, 0.0))) == !kept);
  }
}

TEST_CASE("without a ledger a mirror concerns only the scans after it", "[explain][mirror]") {
  iv::VoxelGrid<iv::BayesLogOdds> grid(0.05);
  iv::ExplainOptions eo;
  eo.ledger_bytes = 0;
  iv::ExplainedSpace space(grid.geometry(), eo);
  iv::InsertOptions io;
  io.max_range = 5.0;
  iv::ScanInserter inserter(io);
  const std::vector<iv::Beam> f = fan(0.0);
  std::vector<iv::BeamClass> before, after;
  space.insert_beams(inserter, grid, std::span<const iv::Beam>(f), &before);
  const auto evidence = test::evidence_map(space);
  space.add_mirror(panel());
  CHECK(test::evidence_map(space) == evidence);
  space.insert_beams(inserter, grid, std::span<const iv::Beam>(f), &after);
  CHECK(std::count(before.begin(), before.end(), iv::BeamClass::Suspect) == 0);
  CHECK(std::count(after.begin(), after.end(), iv::BeamClass::Suspect) > 100);
}

TEST_CASE("an invalid mirror patch is refused and the channel keeps its mirrors", "[explain][mirror][errors]") {
  iv::VoxelGrid<iv::BayesLogOdds> grid(0.05);
  iv::ExplainedSpace space(grid.geometry());
  const auto refused = [&](auto change, const char* what) {
    iv::PlanePatch p = panel();
    change(p);
    CHECK_THROWS_WITH(space.add_mirror(p), Catch::Contains(what));
    CHECK(space.mirrors().empty());
  };
  refused([](iv::PlanePatch& p) { p.center.x() = std::nan(""); }, "finite");
  refused([](iv::PlanePatch& p) { p.normal = iv::Point3(2.0, 0.0, 0.0); }, "normal must be a unit vector");
  refused([](iv::PlanePatch& p) { p.axis_u = iv::Point3(0.0, 0.5, 0.0); }, "axis_u must be a unit vector");
  refused([](iv::PlanePatch& p) { p.axis_u = iv::Point3(1.0, 0.0, 0.0); }, "orthogonal");
  refused([](iv::PlanePatch& p) { p.half_u = -0.1; }, "half_u");
}

TEST_CASE(
    "two mirrors whose merged rectangle would not be finite are kept apart, and the channel saves and loads with both",
    "[explain][mirror][io]") {
  iv::VoxelGrid<iv::BayesLogOdds> grid(0.05);
  iv::ExplainedSpace space(grid.geometry());
  // Two valid rectangles in one plane whose union reaches beyond the largest double.
  iv::PlanePatch a = panel();
  a.half_u = 1e308;
  iv::PlanePatch b = panel();
  b.center.y() = 1e308;
  b.half_u = 1e308;
  space.add_mirror(a);
  space.add_mirror(b);
  REQUIRE(space.mirrors().size() == 2);
  for (const iv::PlanePatch& m : space.mirrors()) CHECK_NOTHROW(m.validate());
  const iv::Key on_a = grid.geometry().key(iv::Point3(1.0, 0.0, 0.0));
  CHECK(space.on_mirror(on_a));
  // What is saved loads again, the mirrors with it.
  const std::string bytes = iv::save_explained_to_memory(space);
  const iv::ExplainedSpace back = iv::load_explained_from_memory(bytes, "merged");
  REQUIRE(back.mirrors().size() == 2);
  CHECK(back.mirrors()[1].center == b.center);
  CHECK(back.on_mirror(on_a));
  // A merge that stays finite still grows one rectangle.
  iv::ExplainedSpace grows(grid.geometry());
  iv::PlanePatch c = panel();
  c.half_u = 1e300;
  grows.add_mirror(c);
  grows.add_mirror(b);
  CHECK(grows.mirrors().size() == 2);  // (b's reach 2e308 is beyond the largest double)
  iv::PlanePatch d = panel();
  d.center.y() = 1e300;
  grows.add_mirror(d);
  CHECK(grows.mirrors().size() == 2);
  CHECK(std::isfinite(grows.mirrors()[0].half_u));
}

namespace known_mirror_test {

// n mirrors of random size (a few very large), orientation and place within +-20 m.
std::vector<iv::PlanePatch> random_mirrors(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0), size(0.02, 1.5);
  std::vector<iv::PlanePatch> out;
  for (std::size_t i = 0; i < n; ++i) {
    iv::PlanePatch p;
    p.center = iv::Point3(20 * u(rng), 20 * u(rng), 20 * u(rng));
    iv::Point3 normal(u(rng), u(rng), u(rng));
    if (i % 5 == 0) normal = iv::Point3::Unit(static_cast<int>(i / 5 % 3));  // axis-aligned, as walls are
    if (normal.norm() < 0.1) normal = iv::Point3::UnitZ();
    p.normal = normal.normalized();
    p.axis_u = iv::PlanePatch::floor_axis(p.normal);
    p.half_u = size(rng);
    p.half_v = size(rng);
    if (i % 97 == 0) p.half_u = 1e6 * size(rng);  // reaches far beyond the map
    if (i % 389 == 0) p.half_v = 1e300;
    out.push_back(p);
  }
  return out;
}

}  // namespace known_mirror_test

TEST_CASE("whether a voxel lies on a known mirror, and whether a beam crosses one, is decided as testing every mirror "
          "decides it",
          "[explain][mirror]") {
  for (const double res : {0.05, 0.2}) {
    INFO("resolution " << res);
    iv::VoxelGrid<iv::BayesLogOdds> grid(res);
    iv::ExplainedSpace space(grid.geometry());
    const std::vector<iv::PlanePatch> mirrors = random_mirrors(1500, 7);
    for (const iv::PlanePatch& m : mirrors) space.add_mirror(m, iv::MirrorMerge::Keep);
    REQUIRE(space.mirrors().size() == mirrors.size());
    const auto oracle = [&](const iv::Key& k) {
      const iv::Point3 c = grid.geometry().center(k);
      for (const iv::PlanePatch& m : mirrors)
        if (m.contains(c, (0.5 * m.normal.cwiseAbs().sum() + 1e-9) * res)) return true;
      return false;
    };
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(-25.0, 25.0), near(-0.3, 0.3);
    std::size_t on = 0, checked = 0, wrong = 0;
    for (int i = 0; i < 20000; ++i) {
      // Anywhere, and at a point of a mirror within a metre of its centre (whose voxel mostly
      // lies on it, or on its edge).
      const iv::PlanePatch& m = mirrors[static_cast<std::size_t>(i) % mirrors.size()];
      const double a = std::min(m.half_u, 1.0) * near(rng) / 0.3, b = std::min(m.half_v, 1.0) * near(rng) / 0.3;
      const iv::Point3 p =
          i % 2 ? iv::Point3(u(rng), u(rng), u(rng)) : iv::Point3(m.center + a * m.axis_u + b * m.axis_v());
      const iv::Key k = grid.geometry().key(p);
      const bool want = oracle(k);
      on += want ? 1 : 0;
      ++checked;
      wrong += space.on_mirror(k) != want ? 1 : 0;
    }
    // Far out, where only the very large mirrors reach.
    for (const double far : {1e4, -3e5}) {
      const iv::Key k = grid.geometry().key(iv::Point3(far, 0.5 * far, 3.0));
      ++checked;
      wrong += space.on_mirror(k) != oracle(k) ? 1 : 0;
    }
    INFO(on << " of " << checked << " voxels on a mirror");
    CHECK(on > 1000);
    CHECK(wrong == 0);
    // Beams: in an empty channel a returned beam is suspect exactly when it crosses a mirror more
    // than crossing_tolerance before its end; short beams go through the index, long ones past it.
    iv::InsertOptions io;
    io.max_range = 1e4;
    std::size_t suspect = 0, beams_wrong = 0;
    std::uniform_real_distribution<double> length(0.1, 12.0);
    for (int i = 0; i < 20000; ++i) {
      const iv::PlanePatch& m = mirrors[static_cast<std::size_t>(i) % mirrors.size()];
      const iv::Point3 o = i % 2 ? iv::Point3(u(rng), u(rng), u(rng))
                                 : iv::Point3(m.center - m.normal * 0.7 + iv::Point3(near(rng), near(rng), near(rng)));
      const iv::Point3 d = i % 2
                               ? iv::Point3(iv::Point3(near(rng), near(rng), near(rng)).normalized())
                               : iv::Point3((m.center + iv::Point3(near(rng), near(rng), near(rng)) - o).normalized());
      const iv::Beam b{o, o + d * (i % 10 == 0 ? 200.0 : length(rng)), true};
      bool want = false;
      for (const iv::PlanePatch& p : mirrors)
        if (const auto t = p.crossing(b.origin, b.end);
            t && (1.0 - *t) * (b.end - b.origin).norm() > space.options().crossing_tolerance)
          want = true;
      const bool got = space.classify(b, io) == iv::BeamClass::Suspect;
      suspect += want ? 1 : 0;
      beams_wrong += got != want ? 1 : 0;
    }
    INFO(suspect << " of 20000 beams cross a mirror");
    CHECK(suspect > 2000);
    CHECK(beams_wrong == 0);
  }
}

TEST_CASE("a query of a channel with 65,536 small mirrors costs about what it costs with one", "[explain][mirror]") {
  iv::VoxelGrid<iv::BayesLogOdds> grid(0.05);
  const auto time_queries = [&](const iv::ExplainedSpace& space) {
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(-50.0, 50.0);
    std::vector<iv::Key> keys;
    for (int i = 0; i < 20000; ++i) keys.push_back(grid.geometry().key(iv::Point3(u(rng), u(rng), u(rng))));
    std::size_t occupied = 0;
    const auto start = std::chrono::steady_clock::now();
    for (int round = 0; round < 3; ++round)
      for (const iv::Key& k : keys) occupied += space.state(k) == iv::ExplainedState::Occupied ? 1 : 0;
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    CHECK(occupied < keys.size());
    return s;
  };
  iv::ExplainedSpace one(grid.geometry()), many(grid.geometry());
  one.add_mirror(panel());
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-50.0, 50.0);
  for (int i = 0; i < 65536; ++i) {
    iv::PlanePatch p = panel();
    p.center = iv::Point3(u(rng), u(rng), u(rng));
    p.half_u = p.half_v = 0.1;
    many.add_mirror(p, iv::MirrorMerge::Keep);
  }
  REQUIRE(many.mirrors().size() == 65536);
  const double t_one = time_queries(one), t_many = time_queries(many);
  INFO("60,000 queries: " << t_one << " s with one mirror, " << t_many << " s with 65,536");
  CHECK(t_many < 20.0 * t_one + 0.05);  // a scan of every mirror costs thousands of times more
}
