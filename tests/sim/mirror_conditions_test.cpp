// Two mirror conditions of a real time-of-flight camera (issue 32), each off by default: the
// near-normal glint (SimOptions::glint: within a few degrees of normal incidence the camera
// measures the mirror's own range) and the robot's own body in the scene (SimOptions::body: it
// appears in mirrors, never to the cameras' direct rays). Closed-form ranges, options off =
// unchanged results, and the same results for any thread count.
#include <catch2/catch.hpp>
#include <intervox/sim/sim.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <vector>

namespace {
namespace iv = intervox;
namespace sim = intervox::sim;
using iv::Point3;

/// The body pose at \p at turned by \p yaw about z.
iv::Pose mc_body(const Point3& at, double yaw) {
  iv::Pose p = iv::Pose::Identity();
  p.linear() = Eigen::AngleAxisd(yaw, Point3::UnitZ()).toRotationMatrix();
  p.translation() = at;
  return p;
}

/// A rig of one camera at \p at (body frame) looking along \p dir.
iv::SensorRig mc_one_camera(const iv::DepthCamera& cam, const Point3& at, const Point3& dir) {
  iv::SensorRig rig;
  rig.add(cam, iv::look_at(at, at + dir), "camera");
  return rig;
}

/// A perfect mirror without noise (a glint's direct return then lies exactly at the mirror).
sim::Material mc_mirror() {
  sim::Material m = sim::Material::mirror();
  m.sigma = 0.0;
  return m;
}

/// A scan and its ground truth.
struct McScan {
  std::vector<iv::Beam> beams;
  std::vector<sim::BeamPath> paths;
};

McScan mc_scan(const iv::SensorRig& rig, const sim::Scene& scene, const iv::Pose& body, const sim::SimOptions& o,
               std::uint64_t seed = 3) {
  McScan s;
  s.beams = sim::simulate(rig, scene, body, seed, o, &s.paths);
  return s;
}

bool mc_same(const McScan& a, const McScan& b) {
  if (a.beams.size() != b.beams.size() || a.paths != b.paths) return false;
  for (std::size_t i = 0; i < a.beams.size(); ++i)
    if (a.beams[i].origin != b.beams[i].origin || a.beams[i].end != b.beams[i].end || a.beams[i].hit != b.beams[i].hit)
      return false;
  return true;
}

/// The noise-free plane-mirror scene of the glint tests: a mirror filling the plane x = \p d in
/// front of a sensor at the origin and a wall in the plane x = -3 behind it.
sim::Scene mc_glint_scene(double d, const sim::Material& mirror) {
  sim::Scene s;
  s.add_quad({d, -6.0, -6.0}, {0.0, 12.0, 0.0}, {0.0, 0.0, 12.0}, mirror, "mirror");
  s.add_quad({-3.0, -40.0, -40.0}, {0.0, 80.0, 0.0}, {0.0, 0.0, 80.0}, sim::Material::diffuse(0.0), "wall_behind");
  return s;
}
}  // namespace

TEST_CASE("near-normal glint: within the angle the camera measures the mirror's own range, beyond it the fold",
          "[sim][reflection][glint]") {
  constexpr double kD = 2.0;
  const sim::Scene scene = mc_glint_scene(kD, mc_mirror());
  // 7 x 7 pixels over 6 degrees: pixel directions from 0 to about 3.6 degrees off the axis.
  const iv::DepthCamera cam = iv::DepthCamera::make(7, 7, iv::deg(6.0), iv::deg(6.0), 0.1, 30.0);
  for (const double yaw_deg : {0.0, 2.0, 10.0})
    for (const double angle_deg : {3.0, 0.5})
      for (const bool glint : {false, true}) {
        INFO("camera " << yaw_deg << " deg off the mirror's normal, glint " << glint << " within " << angle_deg
                       << " deg");
        const iv::SensorRig rig =
            mc_one_camera(cam, Point3::Zero(), Point3(std::cos(iv::deg(yaw_deg)), std::sin(iv::deg(yaw_deg)), 0.0));
        sim::SimOptions o;
        o.glint = glint;
        o.glint_angle = iv::deg(angle_deg);
        const McScan s = mc_scan(rig, scene, iv::Pose::Identity(), o);
        REQUIRE(s.beams.size() == 49);
        int direct = 0, folded = 0;
        for (std::size_t i = 0; i < s.beams.size(); ++i) {
          const iv::Beam& b = s.beams[i];
          REQUIRE(b.hit);
          const double range = (b.end - b.origin).norm();
          const Point3 dir = (b.end - b.origin) / range;
          const double theta = std::acos(std::min(1.0, dir.x()));              // the mirror's normal is -x
          if (std::abs(theta - iv::deg(angle_deg)) < iv::deg(0.01)) continue;  // too close to call
          if (glint && theta <= iv::deg(angle_deg)) {
            CHECK(s.paths[i] == sim::BeamPath::Direct);
            CHECK(std::abs(range - kD / dir.x()) < 1e-9);  // the mirror itself
            ++direct;
          } else {
            CHECK(s.paths[i] == sim::BeamPath::Reflected);
            CHECK(std::abs(range - (2.0 * kD + 3.0) / dir.x()) < 1e-9);  // folded onto the wall behind
            ++folded;
          }
        }
        // The central pixel looks along the camera's axis.
        const bool centre_glints = glint && yaw_deg <= angle_deg;
        CHECK(s.paths[24] == (centre_glints ? sim::BeamPath::Direct : sim::BeamPath::Reflected));
        if (!glint || yaw_deg == 10.0) CHECK(direct == 0);
        if (glint && yaw_deg == 0.0) CHECK(direct == (angle_deg == 3.0 ? 37 : 1));  // 3 deg: all but the 12 outermost
        CHECK(direct + folded >= 45);
      }
}

TEST_CASE("near-normal glint after a reflection returns the folded range to the glinting mirror",
          "[sim][reflection][glint]") {
  // Mirror A in the plane x = 2 folds the beam along (1, 1, 0) onto mirror B (the plane -x + y = 4)
  // at normal incidence: with the glint the folded range 4 sqrt(2) to B; without, the beam retraces
  // its path past the camera into nothing.
  sim::Scene scene;
  scene.add_quad({2.0, -6.0, -6.0}, {0.0, 12.0, 0.0}, {0.0, 0.0, 12.0}, mc_mirror(), "mirror_a");
  scene.add_quad({-1.5, 2.5, -2.0}, {3.0, 3.0, 0.0}, {0.0, 0.0, 4.0}, mc_mirror(), "mirror_b");
  const iv::DepthCamera cam = iv::DepthCamera::make(3, 3, iv::deg(0.5), iv::deg(0.5), 0.1, 30.0);
  const iv::SensorRig rig = mc_one_camera(cam, Point3::Zero(), Point3(1.0, 1.0, 0.0).normalized());
  sim::SimOptions o;
  o.glint = true;
  const McScan on = mc_scan(rig, scene, iv::Pose::Identity(), o);
  REQUIRE(on.beams.size() == 9);
  CHECK(on.paths[4] == sim::BeamPath::Reflected);
  CHECK(std::abs((on.beams[4].end - on.beams[4].origin).norm() - 4.0 * std::sqrt(2.0)) < 1e-9);
  const McScan off = mc_scan(rig, scene, iv::Pose::Identity(), {});
  CHECK(off.paths[4] == sim::BeamPath::NoReturn);
}

TEST_CASE("near-normal glint off, or where no specular surface is met within its angle, changes nothing",
          "[sim][reflection][glint]") {
  // Polished metal seen 10 degrees off its normal: the lobe decides every beam, with the same draws.
  const sim::Scene metal = mc_glint_scene(2.0, sim::Material::polished_metal());
  const iv::DepthCamera cam = iv::DepthCamera::make(7, 7, iv::deg(6.0), iv::deg(6.0), 0.1, 30.0);
  const iv::SensorRig tilted =
      mc_one_camera(cam, Point3::Zero(), Point3(std::cos(iv::deg(10.0)), std::sin(iv::deg(10.0)), 0.0));
  sim::SimOptions on;
  on.glint = true;
  const McScan a = mc_scan(tilted, metal, iv::Pose::Identity(), {}),
               b = mc_scan(tilted, metal, iv::Pose::Identity(), on);
  CHECK(mc_same(a, b));
  CHECK(std::count(a.paths.begin(), a.paths.end(), sim::BeamPath::Direct) > 0);  // the lobe returns some directly
  CHECK(std::count(a.paths.begin(), a.paths.end(), sim::BeamPath::Reflected) > 0);
  // At normal incidence the glint returns every beam within its angle directly; the lobe alone some.
  const iv::SensorRig facing = mc_one_camera(cam, Point3::Zero(), Point3::UnitX());
  const McScan c = mc_scan(facing, metal, iv::Pose::Identity(), on);
  CHECK(c.paths[24] == sim::BeamPath::Direct);
  // The eight cameras in the diffuse lab room (nothing specular): the same scan with the glint on.
  const auto lab = sim::make_lab_room();
  const iv::SensorRig base = iv::SensorRig::mobile_base();
  const iv::Pose body = mc_body({1.6, 4.0, 0.0}, std::numbers::pi);
  CHECK(mc_same(mc_scan(base, lab.scene, body, {}), mc_scan(base, lab.scene, body, on)));
  // Off, the angle is inert: the mirror closet gives the same scan whatever it is.
  sim::LabRoomOptions lo;
  lo.closet_material = sim::Material::mirror();
  const auto mirror_lab = sim::make_lab_room(lo);
  sim::SimOptions wide;
  wide.glint_angle = iv::deg(45.0);
  CHECK(mc_same(mc_scan(base, mirror_lab.scene, body, {}), mc_scan(base, mirror_lab.scene, body, wide)));
  // On, facing the closet 1 m away, some folded beams (or beams whose fold was longer than the
  // cameras' 4 m) become the mirror's own returns.
  const McScan folded = mc_scan(base, mirror_lab.scene, body, {}), glinting = mc_scan(base, mirror_lab.scene, body, on);
  REQUIRE(folded.paths.size() == glinting.paths.size());
  int changed = 0;
  for (std::size_t i = 0; i < folded.paths.size(); ++i)
    if (folded.paths[i] != glinting.paths[i]) {
      ++changed;
      CHECK((folded.paths[i] == sim::BeamPath::Reflected || folded.paths[i] == sim::BeamPath::NoReturn));
      CHECK(glinting.paths[i] == sim::BeamPath::Direct);
      CHECK(glinting.beams[i].end.x() == Approx(0.601).margin(0.05));  // on the closet's face
    }
  CHECK(changed > 0);
}

TEST_CASE("the robot's body appears in a mirror at the closed-form folded range", "[sim][reflection][body]") {
  constexpr double kD = 1.0;  // from the camera on the body's front face to the mirror
  const iv::Pose body = mc_body({1.0, 2.0, 0.0}, iv::deg(30.0));
  const Eigen::Matrix3d rot = body.linear();
  // In the body frame: the mirror in the plane x = 0.3 + D, a wall in the plane x = -4 behind.
  sim::Scene scene;
  scene.add_quad(body * Point3(0.3 + kD, -4.0, -2.0), rot * Point3(0.0, 8.0, 0.0), rot * Point3(0.0, 0.0, 6.0),
                 mc_mirror(), "mirror");
  scene.add_quad(body * Point3(-4.0, -20.0, -20.0), rot * Point3(0.0, 40.0, 0.0), rot * Point3(0.0, 0.0, 40.0),
                 sim::Material::diffuse(0.0), "wall_behind");
  // One camera on the front face of the 0.6 x 0.4 x 0.6 m base, at knee height, facing forward.
  const iv::DepthCamera cam = iv::DepthCamera::make(32, 24, iv::deg(40.0), iv::deg(30.0), 0.1, 30.0);
  const iv::SensorRig rig = mc_one_camera(cam, {0.3, 0.0, 0.5}, Point3::UnitX());
  sim::SimOptions with_body;
  with_body.body = sim::RobotBody::mobile_base({}, 0.6, sim::Material::diffuse(0.0));
  for (const bool on : {false, true}) {
    INFO("body " << on);
    const McScan s = mc_scan(rig, scene, body, on ? with_body : sim::SimOptions{});
    REQUIRE(s.beams.size() == cam.beam_count());
    int on_body = 0, behind = 0;
    for (std::size_t i = 0; i < s.beams.size(); ++i) {
      const iv::Beam& b = s.beams[i];
      REQUIRE(b.hit);
      CHECK(s.paths[i] == sim::BeamPath::Reflected);
      const double range = (b.end - b.origin).norm();
      const Point3 dir = rot.transpose() * (b.end - b.origin) / range;  // body frame
      CHECK((body.inverse() * b.origin - Point3(0.3, 0.0, 0.5)).norm() < 1e-12);
      // The folded beam comes back to the plane of the front face x = 0.3 after 2 D / dir.x, at
      // (y, z); the face covers |y| <= 0.2, 0 <= z <= 0.6.
      const double t = 2.0 * kD / dir.x(), y = dir.y() * t, z = 0.5 + dir.z() * t;
      const double inside = std::min({0.2 - std::abs(y), z, 0.6 - z});
      if (std::abs(inside) < 1e-6) continue;  // on the face's edge: too close to call
      if (on && inside > 0) {
        CHECK(std::abs(range - t) < 1e-9);  // the body's reflection, D behind the mirror
        ++on_body;
      } else {
        CHECK(std::abs(range - (2.0 * kD + 4.3) / dir.x()) < 1e-9);  // the wall behind the robot
        ++behind;
      }
    }
    if (on) CHECK(on_body > 50);
    CHECK(behind > 400);
    // The images of the rig's cameras see the same.
    const auto images = sim::simulate_images(rig, scene, body, 3, on ? with_body : sim::SimOptions{});
    REQUIRE(images.size() == 1);
    CHECK(images[0].paths == s.paths);
  }
}

TEST_CASE("the robot's body is never met by the cameras' direct rays", "[sim][reflection][body]") {
  sim::SimOptions with_body;
  with_body.body = sim::RobotBody::mobile_base();
  // A camera inside the body (a box from the floor to 0.6 m) sees the wall 2 m ahead as without it.
  const iv::Pose body = mc_body({0.0, 0.0, 0.0}, 0.0);
  sim::Scene wall;
  wall.add_quad({2.0, -10.0, -10.0}, {0.0, 20.0, 0.0}, {0.0, 0.0, 20.0}, sim::Material::diffuse(0.0), "wall");
  const iv::SensorRig inside = mc_one_camera(iv::DepthCamera::o3d100(), {0.0, 0.0, 0.3}, Point3::UnitX());
  const McScan a = mc_scan(inside, wall, body, {}), b = mc_scan(inside, wall, body, with_body);
  CHECK(mc_same(a, b));
  CHECK(std::count(b.paths.begin(), b.paths.end(), sim::BeamPath::Direct) == static_cast<long>(b.paths.size()));
  // The eight cameras in the diffuse lab room: no beam is reflected, so nothing changes.
  const auto lab = sim::make_lab_room();
  const iv::SensorRig base = iv::SensorRig::mobile_base();
  for (const iv::Pose& p : {mc_body({6.0, 1.5, 0.0}, 0.0), mc_body({1.6, 4.0, 0.0}, 2.5)})
    CHECK(mc_same(mc_scan(base, lab.scene, p, {}), mc_scan(base, lab.scene, p, with_body)));
  // Facing the mirror closet: direct beams are unchanged; some folded beams now end on the robot's
  // front face instead of the room behind it, and appear as far behind the closet's face.
  sim::LabRoomOptions lo;
  lo.closet_material = sim::Material::mirror();
  const auto mirror_lab = sim::make_lab_room(lo);
  const iv::Pose facing = mc_body({1.6, 4.0, 0.0}, std::numbers::pi);
  const McScan off = mc_scan(base, mirror_lab.scene, facing, {}),
               on = mc_scan(base, mirror_lab.scene, facing, with_body);
  REQUIRE(off.paths.size() == on.paths.size());
  int changed = 0;
  for (std::size_t i = 0; i < off.paths.size(); ++i) {
    if (off.paths[i] == sim::BeamPath::Direct) {
      CHECK(on.paths[i] == sim::BeamPath::Direct);
      CHECK(on.beams[i].end == off.beams[i].end);
    }
    if (on.beams[i].end != off.beams[i].end) {
      ++changed;
      CHECK(on.paths[i] == sim::BeamPath::Reflected);
      // The robot's front face is at x = 1.6 - 0.3 = 1.3, 0.699 m from the closet's face x = 0.601:
      // its phantom lies as far behind the face.
      CHECK(on.beams[i].end.x() == Approx(0.601 - 0.699).margin(0.05));
    }
  }
  CHECK(changed > 0);
}

TEST_CASE("glint and body give the same scans for one and two threads", "[sim][reflection][glint][body][threaded]") {
  sim::LabRoomOptions lo;
  lo.closet_material = sim::Material::mirror();
  lo.door_material = sim::Material::polished_metal();
  const auto lab = sim::make_lab_room(lo);
  const iv::SensorRig base = iv::SensorRig::mobile_base();
  sim::SimOptions one, two;
  one.glint = two.glint = true;
  one.body = two.body = sim::RobotBody::mobile_base();
  two.threads = 2;
  for (const iv::Pose& p : {mc_body({1.6, 4.0, 0.0}, std::numbers::pi), mc_body({6.8, 4.1, 0.0}, 0.2)}) {
    CHECK(mc_same(mc_scan(base, lab.scene, p, one, 11), mc_scan(base, lab.scene, p, two, 11)));
    const auto a = sim::simulate_images(base, lab.scene, p, 11, one),
               b = sim::simulate_images(base, lab.scene, p, 11, two);
    REQUIRE(a.size() == b.size());
    for (std::size_t c = 0; c < a.size(); ++c) {
      CHECK(a[c].paths == b[c].paths);
      CHECK(std::memcmp(a[c].image.depth.data(), b[c].image.depth.data(), a[c].image.depth.size() * sizeof(float)) ==
            0);
    }
  }
  // SimulatedRig carries the options.
  sim::SimulatedRig r1(lab.scene, base, 4, one), r2(lab.scene, base, 4, two);
  const iv::Pose p = mc_body({1.6, 4.0, 0.0}, std::numbers::pi);
  const auto s1 = r1(p), s2 = r2(p);
  REQUIRE(s1.size() == s2.size());
  for (std::size_t i = 0; i < s1.size(); ++i) REQUIRE(s1[i].end == s2[i].end);
  CHECK(r1.last_paths() == r2.last_paths());
}

TEST_CASE("bad glint and body options are rejected", "[sim][glint][body]") {
  sim::SimOptions o;
  CHECK_NOTHROW(o.validate());
  CHECK_FALSE(o.glint);
  CHECK_FALSE(o.body.has_value());
  CHECK(o.glint_angle == Approx(iv::deg(3.0)));
  for (const double bad :
       {-0.01, 2.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    o.glint_angle = bad;
    CHECK_THROWS_AS(o.validate(), iv::InvalidArgument);
  }
  o.glint_angle = 0.0;
  CHECK_NOTHROW(o.validate());
  o.body = sim::RobotBody{};
  CHECK_NOTHROW(o.validate());
  o.body->box = iv::Bounds{{0.0, 0.0, 0.0}, {0.0, 1.0, 1.0}};  // flat
  CHECK_THROWS_AS(o.validate(), iv::InvalidArgument);
  o.body->box = iv::Bounds{{0.0, 0.0, 0.0}, {std::numeric_limits<double>::quiet_NaN(), 1.0, 1.0}};
  CHECK_THROWS_AS(o.validate(), iv::InvalidArgument);
  o.body = sim::RobotBody{};
  o.body->material.sigma = -1.0;
  CHECK_THROWS_AS(o.validate(), iv::InvalidArgument);
  CHECK_THROWS_AS(sim::RobotBody::mobile_base({}, 0.0), iv::InvalidArgument);
  iv::MobileBaseOptions narrow;
  narrow.width = -0.4;
  CHECK_THROWS_AS(sim::RobotBody::mobile_base(narrow), iv::InvalidArgument);
  const sim::RobotBody base = sim::RobotBody::mobile_base();
  CHECK(base.box.min == Point3(-0.3, -0.2, 0.0));
  CHECK(base.box.max == Point3(0.3, 0.2, 0.6));
  // The lone sensors have no body pose.
  sim::SimOptions with_body;
  with_body.body = base;
  const sim::Scene scene = mc_glint_scene(2.0, mc_mirror());
  CHECK_THROWS_AS(sim::simulate(iv::DepthCamera::o3d100(), scene, iv::look_at({0, 0, 0}, {1, 0, 0}), 1, with_body),
                  iv::InvalidArgument);
  CHECK_THROWS_AS(sim::simulate_sweep(iv::LaserStriper::scancontrol_2700(), scene, {iv::look_at({0, 0, 0}, {1, 0, 0})},
                                      1, with_body),
                  iv::InvalidArgument);
  sim::SimOptions bad_angle;
  bad_angle.glint_angle = -1.0;
  CHECK_THROWS_AS(sim::simulate(iv::SensorRig::mobile_base(), scene, iv::Pose::Identity(), 1, bad_angle),
                  iv::InvalidArgument);
  CHECK_THROWS_AS(sim::simulate_images(iv::SensorRig::mobile_base(), scene, iv::Pose::Identity(), 1, bad_angle),
                  iv::InvalidArgument);
}
