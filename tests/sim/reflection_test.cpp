// Mirror reflection, polished metal and glass (the specular model of issue 14) against closed
// forms: phantom points at the mirror image of the true hit, the bounce and range limits, the
// direct-return lobe p0 cos^n θ, Schlick's reflectance, and deterministic streams.
#include <catch2/catch.hpp>
#include <intervox/sim/sim.hpp>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

namespace iv = intervox;
namespace sim = intervox::sim;
using iv::Point3;

namespace {
constexpr double kPi = std::numbers::pi;

/// A rotation whose first column is \p x (unit) and third column lies in the plane of \p x and \p up.
Eigen::Matrix3d frame_with_x(const Point3& x, const Point3& up = Point3::UnitZ()) {
  const Point3 z = (up - up.dot(x) * x).normalized();
  Eigen::Matrix3d r;
  r.col(0) = x;
  r.col(1) = z.cross(x);
  r.col(2) = z;
  return r;
}

/// A noise-free diffuse wall whose front face is the plane through \p w0 with unit normal \p n
/// facing the beams (an oriented box 0.2 m thick, 20 m wide).
void add_wall(sim::Scene& s, const Point3& w0, const Point3& n) {
  iv::Pose p = iv::Pose::Identity();
  p.linear() = frame_with_x(-n, std::abs(n.z()) > 0.9 ? Point3::UnitX() : Point3::UnitZ());
  p.translation() = w0 - 0.1 * n;
  s.add_oriented_box(p, {0.1, 10.0, 10.0}, sim::Material::diffuse(0.0), "wall");
}

Point3 reflect(const Point3& d, const Point3& n) { return d - 2.0 * d.dot(n) * n; }

/// One flat mirror case: the mirror plane (point m0 on it, unit normal n towards the sensor at the
/// origin), the central beam direction c (which meets m0), and how to build the mirror.
struct FlatMirror {
  std::string shape;
  Point3 m0, n, c;
  void add(sim::Scene& s) const {
    const Eigen::Matrix3d f = frame_with_x(n);  // columns: n, in-plane u, in-plane v
    const Point3 u = f.col(1), v = f.col(2);
    const sim::Material m = sim::Material::mirror();
    if (shape == "quad") {
      s.add_quad(m0 - 1.5 * u - 1.5 * v, 3.0 * u, 3.0 * v, m, shape);
    } else if (shape == "mesh") {
      sim::TriangleMesh mesh;
      mesh.vertices = {m0 - 1.5 * u - 1.5 * v, m0 + 1.5 * u - 1.5 * v, m0 + 1.5 * u + 1.5 * v, m0 - 1.5 * u + 1.5 * v};
      mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
      s.add_mesh(mesh, m, shape);
    } else if (shape == "oriented box") {
      iv::Pose p = iv::Pose::Identity();
      p.linear() = f;
      p.translation() = m0 - 0.1 * n;  // the face at local +x is the mirror plane
      s.add_oriented_box(p, {0.1, 1.5, 1.5}, m, shape);
    } else if (shape == "cylinder") {
      s.add_cylinder(m0 - 0.2 * n, m0, 1.5, m, shape);  // the top cap is the mirror
    } else if (shape == "box") {
      REQUIRE(n == Point3(-1, 0, 0));  // axis-aligned: the face x = m0.x, facing -x
      s.add_box({m0 + Point3(0, -1.5, -1.5), m0 + Point3(0.2, 1.5, 1.5)}, m, shape);
    }
  }
};
}  // namespace

TEST_CASE("a flat mirror shows every phantom point at the mirror image of the true hit, for every flat primitive",
          "[sim][reflection]") {
  const Point3 n45 = Point3(-1, 1, 0).normalized();
  const std::vector<FlatMirror> cases = {
      {"quad", {2, 0, 0}, n45, Point3::UnitX()},
      {"mesh", {2, 0, 0}, n45, Point3::UnitX()},
      {"oriented box", {2, 0, 0}, n45, Point3::UnitX()},
      {"cylinder", {2, 0, 0}, n45, Point3::UnitX()},
      {"box", {2, 2, 0}, {-1, 0, 0}, Point3(1, 1, 0).normalized()},
  };
  for (const FlatMirror& mc : cases) {
    CAPTURE(mc.shape);
    sim::Scene s;
    mc.add(s);
    const Point3 rc = reflect(mc.c, mc.n);  // the central reflected direction
    const Point3 w0 = mc.m0 + 3.0 * rc;     // the wall's plane: through w0, normal rc
    add_wall(s, w0, -rc);
    const Eigen::Matrix3d f = frame_with_x(mc.c);
    int checked = 0;
    for (double a = -0.08; a <= 0.0801; a += 0.04)
      for (double b = -0.08; b <= 0.0801; b += 0.04) {
        const Point3 d = (mc.c + a * f.col(1) + b * f.col(2)).normalized();
        // Closed form: the mirror plane, the reflected ray, the wall plane, the image of the hit.
        const double t1 = mc.m0.dot(mc.n) / d.dot(mc.n);
        const Point3 p = t1 * d;
        const Point3 r = reflect(d, mc.n);
        const double t2 = (w0 - p).dot(rc) / r.dot(rc);
        const Point3 q = p + t2 * r;
        const Point3 phantom = q - 2.0 * (q - mc.m0).dot(mc.n) * mc.n;
        sim::BeamRng rng(7, 0, static_cast<std::uint64_t>(checked));
        const sim::TraceResult res = sim::trace(s, Point3::Zero(), d, 0.1, 20.0, rng);
        REQUIRE(res.path == sim::BeamPath::Reflected);
        CHECK(res.bounces == 1);
        CHECK(res.range == Approx(t1 + t2).epsilon(1e-12));
        CHECK((res.range * d - phantom).norm() < 1e-9);
        CHECK((res.surface - q).norm() < 1e-9);
        ++checked;
      }
    CHECK(checked == 25);
  }
}

TEST_CASE("a sphere mirror reflects about its radius as the closed form says", "[sim][reflection]") {
  const Point3 centre(3, 0, 0);
  const double radius = 1.0;
  sim::Scene s;
  s.add_sphere(centre, radius, sim::Material::mirror(), "ball");
  s.add_box({{-3.2, -20, -20}, {-3.0, 20, 20}}, sim::Material::diffuse(0.0), "wall behind the sensor");
  int checked = 0;
  for (double a = -0.2; a <= 0.2001; a += 0.05)
    for (double b = -0.2; b <= 0.2001; b += 0.1) {
      const Point3 d = Point3(1, a, b).normalized();
      // Closed form: |t d - c|^2 = R^2, the nearer root; n = (p - c) / R; r = d - 2 (d.n) n.
      const double bq = d.dot(centre), disc = bq * bq - (centre.squaredNorm() - radius * radius);
      REQUIRE(disc > 0);
      const double t1 = bq - std::sqrt(disc);
      const Point3 p = t1 * d, n = (p - centre) / radius, r = reflect(d, n);
      if (r.x() > -0.3) continue;  // reflected sideways (a folded path beyond range): nothing to compare
      const double t2 = (-3.0 - p.x()) / r.x();
      sim::BeamRng rng(3, 0, static_cast<std::uint64_t>(checked));
      const sim::TraceResult res = sim::trace(s, Point3::Zero(), d, 0.1, 30.0, rng);
      REQUIRE(res.path == sim::BeamPath::Reflected);
      CHECK(res.bounces == 1);
      CHECK(res.range == Approx(t1 + t2).epsilon(1e-12));
      CHECK((res.surface - (p + t2 * r)).norm() < 1e-9);
      // The direction from the mirror point to the true surface is the closed-form reflection.
      CHECK(((res.surface - p).normalized() - r).norm() < 1e-9);
      ++checked;
    }
  CHECK(checked >= 25);
}

TEST_CASE("a cylinder mirror reflects about its mantle's radial normal", "[sim][reflection]") {
  // A vertical mirror cylinder (axis along z through (3, 0)), beams in the plane z = 0.5: the
  // closed form is the circle's, n = (p - c) / R with the z component zero.
  const Point3 axis_point(3, 0, 0.5);
  const double radius = 1.0;
  sim::Scene s;
  s.add_cylinder({3, 0, -2}, {3, 0, 3}, radius, sim::Material::mirror(), "pillar");
  s.add_box({{-3.2, -20, -20}, {-3.0, 20, 20}}, sim::Material::diffuse(0.0), "wall behind the sensor");
  int checked = 0;
  for (double a = -0.3; a <= 0.3001; a += 0.025) {
    const Point3 d = Point3(1, a, 0).normalized();
    const Point3 o(0, 0, 0.5);
    const double bq = d.dot(axis_point - o), disc = bq * bq - ((axis_point - o).squaredNorm() - radius * radius);
    REQUIRE(disc > 0);
    const double t1 = bq - std::sqrt(disc);
    const Point3 p = o + t1 * d, n = (p - axis_point) / radius, r = reflect(d, n);
    REQUIRE(std::abs(n.z()) < 1e-12);
    if (r.x() > -0.3) continue;
    const double t2 = (-3.0 - p.x()) / r.x();
    sim::BeamRng rng(3, 1, static_cast<std::uint64_t>(checked));
    const sim::TraceResult res = sim::trace(s, o, d, 0.1, 30.0, rng);
    REQUIRE(res.path == sim::BeamPath::Reflected);
    CHECK(res.range == Approx(t1 + t2).epsilon(1e-12));
    CHECK(((res.surface - p).normalized() - r).norm() < 1e-9);
    ++checked;
  }
  CHECK(checked >= 15);
}

TEST_CASE("a beam between two parallel mirrors obeys the bounce limit and the range limit", "[sim][reflection]") {
  // Mirrors at y = -1 and y = +1 along x in [0, 20]; a diffuse wall at x = 10. A beam from the
  // origin at slope m meets the mirrors k = floor((10 m + 1) / 2) times before the wall, and its
  // folded path is 10 / cos(atan m) long (the unfolded straight line).
  sim::Scene s;
  s.add_quad({0, -1, -1}, {20, 0, 0}, {0, 0, 2}, sim::Material::mirror(), "south mirror");
  s.add_quad({0, 1, -1}, {20, 0, 0}, {0, 0, 2}, sim::Material::mirror(), "north mirror");
  s.add_box({{10, -1.5, -1.5}, {10.2, 1.5, 1.5}}, sim::Material::diffuse(0.0), "wall");
  const auto shoot = [&](double slope, double max_range, int max_bounces) {
    sim::BeamRng rng(1, 0, 0);
    return sim::trace(s, Point3::Zero(), Point3(1, slope, 0).normalized(), 0.1, max_range, rng, max_bounces);
  };
  for (const double slope : {0.25, 0.55, 0.75, 0.95}) {
    CAPTURE(slope);
    const int k = static_cast<int>(std::floor((10 * slope + 1) / 2));
    const double length = 10.0 * std::sqrt(1 + slope * slope);
    for (int limit = 0; limit <= 5; ++limit) {
      CAPTURE(limit);
      const auto r = shoot(slope, 50.0, limit);
      if (k <= limit) {
        REQUIRE(r.path == (k == 0 ? sim::BeamPath::Direct : sim::BeamPath::Reflected));
        CHECK(r.bounces == k);
        CHECK(r.range == Approx(length).epsilon(1e-12));
        CHECK(r.surface.x() == Approx(10.0));
      } else {
        CHECK(r.path == sim::BeamPath::NoReturn);
        CHECK(r.bounces == limit);
      }
    }
    // A folded path longer than the sensor's range gives no return, a shorter one a return.
    CHECK(shoot(slope, length - 1e-6, 5).path == sim::BeamPath::NoReturn);
    CHECK(shoot(slope, length + 1e-6, 5).returned());
  }
  // Perpendicular to both mirrors the beam is trapped: it ends at the bounce limit (or range).
  sim::BeamRng rng(1, 0, 0);
  const auto trapped = sim::trace(s, {5, 0, 0}, Point3::UnitY(), 0.1, 1e6, rng, 255);
  CHECK(trapped.path == sim::BeamPath::NoReturn);
  CHECK(trapped.bounces == 255);
  const auto short_range = sim::trace(s, {5, 0, 0}, Point3::UnitY(), 0.1, 20.0, rng, 255);
  CHECK(short_range.path == sim::BeamPath::NoReturn);
  // Reflections at path lengths 1, 3, ..., 19 m fit into 20 m; the next surface, at 21 m, does not.
  CHECK(short_range.bounces == 10);
}

TEST_CASE("polished metal returns directly at the rate p0 cos^n theta", "[sim][reflection][statistics]") {
  // A polished plate at x = 2 (nothing else in the scene): a beam at incidence θ returns directly
  // with probability p0 cos^n θ, and is otherwise reflected into empty space (no return).
  constexpr int kBeams = 20000;
  for (const auto& [p0, n] : {std::pair{0.8, 40.0}, std::pair{0.5, 10.0}, std::pair{1.0, 0.0}}) {
    sim::Scene s;
    s.add_quad({2, -50, -1}, {0, 100, 0}, {0, 0, 2}, sim::Material::polished_metal(p0, n, 0.0), "plate");
    for (const double deg : {0.0, 5.0, 10.0, 20.0, 30.0}) {
      CAPTURE(p0, n, deg);
      const double th = deg * kPi / 180;
      const Point3 d(std::cos(th), std::sin(th), 0);
      const double expect = p0 * std::pow(std::cos(th), n);
      int direct = 0;
      for (int i = 0; i < kBeams; ++i) {
        sim::BeamRng rng(11, 2, static_cast<std::uint64_t>(i));
        const auto r = sim::trace(s, Point3::Zero(), d, 0.1, 10.0, rng);
        if (r.returned()) {
          REQUIRE(r.path == sim::BeamPath::Direct);
          REQUIRE(r.range == Approx(2.0 / std::cos(th)).epsilon(1e-12));
          ++direct;
        } else {
          REQUIRE(r.path == sim::BeamPath::NoReturn);
          REQUIRE(r.bounces == 1);
        }
      }
      // Within 4.5 binomial standard deviations (plus a hair for p in {0, 1}).
      const double sd = std::sqrt(expect * (1 - expect) / kBeams);
      CHECK(std::abs(double(direct) / kBeams - expect) <= 4.5 * sd + 1e-9);
    }
  }
  // The default lobe: mostly within ~10° of normal incidence, rarely beyond ~30°.
  const sim::Material m = sim::Material::polished_metal();
  CHECK(m.direct_return_probability(std::cos(10 * kPi / 180)) > 0.4);
  CHECK(m.direct_return_probability(std::cos(30 * kPi / 180)) < 0.005);
  CHECK(sim::Material::mirror().direct_return_probability(1.0) == 0.0);
}

TEST_CASE("glass reflects at Schlick's Fresnel reflectance and passes the rest", "[sim][reflection][statistics]") {
  // A glass pane at x = 2 that passes every beam it does not reflect (p_pass = 1), a diffuse wall
  // at x = 4 behind it: returns are passed beams, losses are reflected ones.
  constexpr int kBeams = 20000;
  sim::Scene s;
  s.add_quad({2, -50, -1}, {0, 100, 0}, {0, 0, 2}, sim::Material::transparent(1.0, 0.0, 1.5), "pane");
  s.add_box({{4, -60, -2}, {4.2, 60, 2}}, sim::Material::diffuse(0.0), "wall");
  const double r0 = 0.04;  // ((1.5 - 1) / (1.5 + 1))^2
  for (const double deg : {0.0, 45.0, 70.0, 80.0}) {
    CAPTURE(deg);
    const double th = deg * kPi / 180;
    const Point3 d(std::cos(th), std::sin(th), 0);
    const double refl = r0 + (1 - r0) * std::pow(1 - std::cos(th), 5);
    CHECK(sim::Material::transparent().fresnel_reflectance(std::cos(th)) == Approx(refl).epsilon(1e-12));
    int passed = 0;
    for (int i = 0; i < kBeams; ++i) {
      sim::BeamRng rng(5, 1, static_cast<std::uint64_t>(i));
      const auto r = sim::trace(s, Point3::Zero(), d, 0.1, 30.0, rng);
      if (r.returned()) {
        REQUIRE(r.path == sim::BeamPath::Passed);
        REQUIRE(r.range == Approx(4.0 / std::cos(th)).epsilon(1e-9));
        ++passed;
      } else {
        REQUIRE(r.bounces == 1);
      }
    }
    const double sd = std::sqrt(refl * (1 - refl) / kBeams);
    CHECK(std::abs(1.0 - double(passed) / kBeams - refl) <= 4.5 * sd);
  }
  // Without Fresnel nothing is reflected.
  CHECK(sim::Material::transparent_without_fresnel().fresnel_reflectance(0.0) == 0.0);
}

TEST_CASE("a mirror closet gives the same phantom room on every run and any number of threads",
          "[sim][reflection][threaded]") {
  sim::LabRoomOptions o;
  o.closet_material = sim::Material::mirror();
  const auto lab = sim::make_lab_room(o);
  const iv::SensorRig rig = iv::SensorRig::mobile_base();
  // The base 1 m east of the closet (west wall, x in [0, 0.6], y in [3.4, 4.6]).
  iv::Pose body = iv::Pose::Identity();
  body.translation() = Point3(1.6, 4.0, 0);
  sim::SimOptions one, two;
  two.threads = 2;
  std::vector<sim::BeamPath> p1, p2, p3;
  const auto a = sim::simulate(rig, lab.scene, body, 9, one, &p1);
  const auto b = sim::simulate(rig, lab.scene, body, 9, two, &p2);
  const auto c = sim::simulate(rig, lab.scene, body, 9, one, &p3);
  REQUIRE(a.size() == b.size());
  REQUIRE(p1.size() == a.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    REQUIRE(a[i].end == b[i].end);
    REQUIRE(a[i].end == c[i].end);
  }
  CHECK(p1 == p2);
  CHECK(p1 == p3);
  // Phantom points: reflected returns appear behind the mirror (west of the closet's face x = 0.6);
  // direct returns never lie outside the room's walls.
  int reflected = 0, behind = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (p1[i] == sim::BeamPath::Reflected) {
      ++reflected;
      behind += a[i].end.x() < 0.6 - 1e-3;
    }
    if (p1[i] == sim::BeamPath::Direct) {
      const iv::Bounds room{lab.scene.bounds().min.array() - 0.1, lab.scene.bounds().max.array() + 0.1};
      REQUIRE(room.contains(a[i].end));
    }
  }
  CHECK(reflected > 500);
  CHECK(behind > reflected * 9 / 10);
}

TEST_CASE("a depth camera labels every pixel with the path of its beam", "[sim][reflection]") {
  sim::LabRoomOptions o;
  o.door_material = sim::Material::mirror();  // the thesis' reflective door (5.2.2)
  const auto lab = sim::make_lab_room(o);
  const iv::DepthCamera cam = iv::DepthCamera::o3d100();
  // A camera 2 m west of the door (east wall, x = 8, y in [3.6, 4.6]) looking at it at an angle.
  const iv::Pose pose = iv::look_at({6.0, 3.0, 1.0}, {8.0, 4.1, 1.0});
  const auto m = sim::simulate(cam, lab.scene, pose, 4);
  REQUIRE(m.paths.size() == m.image.depth.size());
  int reflected = 0, beyond_east_wall = 0;
  for (int v = 0; v < m.image.height; ++v)
    for (int u = 0; u < m.image.width; ++u) {
      const auto i = static_cast<std::size_t>(v * m.image.width + u);
      const double z = m.image.at(u, v);
      const sim::BeamPath p = m.paths[i];
      CHECK(std::isfinite(z) ==
            (p == sim::BeamPath::Direct || p == sim::BeamPath::Reflected || p == sim::BeamPath::Passed));
      if (p == sim::BeamPath::Reflected) {
        ++reflected;
        const Point3 end = pose * (z * cam.intrinsics.ray(u, v));
        beyond_east_wall += end.x() > 8.0;
      }
    }
  CHECK(reflected > 50);
  CHECK(beyond_east_wall == reflected);
}
