// Statistics of each material's noise model over many beams, and determinism of the streams.
#include <catch2/catch.hpp>
#include <intervox/sim/sim.hpp>

#include <cmath>
#include <vector>

namespace iv = intervox;
namespace sim = intervox::sim;
using iv::Point3;

namespace {
constexpr int kBeams = 20000;

/// A wall (box) whose front face lies at x = 2, seen along +x from the origin.
sim::Scene wall_scene(const sim::Material& m) {
  sim::Scene s;
  s.add_box({{2.0, -5, -5}, {2.5, 5, 5}}, m);
  return s;
}

struct Stats {
  int returns = 0, lost = 0, invalid = 0;
  std::vector<double> ranges;
  double mean() const {
    double s = 0;
    for (double r : ranges) s += r;
    return s / ranges.size();
  }
  double sd() const {
    const double m = mean();
    double s = 0;
    for (double r : ranges) s += (r - m) * (r - m);
    return std::sqrt(s / (ranges.size() - 1));
  }
};

Stats run(const sim::Scene& s, double min_range = 0.1, double max_range = 4.0, std::uint64_t seed = 42) {
  Stats st;
  for (int i = 0; i < kBeams; ++i) {
    sim::BeamRng rng(seed, 0, static_cast<std::uint64_t>(i));
    const auto r = sim::trace(s, Point3::Zero(), Point3::UnitX(), min_range, max_range, rng);
    if (r.returned()) {
      ++st.returns;
      st.ranges.push_back(r.range);
    } else if (r.path == sim::BeamPath::NoReturn) {
      ++st.lost;
    } else {
      ++st.invalid;
    }
  }
  return st;
}
}  // namespace

TEST_CASE("the uniform and normal transforms have the textbook moments", "[sim][random]") {
  double su = 0, su2 = 0, sn = 0, sn2 = 0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    sim::BeamRng rng(1, 2, static_cast<std::uint64_t>(i));
    const double u = rng.uniform(), z = rng.normal();
    REQUIRE(u >= 0.0);
    REQUIRE(u < 1.0);
    su += u;
    su2 += u * u;
    sn += z;
    sn2 += z * z;
  }
  CHECK(su / n == Approx(0.5).margin(0.003));
  CHECK(su2 / n - (su / n) * (su / n) == Approx(1.0 / 12).margin(0.002));
  CHECK(sn / n == Approx(0.0).margin(0.01));
  CHECK(sn2 / n == Approx(1.0).margin(0.01));
}

TEST_CASE("a diffuse surface returns the true range with Gaussian noise of the set sigma", "[sim][material]") {
  // sigma(d) = 0.01 + 0.005 d = 0.02 at d = 2; the standard error of the mean is 0.02/141.
  const auto st = run(wall_scene(sim::Material::diffuse(0.01, 0.005)));
  REQUIRE(st.returns == kBeams);
  CHECK(st.mean() == Approx(2.0).margin(0.001));
  CHECK(st.sd() == Approx(0.02).epsilon(0.03));
  // About 68.3 % within one sigma.
  int within = 0;
  for (double r : st.ranges) within += std::abs(r - 2.0) < 0.02;
  CHECK(double(within) / kBeams == Approx(0.6827).margin(0.015));
}

TEST_CASE("a noise-free diffuse surface returns exactly the geometric range", "[sim][material]") {
  const auto st = run(wall_scene(sim::Material::diffuse(0.0)));
  REQUIRE(st.returns == kBeams);
  CHECK(st.mean() == 2.0);
  CHECK(st.sd() == 0.0);
}

TEST_CASE("an absorbing surface returns at the set rate and is otherwise lost", "[sim][material]") {
  for (const double p : {0.05, 0.3}) {
    const auto st = run(wall_scene(sim::Material::absorbing(p, 0.01)));
    CHECK(st.invalid == 0);
    CHECK(st.returns + st.lost == kBeams);
    // Binomial standard deviation sqrt(p (1 - p) / N) <= 0.0033: tolerance of about 4 of them.
    CHECK(double(st.returns) / kBeams == Approx(p).margin(0.012));
    CHECK(st.mean() == Approx(2.0).margin(0.005));  // the returns are diffuse
  }
  const auto never = run(wall_scene(sim::Material::absorbing(0.0)));
  CHECK(never.returns == 0);
}

TEST_CASE("the first edition's specular model returns a range uniform over the sensor's window", "[sim][material]") {
  const double lo = 0.1, hi = 4.0;
  const auto st = run(wall_scene(sim::Material::specular_random_range()), lo, hi);
  REQUIRE(st.returns == kBeams);
  double mn = hi, mx = lo;
  int below_one = 0;
  for (double r : st.ranges) {
    mn = std::min(mn, r);
    mx = std::max(mx, r);
    below_one += r < 1.0;
  }
  CHECK(mn >= lo);
  CHECK(mx < hi);
  CHECK(mn < lo + 0.01);
  CHECK(mx > hi - 0.01);
  CHECK(st.mean() == Approx(0.5 * (lo + hi)).margin(0.03));
  CHECK(st.sd() == Approx((hi - lo) / std::sqrt(12.0)).epsilon(0.02));
  CHECK(double(below_one) / kBeams == Approx((1.0 - lo) / (hi - lo)).margin(0.012));
}

TEST_CASE("a transparent closet without Fresnel splits beams between itself, its back face and the wall behind",
          "[sim][material]") {
  // A transparent box [2, 2.6] in front of a diffuse wall at 2.601: each transparent face
  // passes with p = 0.5, so front 1/2, back 1/4, wall 1/4.
  sim::Scene s;
  s.add_box({{2.0, -1, -1}, {2.6, 1, 1}}, sim::Material::transparent_without_fresnel(0.5, 0.001));
  s.add_box({{2.601, -5, -5}, {2.7, 5, 5}}, sim::Material::diffuse(0.001));
  const auto st = run(s);
  REQUIRE(st.returns == kBeams);
  int front = 0, back = 0, wall = 0;
  for (double r : st.ranges) {
    if (std::abs(r - 2.0) < 0.01)
      ++front;
    else if (std::abs(r - 2.6) < 0.0005)
      ++back;
    else if (std::abs(r - 2.601) < 0.0005)
      ++wall;
  }
  // Range resolution: the back face and the wall are 1 mm apart with sigma 1 mm, so count them
  // together and check the front/behind split, then the sum.
  CHECK(double(front) / kBeams == Approx(0.5).margin(0.015));
  const int behind =
      static_cast<int>(std::count_if(st.ranges.begin(), st.ranges.end(), [](double r) { return r > 2.5; }));
  CHECK(double(behind) / kBeams == Approx(0.5).margin(0.015));
  CHECK(front + behind == kBeams);

  // With the wall 0.4 m behind, back face and wall separate cleanly: 1/4 each.
  sim::Scene s2;
  s2.add_box({{2.0, -1, -1}, {2.6, 1, 1}}, sim::Material::transparent_without_fresnel(0.5, 0.001));
  s2.add_box({{3.0, -5, -5}, {3.1, 5, 5}}, sim::Material::diffuse(0.001));
  const auto st2 = run(s2);
  int f2 = 0, b2 = 0, w2 = 0;
  for (double r : st2.ranges) {
    f2 += std::abs(r - 2.0) < 0.01;
    b2 += std::abs(r - 2.6) < 0.01;
    w2 += std::abs(r - 3.0) < 0.01;
  }
  CHECK(f2 + b2 + w2 == kBeams);
  CHECK(double(f2) / kBeams == Approx(0.5).margin(0.015));
  CHECK(double(b2) / kBeams == Approx(0.25).margin(0.013));
  CHECK(double(w2) / kBeams == Approx(0.25).margin(0.013));
  (void)back;
  (void)wall;
}

TEST_CASE("a transparent surface with nothing behind it loses the passing beams", "[sim][material]") {
  sim::Scene s;
  s.add_quad({2, -1, -1}, {0, 2, 0}, {0, 0, 2}, sim::Material::transparent_without_fresnel(0.8));
  const auto st = run(s);
  CHECK(double(st.lost) / kBeams == Approx(0.8).margin(0.012));
}

TEST_CASE("surfaces beyond max range give no return and closer than min range an invalid beam", "[sim][material]") {
  CHECK(run(wall_scene(sim::Material::diffuse()), 0.1, 1.9).lost == kBeams);
  CHECK(run(wall_scene(sim::Material::diffuse()), 2.1, 4.0).invalid == kBeams);
}

TEST_CASE("the same seed gives the same ranges and another seed different ones", "[sim][random]") {
  const auto s = wall_scene(sim::Material::diffuse(0.05));
  const auto a = run(s, 0.1, 4.0, 5), b = run(s, 0.1, 4.0, 5), c = run(s, 0.1, 4.0, 6);
  CHECK(a.ranges == b.ranges);
  CHECK(a.ranges != c.ranges);
}

TEST_CASE("materials reject parameters outside their ranges", "[sim][material][errors]") {
  CHECK_THROWS_AS(sim::Material::diffuse(-0.1), iv::InvalidArgument);
  CHECK_THROWS_AS(sim::Material::diffuse(std::nan("")), iv::InvalidArgument);
  CHECK_THROWS_AS(sim::Material::absorbing(1.5), iv::InvalidArgument);
  CHECK_THROWS_AS(sim::Material::transparent(-0.01), iv::InvalidArgument);
  CHECK_THROWS_AS(sim::Material::transparent(0.5, 0.01, 0.9), iv::InvalidArgument);
  CHECK_THROWS_AS(sim::Material::polished_metal(1.2), iv::InvalidArgument);
  CHECK_THROWS_AS(sim::Material::polished_metal(0.5, -1.0), iv::InvalidArgument);
  CHECK_THROWS_AS(sim::Material::polished_metal(0.5, std::nan("")), iv::InvalidArgument);
  CHECK_THROWS_AS(sim::material_from_string("chrome"), iv::InvalidArgument);
  for (const auto name : sim::kMaterialNames) CHECK_NOTHROW(sim::material_from_string(name).validate());
  sim::SimOptions bad;
  bad.max_bounces = -1;
  CHECK_THROWS_AS(bad.validate(), iv::InvalidArgument);
  bad.max_bounces = 256;
  CHECK_THROWS_AS(bad.validate(), iv::InvalidArgument);
  sim::Material m;
  m.p_pass = std::nan("");
  sim::Scene s;
  CHECK_THROWS_AS(s.add_sphere({0, 0, 0}, 1, m), iv::InvalidArgument);
  const auto id = s.add_sphere({0, 0, 0}, 1);
  CHECK_THROWS_AS(s.set_material(id, m), iv::InvalidArgument);
  CHECK_THROWS_AS(s.set_material(id + 1, sim::Material::specular()), iv::OutOfRange);
  s.set_material(id, sim::Material::specular());
  CHECK(s.material(id).surface == sim::Surface::Specular);
}
