#include "reference.hpp"

#include <catch2/catch.hpp>

#include <limits>
#include <intervox/grid/named_grids.hpp>

namespace iv = intervox;

namespace {
/// A wall of occupied voxels at x = 10 (0.1 m voxels), free space in front of it.
template <class Grid>
Grid wall_grid() {
  auto g = rt::make_grid<Grid>(0.1);
  std::vector<iv::Point3> pts;
  for (int y = -5; y <= 5; ++y)
    for (int z = -5; z <= 5; ++z) pts.emplace_back(1.05, 0.1 * y + 0.05, 0.1 * z + 0.05);
  iv::ScanInserter ins;
  for (int i = 0; i < 20; ++i) ins.insert_point_cloud(g, iv::Point3(0.05, 0.05, 0.05), pts);
  return g;
}
}  // namespace

TEMPLATE_TEST_CASE("cast_ray finds the first occupied voxel and its entry distance", "[raycast][cast]",
                   INTERVOX_TEST_GRIDS) {
  const auto g = wall_grid<TestType>();
  REQUIRE(g.occupancy(iv::Key{10, 0, 0}) == iv::Occupancy::Occupied);
  const auto r = iv::cast_ray(g, iv::Point3(0.05, 0.05, 0.05), iv::Point3(1, 0, 0));
  CHECK(r.status == iv::CastStatus::Occupied);
  CHECK(r.hit());
  CHECK(r.key == iv::Key{10, 0, 0});
  CHECK(r.distance == Approx(0.95));
  CHECK(r.voxels == 11);
  // The same along a diagonal within the wall's extent.
  const auto d = iv::cast_ray(g, iv::Point3(0.05, 0.05, 0.05), iv::Point3(1, 0.2, -0.1));
  CHECK(d.hit());
  CHECK(d.key.x == 10);
}

TEMPLATE_TEST_CASE("cast_ray stops at max range, at unknown voxels on request, and when leaving the grid",
                   "[raycast][cast]", INTERVOX_TEST_GRIDS) {
  const auto g = wall_grid<TestType>();
  const iv::Point3 o(0.05, 0.05, 0.05);
  const auto short_cast = iv::cast_ray(g, o, iv::Point3(1, 0, 0), {.max_range = 0.5});
  CHECK(short_cast.status == iv::CastStatus::MaxRange);
  CHECK(short_cast.key == iv::Key{5, 0, 0});  // entered at 0.45 <= 0.5; voxel 6 starts at 0.55
  // Backwards: free voxels near the origin, then never-observed space.
  const auto stop = iv::cast_ray(g, o, iv::Point3(-1, 0, 0), {.unknown = iv::UnknownVoxels::Stop});
  CHECK(stop.status == iv::CastStatus::Unknown);
  CHECK(stop.key == iv::Key{-1, 0, 0});
  const auto pass = iv::cast_ray(g, o, iv::Point3(-1, 0, 0), {.max_range = 2.0, .unknown = iv::UnknownVoxels::Pass});
  CHECK(pass.status == iv::CastStatus::MaxRange);
  if constexpr (test::kConstructBounded<TestType>) {
    const auto out = iv::cast_ray(g, o, iv::Point3(-1, 0, 0));
    CHECK(out.status == iv::CastStatus::LeftGrid);
    CHECK(out.key == iv::Key{-30, 0, 0});
  }
  // The origin voxel can be skipped.
  const auto inside = iv::cast_ray(g, iv::Point3(1.05, 0.05, 0.05), iv::Point3(1, 0, 0));
  CHECK(inside.key == iv::Key{10, 0, 0});
  CHECK(inside.distance == 0.0);
  const auto skip = iv::cast_ray(g, iv::Point3(1.05, 0.05, 0.05), iv::Point3(1, 0, 0),
                                 {.max_range = 1.0, .ignore_origin_voxel = true});
  CHECK(skip.status == iv::CastStatus::MaxRange);
}

TEST_CASE("cast_ray rejects invalid input without examining a voxel", "[raycast][cast]") {
  iv::BayesGrid g(0.1);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CHECK(iv::cast_ray(g, iv::Point3(0, 0, 0), iv::Point3(0, 0, 0)).status == iv::CastStatus::Invalid);
  CHECK(iv::cast_ray(g, iv::Point3(nan, 0, 0), iv::Point3(1, 0, 0)).status == iv::CastStatus::Invalid);
  CHECK(iv::cast_ray(g, iv::Point3(0, 0, 0), iv::Point3(1, nan, 0)).status == iv::CastStatus::Invalid);
  CHECK(iv::cast_ray(g, iv::Point3(1e9, 0, 0), iv::Point3(1, 0, 0)).voxels == 0);
}

TEST_CASE("cast_ray walks the same voxels as traverse", "[raycast][cast]") {
  // A grid where every voxel is observed free, then one occupied voxel at the end of a segment.
  iv::BayesGrid g(0.1);
  const iv::Point3 a(0.013, 0.027, -0.031), b(1.234, -0.777, 0.456);
  std::vector<iv::Key> keys;
  iv::traverse(g.geometry(), a, b, [&](const iv::Key& k) { return keys.push_back(k), true; });
  for (std::size_t j = 0; j + 1 < keys.size(); ++j)
    for (int i = 0; i < 4; ++i) g.update(keys[j], iv::Observation::Miss);  // free: 0.5 -> 0.012
  for (int i = 0; i < 5; ++i) g.update(keys.back(), iv::Observation::Hit);
  const auto r = iv::cast_ray(g, a, b - a, {.unknown = iv::UnknownVoxels::Stop});
  CHECK(r.status == iv::CastStatus::Occupied);
  CHECK(r.key == keys.back());
  CHECK(r.voxels == keys.size());
}
