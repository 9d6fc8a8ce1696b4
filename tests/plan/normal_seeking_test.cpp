// Views that seek normals (plan/normal_seeking.hpp): glint targets with fitted normals, the
// specular condition of a triangulation striper in closed form, and the arm planner's choice
// against a brute-force search over the sphere of views.
#include <catch2/catch.hpp>
#include <intervox/grid/named_grids.hpp>
#include <intervox/plan/arm_planner.hpp>
#include <intervox/plan/normal_seeking.hpp>

#include "../common/grid_types.hpp"

#include <cmath>
#include <numbers>
#include <vector>

namespace iv = intervox;
using Approx = Catch::Detail::Approx;

namespace {
// A plane patch through the object region's centre with unit normal n (tilted towards +x), as the
// beams of a sensor far above it would return from it: one beam per 5 mm on the patch.
std::vector<iv::Beam> plane_hits(const iv::Point3& center, const iv::Point3& n, double half) {
  const iv::Point3 u = n.cross(iv::Point3::UnitY()).normalized(), v = n.cross(u).normalized();
  std::vector<iv::Beam> beams;
  for (double a = -half; a <= half + 1e-9; a += 0.005)
    for (double b = -half; b <= half + 1e-9; b += 0.005) {
      const iv::Point3 p = center + a * u + b * v;
      beams.push_back({p + 0.4 * n, p, true});
    }
  return beams;
}

iv::Point3 tilted_normal(double tilt) { return iv::Point3(std::sin(tilt), 0.0, std::cos(tilt)); }

// Brute force, written apart from glint_score: for each target, the profile of the sweep whose
// laser plane lies nearest (searched over every profile), if within half a voxel or half the
// profile spacing; inside its fan and range, facing laser and camera: cos^n of the angle between
// the normal and the half-vector.
double brute_glint(const iv::LaserStriper& st, const std::vector<iv::Pose>& sweep,
                   const std::vector<iv::GlintTarget>& targets, double exponent, double voxel, double spacing) {
  double total = 0;
  for (const iv::GlintTarget& t : targets) {
    const iv::Pose* nearest = nullptr;
    double off = 1e300;
    for (const iv::Pose& p : sweep) {
      const double y = std::abs((p.inverse() * t.center).y());
      if (y < off - 1e-12) {
        off = y;
        nearest = &p;
      }
    }
    if (off > std::max(0.5 * voxel, 0.5 * spacing) + 1e-12) continue;
    const iv::Pose& p = *nearest;
    const iv::Point3 q = p.inverse() * t.center;
    if (q.z() <= 0) continue;
    const double range = std::sqrt(q.x() * q.x() + q.z() * q.z());
    if (range < st.min_range || range > st.max_range || std::abs(std::atan(q.x() / q.z())) > st.opening / 2) continue;
    const iv::Point3 to_laser = (iv::Point3(p.translation()) - t.center).normalized();
    const iv::Point3 to_camera = (iv::Point3(p * st.camera_position()) - t.center).normalized();
    if (to_laser.dot(t.normal) <= 0 || to_camera.dot(t.normal) <= 0) continue;
    total += std::pow((to_laser + to_camera).normalized().dot(t.normal), exponent);
  }
  return total;
}
}  // namespace

TEMPLATE_TEST_CASE(
    "glint targets are the undecided hit voxels, with the normal of the plane their neighbours' hits lie on",
    "[plan][arm][normals]", INTERVOX_TEST_GRIDS) {
  TestType grid = test::make_grid_for<TestType>(0.01, iv::Bounds{{0, 0, 0}, {1.5, 1.5, 1.5}});
  const iv::Point3 center(0.75, 0.75, 0.77);
  const iv::Bounds bounds{center - iv::Point3::Constant(0.05), center + iv::Point3::Constant(0.05)};
  for (const double tilt : {0.0, 0.4, 0.9}) {
    const iv::Point3 n = tilted_normal(tilt);
    iv::HitRecord hits;
    hits.add(grid.geometry(), plane_hits(center, n, 0.04));
    iv::NormalSeekingParams p;
    const std::vector<iv::GlintTarget> targets = iv::glint_targets(grid, hits, bounds, center - 0.2 * n, p);
    INFO("tilt " << tilt);
    REQUIRE(targets.size() > 20);
    for (const iv::GlintTarget& t : targets) {
      CHECK(hits.contains(t.key));
      // Voxelised plane: within 15 degrees of the true normal, turned away from the inside point.
      CHECK(t.normal.dot(n) > std::cos(15.0 * std::numbers::pi / 180));
      CHECK(t.normal.norm() == Approx(1.0));
    }
  }
  // Voxels the grid holds occupied are decided: no target there.
  iv::HitRecord hits;
  const iv::Point3 n = tilted_normal(0.4);
  hits.add(grid.geometry(), plane_hits(center, n, 0.04));
  const std::vector<iv::GlintTarget> before = iv::glint_targets(grid, hits, bounds, center - 0.2 * n, {});
  const iv::Key decided = before.front().key;
  for (int i = 0; i < 20; ++i) grid.update(decided, iv::Observation::Hit);
  REQUIRE(grid.occupancy(decided) == iv::Occupancy::Occupied);
  const std::vector<iv::GlintTarget> after = iv::glint_targets(grid, hits, bounds, center - 0.2 * n, {});
  CHECK(after.size() == before.size() - 1);
  for (const iv::GlintTarget& t : after) CHECK(!(t.key == decided));
  // Beams without a return and lone hits make no target.
  iv::HitRecord lone;
  lone.add(grid.geometry(),
           std::vector<iv::Beam>{{center + iv::Point3(0, 0, 0.4), center, false},
                                 {center + iv::Point3(0, 0, 0.4), center + iv::Point3(0.03, 0, 0), true}});
  CHECK(lone.size() == 1);
  CHECK(iv::glint_targets(grid, lone, bounds, center, {}).empty());
}

TEST_CASE("the specular match is cos^n of the angle between the normal and the half-vector of laser and camera",
          "[plan][arm][normals]") {
  const iv::LaserStriper st = iv::LaserStriper::scancontrol_2700();
  const iv::Pose sensor = iv::look_at(iv::Point3(0, 0, 0.45), iv::Point3::Zero());
  const iv::Point3 laser(sensor.translation()), camera = sensor * st.camera_position();
  const iv::Point3 half = ((laser.normalized() + camera.normalized())).normalized();
  for (const double off : {0.0, 0.05, 0.15, 0.3}) {
    // The normal turned by `off` from the half-vector, about an axis perpendicular to it.
    const iv::Point3 axis = half.cross(iv::Point3::UnitX()).normalized();
    const iv::Point3 n = Eigen::AngleAxisd(off, axis) * half;
    const iv::GlintTarget t{iv::Key{}, iv::Point3::Zero(), n};
    CHECK(iv::specular_match(st, sensor, t, 40.0) == Approx(std::pow(std::cos(off), 40.0)).epsilon(1e-9));
  }
  // The triangulation angle is the half-vector's offset from the beam: twice it apart at the target.
  CHECK(std::acos(laser.normalized().dot(camera.normalized())) == Approx(st.triangulation_angle()).epsilon(1e-9));
  // Facing away, outside the fan, beyond the range: no match.
  CHECK(iv::specular_match(st, sensor, {iv::Key{}, iv::Point3::Zero(), -half}, 40.0) == 0.0);
  CHECK(iv::specular_match(st, sensor, {iv::Key{}, iv::Point3(0.3, 0.3, 0), half}, 40.0) == 0.0);
  const iv::Pose far = iv::look_at(iv::Point3(0, 0, 1.5), iv::Point3::Zero());
  CHECK(iv::specular_match(st, far, {iv::Key{}, iv::Point3::Zero(), half}, 40.0) == 0.0);
}

TEMPLATE_TEST_CASE(
    "seeking normals, the arm planner chooses the sweep a brute-force search over its candidates finds best",
    "[plan][arm][normals]", iv::DenseIntervalGrid, iv::IntervalGrid, iv::BayesGrid) {
  using G = TestType;
  iv::ArmPlannerParams p;
  p.normals.enabled = true;
  p.normals.weight = 1e6;  // the glint decides
  p.candidates = 64;
  p.threads = GENERATE(1u, 2u);
  iv::ArmPlanner planner(iv::SensorRig::arm(), p);
  auto map = planner.make_map(G(0.01, iv::Bounds{{0, 0, 0}, {1.5, 1.5, 1.5}}));
  const G& grid = map.grid();
  (void)planner.plan(map);  // the initial view
  const iv::Point3 center = *planner.params().center;
  const iv::Point3 n = tilted_normal(0.6);
  const std::vector<iv::Beam> beams = plane_hits(center, n, 0.04);
  map.add_evidence(std::span<const iv::Beam>(beams));  // the hits, the grid left empty
  const iv::ArmPlan r = planner.plan(map);
  REQUIRE(r.termination == iv::Termination::Running);
  REQUIRE(r.glint_targets > 20);
  REQUIRE(r.glint.size() == r.candidates.size());
  REQUIRE(r.selected);
  iv::HitRecord hits;
  hits.add(grid.geometry(), beams);
  const std::vector<iv::GlintTarget> targets = iv::glint_targets(grid, hits, p.object_region, center, p.normals);
  const iv::LaserStriper& st = std::get<iv::LaserStriper>(planner.rig().sensors()[0].sensor);
  std::size_t brute_best = 0;
  std::vector<double> brute;
  for (std::size_t k = 0; k < r.candidates.size(); ++k) {
    brute.push_back(brute_glint(st, planner.sweep(r.candidates[k]), targets, p.normals.lobe_exponent, 0.01,
                                p.sweep_length / (p.profiles - 1)));
    if (brute[k] > brute[brute_best]) brute_best = k;
    CHECK(r.glint[k] == Approx(brute[k]).epsilon(1e-6).margin(1e-9));
  }
  REQUIRE(brute[brute_best] > 0);
  CHECK(brute[*r.selected] == Approx(brute[brute_best]).epsilon(1e-9));
  // The chosen sweep looks at the plane from near its mirror direction, not from the gain's favourite.
  const iv::Point3 from = (iv::Point3(r.view.translation()) - center).normalized();
  CHECK(from.dot(n) > std::cos(0.6));
  // Without the weight the same candidates are chosen by gain (reason Gain).
  iv::ArmPlannerParams plain = p;
  plain.normals.enabled = false;
  iv::ArmPlanner gain_only(iv::SensorRig::arm(), plain);
  (void)gain_only.plan(grid);
  const iv::ArmPlan g = gain_only.plan(grid);
  CHECK(g.reason == iv::ViewReason::Gain);
  CHECK(g.glint.empty());
  if (!(g.view.matrix() == r.view.matrix())) CHECK(r.reason == iv::ViewReason::Normals);
}

TEST_CASE("bad normal-seeking input throws", "[plan][arm][normals]") {
  iv::NormalSeekingParams p;
  p.weight = -1;
  CHECK_THROWS_AS(p.validate(), iv::InvalidArgument);
  p = {};
  p.min_hits = 2;
  CHECK_THROWS_AS(p.validate(), iv::InvalidArgument);
  p = {};
  p.neighbourhood = 0;
  CHECK_THROWS_AS(p.validate(), iv::InvalidArgument);
  iv::ArmPlannerParams a;
  a.normals.lobe_exponent = std::nan("");
  CHECK_THROWS_AS(iv::ArmPlanner(iv::SensorRig::arm(), a), iv::InvalidArgument);
  CHECK_THROWS_AS(iv::glint_score(iv::LaserStriper{}, {}, {}, 40.0, 0.01), iv::InvalidArgument);
  // A target without a finite centre scores nothing.
  const double nan = std::nan("");
  const std::vector<iv::GlintTarget> bad{{iv::Key{}, iv::Point3(nan, 0, 0), iv::Point3::UnitZ()}};
  CHECK(iv::glint_score(iv::LaserStriper{}, {iv::Pose::Identity(), iv::Pose::Identity()}, bad, 40.0, 0.01) == 0.0);
}
