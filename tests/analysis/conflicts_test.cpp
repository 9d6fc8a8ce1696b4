// Conflict detection (thesis ch. 6) on hand-built grids: a planted conflict cluster (narrow
// interval, unknown state, away from any surface) and planted surface-edge mixing (the same
// signature on the voxels in front of a wall). Update sequences are chosen so that the interval is
// known in closed form: with the default parameters, 6 hits, 6 misses and 2 hits leave the
// interval [0.321, 0.550] (narrow, state unknown); 10 hits leave [0.99, 0.99] (occupied); 10 misses
// leave [0.01, 0.01] (free).
#include <catch2/catch.hpp>
#include <intervox/analysis/conflicts.hpp>
#include <intervox/grid/named_grids.hpp>
#include <intervox/grid/voxel_grid.hpp>

#include <cmath>
#include <numbers>
#include <string_view>

namespace iv = intervox;
using Approx = Catch::Detail::Approx;

namespace {
constexpr std::string_view kConflict = "HHHHHHMMMMMMHH";
constexpr std::string_view kOccupied = "HHHHHHHHHH";
constexpr std::string_view kFree = "MMMMMMMMMM";

template <class Grid>
void feed(Grid& g, const iv::Key& k, std::string_view seq) {
  for (const char c : seq) g.update(k, c == 'H' ? iv::Observation::Hit : iv::Observation::Miss);
}

// A 20 x 20 x 10 room of free voxels (0.1 m) with a wall of occupied voxels at x = 0, the layer
// x = 1 in front of it mixed (surface-edge signature), and a 3 x 3 x 3 conflict cluster at
// keys [10, 12] x [5, 7] x [3, 5] in free space, plus one isolated conflict voxel at (15, 15, 8).
template <class Grid>
Grid planted_room() {
  Grid g(0.1);
  for (int z = 0; z < 10; ++z)
    for (int y = 0; y < 20; ++y)
      for (int x = 0; x < 20; ++x) {
        const iv::Key k{x, y, z};
        const bool cluster = x >= 10 && x <= 12 && y >= 5 && y <= 7 && z >= 3 && z <= 5;
        if (x == 0)
          feed(g, k, kOccupied);
        else if (x == 1 || cluster || k == iv::Key{15, 15, 8})
          feed(g, k, kConflict);
        else
          feed(g, k, kFree);
      }
  return g;
}
}  // namespace

TEST_CASE("the signature is a narrow interval with an unknown state, for float and compact intervals",
          "[analysis][conflicts]") {
  iv::IntervalGrid g(0.1);
  iv::CompactIntervalGrid c(0.1);
  const iv::Key k{0, 0, 0};
  feed(g, k, kConflict);
  feed(c, k, kConflict);
  CHECK(g.interval(k).lower == Approx(0.321).margin(1e-3));
  CHECK(g.interval(k).upper == Approx(0.550).margin(1e-3));
  CHECK(iv::conflict_signature(g.update_policy(), g.cell(k)));
  CHECK(iv::conflict_signature(c.update_policy(), c.cell(k)));
  // Narrower threshold than the width (0.229): not narrow.
  iv::ConflictParams narrow;
  narrow.max_width = 0.2;
  CHECK_FALSE(iv::conflict_signature(g.update_policy(), g.cell(k), narrow));
  // Unobserved (broad prior), occupied and free voxels have no signature.
  iv::ConflictParams any_width;
  any_width.max_width = 1.0;
  CHECK_FALSE(iv::conflict_signature(g.update_policy(), g.cell({5, 5, 5}), any_width));
  // Consistent data in transit: three misses give [0.01, 0.41], narrow and classified unknown,
  // but its midpoint (0.21) lies outside the undecided band of Table 5.2.
  feed(g, {4, 0, 0}, "MMM");
  CHECK(g.interval({4, 0, 0}).upper == Approx(0.413).margin(1e-3));
  CHECK(g.occupancy({4, 0, 0}) == iv::Occupancy::Unknown);
  CHECK_FALSE(iv::conflict_signature(g.update_policy(), g.cell({4, 0, 0})));
  feed(g, {1, 0, 0}, kOccupied);
  feed(g, {2, 0, 0}, kFree);
  CHECK_FALSE(iv::conflict_signature(g.update_policy(), g.cell({1, 0, 0})));
  CHECK_FALSE(iv::conflict_signature(g.update_policy(), g.cell({2, 0, 0})));
  // Alternating hits and misses never saturate a bound: the interval stays broad (ignorance).
  feed(g, {3, 0, 0}, "HMHMHMHMHMHM");
  CHECK(g.interval({3, 0, 0}).width() > 0.8);
  CHECK_FALSE(iv::conflict_signature(g.update_policy(), g.cell({3, 0, 0})));
}

TEST_CASE("detection finds the planted cluster with its extent and ignores surface-edge mixing",
          "[analysis][conflicts]") {
  auto check = [](const auto& g) {
    const iv::ConflictReport r = iv::detect_conflicts(g);
    CHECK(r.signature_voxels == 20 * 10 + 27 + 1);
    CHECK(r.fringe_voxels == 20 * 10);  // the layer in front of the wall
    CHECK(r.isolated_voxels == 1);
    REQUIRE(r.regions.size() == 1);
    const iv::ConflictRegion& c = r.regions[0];
    CHECK(c.size() == 27);
    CHECK(c.keys == iv::KeyBox{{10, 5, 3}, {12, 7, 5}});
    CHECK(c.bounds.min.isApprox(iv::Point3(1.0, 0.5, 0.3)));
    CHECK(c.bounds.max.isApprox(iv::Point3(1.3, 0.8, 0.6)));
    CHECK(c.centroid.isApprox(iv::Point3(1.15, 0.65, 0.45)));
    CHECK_FALSE(c.normal.has_value());  // no occupied voxel within 2 voxels
    CHECK(r.contains({11, 6, 4}));
    CHECK_FALSE(r.contains({1, 6, 4}));
    CHECK(r.conflict_voxels() == 27);
  };
  check(planted_room<iv::IntervalGrid>());
  check(planted_room<iv::CompactIntervalGrid>());
  check(planted_room<iv::VoxelGrid<iv::CompactIntervalUpdate<iv::UpperState>, iv::MaxEntropy>>());
}

TEST_CASE("without the fringe rule the surface-edge layer is one large region", "[analysis][conflicts]") {
  const auto g = planted_room<iv::IntervalGrid>();
  iv::ConflictParams p;
  p.fringe_distance = 0;
  const auto r = iv::detect_conflicts(g, p);
  REQUIRE(r.regions.size() == 2);
  CHECK(r.regions[0].size() == 200);
  CHECK(r.regions[0].keys == iv::KeyBox{{1, 0, 0}, {1, 19, 9}});
  CHECK(r.regions[1].size() == 27);
  CHECK(r.fringe_voxels == 0);
}

TEST_CASE("a limit restricts detection to voxel centres inside it", "[analysis][conflicts]") {
  const auto g = planted_room<iv::IntervalGrid>();
  const auto r = iv::detect_conflicts(g, {}, iv::Bounds{{1.0, 0.5, 0.3}, {1.3, 0.8, 0.45}});  // z centres 0.35, 0.45
  REQUIRE(r.regions.size() == 1);
  CHECK(r.regions[0].size() == 18);
  iv::ConflictParams bad;
  bad.max_width = 0;
  CHECK_THROWS_AS(iv::detect_conflicts(g, bad), iv::InvalidArgument);
  CHECK_THROWS_AS(iv::detect_conflicts(g, {}, iv::Bounds{{1, 1, 1}, {0, 0, 0}}), iv::InvalidArgument);
}

TEST_CASE("a region's normal comes from the occupied voxels around it and faces its viewers", "[analysis][conflicts]") {
  // A 1 x 5 x 5 sheet of conflict voxels in the plane x = 10, framed by occupied voxels in the
  // same plane two voxels away (like a mirror in a diffuse frame); the rest free.
  iv::IntervalGrid g(0.1);
  for (int z = 0; z < 15; ++z)
    for (int y = 0; y < 15; ++y)
      for (int x = 0; x < 20; ++x) {
        const iv::Key k{x, y, z};
        const bool sheet = x == 10 && y >= 5 && y <= 9 && z >= 5 && z <= 9;
        const bool frame =
            x == 10 && (y == 3 || y == 11 || z == 3 || z == 11) && y >= 3 && y <= 11 && z >= 3 && z <= 11;
        feed(g, k, sheet ? kConflict : frame ? kOccupied : kFree);
      }
  // An occupied pillar at x = 15 blocks one origin.
  for (int z = 5; z <= 9; ++z)
    for (int y = 5; y <= 9; ++y) feed(g, {15, y, z}, kOccupied);
  auto r = iv::detect_conflicts(g);
  REQUIRE(r.regions.size() == 1);
  auto& reg = r.regions[0];
  CHECK(reg.size() == 25);
  REQUIRE(reg.normal.has_value());
  CHECK(std::abs(reg.normal->x()) == Approx(1.0));
  const iv::Point3 c = reg.centroid;  // (1.05, 0.75, 0.75)
  auto dir = [&](double deg, double dist) {
    const double a = deg * std::numbers::pi / 180;
    return iv::Point3(c + dist * iv::Point3(-std::cos(a), std::sin(a), 0));
  };
  const std::vector<iv::Point3> origins{dir(0, 0.9),
                                        dir(40, 0.9),
                                        dir(80, 0.9),
                                        dir(10, 0.9),
                                        dir(0, 0.9),                            // duplicate: counted once
                                        iv::Point3(c + iv::Point3(0.9, 0, 0)),  // behind the pillar
                                        dir(20, 9.0)};                          // out of range
  iv::observe_regions(g, origins, r.regions);
  REQUIRE(reg.views.size() == 4);
  CHECK(reg.views[1].direction.isApprox(iv::Point3(-std::cos(0.698131700797732), std::sin(0.698131700797732), 0)));
  CHECK(reg.normal->x() == Approx(-1.0));                                       // oriented towards the viewers at -x
  CHECK(iv::distinct_directions(reg.views, 30 * std::numbers::pi / 180) == 3);  // 0, 40, 80 (10 is too close to 0)
  CHECK(iv::distinct_directions(reg.views, 45 * std::numbers::pi / 180) == 2);  // 0, 80
  CHECK(iv::distinct_directions(reg.views, 5 * std::numbers::pi / 180) == 4);
}

TEST_CASE("the modelling rule drops occupied voxels next to conflict regions", "[analysis][conflicts]") {
  iv::IntervalGrid g(0.1);
  for (int x = 0; x < 10; ++x) feed(g, {x, 0, 0}, kOccupied);  // a line of surface
  for (int x = 6; x < 10; ++x)
    for (int y = 2; y < 4; ++y) feed(g, {x, y, 0}, kConflict);  // 8 conflict voxels, 2 above the line
  const auto r = iv::detect_conflicts(g);
  REQUIRE(r.regions.size() == 1);
  CHECK(iv::model_voxels(g, r, 0).size() == 10);
  CHECK(iv::model_voxels(g, r, 1).size() == 10);  // the surface is 2 voxels away
  CHECK(iv::model_voxels(g, r, 2).size() == 4);   // x = 4 ... 9 lie within 2 voxels (Chebyshev) of the region
  CHECK(iv::model_voxels(g, r, 2).front() == iv::Key{0, 0, 0});
  CHECK_THROWS_AS(iv::model_voxels(g, r, -1), iv::InvalidArgument);
}
