// Free space that only beams without a return crossed (thesis 5.2, 5.5), against a brute-force
// oracle: the voxels of each beam's free part walked with traverse().
#include <catch2/catch.hpp>
#include <intervox/analysis/no_return_evidence.hpp>
#include <intervox/raycast/traversal.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <vector>

namespace iv = intervox;

namespace {
// The free voxels of one beam under the insertion's rule (see the header).
std::set<iv::Key> free_part(const iv::GridGeometry& g, const iv::Beam& b, double max_range) {
  std::set<iv::Key> out;
  const iv::Point3 d = b.end - b.origin;
  const double len = d.norm();
  if (b.hit && len <= max_range) {
    const iv::Key end = g.key(b.end);
    iv::traverse(g, b.origin, b.end, [&](const iv::Key& k) {
      if (k == end) return false;
      out.insert(k);
      return true;
    });
  } else {
    iv::traverse(g, b.origin, iv::Point3(b.origin + d * (max_range / len)), [&](const iv::Key& k) {
      out.insert(k);
      return true;
    });
  }
  return out;
}
}  // namespace

TEST_CASE("a voxel is unconfirmed when beams without a return crossed it and no return did", "[analysis][no-return]") {
  const iv::GridGeometry g(0.1);
  iv::NoReturnEvidence ev(g, 2.0);
  // No return along +x from x = 0.05: free up to 2 m further, x = 2.05, voxels 0..20.
  const iv::Beam lost{{0.05, 0.05, 0.05}, {4.05, 0.05, 0.05}, false};
  ev.add(std::span<const iv::Beam>(&lost, 1));
  CHECK(ev.unconfirmed_voxels().size() == 21);
  CHECK(ev.unconfirmed({0, 0, 0}));
  CHECK(ev.unconfirmed({20, 0, 0}));
  CHECK_FALSE(ev.unconfirmed({21, 0, 0}));  // beyond max range
  CHECK_FALSE(ev.unconfirmed({5, 1, 0}));   // never crossed
  // A return at x = 0.85 confirms the voxels before its end voxel (0..7); its end voxel (8) is a
  // hit, not free, so it stays unconfirmed.
  const iv::Beam back{{0.05, 0.05, 0.05}, {0.85, 0.05, 0.05}, true};
  ev.add(std::span<const iv::Beam>(&back, 1));
  for (int x = 0; x < 8; ++x) CHECK_FALSE(ev.unconfirmed({x, 0, 0}));
  for (int x = 8; x <= 20; ++x) CHECK(ev.unconfirmed({x, 0, 0}));
  CHECK(ev.unconfirmed_voxels().size() == 13);
  // A return beyond max range is cut there and confirms everything up to it.
  const iv::Beam far{{0.05, 0.05, 0.05}, {3.05, 0.05, 0.05}, true};
  ev.add(std::span<const iv::Beam>(&far, 1));
  CHECK(ev.unconfirmed_voxels().empty());
  CHECK(ev.size() == 21);
}

TEST_CASE("unconfirmed voxels equal the brute-force set difference on random beams", "[analysis][no-return]") {
  const iv::GridGeometry g(0.05);
  const double max_range = 1.5;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<iv::Beam> beams;
  for (int i = 0; i < 400; ++i) {
    const iv::Point3 o(0.3 * u(rng), 0.3 * u(rng), 0.3 * u(rng));
    iv::Point3 d(u(rng), u(rng), u(rng));
    if (d.norm() < 1e-3) continue;
    d.normalize();
    const bool hit = i % 3 != 0;
    const double range = hit ? 2.0 * (0.5 + 0.5 * u(rng)) : max_range;  // some returns beyond max range
    beams.push_back({o, o + range * d, hit});
  }
  iv::NoReturnEvidence ev(g, max_range);
  ev.add(beams);
  std::set<iv::Key> lost, confirmed;
  for (const iv::Beam& b : beams) {
    const bool trusted = b.hit;  // a return (cut or not) confirms its free part
    for (const iv::Key& k : free_part(g, b, max_range)) (trusted ? confirmed : lost).insert(k);
  }
  std::vector<iv::Key> expected;
  for (const iv::Key& k : lost)
    if (!confirmed.count(k)) expected.push_back(k);
  const std::vector<iv::Key> got = ev.unconfirmed_voxels();
  REQUIRE(!expected.empty());
  CHECK(got == expected);  // both sorted by Key
  // A limit keeps the voxels whose centre lies inside it.
  const iv::Bounds half{{0.0, -2.0, -2.0}, {2.0, 2.0, 2.0}};
  std::vector<iv::Key> in_half;
  for (const iv::Key& k : expected)
    if (half.contains(g.center(k))) in_half.push_back(k);
  CHECK(ev.unconfirmed_voxels(half) == in_half);
}

TEST_CASE("bad no-return evidence input is refused or skipped", "[analysis][no-return]") {
  const iv::GridGeometry g(0.1);
  CHECK_THROWS_AS(iv::NoReturnEvidence(g, 0.0), iv::InvalidArgument);
  CHECK_THROWS_AS(iv::NoReturnEvidence(g, std::numeric_limits<double>::infinity()), iv::InvalidArgument);
  CHECK_THROWS_AS(iv::NoReturnEvidence(g, std::nan("")), iv::InvalidArgument);
  iv::NoReturnEvidence ev(g, 1.0);
  const double nan = std::nan("");
  const std::vector<iv::Beam> bad{
      {{nan, 0, 0}, {1, 0, 0}, false}, {{0, 0, 0}, {0, 0, 0}, false}, {{0, 0, 0}, {nan, 0, 0}, true}};
  ev.add(bad);
  CHECK(ev.size() == 0);
  // A length that overflows (coordinates near the double limit) is skipped, as by the insertion;
  // a return far outside the key range but of finite length is cut at max range like any other.
  const iv::Beam overflow{{0.05, 0.05, 0.05}, {1e300, 0.05, 0.05}, true};
  ev.add(std::span<const iv::Beam>(&overflow, 1));
  CHECK(ev.size() == 0);
  const iv::Beam far{{0.05, 0.05, 0.05}, {1e12, 0.05, 0.05}, true};
  ev.add(std::span<const iv::Beam>(&far, 1));
  CHECK(ev.size() == 11);  // x from 0.05 to 1.05
  CHECK(ev.unconfirmed_voxels().empty());
  CHECK_THROWS_AS(ev.unconfirmed_voxels(iv::Bounds{{1, 1, 1}, {0, 0, 0}}), iv::InvalidArgument);
}
