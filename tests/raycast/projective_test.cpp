// Projective insertion (raycast/projective.hpp): the per-voxel rule against a brute-force
// projection of every voxel, closed forms (a wall, no-return pixels), every policy and storage
// against a hand-applied update, the thread count and the vector form, the agreement with the
// exact insertion, and bad input.
#include "../common/grid_types.hpp"
#include "reference.hpp"

#include <catch2/catch.hpp>
#include <intervox/grid/named_grids.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/raycast/insert.hpp>
#include <intervox/raycast/projective.hpp>
#include <intervox/raycast/vector_walks.hpp>

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <vector>

namespace iv = intervox;

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// A 32 x 24 camera at a tilted pose looking into a box room 4 x 3 x 2.5 m with a block in it,
// depths by ray casting; a few no-return and invalid pixels.
iv::DepthFrame room_frame_small(std::uint64_t seed) {
  iv::DepthFrame f;
  f.intrinsics = iv::PinholeIntrinsics::from_fov(32, 24, 1.0, 0.8);
  f.image = iv::DepthImage(32, 24);
  f.pose = iv::Pose::Identity();
  f.pose.translate(iv::Point3(0.6, 1.4, 1.2));
  // Optical frame: z forward along +x turned by a yaw, x right, y down, pitched a little.
  const double yaw = 0.3, pitch = 0.15;
  const iv::Point3 fwd(std::cos(yaw) * std::cos(pitch), std::sin(yaw) * std::cos(pitch), -std::sin(pitch));
  const iv::Point3 right = iv::Point3(0, 0, -1).cross(fwd).normalized();
  const iv::Point3 down = fwd.cross(right);
  Eigen::Matrix3d r;
  r.col(0) = right;
  r.col(1) = down;
  r.col(2) = fwd;
  f.pose.linear() = r;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.005);
  const iv::Point3 lo(0, 0, 0), hi(4, 3, 2.5), blo(2.2, 1.6, 0), bhi(2.8, 2.3, 0.9);
  for (int v = 0; v < 24; ++v)
    for (int u = 0; u < 32; ++u) {
      const iv::Point3 d = r * f.intrinsics.ray(u, v);  // z-depth = ray parameter
      const iv::Point3 o = f.pose.translation();
      double t = std::numeric_limits<double>::infinity();
      for (int a = 0; a < 3; ++a) {
        if (d[a] > 0) t = std::min(t, (hi[a] - o[a]) / d[a]);
        if (d[a] < 0) t = std::min(t, (lo[a] - o[a]) / d[a]);
      }
      double t0 = 0, t1 = std::numeric_limits<double>::infinity();
      for (int a = 0; a < 3; ++a) {
        double ta = (blo[a] - o[a]) / d[a], tb = (bhi[a] - o[a]) / d[a];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
      }
      if (t0 <= t1 && t0 > 0) t = std::min(t, t0);
      f.image.at(u, v) = static_cast<float>(t + noise(rng));
    }
  for (int u = 0; u < 32; u += 5) f.image.at(u, 3) = kInf;  // no return
  f.image.at(7, 9) = std::numeric_limits<float>::quiet_NaN();
  f.image.at(8, 9) = 0.0f;
  f.image.at(9, 9) = -1.0f;
  f.max_range = 4.0;
  return f;
}

enum class Class { None, Miss, Hit };

// The classes the rule of projective.hpp gives, computed for every voxel of a box around the
// frustum in double precision, straight from the documentation: hits at the voxels of the
// returns, misses where the centre projects into a pixel whose reach it does not pass. Voxels
// within a hair of a pixel edge or of a reach (where single and double precision may round
// apart) are returned in `unsure`.
struct Expected {
  std::map<iv::Key, Class> cls;
  std::set<iv::Key> unsure;
};
Expected brute_force(const iv::GridGeometry& g, const iv::DepthFrame& f, double max_range, double band_voxels) {
  Expected out;
  const auto& k = f.intrinsics;
  const iv::Point3 o = f.pose.translation();
  const Eigen::Matrix3d rt = f.pose.linear().transpose();
  const int w = k.width, h = k.height;
  std::vector<double> reach(static_cast<std::size_t>(w * h), 0.0);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const double d = f.image.at(u, v);
      const iv::Point3 ray = k.ray(u, v);
      const double norm = ray.norm();
      double& r = reach[static_cast<std::size_t>(v * w + u)];
      if (d > 0 && std::isfinite(d)) {
        const iv::Point3 end = iv::pixel_point(k, f.pose, u, v, d);
        if ((end - o).norm() > max_range) {
          r = max_range / norm;
        } else {
          out.cls[g.key(end)] = Class::Hit;
          r = d - band_voxels * g.resolution() / norm;
        }
      } else if (d == std::numeric_limits<double>::infinity()) {
        r = max_range / norm;
      }
    }
  const iv::Key lo = g.key(o - iv::Point3::Constant(max_range + 0.5));
  const iv::Key hi = g.key(o + iv::Point3::Constant(max_range + 0.5));
  for (int z = lo.z; z <= hi.z; ++z)
    for (int y = lo.y; y <= hi.y; ++y)
      for (int x = lo.x; x <= hi.x; ++x) {
        const iv::Key key{x, y, z};
        const iv::Point3 p = rt * (g.center(key) - o);
        if (p.z() <= 1e-6) continue;
        const double u = k.fx * p.x() / p.z() + k.cx + 0.5, v = k.fy * p.y() / p.z() + k.cy + 0.5;
        if (u < -1e-4 || v < -1e-4 || u >= w + 1e-4 || v >= h + 1e-4) continue;
        const bool near_edge = std::abs(u - std::round(u)) < 1e-4 || std::abs(v - std::round(v)) < 1e-4;
        const int ui = std::clamp(static_cast<int>(std::floor(u)), 0, w - 1),
                  vi = std::clamp(static_cast<int>(std::floor(v)), 0, h - 1);
        const double r = reach[static_cast<std::size_t>(vi * w + ui)];
        if (near_edge || std::abs(p.z() - r) < 1e-4) {
          if (!out.cls.contains(key) || out.cls[key] != Class::Hit) out.unsure.insert(key);
          continue;
        }
        if (p.z() <= r && !out.cls.contains(key)) out.cls[key] = Class::Miss;
      }
  return out;
}

// The class a Bayes grid holds after one update: a hit raises the log-odds, a miss lowers them.
Class class_of(const iv::BayesGrid& g, const iv::Key& k) {
  if (!g.is_observed(k)) return Class::None;
  return g.update_policy().log_odds(g.cell(k)) > 0 ? Class::Hit : Class::Miss;
}

}  // namespace

TEST_CASE("projective insertion gives each voxel the class of the pixel its centre projects into",
          "[raycast][projective]") {
  for (const std::uint64_t seed : {1u, 2u, 3u}) {
    for (const double band : {0.0, 0.5, 1.5}) {
      CAPTURE(seed, band);
      const iv::DepthFrame f = room_frame_small(seed);
      iv::BayesGrid grid(0.05);
      const iv::InsertStats st = iv::insert_depth_image_projective(grid, f, {}, band);
      const Expected want = brute_force(grid.geometry(), f, f.max_range, band);
      std::size_t compared = 0, hits = 0, misses = 0;
      for (const auto& [key, c] : want.cls) {
        if (want.unsure.contains(key)) continue;
        ++compared;
        (c == Class::Hit ? hits : misses) += 1;
        REQUIRE(class_of(grid, key) == c);
      }
      // Nothing outside the brute force's classes (save the unsure voxels) is observed.
      grid.for_each_observed([&](const iv::Key& key, const auto&) {
        if (!want.unsure.contains(key)) REQUIRE(want.cls.contains(key));
      });
      CHECK(want.unsure.size() * 50 < compared);
      CHECK(hits > 300);
      CHECK(misses > 10000);
      CHECK(st.hits == hits + static_cast<std::size_t>(
                                  std::count_if(want.unsure.begin(), want.unsure.end(),
                                                [&](const iv::Key& k) { return class_of(grid, k) == Class::Hit; })));
      CHECK(st.rays + st.skipped() == f.image.depth.size());
      CHECK(st.skipped_invalid == 3);
    }
  }
}

TEST_CASE("projective insertion of a wall frees the voxels in front, hits the wall's voxels, leaves those behind",
          "[raycast][projective]") {
  // Camera at the origin looking along world +z (identity pose: optical z forward = world z), a
  // wall at z-depth 1.02 over the whole image; 0.1 m voxels: key z 10 holds the wall.
  const auto k = iv::PinholeIntrinsics::from_fov(40, 30, 0.9, 0.7);
  iv::DepthImage img(40, 30);
  for (auto& d : img.depth) d = 1.02f;
  iv::BayesGrid grid(iv::GridGeometry(0.1, iv::Point3(-5.0, -5.0, -5.0)), std::nullopt);  // centres at z = 0.05 + 0.1 k
  const iv::InsertStats st = iv::insert_depth_image_projective(grid, img, k, iv::Pose::Identity());
  CHECK(st.rays == 1200);
  CHECK(st.truncated == 0);
  std::size_t free_in_front = 0, wall = 0;
  grid.for_each_observed([&](const iv::Key& key, const auto&) {
    const double z = grid.geometry().center(key).z();
    if (z < 0.96) {
      REQUIRE(class_of(grid, key) == Class::Miss);
      ++free_in_front;
    } else {
      REQUIRE(z == Approx(1.05));  // the wall's layer, nothing behind it
      REQUIRE(class_of(grid, key) == Class::Hit);
      ++wall;
    }
  });
  // The wall's voxels: those the 1200 returns fall in (x and y within the image's footprint).
  std::set<iv::Key> walls;
  for (int v = 0; v < 30; ++v)
    for (int u = 0; u < 40; ++u)
      walls.insert(grid.geometry().key(iv::pixel_point(k, iv::Pose::Identity(), u, v, 1.02)));
  CHECK(wall == walls.size());
  // A column of free voxels along the optical axis (the first two, within 0.2 m of the camera,
  // have centres 0.05 m off the axis that project outside this narrow image).
  for (int z = 2; z < 10; ++z) {
    const iv::Key axis = grid.geometry().key(iv::Point3(0.01, 0.01, 0.1 * z + 0.05));
    CHECK(class_of(grid, axis) == Class::Miss);
  }
  CHECK(free_in_front > 100);
}

TEST_CASE("projective insertion frees no-return pixels up to the max range, and skips them without one",
          "[raycast][projective]") {
  const auto k = iv::PinholeIntrinsics::from_fov(20, 16, 0.8, 0.6);
  iv::DepthImage img(20, 16);
  for (auto& d : img.depth) d = kInf;
  iv::Pose pose = iv::Pose::Identity();
  pose.translate(iv::Point3(0.33, -0.21, 0.47));
  pose.rotate(Eigen::AngleAxisd(0.7, iv::Point3(0.2, 1.0, -0.4).normalized()));
  SECTION("with a max range") {
    iv::BayesGrid grid(0.05);
    const iv::InsertStats st = iv::insert_depth_image_projective(grid, img, k, pose, {.max_range = 1.5});
    CHECK(st.rays == 320);
    CHECK(st.truncated == 320);
    CHECK(st.hits == 0);
    CHECK(st.misses > 1000);
    // Every observed voxel is free, its centre within the max range (its pixel's ray is within
    // a pixel of its own direction: a relative slack of 1e-2).
    grid.for_each_observed([&](const iv::Key& key, const auto&) {
      REQUIRE(class_of(grid, key) == Class::Miss);
      REQUIRE((grid.geometry().center(key) - pose.translation()).norm() <= 1.5 * 1.01);
    });
    // On the optical axis: free up to the range.
    CHECK(class_of(grid, grid.geometry().key(pose * iv::Point3(0, 0, 1.4))) == Class::Miss);
    CHECK(class_of(grid, grid.geometry().key(pose * iv::Point3(0, 0, 1.6))) == Class::None);
  }
  SECTION("without one") {
    iv::BayesGrid grid(0.05);
    const iv::InsertStats st = iv::insert_depth_image_projective(grid, img, k, pose);
    CHECK(st.skipped_no_max_range == 320);
    CHECK(st.rays == 0);
    CHECK(grid.observed_count() == 0);
  }
}

TEST_CASE("a return beyond the max range frees up to it and hits nothing, and one closer than min_range is skipped",
          "[raycast][projective]") {
  const auto k = iv::PinholeIntrinsics::from_fov(10, 8, 0.5, 0.4);
  iv::DepthImage img(10, 8);
  for (auto& d : img.depth) d = 3.0f;
  img.at(0, 0) = 0.05f;
  iv::BayesGrid grid(0.05);
  const iv::InsertStats st =
      iv::insert_depth_image_projective(grid, img, k, iv::Pose::Identity(), {.max_range = 2.0, .min_range = 0.1});
  CHECK(st.skipped_min_range == 1);
  CHECK(st.rays == 79);
  CHECK(st.truncated == 79);
  CHECK(st.hits == 0);
  CHECK(class_of(grid, grid.geometry().key(iv::Point3(0.01, 0.01, 1.9))) == Class::Miss);
  CHECK(class_of(grid, grid.geometry().key(iv::Point3(0.01, 0.01, 2.1))) == Class::None);
}

TEMPLATE_TEST_CASE("projective insertion updates every policy and storage as a hand-applied update of the same voxels",
                   "[raycast][projective][typed]", INTERVOX_TEST_GRIDS) {
  const iv::DepthFrame f = room_frame_small(5);
  const iv::Bounds bounds{{-0.5, -0.5, -0.5}, {3.0, 3.5, 3.0}};  // cuts the room: outside_bounds counted
  // The classes from a Bayes grid (the rule is the policy's business no more than the storage's).
  iv::BayesGrid probe(0.05);
  iv::insert_depth_image_projective(probe, f);
  TestType grid = test::make_grid_for<TestType>(0.05, bounds);
  TestType hand = test::make_grid_for<TestType>(0.05, bounds);
  const iv::InsertStats st = iv::insert_depth_image_projective(grid, f);
  std::size_t inside = 0, outside = 0;
  probe.for_each_observed([&](const iv::Key& key, const auto&) {
    const bool in = !hand.key_box() || hand.key_box()->contains(key);
    (in ? inside : outside) += 1;
    if (in) hand.update(key, class_of(probe, key) == Class::Hit ? iv::Observation::Hit : iv::Observation::Miss);
  });
  CHECK(st.hits + st.misses == inside);
  // Counted: the voxels of blocks the box cuts (blocks wholly outside it are never visited).
  CHECK(st.outside_bounds <= outside);
  if constexpr (test::kConstructBounded<TestType>) CHECK(outside > 0);
  if constexpr (!test::kConstructBounded<TestType>) CHECK(st.outside_bounds == 0);
  REQUIRE(grid.observed_count() == hand.observed_count());
  grid.for_each_observed([&](const iv::Key& key, const auto& c) { REQUIRE(rt::same_cell(c, hand.cell(key))); });
}

TEST_CASE("projective insertion gives the same grid on any number of threads and with the vector or scalar form",
          "[raycast][projective][threads]") {
  iv::use_vector_walks();  // the AVX2 form where the processor runs it
  std::vector<iv::DepthFrame> frames;
  for (std::uint64_t s = 1; s <= 4; ++s) frames.push_back(room_frame_small(s));
  auto run = [&](unsigned threads, iv::detail::WalkKind walk) {
    test::ThreadCap cap(threads);
    iv::BayesGrid g(0.02);
    iv::ProjectiveInserter ins({.threads = threads});
    iv::detail::ScanInserterAccess::set_walk(ins, walk);
    std::vector<iv::InsertStats> stats;
    for (const auto& f : frames) stats.push_back(ins.insert_depth_image(g, f));
    std::vector<std::pair<iv::Key, float>> cells;  // in storage order: the block allocation order too
    g.for_each_observed([&](const iv::Key& k, float c) { cells.emplace_back(k, c); });
    return std::pair{cells, stats};
  };
  const auto one = run(1, iv::detail::WalkKind::Table);
  REQUIRE(one.first.size() > 50000);
  for (const unsigned t : {1u, 2u, 3u, 5u})
    for (const auto walk : {iv::detail::WalkKind::Table, iv::detail::WalkKind::Fastest}) {
      CAPTURE(t, iv::detail::walk_name(walk));
      const auto other = run(t, walk);
      REQUIRE(other.first == one.first);
      REQUIRE(other.second == one.second);
    }
}

TEST_CASE("projective insertion agrees with the exact insertion on the class of most voxels both observe",
          "[raycast][projective]") {
  // Ten frames of the small room, both inserters; the classes (occupied, free, unknown by the
  // Bayes thresholds) of the voxels both observe. docs/raycasting.md measures the room frame
  // (640 x 480) with bench_raycast: 98.4 %.
  iv::BayesGrid exact(0.05), proj(0.05);
  iv::ScanInserter ex;
  iv::ProjectiveInserter pj;
  for (std::uint64_t s = 1; s <= 10; ++s) {
    const iv::DepthFrame f = room_frame_small(s);
    ex.insert_depth_image(exact, f);
    pj.insert_depth_image(proj, f);
  }
  std::size_t both = 0, same = 0, occupied = 0, occupied_same = 0;
  exact.for_each_observed([&](const iv::Key& k, float) {
    if (!proj.is_observed(k)) return;
    ++both;
    same += exact.occupancy(k) == proj.occupancy(k);
    if (exact.occupancy(k) == iv::Occupancy::Occupied) {
      ++occupied;
      occupied_same += proj.occupancy(k) == iv::Occupancy::Occupied;
    }
  });
  CAPTURE(both, same, occupied, occupied_same);
  CHECK(both > 20000);
  CHECK(double(same) / double(both) >= 0.95);
  CHECK(double(occupied_same) / double(occupied) >= 0.95);
}

TEST_CASE("projective insertion refuses bad input with a clear error and leaves the grid unchanged",
          "[raycast][projective][errors]") {
  const iv::DepthFrame f = room_frame_small(1);
  iv::BayesGrid grid(0.05);
  SECTION("intrinsics that do not match the image") {
    auto k = f.intrinsics;
    k.width = 31;
    CHECK_THROWS_AS(iv::insert_depth_image_projective(grid, f.image, k, f.pose), iv::InvalidArgument);
  }
  SECTION("a hit band that is negative or NaN") {
    CHECK_THROWS_AS(iv::ProjectiveInserter({}, -0.5), iv::InvalidArgument);
    CHECK_THROWS_AS(iv::ProjectiveInserter({}, std::nan("")), iv::InvalidArgument);
  }
  SECTION("a pose that is not rigid") {
    iv::Pose p = f.pose;
    p.linear() *= 1.5;
    CHECK_THROWS_AS(iv::insert_depth_image_projective(grid, f.image, f.intrinsics, p), iv::InvalidArgument);
  }
  SECTION("a pose with NaN skips every pixel") {
    iv::Pose p = f.pose;
    p.translation().x() = std::nan("");
    const iv::InsertStats st = iv::insert_depth_image_projective(grid, f.image, f.intrinsics, p, {.max_range = 4.0});
    CHECK(st.skipped_invalid == f.image.depth.size());
  }
  SECTION("depth in millimetres read as metres, without a max range, exceeds the insertion budget") {
    iv::DepthImage mm = f.image;
    for (auto& d : mm.depth) d *= 1000.0f;
    CHECK_THROWS_WITH(iv::insert_depth_image_projective(grid, mm, f.intrinsics, f.pose),
                      Catch::Contains("millimetres") && Catch::Contains("max_grid_bytes"));
  }
  CHECK(grid.observed_count() == 0);
}

TEST_CASE("a block corner a hair in front of the camera plane is projected without an out-of-range conversion",
          "[raycast][projective]") {
  // The camera looks along world +x from 1e-7 m before a plane of voxel centres (x = 0.025 at
  // 5 cm), a quarter voxel off their rows; a 100 px focal length: those centres project to
  // u = 100 y / 1e-7, far beyond what an int holds (UBSan: float-cast-overflow in may_update()).
  const iv::PinholeIntrinsics k{32, 24, 100.0, 100.0, 15.5, 11.5};
  iv::DepthFrame f;
  f.intrinsics = k;
  f.image = iv::DepthImage(32, 24);
  for (auto& d : f.image.depth) d = 0.975f;  // a wall at x = 1
  f.image.at(3, 4) = kInf;
  f.pose = iv::Pose::Identity();
  Eigen::Matrix3d r;
  r.col(0) = iv::Point3(0, -1, 0);  // optical x: world -y
  r.col(1) = iv::Point3(0, 0, -1);  // optical y: world -z
  r.col(2) = iv::Point3(1, 0, 0);   // optical z: world +x
  f.pose.linear() = r;
  f.pose.translation() = iv::Point3(0.025 - 1e-7, 0.0125, 0.0125);
  f.max_range = 2.0;
  // The test of one box straight: corners from the plane 1e-7 m ahead to 3 m, +-3 m aside.
  iv::detail::ProjectedFrame frame;
  iv::BayesGrid grid(0.05);
  iv::InsertStats ignored;
  frame.build(grid.geometry(), f.image, k, f.pose, {.max_range = 2.0}, 0.025, 1, ignored);
  CHECK(frame.may_update(iv::Point3(0.025, -3.0, -3.0), iv::Point3(3.0, 3.0, 3.0)));
  CHECK(frame.may_update(iv::Point3(0.025, -3.0, -3.0), iv::Point3(0.025, 3.0, 3.0)));      // u from -3e9 to 3e9
  CHECK_FALSE(frame.may_update(iv::Point3(0.025, 2.0, 2.0), iv::Point3(0.025, 3.0, 3.0)));  // all left of the image
  // The insertion: each voxel the class of the pixel its centre projects into.
  const iv::InsertStats st = iv::insert_depth_image_projective(grid, f, {}, 0.5);
  const Expected want = brute_force(grid.geometry(), f, f.max_range, 0.5);
  std::size_t compared = 0;
  for (const auto& [key, c] : want.cls) {
    if (want.unsure.contains(key)) continue;
    ++compared;
    REQUIRE(class_of(grid, key) == c);
  }
  grid.for_each_observed([&](const iv::Key& key, const auto&) {
    if (!want.unsure.contains(key)) REQUIRE(want.cls.contains(key));
  });
  CHECK(compared > 100);
  CHECK(st.hits > 10);
  CHECK(st.misses > 50);
}

TEST_CASE("a finite max range beyond the largest float frees what any range beyond the map frees",
          "[raycast][projective]") {
  // No-return pixels from inside a dense 4 m box: every range that reaches past the box frees the
  // same voxels. 1e39 is finite as a double and infinite as a float.
  const auto k = iv::PinholeIntrinsics::from_fov(24, 18, 1.0, 0.8);
  iv::DepthImage img(24, 18);
  for (auto& d : img.depth) d = kInf;
  iv::Pose pose = iv::Pose::Identity();
  pose.translate(iv::Point3(0.52, 0.48, 0.51));
  pose.rotate(Eigen::AngleAxisd(0.3, iv::Point3(0.1, 1.0, 0.2).normalized()));
  const iv::Bounds box{{0, 0, 0}, {4, 4, 4}};
  iv::DenseBayesGrid near_range(0.1, box), huge_range(0.1, box);
  const iv::InsertStats a = iv::insert_depth_image_projective(near_range, img, k, pose, {.max_range = 100.0});
  const iv::InsertStats b = iv::insert_depth_image_projective(huge_range, img, k, pose, {.max_range = 1e39});
  CHECK(a.misses > 5000);
  CHECK(b.misses == a.misses);
  CHECK(b.rays == a.rays);
  std::size_t differ = 0;
  near_range.for_each_observed([&](const iv::Key& key, const auto& c) {
    differ += !huge_range.is_observed(key) || !(huge_range.cell(key) == c) ? 1 : 0;
  });
  CHECK(differ == 0);
  CHECK(huge_range.observed_count() == near_range.observed_count());
  // A sparse grid cannot hold what such a range frees: the budget refuses it.
  iv::BayesGrid sparse(0.1);
  CHECK_THROWS_WITH(iv::insert_depth_image_projective(sparse, img, k, pose, {.max_range = 1e39}),
                    Catch::Contains("max_grid_bytes"));
  CHECK(sparse.observed_count() == 0);
}

TEST_CASE("with the budget off, a frame reaching hundreds of kilometres is refused at once, and a dense grid clips it",
          "[raycast][projective][errors]") {
  // One return 400 km away (within the key range at 5 cm), the rest on a wall 2 m ahead.
  const auto k = iv::PinholeIntrinsics::from_fov(64, 48, 1.0, 0.8);
  iv::DepthImage img(64, 48);
  for (auto& d : img.depth) d = 2.0f;
  img.at(40, 30) = 4e5f;
  iv::Pose pose = iv::Pose::Identity();
  pose.translate(iv::Point3(1.01, 1.02, 1.03));
  iv::InsertOptions off;
  off.max_grid_bytes = iv::kUnlimitedInsertBudget;
  iv::BayesGrid sparse(0.05);
  const auto start = std::chrono::steady_clock::now();
  CHECK_THROWS_WITH(iv::insert_depth_image_projective(sparse, img, k, pose, off),
                    Catch::Contains("superblocks") && Catch::Contains("exact insertion"));
  CHECK(std::chrono::steady_clock::now() - start < std::chrono::seconds(10));
  CHECK(sparse.observed_count() == 0);
  // A dense grid visits its box only.
  iv::DenseBayesGrid dense(0.05, iv::Bounds{{0, 0, 0}, {4, 4, 4}});
  const iv::InsertStats st = iv::insert_depth_image_projective(dense, img, k, pose, off);
  CHECK(st.rays == 64 * 48);
  CHECK(st.misses > 10000);
  CHECK(st.outside_bounds >= 1);  // the far return's hit
}
