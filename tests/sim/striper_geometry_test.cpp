// The laser striper as a triangulation sensor (LaserStriper::baseline, camera_crossing): the
// half-vector lobe of polished surfaces, the triangulation shadow, a coaxial striper (baseline 0)
// equal to the time-of-flight model bit for bit, thread-count independence, and validation.
#include "../common/grid_types.hpp"

#include <catch2/catch.hpp>
#include <intervox/sim/sim.hpp>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace iv = intervox;
namespace sim = intervox::sim;
using iv::Point3;

namespace {

// The striper at height h above the origin looking straight down: its line along world x, its
// camera baseline towards world -y (sensor x = world x, y = -world y, z = -world z).
iv::Pose striper_looking_down(double h) {
  iv::Pose p = iv::Pose::Identity();
  p.linear() << 1, 0, 0, 0, -1, 0, 0, 0, -1;
  p.translation() = Point3(0, 0, h);
  return p;
}

// The unit normal of a plane tilted from horizontal by alpha towards world -y (the camera's side)
// and by beta towards +x.
Point3 tilted_normal(double alpha, double beta) {
  return {std::sin(beta) * std::cos(alpha), -std::sin(alpha), std::cos(alpha) * std::cos(beta)};
}

// A square quad of side 2 m through the origin with unit normal n.
void add_plane(sim::Scene& scene, const Point3& n, const sim::Material& m) {
  const Point3 e1 = n.cross(Point3::UnitY()).normalized(), e2 = n.cross(e1);
  scene.add_quad(-e1 - e2, 2 * e1, 2 * e2, m);
}

// Closed form: where beam i of striper st at pose meets the plane through the origin with unit
// normal n (facing the striper), and cos θ_h = n · h there, h = normalize(l + v).
struct SpotGeometry {
  Point3 spot;
  double cos_half = 0;
};
SpotGeometry plane_spot(const sim::LaserStriper& st, const iv::Pose& pose, int i, const Point3& n) {
  const Point3 laser = pose.translation(), camera = pose * st.camera_position();
  const Point3 d = pose.linear() * st.direction(i);
  const Point3 p = laser - (n.dot(laser) / n.dot(d)) * d;
  const Point3 l = (laser - p).normalized(), v = (camera - p).normalized();
  return {p, n.dot((l + v).normalized())};
}

// profiles copies of one pose: profile k draws from its own streams, so one sweep gives
// `profiles` independent trials of every sample.
std::vector<iv::Pose> repeated(const iv::Pose& pose, int profiles) { return std::vector<iv::Pose>(profiles, pose); }

// Direct returns of every sample over all profiles of a sweep with no invalid beams.
std::vector<int> direct_counts(const sim::SweepMeasurement& m, int samples) {
  std::vector<int> count(static_cast<std::size_t>(samples), 0);
  for (std::size_t j = 0; j < m.paths.size(); ++j) count[j % count.size()] += m.paths[j] == sim::BeamPath::Direct;
  return count;
}

// Bit-for-bit equality of two trace results (NaN ranges and surfaces compare equal).
bool same_trace(const sim::TraceResult& a, const sim::TraceResult& b) {
  const auto same = [](double x, double y) { return x == y || (std::isnan(x) && std::isnan(y)); };
  return a.path == b.path && a.bounces == b.bounces && same(a.range, b.range) && same(a.surface.x(), b.surface.x()) &&
         same(a.surface.y(), b.surface.y()) && same(a.surface.z(), b.surface.z());
}

bool same_sweep_beams(const std::vector<iv::Beam>& x, const std::vector<iv::Beam>& y) {
  if (x.size() != y.size()) return false;
  for (std::size_t i = 0; i < x.size(); ++i)
    if (x[i].origin != y[i].origin || x[i].end != y[i].end || x[i].hit != y[i].hit) return false;
  return true;
}

// Every sample of a sweep traced alone with trace() (time of flight) or trace_striper() (with the
// camera at pose * camera_position()), invalid beams dropped: the exact BVH path.
void trace_sweep_alone(const sim::LaserStriper& st, const sim::Scene& scene, const std::vector<iv::Pose>& path,
                       std::uint64_t seed, std::uint64_t sensor, bool triangulate, std::vector<iv::Beam>& beams,
                       std::vector<sim::BeamPath>& paths) {
  beams.clear();
  paths.clear();
  for (std::size_t k = 0; k < path.size(); ++k)
    for (int i = 0; i < st.samples; ++i) {
      const Point3 o = path[k].translation(), d = path[k].linear() * st.direction(i);
      sim::BeamRng rng(seed, sensor, k * st.beam_count() + static_cast<std::size_t>(i));
      const Point3 camera = path[k] * st.camera_position();
      const auto t = triangulate ? sim::trace_striper(scene, o, d, camera, st.min_range, st.max_range, rng)
                                 : sim::trace(scene, o, d, st.min_range, st.max_range, rng);
      if (t.path == sim::BeamPath::Invalid) continue;
      beams.push_back({o, o + (t.returned() ? t.range : st.max_range) * d, t.returned()});
      paths.push_back(t.path);
    }
}

}  // namespace

TEST_CASE("the striper preset and the default striper describe an 18 degree triangulation", "[sim][sensor][striper]") {
  const auto preset = sim::LaserStriper::scancontrol_2700();
  const sim::LaserStriper plain{};
  const auto made = sim::LaserStriper::make(640, sim::deg(14), 0.1, 1.0);  // the four-argument form
  for (const auto& st : {preset, plain, made}) {
    CHECK(st.baseline == 0.15);
    CHECK(st.camera_crossing == 0.45);
    CHECK(st.camera_position() == Point3(0, 0.15, 0));
    CHECK(st.triangulation_angle() == Approx(std::atan(1.0 / 3.0)));
  }
  CHECK(preset.triangulation_angle() * 180 / std::numbers::pi == Approx(18.43).margin(0.01));
  const auto coaxial = sim::LaserStriper::make(640, sim::deg(14), 0.1, 1.0, 0.0, 0.3);
  CHECK(coaxial.camera_position() == Point3::Zero());
  CHECK(coaxial.triangulation_angle() == 0.0);
  CHECK(sim::LaserStriper::make(32, sim::deg(10), 0.2, 0.8, 0.05, 0.5).triangulation_angle() == Approx(std::atan(0.1)));
  // SensorRig::arm() carries the preset.
  const auto arm = sim::SensorRig::arm();
  const auto& mounted = std::get<sim::LaserStriper>(arm.sensors()[0].sensor);
  CHECK(mounted.baseline == preset.baseline);
  CHECK(mounted.camera_crossing == preset.camera_crossing);
}

TEST_CASE("a polished plane returns directly with p0 cos^n of the half-vector angle", "[sim][sensor][striper]") {
  // A 65-sample striper with the preset's triangulation, 0.45 m above planes at known tilts; the
  // reflected beams leave the scene (no return), so every return is a direct one.
  const auto st = sim::LaserStriper::make(65, sim::deg(14), 0.1, 1.0);
  const iv::Pose pose = striper_looking_down(0.45);
  const int profiles = 3000;
  // The tilt at which the normal bisects the centre beam and the view to the camera.
  const double bisecting = 0.5 * std::atan2(st.baseline, 0.45);
  const sim::Material metal =
      sim::Material::polished_metal(sim::Material::kPolishedP0, sim::Material::kPolishedExponent, 0.0);
  struct Tilt {
    double alpha, beta;
  };
  for (const Tilt tilt : {Tilt{0.0, 0.0}, Tilt{bisecting, 0.0}, Tilt{2 * bisecting, 0.0}, Tilt{bisecting, sim::deg(4)},
                          Tilt{-sim::deg(6), sim::deg(3)}}) {
    INFO("tilt " << tilt.alpha << ", " << tilt.beta);
    const Point3 n = tilted_normal(tilt.alpha, tilt.beta);
    sim::Scene scene;
    add_plane(scene, n, metal);
    const auto m = sim::simulate_sweep(st, scene, repeated(pose, profiles), 11);
    REQUIRE(m.paths.size() == static_cast<std::size_t>(profiles * st.samples));
    const auto count = direct_counts(m, st.samples);
    for (const int i : {0, 16, 32, 48, 64}) {
      INFO("sample " << i);
      const SpotGeometry g = plane_spot(st, pose, i, n);
      const double p = metal.direct_return_probability(std::max(0.0, g.cos_half));
      const double expected = profiles * p, sd = std::sqrt(profiles * p * (1 - p));
      CHECK(std::abs(count[static_cast<std::size_t>(i)] - expected) <= 4.5 * sd + 1.0);
    }
    // Every return lies on the plane, at the spot of its beam (σ = 0).
    for (std::size_t j = 0; j < m.paths.size(); ++j) {
      if (m.paths[j] != sim::BeamPath::Direct) continue;
      const SpotGeometry g = plane_spot(st, pose, static_cast<int>(j % 65), n);
      REQUIRE((m.beams[j].end - g.spot).norm() < 1e-9);
    }
  }
  // At the bisecting tilt the centre sample sees the lobe's peak, and a horizontal plane the lobe
  // half the triangulation angle off it: far fewer returns than a time-of-flight sensor's.
  CHECK(plane_spot(st, pose, 32, tilted_normal(bisecting, 0)).cos_half == Approx(1.0).margin(1e-12));
  CHECK(std::acos(plane_spot(st, pose, 32, tilted_normal(0, 0)).cos_half) == Approx(bisecting).margin(1e-12));
}

TEST_CASE("a narrow lobe returns exactly at the samples whose half-vector meets the normal", "[sim][sensor][striper]") {
  // p0 = 1, n = 4000: p > 0.5 within 1.07 degrees of the half-vector, below 1e-12 beyond 6.4.
  const sim::Material needle = sim::Material::polished_metal(1.0, 4000.0, 0.0);
  const auto st = sim::LaserStriper::scancontrol_2700();
  const auto coaxial = sim::LaserStriper::make(640, sim::deg(14), 0.1, 1.0, 0.0);
  const iv::Pose pose = striper_looking_down(0.45);
  const int profiles = 60;
  const double bisecting = 0.5 * std::atan2(st.baseline, 0.45);
  struct Case {
    double alpha, beta;
    bool triangulating;
    int sure_min;  // at least this many samples sure to return (p > 0.5)
  };
  for (const Case c :
       {Case{bisecting, 0.0, true, 60}, Case{bisecting, sim::deg(3), true, 60}, Case{bisecting, sim::deg(-5), true, 30},
        Case{0.0, 0.0, true, 0}, Case{0.0, 0.0, false, 60}, Case{bisecting, 0.0, false, 0}}) {
    INFO("tilt " << c.alpha << ", " << c.beta << (c.triangulating ? ", triangulating" : ", coaxial"));
    const auto& striper = c.triangulating ? st : coaxial;
    const Point3 n = tilted_normal(c.alpha, c.beta);
    sim::Scene scene;
    add_plane(scene, n, needle);
    const auto m = sim::simulate_sweep(striper, scene, repeated(pose, profiles), 12);
    REQUIRE(m.paths.size() == static_cast<std::size_t>(profiles * 640));
    const auto count = direct_counts(m, 640);
    // The expected set in closed form: for a coaxial striper the camera sits at the laser.
    int sure = 0, never = 0, wrong = 0, total = 0;
    double expected = 0, variance = 0;
    for (int i = 0; i < 640; ++i) {
      const double p = needle.direct_return_probability(std::max(0.0, plane_spot(striper, pose, i, n).cos_half));
      const int k = count[static_cast<std::size_t>(i)];
      if (p > 0.5) {
        ++sure;
        wrong += k == 0;  // missed in all 60 trials: probability below 1e-18
      } else if (p < 1e-12) {
        ++never;
        wrong += k != 0;
      }
      expected += profiles * p;
      variance += profiles * p * (1 - p);
      total += k;
    }
    CHECK(wrong == 0);
    CHECK(sure >= c.sure_min);
    if (c.sure_min == 0)
      CHECK(never == 640);  // the lobe misses the whole line: no direct return at all
    else
      CHECK(never > 10);  // the line's ends at least
    CHECK(std::abs(total - expected) <= 4.5 * std::sqrt(variance) + 1.0);
  }
  // For the coaxial striper the closed form is the beam angle: sample 320 looks 7°/639 off the axis.
  CHECK(plane_spot(coaxial, pose, 320, tilted_normal(0, 0)).cos_half == Approx(std::cos(sim::deg(7) / 639)));
}

TEST_CASE("a spot hidden from the striper's camera gives no return: the triangulation shadow",
          "[sim][sensor][striper]") {
  const auto st = sim::LaserStriper::scancontrol_2700();
  const auto coaxial = sim::LaserStriper::make(640, sim::deg(14), 0.1, 1.0, 0.0);
  const double h = 0.45;
  const iv::Pose pose = striper_looking_down(h);  // camera at (0, -0.15, 0.45)
  const iv::Pose path_pose[] = {pose};
  const std::vector<iv::Pose> path(std::begin(path_pose), std::end(path_pose));

  SECTION("a box between the laser line and the camera") {
    // A diffuse floor (top at z = 0) and a box x in [0.01, 0.02], y in [-0.06, -0.03], 0.25 m tall,
    // beside the laser line (y = 0) on the camera's side.
    sim::Scene scene;
    scene.add_box({{-1, -1, -0.1}, {1, 1, 0}}, sim::Material::diffuse(0.0));
    const double xa = 0.01, xb = 0.02, ya = 0.03, yb = 0.06;
    scene.add_box({{xa, -yb, 0}, {xb, -ya, 0.25}}, sim::Material::diffuse(0.0));
    // The line of sight from the floor spot (x, 0, 0) to the camera (0, -b, h) is
    // (x (1 - s), -b s, h s); it crosses the box's y slab for s in [ya / b, yb / b], at heights up
    // to h yb / b = 0.18 < 0.25, where its x runs over [x (1 - yb / b), x (1 - ya / b)]: hidden iff
    // x lies in [xa / (1 - ya / b), xb / (1 - yb / b)] = [0.0125, 0.0333].
    const double b = st.baseline, lo = xa / (1 - ya / b), hi = xb / (1 - yb / b);
    const auto m = sim::simulate_sweep(st, scene, path, 5);
    const auto tof = sim::simulate_sweep(coaxial, scene, path, 5);
    REQUIRE(m.paths.size() == 640);
    REQUIRE(tof.paths.size() == 640);
    int hidden = 0, mismatches = 0;
    for (int i = 0; i < 640; ++i) {
      const double x = h * std::tan(-0.5 * st.opening + st.opening * i / 639.0);
      REQUIRE(std::min(std::abs(x - lo), std::abs(x - hi)) > 1e-6);  // no sample on the edge of the shadow
      const bool in_shadow = x >= lo && x <= hi;
      hidden += in_shadow;
      const auto path_i = m.paths[static_cast<std::size_t>(i)];
      mismatches += in_shadow ? path_i != sim::BeamPath::NoReturn : path_i != sim::BeamPath::Direct;
      if (!in_shadow)
        REQUIRE((m.beams[static_cast<std::size_t>(i)].end - Point3(x, 0, 0)).norm() < 1e-9);
      else
        CHECK(std::isinf(m.image.at(i, 0)));
      // A coaxial striper sees every floor spot.
      REQUIRE(tof.paths[static_cast<std::size_t>(i)] == sim::BeamPath::Direct);
    }
    CHECK(mismatches == 0);
    CHECK(hidden > 100);  // (0.0333 - 0.0125) / (0.45 * 14° / 639): about 120 samples
    CHECK(hidden < 200);
  }

  SECTION("a surface the camera sees from behind") {
    // A diffuse quad through the origin, tilted away from the camera by gamma: every laser spot
    // lies at (x, 0, 0), the camera at (0, -b, h) is in front iff -b sin gamma + h cos gamma > 0,
    // i.e. gamma < atan(h / b) = 71.6°.
    for (const double gamma_deg : {65.0, 75.0}) {
      INFO("tilt " << gamma_deg);
      sim::Scene scene;
      add_plane(scene, tilted_normal(-sim::deg(gamma_deg), 0.0), sim::Material::diffuse(0.0));
      const bool front = -st.baseline * std::sin(sim::deg(gamma_deg)) + h * std::cos(sim::deg(gamma_deg)) > 0;
      CHECK(front == (gamma_deg < 70));
      const auto m = sim::simulate_sweep(st, scene, path, 6);
      const auto tof = sim::simulate_sweep(coaxial, scene, path, 6);
      REQUIRE(m.paths.size() == 640);
      int returned = 0, tof_returned = 0;
      for (std::size_t i = 0; i < 640; ++i) {
        returned += m.paths[i] == sim::BeamPath::Direct;
        tof_returned += tof.paths[i] == sim::BeamPath::Direct;
      }
      CHECK(returned == (front ? 640 : 0));
      CHECK(tof_returned == 640);
    }
  }

  SECTION("glass in the line of sight does not hide a spot") {
    // A glass pane beside the laser plane (the laser never meets it), between every floor spot
    // and the camera: the camera sees through it.
    sim::Scene scene;
    scene.add_box({{-1, -1, -0.1}, {1, 1, 0}}, sim::Material::diffuse(0.0));
    scene.add_box({{-0.2, -0.06, 0}, {0.2, -0.03, 0.25}}, sim::Material::transparent());
    const auto m = sim::simulate_sweep(st, scene, path, 7);
    REQUIRE(m.paths.size() == 640);
    for (const auto p : m.paths) REQUIRE(p == sim::BeamPath::Direct);
    // The same pane opaque hides every spot.
    sim::Scene opaque;
    opaque.add_box({{-1, -1, -0.1}, {1, 1, 0}}, sim::Material::diffuse(0.0));
    opaque.add_box({{-0.2, -0.06, 0}, {0.2, -0.03, 0.25}}, sim::Material::diffuse());
    for (const auto p : sim::simulate_sweep(st, opaque, path, 7).paths) REQUIRE(p == sim::BeamPath::NoReturn);
  }
}

TEST_CASE("a coaxial striper (baseline 0) gives the time-of-flight results bit for bit",
          "[sim][sensor][striper][oracle]") {
  const auto coaxial = sim::LaserStriper::make(640, sim::deg(14), 0.1, 1.0, 0.0);
  const auto cell = sim::make_workcell();  // polished ring (reflects), glass bottle (passes)
  const auto path = sim::sweep_towards({0.7, 0.3, 1.1}, cell.table_center, 0.3, 24);
  std::vector<iv::Beam> expected;
  std::vector<sim::BeamPath> expected_paths;
  trace_sweep_alone(coaxial, cell.scene, path, 41, 3, false, expected, expected_paths);
  std::size_t other = 0;
  for (const auto p : expected_paths) other += p == sim::BeamPath::Reflected || p == sim::BeamPath::Passed;
  CHECK(other > 100);  // the ring and the bottle are on the paths
  for (const unsigned threads : {1u, 3u}) {
    INFO("threads " << threads);
    const test::ThreadCap cap(8);
    const auto m = sim::simulate_sweep(coaxial, cell.scene, path, 41, {threads}, 3);
    CHECK(same_sweep_beams(m.beams, expected));
    CHECK(m.paths == expected_paths);
  }
  // trace_striper() with the camera at the laser is trace(), field by field.
  int differ = 0;
  for (std::size_t k = 0; k < path.size(); ++k)
    for (int i = 0; i < 640; i += 7) {
      const Point3 o = path[k].translation(), d = path[k].linear() * coaxial.direction(i);
      sim::BeamRng a(43, 0, k * 640 + static_cast<std::size_t>(i)), b = a;
      differ += !same_trace(sim::trace(cell.scene, o, d, 0.1, 1.0, a),
                            sim::trace_striper(cell.scene, o, d, path[k] * coaxial.camera_position(), 0.1, 1.0, b));
    }
  CHECK(differ == 0);
  // The preset's triangulation changes some of these beams (shadows, the lobe on the ring).
  const auto triangulated = sim::simulate_sweep(sim::LaserStriper::scancontrol_2700(), cell.scene, path, 41, {}, 3);
  CHECK_FALSE(triangulated.paths == expected_paths);
}

TEST_CASE("a triangulating striper's sweep is the same for every thread count and equals tracing every sample alone",
          "[sim][sensor][striper][oracle]") {
  const auto st = sim::LaserStriper::scancontrol_2700();
  const auto cell = sim::make_workcell();
  const auto path = sim::sweep_towards({0.75, 0.2, 1.2}, cell.table_center, 0.3, 24);
  std::vector<iv::Beam> expected, tof;
  std::vector<sim::BeamPath> expected_paths, tof_paths;
  trace_sweep_alone(st, cell.scene, path, 51, 1, true, expected, expected_paths);
  trace_sweep_alone(st, cell.scene, path, 51, 1, false, tof, tof_paths);
  // The triangulation hides spots that a time-of-flight sensor measures (the shadows of the
  // objects on the table), and the ring returns where its normal bisects laser and camera.
  REQUIRE(expected_paths.size() == tof_paths.size());
  std::size_t shadowed = 0;
  for (std::size_t j = 0; j < tof_paths.size(); ++j)
    shadowed += tof_paths[j] == sim::BeamPath::Direct && expected_paths[j] == sim::BeamPath::NoReturn;
  CHECK(shadowed > 50);
  for (const unsigned threads : {1u, 2u, 5u}) {
    INFO("threads " << threads);
    const test::ThreadCap cap(8);  // 5 threads even on a 2-core machine
    const auto m = sim::simulate_sweep(st, cell.scene, path, 51, {threads}, 1);
    CHECK(same_sweep_beams(m.beams, expected));
    CHECK(m.paths == expected_paths);
  }
}

TEST_CASE("a striper rejects a bad baseline or camera crossing", "[sim][sensor][striper][errors]") {
  const auto message = [](const sim::LaserStriper& s) {
    try {
      s.validate();
    } catch (const iv::InvalidArgument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  for (const double b : {nan, inf, -inf}) {
    INFO("baseline " << b);
    CHECK_THROWS_AS(sim::LaserStriper::make(640, sim::deg(14), 0.1, 1.0, b, 0.45), iv::InvalidArgument);
    sim::LaserStriper s;
    s.baseline = b;
    CHECK_THAT(message(s), Catch::Contains("intervox::LaserStriper") && Catch::Contains("baseline"));
    CHECK_THROWS_AS(sim::SensorRig::arm({s, 0.1}), iv::InvalidArgument);
    CHECK_THROWS_AS(sim::simulate_sweep(s, sim::Scene{}, {striper_looking_down(1)}, 1), iv::InvalidArgument);
  }
  for (const double c : {0.0, -0.45, nan, inf}) {
    INFO("camera_crossing " << c);
    CHECK_THROWS_AS(sim::LaserStriper::make(640, sim::deg(14), 0.1, 1.0, 0.15, c), iv::InvalidArgument);
    sim::LaserStriper s;
    s.camera_crossing = c;
    CHECK_THAT(message(s), Catch::Contains("camera_crossing"));
  }
  // A camera on the -y side (negative baseline: the same angle, the camera mirrored), baseline 0
  // (coaxial) and a crossing outside the range window are valid.
  const auto minus = sim::LaserStriper::make(640, sim::deg(14), 0.1, 1.0, -0.15, 0.45);
  CHECK(minus.camera_position() == iv::Point3(0, -0.15, 0));
  CHECK(minus.triangulation_angle() == sim::LaserStriper::scancontrol_2700().triangulation_angle());
  CHECK_NOTHROW(sim::LaserStriper::make(640, sim::deg(14), 0.1, 0.3, 0.0, 0.45));
  CHECK_NOTHROW(sim::LaserStriper::make(640, sim::deg(14), 0.1, 0.3, 0.2, 2.0));
}
