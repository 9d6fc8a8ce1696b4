// The simulator's fast paths against the exact ones: the BVH and the cone candidates of pixel
// tiles and striper runs against testing every primitive (the brute-force first hit), and the
// tiled rig, camera and sweep simulation against tracing every ray one by one with sim::trace()
// (a striper's with sim::trace_striper()).
#include "../common/grid_types.hpp"

#include <catch2/catch.hpp>
#include <intervox/core/parallel.hpp>
#include <intervox/sim/sim.hpp>

#include <Eigen/Geometry>
#include <cmath>
#include <string>
#include <variant>
#include <vector>

namespace iv = intervox;
namespace sim = intervox::sim;
using iv::Point3;

namespace {

struct NamedScene {
  std::string name;
  sim::Scene scene;
  iv::Bounds region;  // where ray origins and cameras are drawn
};

// The lab room with a glass closet, the lab room with mirror closet and door, and the workcell.
std::vector<NamedScene> scenes() {
  std::vector<NamedScene> out;
  const auto glass = sim::make_lab_room({sim::Material::transparent()});
  out.push_back({"lab room, glass closet", glass.scene, glass.interior});
  sim::LabRoomOptions o;
  o.closet_material = sim::Material::mirror();
  o.door_material = sim::Material::mirror();
  const auto mirrors = sim::make_lab_room(o);
  out.push_back({"lab room, mirror closet and door", mirrors.scene, mirrors.interior});
  const auto cell = sim::make_workcell();
  out.push_back({"workcell", cell.scene, cell.scene.bounds()});
  return out;
}

Point3 random_point(sim::BeamRng& rng, const iv::Bounds& b) {
  return {rng.uniform(b.min.x(), b.max.x()), rng.uniform(b.min.y(), b.max.y()), rng.uniform(b.min.z(), b.max.z())};
}

Point3 random_direction(sim::BeamRng& rng) { return Point3(rng.normal(), rng.normal(), rng.normal()).normalized(); }

iv::Pose random_pose(sim::BeamRng& rng, const iv::Bounds& region) {
  iv::Pose p = iv::Pose::Identity();
  const Eigen::Quaterniond q(rng.normal(), rng.normal(), rng.normal(), rng.normal());
  p.linear() = q.normalized().toRotationMatrix();
  p.translation() = random_point(rng, region);
  return p;
}

// Exactly the same hit: the same t bit for bit, object and primitive.
bool same_hit(const std::optional<sim::RayHit>& a, const std::optional<sim::RayHit>& b) {
  if (a.has_value() != b.has_value()) return false;
  return !a || (a->t == b->t && a->object == b->object && a->primitive == b->primitive);
}

bool same_beams(const std::vector<iv::Beam>& x, const std::vector<iv::Beam>& y) {
  if (x.size() != y.size()) return false;
  for (std::size_t i = 0; i < x.size(); ++i)
    if (x[i].origin != y[i].origin || x[i].end != y[i].end || x[i].hit != y[i].hit) return false;
  return true;
}

// The exact path of a rig scan: every ray of SensorRig::rays() traced alone (as simulate_path()
// did before the tiles), invalid beams dropped; a striper's with trace_striper() and its camera.
std::vector<iv::Beam> trace_one_by_one(const iv::SensorRig& rig, const sim::Scene& scene,
                                       const std::vector<iv::Pose>& bodies, std::uint64_t seed,
                                       std::vector<sim::BeamPath>& paths) {
  std::vector<iv::Beam> beams;
  paths.clear();
  for (std::size_t k = 0; k < bodies.size(); ++k)
    for (const auto& r : rig.rays(bodies[k])) {
      sim::BeamRng rng(seed, r.sensor, k * rig.beam_count(r.sensor) + r.beam);
      const auto* st = std::get_if<sim::LaserStriper>(&rig.sensors()[r.sensor].sensor);
      const auto t = st ? sim::trace_striper(scene, r.ray.origin, r.ray.direction,
                                             rig.sensor_pose(r.sensor, bodies[k]) * st->camera_position(), r.min_range,
                                             r.ray.range, rng)
                        : sim::trace(scene, r.ray.origin, r.ray.direction, r.min_range, r.ray.range, rng);
      if (t.path == sim::BeamPath::Invalid) continue;
      beams.push_back({r.ray.origin, r.ray.at(t.returned() ? t.range : r.ray.range), t.returned()});
      paths.push_back(t.path);
    }
  return beams;
}

}  // namespace

TEST_CASE("the BVH finds exactly the brute-force first hit, ties on shared faces included",
          "[sim][intersect][oracle]") {
  for (const auto& s : scenes()) {
    INFO(s.name);
    sim::BeamRng rng(21, 0, 0);
    int mismatches = 0;
    for (int i = 0; i < 3000; ++i) {
      const Point3 o = random_point(rng, s.scene.bounds()), d = random_direction(rng);
      const double tmin = i % 3 == 0 ? rng.uniform(0.0, 1.0) : 0.0;
      mismatches += !same_hit(s.scene.intersect(o, d, tmin), s.scene.intersect_brute_force(o, d, tmin));
    }
    CHECK(mismatches == 0);
  }
  // Downward rays inside the lab's closet meet its bottom face and the floor's top face at the same
  // t (both at z = 0): the primitive added first (the floor) wins on every path.
  const auto lab = sim::make_lab_room();
  sim::Scene closet_alone;
  closet_alone.add_box(lab.scene.object_bounds(lab.closet));
  sim::BeamRng rng(22, 0, 0);
  int ties = 0, mismatches = 0;
  for (int i = 0; i < 2000; ++i) {
    const Point3 o(rng.uniform(0.01, 0.59), rng.uniform(3.41, 4.59), rng.uniform(0.01, 1.9));
    const Point3 d = Point3(rng.normal(), rng.normal(), -std::abs(rng.normal())).normalized();
    const auto a = lab.scene.intersect(o, d), e = lab.scene.intersect_brute_force(o, d);
    mismatches += !same_hit(a, e);
    const auto c = closet_alone.intersect(o, d);  // the closet's own first hit from inside: its boundary
    ties += a && c && a->object == *lab.scene.find("floor") && c->t == a->t;
  }
  CHECK(mismatches == 0);
  CHECK(ties > 200);  // the tie is common for these rays, so the rule is exercised
}

TEST_CASE("the cone candidates of a pixel tile give exactly the brute-force first hit of each pixel",
          "[sim][intersect][oracle]") {
  const auto cam = sim::DepthCamera::o3d100();
  const int w = cam.intrinsics.width, h = cam.intrinsics.height;
  for (const auto& s : scenes()) {
    INFO(s.name);
    sim::BeamRng rng(23, 0, 0);
    std::vector<sim::ConeCandidate> candidates;
    int rays = 0, mismatches = 0, passes = 0;
    std::size_t listed = 0, tiles = 0;
    for (int view = 0; view < 40; ++view) {
      const iv::Pose pose = random_pose(rng, s.region);
      for (int v0 = 0; v0 < h; v0 += sim::detail::kTileSize)
        for (int u0 = 0; u0 < w; u0 += sim::detail::kTileSize) {
          const int u1 = std::min(w, u0 + sim::detail::kTileSize) - 1,
                    v1 = std::min(h, v0 + sim::detail::kTileSize) - 1;
          s.scene.cone_primitives(sim::detail::pixel_cone(cam.intrinsics, pose, u0, v0, u1, v1), candidates);
          listed += candidates.size();
          ++tiles;
          for (int v = v0; v <= v1; ++v)
            for (int u = u0; u <= u1; ++u) {
              const iv::Ray r = iv::pixel_ray(cam.intrinsics, pose, u, v, cam.max_range);
              const auto e = s.scene.intersect_brute_force(r.origin, r.direction, 0.0, r.range);
              mismatches += !same_hit(s.scene.intersect_among(candidates, r.origin, r.direction, 0.0, r.range), e);
              ++rays;
              if (!e) continue;
              // The continuation of a beam that passes a transparent surface: from just beyond it.
              const double from = e->t + 1e-6;
              mismatches += !same_hit(s.scene.intersect_among(candidates, r.origin, r.direction, from, r.range),
                                      s.scene.intersect_brute_force(r.origin, r.direction, from, r.range));
              ++passes;
            }
        }
    }
    CHECK(mismatches == 0);
    CHECK(rays == 40 * w * h);
    CHECK(passes > rays / 4);
    // The cones cull: a tile lists far fewer than all primitives.
    CHECK(double(listed) / double(tiles) < 0.5 * double(s.scene.primitive_count()));
  }
}

TEST_CASE("the cone candidates of a run of striper samples give exactly the brute-force first hit of each sample",
          "[sim][intersect][oracle]") {
  const auto st = sim::LaserStriper::scancontrol_2700();
  for (const auto& s : scenes()) {
    INFO(s.name);
    sim::BeamRng rng(26, 0, 0);
    std::vector<sim::ConeCandidate> candidates;
    int rays = 0, mismatches = 0, hits = 0;
    std::size_t listed = 0, runs = 0;
    for (int profile = 0; profile < 60; ++profile) {
      const iv::Pose pose = random_pose(rng, s.region);
      for (int i0 = 0; i0 < st.samples; i0 += sim::detail::kFanRun) {
        const int i1 = std::min(st.samples, i0 + sim::detail::kFanRun) - 1;
        s.scene.cone_primitives(sim::detail::fan_cone(st, pose, i0, i1), candidates);
        listed += candidates.size();
        ++runs;
        for (int i = i0; i <= i1; ++i) {
          const Point3 d = pose.linear() * st.direction(i);
          const auto e = s.scene.intersect_brute_force(pose.translation(), d, 0.0, st.max_range);
          mismatches += !same_hit(s.scene.intersect_among(candidates, pose.translation(), d, 0.0, st.max_range), e);
          hits += e.has_value();
          ++rays;
        }
      }
    }
    CHECK(mismatches == 0);
    CHECK(rays == 60 * st.samples);
    CHECK(hits > rays / 10);
    CHECK(double(listed) / double(runs) < 0.5 * double(s.scene.primitive_count()));
  }
}

TEST_CASE("cone candidates are listed nearest first and a bad cone is rejected", "[sim][intersect][errors]") {
  const auto lab = sim::make_lab_room();
  const auto cam = sim::DepthCamera::o3d100();
  iv::Pose pose = iv::Pose::Identity();
  pose.linear() = sim::look_at({6, 1.5, 0.5}, {0, 1.5, 0.5}).linear();
  pose.translation() = Point3(6, 1.5, 0.5);
  std::vector<sim::ConeCandidate> c;
  lab.scene.cone_primitives(sim::detail::pixel_cone(cam.intrinsics, pose, 0, 0, 63, 47), c);
  REQUIRE(c.size() >= 2);
  for (std::size_t i = 1; i < c.size(); ++i) CHECK(c[i - 1].distance <= c[i].distance);
  // The length of a normal does not matter.
  sim::RayCone scaled = sim::detail::pixel_cone(cam.intrinsics, pose, 0, 0, 63, 47);
  for (auto& n : scaled.normals) n *= 1e3;
  std::vector<sim::ConeCandidate> c2;
  lab.scene.cone_primitives(scaled, c2);
  REQUIRE(c2.size() == c.size());
  for (std::size_t i = 0; i < c.size(); ++i)
    CHECK((c2[i].primitive == c[i].primitive && c2[i].distance == c[i].distance));
  // Every object of the lab room is one primitive: the floor lies 0.5 m below the camera.
  REQUIRE(lab.scene.primitive_count() == lab.scene.size());
  bool floor = false;
  for (const auto& x : c)
    if (lab.scene.name(x.primitive) == "floor") {
      floor = true;
      CHECK(x.distance <= 0.5);
      CHECK(x.distance > 0.5 - 1e-6);
    }
  CHECK(floor);
  sim::RayCone bad;
  bad.planes = 5;
  CHECK_THROWS_AS(lab.scene.cone_primitives(bad, c), iv::InvalidArgument);
  bad.planes = 1;
  bad.normals[0] = Point3(std::nan(""), 0, 0);
  CHECK_THROWS_AS(lab.scene.cone_primitives(bad, c), iv::InvalidArgument);
  bad.normals[0] = Point3::Zero();
  CHECK_THROWS_AS(lab.scene.cone_primitives(bad, c), iv::InvalidArgument);
  bad.normals[0] = Point3::UnitX();
  bad.apex = Point3(0, std::numeric_limits<double>::infinity(), 0);
  CHECK_THROWS_AS(lab.scene.cone_primitives(bad, c), iv::InvalidArgument);
}

TEST_CASE("a tiled rig scan equals tracing every ray of the rig one by one, bit for bit", "[sim][rig][oracle]") {
  const auto all = scenes();
  sim::BeamRng rng(24, 0, 0);
  for (std::size_t k = 0; k < 2; ++k) {
    const auto& s = all[k];  // the two lab rooms: the mobile base
    INFO(s.name);
    const auto rig = iv::SensorRig::mobile_base();
    std::vector<iv::Pose> bodies;
    for (const Point3& p : {Point3(6.0, 1.5, 0.0), Point3(1.6, 4.0, 0.0), Point3(4.5, 4.0, 0.0)}) {
      iv::Pose b = iv::Pose::Identity();
      b.linear() = Eigen::AngleAxisd(rng.uniform(0.0, 6.28), Point3::UnitZ()).toRotationMatrix();
      b.translation() = p;
      bodies.push_back(b);
    }
    std::vector<sim::BeamPath> expected_paths;
    const auto expected = trace_one_by_one(rig, s.scene, bodies, 31, expected_paths);
    std::size_t reflected = 0;
    for (const auto p : expected_paths) reflected += p == sim::BeamPath::Reflected || p == sim::BeamPath::Passed;
    CHECK(reflected > 100);  // mirrors and glass are on the paths
    for (const unsigned threads : {1u, 2u, 5u}) {
      INFO("threads " << threads);
      const test::ThreadCap cap(8);  // 5 threads even on a 2-core machine
      std::vector<sim::BeamPath> paths;
      const auto beams = sim::simulate_path(rig, s.scene, bodies, 31, {threads}, &paths);
      CHECK(same_beams(beams, expected));
      CHECK(paths == expected_paths);
    }
  }
  // The arm's striper on the workcell (polished ring, glass bottle).
  const auto cell = sim::make_workcell();
  const auto arm = iv::SensorRig::arm();
  std::vector<iv::Pose> flange;
  for (const auto& p : sim::sweep_towards({0.75, 0.2, 1.2}, cell.table_center, 0.25, 12))
    flange.push_back(arm.body_pose_for(0, p));
  std::vector<sim::BeamPath> expected_paths, paths;
  const auto expected = trace_one_by_one(arm, cell.scene, flange, 32, expected_paths);
  CHECK(same_beams(sim::simulate_path(arm, cell.scene, flange, 32, {2}, &paths), expected));
  CHECK(paths == expected_paths);
}

TEST_CASE("a striper sweep traced in runs equals tracing every sample one by one, bit for bit",
          "[sim][sensor][oracle]") {
  // The preset's triangulation: the camera's lines of sight go through the BVH in both.
  const auto st = sim::LaserStriper::scancontrol_2700();
  const auto cell = sim::make_workcell();  // polished ring (reflects), glass bottle (passes)
  const auto path = sim::sweep_towards({0.7, 0.3, 1.1}, cell.table_center, 0.3, 30);
  std::vector<iv::Beam> expected;
  std::vector<sim::BeamPath> expected_paths;
  std::size_t other = 0;
  for (std::size_t k = 0; k < path.size(); ++k)
    for (int i = 0; i < st.samples; ++i) {
      const Point3 d = path[k].linear() * st.direction(i);
      sim::BeamRng rng(33, 2, k * st.beam_count() + static_cast<std::size_t>(i));
      const auto t = sim::trace_striper(cell.scene, path[k].translation(), d, path[k] * st.camera_position(),
                                        st.min_range, st.max_range, rng);
      if (t.path == sim::BeamPath::Invalid) continue;
      expected.push_back(
          {path[k].translation(), path[k].translation() + (t.returned() ? t.range : st.max_range) * d, t.returned()});
      expected_paths.push_back(t.path);
      other += t.path == sim::BeamPath::Reflected || t.path == sim::BeamPath::Passed;
    }
  CHECK(other > 100);  // the ring and the bottle are on the paths
  for (const unsigned threads : {1u, 2u, 5u}) {
    INFO("threads " << threads);
    const test::ThreadCap cap(8);
    const auto m = sim::simulate_sweep(st, cell.scene, path, 33, {threads}, 2);
    CHECK(same_beams(m.beams, expected));
    CHECK(m.paths == expected_paths);
  }
}

TEST_CASE("a tiled depth image equals tracing every pixel's ray one by one, bit for bit", "[sim][sensor][oracle]") {
  const auto all = scenes();
  // A camera with a partial last tile (width and height not multiples of the tile size).
  const auto odd = sim::DepthCamera::make(37, 21, sim::deg(50), sim::deg(30), 0.1, 6.0);
  for (const auto& s : all) {
    INFO(s.name);
    sim::BeamRng rng(25, 0, 0);
    for (const auto& cam : {sim::DepthCamera::o3d100(), odd}) {
      for (int view = 0; view < 6; ++view) {
        const iv::Pose pose = random_pose(rng, s.region);
        const auto m = sim::simulate(cam, s.scene, pose, 40 + static_cast<std::uint64_t>(view), {2}, 3);
        int mismatches = 0;
        for (int v = 0; v < cam.intrinsics.height; ++v)
          for (int u = 0; u < cam.intrinsics.width; ++u) {
            const std::size_t i = static_cast<std::size_t>(v * cam.intrinsics.width + u);
            const iv::Ray r = iv::pixel_ray(cam.intrinsics, pose, u, v, cam.max_range);
            sim::BeamRng beam_rng(40 + static_cast<std::uint64_t>(view), 3, i);
            const auto t = sim::trace(s.scene, r.origin, r.direction, cam.min_range, r.range, beam_rng);
            const float z = t.returned()                        ? static_cast<float>(t.range * cam.direction(u, v).z())
                            : t.path == sim::BeamPath::NoReturn ? std::numeric_limits<float>::infinity()
                                                                : std::numeric_limits<float>::quiet_NaN();
            const float got = m.image.depth[i];
            mismatches += !(got == z || (std::isnan(got) && std::isnan(z))) || m.paths[i] != t.path;
          }
        CHECK(mismatches == 0);
      }
    }
  }
}
