// The information gain's fast path (block-cached reads, memoised utilities, threads) against a
// plain recomputation from the grid's own reads on random grids and views, for every update
// policy, utility and storage.
#include "../common/grid_types.hpp"

#include <catch2/catch.hpp>
#include <intervox/plan/information_gain.hpp>
#include <intervox/raycast/insert.hpp>
#include <intervox/raycast/traversal.hpp>

#include <algorithm>
#include <random>
#include <set>
#include <span>
#include <vector>

namespace iv = intervox;

namespace {
const iv::Bounds kGridBounds{{-3, -3, -3}, {3, 3, 3}};

// The gain of one pose recomputed voxel by voxel with grid.occupancy(k) and grid.utility(k);
// per view, a voxel counts on its first visit (an ordered std::set remembers the visited ones).
template <class Grid>
iv::ViewGain oracle(const Grid& g, const iv::RayBundle& rays, const iv::Pose& pose, const iv::GainOptions& o) {
  iv::ViewGain r;
  std::set<iv::Key> seen;
  for (const iv::Ray& ray : rays.rays()) {
    iv::Point3 a = pose * ray.origin;
    iv::Point3 b = a + pose.linear() * ray.direction * std::min(ray.range, o.max_range);
    if (o.bounds && !iv::detail::clip_segment(*o.bounds, a, b)) continue;
    iv::traverse(g.geometry(), a, b, [&](const iv::Key& k) {
      ++r.steps;
      const iv::Occupancy occ = g.occupancy(k);
      if ((o.voxels == iv::GainVoxels::All || occ == iv::Occupancy::Unknown) &&
          (o.count == iv::GainCount::PerBeam || seen.insert(k).second)) {
        r.gain += g.utility(k);
        ++r.voxels;
      }
      return occ != iv::Occupancy::Occupied;
    });
  }
  return r;
}
}  // namespace

TEMPLATE_TEST_CASE("the gain of random views equals the voxel-by-voxel recomputation, on any thread count",
                   "[plan][gain][oracle][threaded]", INTERVOX_TEST_GRIDS) {
  TestType g = test::make_grid_for<TestType>(0.1, kGridBounds);
  std::mt19937_64 rng(1130);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  // A random map: returns from a wall patch at x = 2 (occupied, free space in front of it) and
  // 1500 random beams from near the centre, 30 % with a return, some ending outside the bounds of
  // the bounded grids (mixed and unknown voxels).
  std::vector<iv::Beam> beams;
  for (int i = 0; i < 1500; ++i) {
    const iv::Point3 o(0.4 * u(rng), 0.4 * u(rng), 0.4 * u(rng));
    beams.push_back({o, iv::Point3(2.0, 1.2 * u(rng), 1.2 * u(rng)), true});
    beams.push_back({o, iv::Point3(3.2 * u(rng), 3.2 * u(rng), 3.2 * u(rng)), u(rng) < -0.4});
  }
  for (int pass = 0; pass < 6; ++pass) iv::insert_beams(g, std::span<const iv::Beam>(beams));
  // A random rig of 150 rays and 6 random poses.
  iv::RayBundle rays;
  for (int i = 0; i < 150; ++i)
    rays.add(iv::Point3(0.1 * u(rng), 0.1 * u(rng), 0.0), iv::Point3(u(rng), u(rng), u(rng)) + iv::Point3(1e-3, 0, 0),
             2.0 + 2.0 * (u(rng) + 1.0));
  std::vector<iv::Pose> poses;
  for (int i = 0; i < 6; ++i) {
    iv::Pose p = iv::Pose::Identity();
    p.linear() =
        (Eigen::AngleAxisd(3.0 * u(rng), iv::Point3::UnitZ()) * Eigen::AngleAxisd(0.5 * u(rng), iv::Point3::UnitY()))
            .toRotationMatrix();
    p.translation() = iv::Point3(u(rng), u(rng), 0.5 * u(rng));
    poses.push_back(p);
  }
  const test::ThreadCap cap(3);
  for (const iv::GainCount count : {iv::GainCount::PerBeam, iv::GainCount::PerView})
    for (const iv::GainVoxels voxels : {iv::GainVoxels::All, iv::GainVoxels::Unknown})
      for (const bool clip : {false, true}) {
        iv::GainOptions o;
        o.max_range = 3.5;
        o.count = count;
        o.voxels = voxels;
        if (clip) o.bounds = iv::Bounds{{-2.0, -2.5, -1.0}, {2.5, 2.0, 1.5}};
        std::vector<iv::ViewGain> want;
        for (const iv::Pose& p : poses) want.push_back(oracle(g, rays, p, o));
        for (const unsigned threads : {1u, 2u, 3u}) {
          const std::vector<iv::ViewGain> got = iv::evaluate_views(g, rays, poses, o, threads);
          REQUIRE(got.size() == want.size());
          for (std::size_t i = 0; i < got.size(); ++i) {
            INFO("count " << int(count) << ", voxels " << int(voxels) << ", clipped " << clip << ", threads " << threads
                          << ", pose " << i);
            CHECK(got[i].gain == want[i].gain);  // same voxels, same order of summation: equal bits
            CHECK(got[i].steps == want[i].steps);
            CHECK(got[i].voxels == want[i].voxels);
          }
        }
        // The accumulator remembering the view in a bitmap of the grid's key box (the path
        // path_gain takes when the view's box is small next to its steps) gives the same bits. The
        // box holds every pose's reach (poses within 1.2 m of the origin, beams of 3.5 m).
        const iv::Key lo = g.geometry().key(iv::Point3(-5, -5, -5)), hi = g.geometry().key(iv::Point3(5, 5, 5));
        iv::KeyBoxSet box;
        REQUIRE(box.reset(lo, hi));
        for (std::size_t i = 0; i < poses.size(); ++i) {
          iv::GainAccumulator<TestType> acc(g, o.count, o.voxels, nullptr, &box);
          for (const iv::Ray& ray : rays.rays()) {
            iv::Point3 a = poses[i] * ray.origin;
            iv::Point3 b = a + poses[i].linear() * ray.direction * std::min(ray.range, o.max_range);
            if (o.bounds && !iv::detail::clip_segment(*o.bounds, a, b)) continue;
            acc.walk(g.geometry(), a, b);
          }
          const iv::ViewGain got = acc.finish();
          INFO("bitmap of the box, count " << int(count) << ", voxels " << int(voxels) << ", pose " << i);
          CHECK(got.gain == want[i].gain);
          CHECK(got.steps == want[i].steps);
          CHECK(got.voxels == want[i].voxels);
          CHECK(box.size() == (count == iv::GainCount::PerView ? got.voxels : 0));
          REQUIRE(box.reset(lo, hi));
        }
        // The oracle is not vacuous: the views see known and unknown voxels and are stopped.
        double total = 0;
        for (const iv::ViewGain& w : want) total += w.gain;
        CHECK(total > 0);
      }
  CHECK(g.counts().occupied > 50);
  CHECK(g.counts().free > 50);
}
