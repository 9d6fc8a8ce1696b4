// The explained-free-space channel: the belief combination against sequential Dempster
// combination, beam classes on planted scenes with closed-form phantoms (no simulator), the
// evidence against a brute-force per-scan reference, the grid untouched bit for bit under every
// policy and storage, thread-count and order independence, bad input.
#include <intervox/explain/explain.hpp>
#include <intervox/raycast/insert.hpp>
#include <intervox/raycast/traversal.hpp>
#include <intervox/update/bayes_log_odds.hpp>

#include "../common/grid_types.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <random>
#include <vector>

namespace iv = intervox;

namespace {

// ---- a brute-force Dempster–Shafer oracle on the frame {free, occupied} -----------------------
struct Mass {
  double f = 0, o = 0, theta = 1;  // m({free}), m({occupied}), m(frame)
};
Mass dempster(const Mass& a, const Mass& b) {
  const double k = a.f * b.o + a.o * b.f;  // conflict
  Mass m;
  m.f = (a.f * b.f + a.f * b.theta + a.theta * b.f) / (1 - k);
  m.o = (a.o * b.o + a.o * b.theta + a.theta * b.o) / (1 - k);
  m.theta = a.theta * b.theta / (1 - k);
  return m;
}
Mass discount(const Mass& m, double r) { return {r * m.f, r * m.o, 1 - r * (m.f + m.o)}; }

// One class: its items combined one by one in the given order, then the class discounted.
Mass class_mass(int hits, int misses, double hit_mass, double miss_mass, double reliability, std::mt19937_64& rng) {
  std::vector<Mass> items;
  for (int i = 0; i < hits; ++i) items.push_back({0, hit_mass, 1 - hit_mass});
  for (int i = 0; i < misses; ++i) items.push_back({miss_mass, 0, 1 - miss_mass});
  std::shuffle(items.begin(), items.end(), rng);
  Mass m;  // vacuous
  // Within a class the items support one focus each, hits and misses separately (simple support
  // functions combined per focus), so combine the hits and the misses apart and then the two.
  Mass h, s;
  for (const Mass& it : items) (it.o > 0 ? h : s) = dempster(it.o > 0 ? h : s, it);
  m = discount(h, reliability);
  const Mass ms = discount(s, reliability);
  return dempster(m, ms);
}

iv::Beam ret(const iv::Point3& o, const iv::Point3& e) { return {o, e, true}; }

// A wall in the plane x = wall_x, seen straight on from origins along x = 0: a scan of returns
// on a grid of points of the wall, skipping those a panel in the plane x = panel_x over
// y in [panel_lo, panel_hi] hides from the origin.
std::vector<iv::Beam> wall_scan(const iv::Point3& o, double wall_x, double panel_x, double panel_lo, double panel_hi) {
  std::vector<iv::Beam> out;
  for (double y = -2.0; y <= 2.0; y += 0.02)
    for (double z = -0.5; z <= 0.5; z += 0.05) {
      const iv::Point3 w(wall_x, y, z);
      const double at = o.y() + (w.y() - o.y()) * (panel_x - o.x()) / (w.x() - o.x());
      if (at >= panel_lo && at <= panel_hi) continue;
      out.push_back(ret(o, w));
    }
  return out;
}

// A floor at z = 0.01 over x in [0, edge_x] (beyond it, up to x = 6, a lower one at z = beyond_z),
// y in [-0.5, 0.5], seen from 1.5 m above point by point, three times.
void floor_seen_from_above(iv::ExplainedSpace& space, iv::VoxelGrid<iv::BayesLogOdds>& grid, iv::ScanInserter& inserter,
                           double edge_x = 6.0, double beyond_z = 0.01) {
  for (int round = 0; round < 3; ++round) {
    std::vector<iv::Beam> scan;
    for (double x = 0.0; x <= 6.0; x += 0.025)
      for (double y = -0.5; y <= 0.5; y += 0.05)
        scan.push_back(ret({x, y, 1.5}, {x, y, x <= edge_x ? 0.01 : beyond_z}));
    space.insert_beams(inserter, grid, std::span<const iv::Beam>(scan));
  }
}

}  // namespace

TEST_CASE("the belief of counts is the sequential Dempster combination of the same evidence in any order",
          "[explain][belief]") {
  const iv::EvidenceModel model;
  std::mt19937_64 rng(7);
  std::uniform_int_distribution<int> n(0, 12);
  for (int trial = 0; trial < 300; ++trial) {
    iv::EvidenceCell c;
    c.trusted_hits = static_cast<std::uint16_t>(n(rng));
    c.trusted_misses = static_cast<std::uint16_t>(n(rng));
    c.suspect_hits = static_cast<std::uint16_t>(n(rng));
    c.suspect_misses = static_cast<std::uint16_t>(n(rng));
    c.no_return_misses = static_cast<std::uint16_t>(n(rng));
    std::vector<Mass> classes = {
        class_mass(c.trusted_hits, c.trusted_misses, model.hit_mass, model.miss_mass, model.trusted_reliability, rng),
        class_mass(c.suspect_hits, c.suspect_misses, model.hit_mass, model.miss_mass, model.suspect_reliability, rng),
        class_mass(0, c.no_return_misses, model.hit_mass, model.miss_mass, model.no_return_reliability, rng)};
    std::shuffle(classes.begin(), classes.end(), rng);
    Mass m;
    for (const Mass& k : classes) m = dempster(m, k);
    const iv::ExplainedBelief b = model.combine(c);
    CHECK(b.free == Approx(m.f).margin(1e-12));
    CHECK(b.occupied == Approx(m.o).margin(1e-12));
    CHECK(b.lower_free() <= b.upper_free());
    CHECK(b.occupancy().lower == Approx(b.occupied));
    CHECK(b.occupancy().upper == Approx(1 - b.free));
  }
}

TEST_CASE("one trusted miss or hit decides a voxel, no amount of suspect or no-return evidence does",
          "[explain][belief]") {
  const iv::EvidenceModel model;
  iv::EvidenceCell c;
  CHECK(model.state(c) == iv::ExplainedState::Unknown);
  c.trusted_misses = 1;
  CHECK(model.combine(c).free == Approx(0.4));
  CHECK(model.state(c) == iv::ExplainedState::Free);
  c = {};
  c.trusted_hits = 1;
  CHECK(model.combine(c).occupied == Approx(0.7));
  CHECK(model.state(c) == iv::ExplainedState::Occupied);
  c = {};
  c.suspect_misses = 65535;
  c.no_return_misses = 65535;
  const iv::ExplainedBelief b = model.combine(c);
  CHECK(b.free == Approx(0.1));  // the suspect class's reliability: the lower bound of free
  CHECK(b.upper_free() == 1.0);  // nothing says occupied: the upper bound
  CHECK(model.state(c) == iv::ExplainedState::Unexplained);
  c.suspect_hits = 65535;
  CHECK(model.state(c) == iv::ExplainedState::Unexplained);
}

TEST_CASE("counts of any size give a finite belief that the larger evidence wins", "[explain][belief]") {
  const iv::EvidenceModel model;
  for (const std::uint16_t big : {std::uint16_t{2000}, std::uint16_t{65535}}) {
    iv::EvidenceCell c;
    c.trusted_hits = big;
    c.trusted_misses = 10;
    iv::ExplainedBelief b = model.combine(c);
    REQUIRE(std::isfinite(b.free));
    REQUIRE(std::isfinite(b.occupied));
    CHECK(b.occupied > 0.99);
    CHECK(b.free + b.occupied <= 1.0 + 1e-12);
    c.trusted_misses = big;
    c.trusted_hits = 10;
    b = model.combine(c);
    CHECK(b.free > 0.99);
    c.trusted_hits = big;  // both saturated: each side's support is 1 to double precision
    b = model.combine(c);
    REQUIRE(std::isfinite(b.free));
    CHECK(b.free + b.occupied <= 1.0 + 1e-12);
    CHECK(model.state(c) != iv::ExplainedState::Unknown);
  }
}

TEST_CASE("invalid evidence and explain options are refused with the parameter's name", "[explain][errors]") {
  iv::EvidenceModel m;
  m.hit_mass = 1.0;
  CHECK_THROWS_WITH(m.validate(), Catch::Contains("hit_mass"));
  m = {};
  m.suspect_reliability = std::nan("");
  CHECK_THROWS_WITH(m.validate(), Catch::Contains("suspect_reliability"));
  iv::ExplainOptions o;
  o.crossing_tolerance = -1;
  CHECK_THROWS_WITH(iv::ExplainedSpace(iv::GridGeometry(0.05), o), Catch::Contains("crossing_tolerance"));
  o = {};
  o.min_surface_hits = 0;
  CHECK_THROWS_WITH(o.validate(), Catch::Contains("min_surface_hits"));
  o = {};
  o.mid_air_misses = 0;
  CHECK_THROWS_WITH(o.validate(), Catch::Contains("mid_air_misses"));
  for (const double angle : {-1.0, 91.0, std::nan("")}) {
    o = {};
    o.no_return_crossing_angle = angle;
    CHECK_THROWS_WITH(o.validate(), Catch::Contains("no_return_crossing_angle"));
  }
}

TEST_CASE("a planted mirror's phantoms that pass a wall seen directly are suspect, direct returns trusted",
          "[explain][classes]") {
  // A wall in the plane x = 2 and, 1 m in front of it, a mirror panel in the plane x = 1 over
  // y in [0.5, 1.5]. A back wall in the plane x = -1 is what the mirror shows. A beam from o
  // that meets the panel at m reflects to the real point r on the back wall; the sensor reports
  // the folded range along its own direction: the phantom o + (|m - o| + |r - m|) d, which is r
  // reflected about x = 1 (closed form: (2 - r.x, r.y, r.z) = (3, r.y, r.z)).
  iv::VoxelGrid<iv::BayesLogOdds> grid(0.05);
  iv::ExplainedSpace space(grid.geometry());
  iv::InsertOptions io;
  io.max_range = 6.0;
  iv::ScanInserter inserter(io);
  // The wall seen directly from three places, twice each (a supported surface needs 2 hits).
  for (int round = 0; round < 2; ++round)
    for (const double y0 : {-1.5, 0.0, 1.0, 3.0}) {
      const auto scan = wall_scan({0.0, y0, 0.0}, 2.0, 1.0, 0.5, 1.5);
      const iv::InsertStats st = space.insert_beams(inserter, grid, std::span<const iv::Beam>(scan));
      CHECK(st.beams_trusted == scan.size());
      CHECK(st.beams_suspect == 0);
    }
  // Phantom beams through the panel from o = (0, 1, 0).
  const iv::Point3 o(0.0, 1.0, 0.0);
  std::vector<iv::Beam> phantoms;
  std::vector<iv::Point3> truth;
  for (double y = 0.55; y <= 1.45; y += 0.05)
    for (double z = -0.2; z <= 0.2; z += 0.1) {  // they pass x = 2 within the wall's scanned |z| <= 0.5
      const iv::Point3 m(1.0, y, z);
      const iv::Point3 d = (m - o).normalized();
      const iv::Point3 rd(-d.x(), d.y(), d.z());              // reflected about the plane x = 1
      const iv::Point3 r = m + rd * ((m.x() + 1.0) / d.x());  // meets the back wall x = -1
      const double range = (m - o).norm() + (r - m).norm();
      const iv::Point3 phantom = o + d * range;
      REQUIRE(phantom.x() == Approx(2.0 - r.x()));  // the closed form
      phantoms.push_back(ret(o, phantom));
      truth.push_back(r);
    }
  std::vector<iv::BeamClass> classes;
  const iv::InsertStats st = space.insert_beams(inserter, grid, std::span<const iv::Beam>(phantoms), &classes);
  CHECK(st.beams_suspect == phantoms.size());
  for (const iv::BeamClass c : classes) CHECK(c == iv::BeamClass::Suspect);
  // The plain grid believes the phantoms: the wall voxels they crossed got misses. The channel
  // keeps them apart: the space behind the wall that only phantoms crossed is not explained free,
  // while the grid calls some of it free.
  int phantom_only = 0, plain_free = 0;
  for (const iv::Beam& b : phantoms) {
    const iv::Key k = grid.key(b.origin + (b.end - b.origin) * (2.53 / b.end.x()));  // behind the wall, off voxel faces
    const iv::EvidenceCell e = space.evidence(k);
    CHECK(e.trusted_misses == 0);
    CHECK(e.suspect_misses >= 1);
    CHECK(space.state(k) == iv::ExplainedState::Unexplained);
    ++phantom_only;
    if (grid.occupancy(k) == iv::Occupancy::Free || grid.probability(k) < 0.5) ++plain_free;
  }
  CHECK(plain_free == phantom_only);  // the plain map took every phantom's word
  // The phantoms never widen the trusted extent (it ends at the wall, x = 2).
  REQUIRE(space.trusted_extent());
  CHECK(grid.center(space.trusted_extent()->max).x() < 2.1);
  // Direct returns from the same place stay trusted.
  const auto direct = wall_scan(o, 2.0, 1.0, 0.5, 1.5);
  const auto direct_classes = space.classify(std::span<const iv::Beam>(direct), io);
  CHECK(std::count(direct_classes.begin(), direct_classes.end(), iv::BeamClass::Trusted) ==
        static_cast<std::ptrdiff_t>(direct.size()));
}

TEST_CASE("a beam that grazes a supported floor and ends on it is trusted, one that passes through is not",
          "[explain][classes]") {
  iv::VoxelGrid<iv::BayesLogOdds> grid(0.05);
  iv::ExplainedSpace space(grid.geometry());
  iv::InsertOptions io;
  io.max_range = 8.0;
  iv::ScanInserter inserter(io);
  floor_seen_from_above(space, grid, inserter);
  // Knee-height grazing returns from 0.3 m above the floor, ending on it 2..5 m away (about 3.4
  // to 8.5 degrees): they pass floor voxels more than the tolerance before their ends.
  std::vector<iv::Beam> grazing;
  for (double x = 2.0; x <= 5.0; x += 0.25) grazing.push_back(ret({0.0, 0.0, 0.3}, {x, 0.0, 0.01}));
  for (const iv::BeamClass c : space.classify(std::span<const iv::Beam>(grazing), io))
    CHECK(c == iv::BeamClass::Trusted);
  // Steeper returns from the same origin that end 1 m below the floor: they pass it well before
  // their ends, and nothing supported lies near those ends (a phantom of a mirror on the floor).
  std::vector<iv::Beam> through;
  for (double x = 2.0; x <= 5.0; x += 0.25) through.push_back(ret({0.0, 0.0, 0.3}, {x, 0.0, -1.0}));
  for (const iv::BeamClass c : space.classify(std::span<const iv::Beam>(through), io))
    CHECK(c == iv::BeamClass::Suspect);
}

TEST_CASE("a return in mid-air, where trusted beams saw free space, is suspect, one on a new surface behind it is not",
          "[explain][classes]") {
  iv::VoxelGrid<iv::BayesLogOdds> grid(0.05);
  iv::ExplainedSpace space(grid.geometry());
  iv::InsertOptions io;
  io.max_range = 8.0;
  iv::ScanInserter inserter(io);
  // A wall at x = 4 seen from x = 0 three times: the space in between is trusted free.
  std::vector<iv::Beam> scan;
  for (double y = -1.0; y <= 1.0; y += 0.02)
    for (double z = -0.2; z <= 0.2; z += 0.02) scan.push_back(ret({0, 0, 0}, {4.0, y, z}));
  for (int round = 0; round < 3; ++round) space.insert_beams(inserter, grid, std::span<const iv::Beam>(scan));
  const std::vector<iv::Beam> probe = {ret({0, 0, 0}, {2.0, 0.1, 0.05}),   // mid-air
                                       ret({0, 0, 0}, {4.0, 0.1, 0.05})};  // on the wall
  const auto c = space.classify(std::span<const iv::Beam>(probe), io);
  CHECK(c[0] == iv::BeamClass::Suspect);
  CHECK(c[1] == iv::BeamClass::Trusted);
  // From a new side (x = 6, behind the wall) the wall's back is new: no crossing, no mid-air.
  CHECK(space.classify(ret({6.0, 0.0, 0.0}, {4.05, 0.0, 0.0}), io) == iv::BeamClass::Trusted);
}

TEST_CASE("beams without a return never make space explained free and never widen the trusted extent",
          "[explain][classes]") {
  // A black sofa: the beams that meet it return nothing and are free up to the max range.
  iv::VoxelGrid<iv::BayesLogOdds> grid(0.05, iv::BayesLogOdds::octomap());
  iv::ExplainedSpace space(grid.geometry());
  iv::InsertOptions io;
  io.max_range = 3.0;
  iv::ScanInserter inserter(io);
  std::vector<iv::Beam> scan;
  const iv::Point3 o(0.0, 0.01, 0.01);  // off the voxel faces
  for (int i = -10; i <= 10; ++i) scan.push_back({o, o + iv::Point3(1.0, 0.05 * i, 0.0), false});
  scan.push_back(ret(o, o + iv::Point3(0.0, 1.0, 0.0)));  // one return elsewhere: the trusted extent starts
  std::vector<iv::BeamClass> classes;
  const iv::InsertStats st = space.insert_beams(inserter, grid, std::span<const iv::Beam>(scan), &classes);
  CHECK(st.beams_no_return == scan.size() - 1);
  CHECK(st.beams_trusted == 1);
  CHECK(st.beams_no_return + st.beams_trusted + st.beams_suspect == st.rays);
  const iv::Key behind = grid.key(o + iv::Point3(2.5, 0.0, 0.0));
  CHECK(grid.occupancy(behind) == iv::Occupancy::Free);  // the plain map: free behind the sofa
  CHECK(space.state(behind) == iv::ExplainedState::Unexplained);
  CHECK(space.belief(behind).lower_free() == 0.0);
  REQUIRE(space.trusted_extent());
  CHECK(space.trusted_extent()->max.x <= grid.key(o + iv::Point3(0.0, 1.0, 0.0)).x);
}

TEST_CASE("a beam without a return that passes a supported wall into the space behind it is suspect, one that stops "
          "short is not",
          "[explain][classes]") {
  // A wall in the plane x = 2 seen directly from four places, twice each.
  iv::VoxelGrid<iv::BayesLogOdds> grid(0.05);
  iv::ExplainedSpace space(grid.geometry());
  iv::InsertOptions io;
  io.max_range = 6.0;
  iv::ScanInserter inserter(io);
  for (int round = 0; round < 2; ++round)
    for (const double y0 : {-1.5, 0.0, 1.0, 3.0}) {
      const auto scan = wall_scan({0.0, y0, 0.0}, 2.0, 1.0, 5.0, 4.0);  // no panel
      space.insert_beams(inserter, grid, std::span<const iv::Beam>(scan));
    }
  const iv::Point3 o(0.0, 0.51, 0.01);  // off the voxel faces
  const iv::Point3 d = iv::Point3(1.0, 0.1, 0.02).normalized();
  const auto none = [&](double end) { return iv::Beam{o, o + d * end, false}; };
  // A black panel in front of the wall swallowed it: it went through the wall, within the
  // sensor's range (its end), into space no trusted beam crossed.
  CHECK(space.classify(none(4.0), io) == iv::BeamClass::Suspect);
  // The sensor's range ends before the wall (plus the tolerance): nothing to see within it.
  CHECK(space.classify(none(1.9), io) == iv::BeamClass::NoReturn);
  CHECK(space.classify(none(2.0 + 0.5 * io.max_range), io) == iv::BeamClass::Suspect);
  // An end beyond the max range: the max range is the window.
  iv::InsertOptions near = io;
  near.max_range = 1.9;
  CHECK(space.classify(none(50.0), near) == iv::BeamClass::NoReturn);
  CHECK(space.classify(none(50.0), io) == iv::BeamClass::Suspect);
  // Inserted, its misses are suspect evidence: the space behind the wall it alone crossed is free
  // only by lying beams; a beam without a return that stopped short leaves no such voxel.
  std::vector<iv::BeamClass> classes;
  const std::vector<iv::Beam> both{none(4.0),
                                   iv::Beam{iv::Point3(0.0, -0.49, 0.01), iv::Point3(1.9, -0.3, 0.05), false}};
  const iv::InsertStats st = space.insert_beams(inserter, grid, std::span<const iv::Beam>(both), &classes);
  CHECK(classes == std::vector<iv::BeamClass>{iv::BeamClass::Suspect, iv::BeamClass::NoReturn});
  CHECK(st.beams_suspect == 1);
  CHECK(st.beams_no_return == 1);
  const iv::Key behind = grid.key(o + d * 3.0);
  CHECK(space.evidence(behind).suspect_misses == 1);
  CHECK(space.free_only_by_lying_beams(behind));
  const iv::Key short_of = grid.key(iv::Point3(0.0, -0.49, 0.01) + (iv::Point3(1.9, 0.19, 0.04)).normalized() * 1.0);
  CHECK(space.evidence(short_of).no_return_misses >= 1);
  CHECK_FALSE(space.free_only_by_lying_beams(short_of));
}

TEST_CASE("a beam without a return that grazes a surface's edge into space trusted beams crossed is not suspect",
          "[explain][classes]") {
  iv::VoxelGrid<iv::BayesLogOdds> grid(0.05);
  iv::ExplainedSpace space(grid.geometry());
  iv::InsertOptions io;
  io.max_range = 8.0;
  iv::ScanInserter inserter(io);
  // A table top at z = 0.01 over x in [0, 3], seen from 1.5 m above, and beyond its edge a floor
  // at z = -1 seen the same way: the space beside and below the edge is trusted free.
  floor_seen_from_above(space, grid, inserter, 3.0, -1.0);
  // A shallow beam without a return that skims the table top's last voxels and leaves past its
  // edge into the trusted space beyond (a real sensor loses such grazing returns).
  const iv::Beam skim{{0.0, 0.01, 0.31}, {6.0, 0.01, -0.29}, false};
  CHECK(space.classify(skim, io) == iv::BeamClass::NoReturn);
  // A steeper one that passes the table top well before its edge, into the space under it that
  // no trusted beam crossed: through a supported surface.
  const iv::Beam through{{0.0, 0.01, 0.31}, {2.0, 0.01, -0.69}, false};
  CHECK(space.classify(through, io) == iv::BeamClass::Suspect);
}

TEST_CASE("a depth frame's pixel without a return is classed up to the frame's range", "[explain][classes]") {
  iv::PinholeIntrinsics k;
  k.width = 8;
  k.height = 6;
  k.fx = k.fy = 20.0;
  k.cx = 3.5;
  k.cy = 2.5;
  iv::VoxelGrid<iv::BayesLogOdds> grid(0.05);
  iv::ExplainedSpace space(grid.geometry());
  iv::ScanInserter inserter;
  // A wall in the plane z = 2 in front of the camera (it looks along +z from the origin), seen
  // from four places twice each.
  for (int round = 0; round < 2; ++round)
    for (const double x0 : {-0.6, -0.2, 0.2, 0.6}) {
      std::vector<iv::Beam> scan;
      for (double x = -1.0; x <= 1.0; x += 0.02)
        for (double y = -1.0; y <= 1.0; y += 0.02) scan.push_back(ret({x0, 0.0, 0.0}, {x, y, 2.0}));
      iv::InsertOptions io;
      io.max_range = 6.0;
      iv::ScanInserter wall(io);
      space.insert_beams(wall, grid, std::span<const iv::Beam>(scan));
    }
  iv::DepthFrame f;
  f.intrinsics = k;
  f.image.width = 8;
  f.image.height = 6;
  f.image.depth.assign(8 * 6, std::numeric_limits<float>::infinity());  // the panel swallowed every beam
  f.pose = iv::Pose::Identity();
  f.pose.translation() = iv::Point3(0.013, 0.011, 0.0);
  std::vector<iv::BeamClass> classes;
  f.max_range = 4.0;  // the wall lies within the frame's range: every beam went through it
  space.insert_depth_image(inserter, grid, f, &classes);
  CHECK(std::count(classes.begin(), classes.end(), iv::BeamClass::Suspect) == 8 * 6);
  f.max_range = 1.9;  // it does not
  space.insert_depth_image(inserter, grid, f, &classes);
  CHECK(std::count(classes.begin(), classes.end(), iv::BeamClass::NoReturn) == 8 * 6);
}

TEST_CASE("the evidence equals a brute-force per-scan reference of the beams' final classes", "[explain][evidence]") {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  const iv::GridGeometry g(0.1);
  iv::VoxelGrid<iv::BayesLogOdds> grid(g, std::nullopt);
  iv::ExplainedSpace space(g);
  iv::InsertOptions io;
  io.max_range = 2.0;
  iv::ScanInserter inserter(io);
  std::vector<std::vector<iv::Beam>> scans;
  for (int scan = 0; scan < 20; ++scan) {
    const iv::Point3 o(u(rng) * 0.3, u(rng) * 0.3, 0.0);
    std::vector<iv::Beam> beams;
    for (int i = 0; i < 200; ++i) beams.push_back({o, o + iv::Point3(u(rng), u(rng), 0.3 * u(rng)) * 1.5, i % 7 != 0});
    std::vector<iv::BeamClass> classes;
    space.insert_beams(inserter, grid, std::span<const iv::Beam>(beams), &classes);
    for (std::size_t i = 0; i < beams.size(); ++i) CHECK(classes[i] != iv::BeamClass::Skipped);
    scans.push_back(std::move(beams));
  }
  // Every scan is still in the ledger, with its beams as given and its classes now (revision
  // moved some of them, which is what this test is for).
  REQUIRE(space.ledger().scans().size() == scans.size());
  const iv::ExplainedSpace::RevisionStats& rs = space.revision_stats();
  CHECK(rs.to_suspect + rs.to_trusted > 0);
  std::map<iv::Key, iv::EvidenceCell> ref;
  for (std::size_t s = 0; s < scans.size(); ++s) {
    const iv::LedgerScan& kept = space.ledger().scans()[s];
    REQUIRE(kept.size() == scans[s].size());
    // Reference: per class, the miss keys minus the hit keys get a miss, the hit keys a hit.
    std::map<iv::Key, int>
        marks;  // bits: 1 trusted hit, 2 trusted miss, 4 suspect hit, 8 suspect miss, 16 no-return miss
    kept.for_each([&](std::size_t i, const iv::Beam& b, iv::BeamClass c) {
      CHECK(b.origin == scans[s][i].origin);
      CHECK(b.end == scans[s][i].end);
      CHECK(b.hit == scans[s][i].hit);
      const int cls = static_cast<int>(c);
      const int hit_bit = cls == 0 ? 1 : cls == 1 ? 4 : 0, miss_bit = cls == 0 ? 2 : cls == 1 ? 8 : 16;
      const double len = (b.end - b.origin).norm();
      const bool cut = !b.hit || len > io.max_range;
      const iv::Point3 end = cut ? iv::Point3(b.origin + (b.end - b.origin) * (io.max_range / len)) : b.end;
      const iv::Key last = g.key(end);
      iv::traverse(g, b.origin, end, [&](const iv::Key& k) {
        if (k != last) marks[k] |= miss_bit;
        return true;
      });
      if (!cut) marks[last] |= hit_bit;
    });
    for (const auto& [k, m] : marks) {
      iv::EvidenceCell& c = ref[k];
      if (m & 1)
        ++c.trusted_hits;
      else if (m & 2)
        ++c.trusted_misses;
      if (m & 4)
        ++c.suspect_hits;
      else if (m & 8)
        ++c.suspect_misses;
      if (m & 16) ++c.no_return_misses;
    }
  }
  std::size_t seen = 0;
  space.for_each([&](const iv::Key& k, const iv::EvidenceCell& c) {
    CHECK(c.any());  // a voxel whose evidence revision moved away entirely is not listed
    ++seen;
    const auto it = ref.find(k);
    REQUIRE(it != ref.end());
    CHECK(c == it->second);
  });
  CHECK(seen == ref.size());
  CHECK(space.memory_bytes() > space.ledger().bytes());
}

TEMPLATE_TEST_CASE("classing beams leaves the grid's update bit for bit as the plain insertion's", "[explain][grid]",
                   INTERVOX_TEST_GRIDS) {
  const iv::Bounds bounds{{-3.0, -3.0, -3.0}, {3.0, 3.0, 3.0}};
  TestType plain = test::make_grid_for<TestType>(0.1, bounds);
  TestType explained = test::make_grid_for<TestType>(0.1, bounds);
  iv::ExplainedSpace space(explained.geometry());
  iv::InsertOptions io;
  io.max_range = 2.5;
  iv::ScanInserter a(io), b(io);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int scan = 0; scan < 8; ++scan) {
    std::vector<iv::Beam> beams;
    const iv::Point3 o(0.2 * u(rng), 0.2 * u(rng), 0.0);
    for (int i = 0; i < 400; ++i) beams.push_back({o, o + iv::Point3(u(rng), u(rng), 0.4 * u(rng)) * 3.0, i % 5 != 0});
    const iv::InsertStats sa = a.insert_beams(plain, std::span<const iv::Beam>(beams));
    iv::InsertStats sb = space.insert_beams(b, explained, std::span<const iv::Beam>(beams));
    CHECK(sb.beams_trusted + sb.beams_suspect + sb.beams_no_return == sb.rays);
    sb.beams_trusted = sb.beams_suspect = sb.beams_no_return = 0;
    CHECK(sa == sb);
  }
  std::vector<std::pair<iv::Key, typename TestType::Cell>> ca, cb;
  plain.for_each_observed([&](const iv::Key& k, const auto& c) { ca.emplace_back(k, c); });
  explained.for_each_observed([&](const iv::Key& k, const auto& c) { cb.emplace_back(k, c); });
  REQUIRE(ca.size() == cb.size());
  REQUIRE(!ca.empty());
  for (std::size_t i = 0; i < ca.size(); ++i) {
    CHECK(ca[i].first == cb[i].first);
    CHECK(std::memcmp(&ca[i].second, &cb[i].second, sizeof(ca[i].second)) == 0);
  }
}

TEST_CASE("classes and evidence do not depend on the thread count or the order of a scan's beams",
          "[explain][threaded]") {
  test::ThreadCap cap(4);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<std::vector<iv::Beam>> scans;
  for (int s = 0; s < 6; ++s) {
    std::vector<iv::Beam> beams;
    const iv::Point3 o(0.5 * u(rng), 0.5 * u(rng), 0.0);
    for (int i = 0; i < 6000; ++i) beams.push_back({o, o + iv::Point3(u(rng), u(rng), 0.3 * u(rng)) * 3.0, i % 9 != 0});
    scans.push_back(std::move(beams));
  }
  const auto run = [&](unsigned threads, bool shuffled) {
    iv::VoxelGrid<iv::BayesLogOdds> grid(0.05);
    iv::ExplainedSpace space(grid.geometry());
    iv::InsertOptions io;
    io.max_range = 2.0;
    io.threads = threads;
    iv::ScanInserter inserter(io);
    std::vector<iv::BeamClass> all;
    std::mt19937_64 order(9);
    for (auto beams : scans) {
      std::vector<std::size_t> idx(beams.size());
      for (std::size_t i = 0; i < idx.size(); ++i) idx[i] = i;
      if (shuffled) std::shuffle(idx.begin(), idx.end(), order);
      std::vector<iv::Beam> in(beams.size());
      for (std::size_t i = 0; i < idx.size(); ++i) in[i] = beams[idx[i]];
      std::vector<iv::BeamClass> c;
      space.insert_beams(inserter, grid, std::span<const iv::Beam>(in), &c);
      std::vector<iv::BeamClass> back(c.size());
      for (std::size_t i = 0; i < idx.size(); ++i) back[idx[i]] = c[i];
      all.insert(all.end(), back.begin(), back.end());
    }
    std::map<iv::Key, iv::EvidenceCell> ev;
    space.for_each([&](const iv::Key& k, const iv::EvidenceCell& e) { ev[k] = e; });
    return std::make_pair(all, ev);
  };
  const auto one = run(1, false);
  const auto four = run(4, false);
  const auto shuffled = run(2, true);
  CHECK(one.first == four.first);
  CHECK(one.second == four.second);
  CHECK(one.first == shuffled.first);
  CHECK(one.second == shuffled.second);
  CHECK(std::count(one.first.begin(), one.first.end(), iv::BeamClass::Suspect) > 0);  // the test sees both classes
}

TEST_CASE("bad beams, empty scans and mismatched input follow the insertion's rules or are refused",
          "[explain][errors]") {
  iv::VoxelGrid<iv::BayesLogOdds> grid(0.05);
  iv::ExplainedSpace space(grid.geometry());
  iv::InsertOptions io;
  io.max_range = 3.0;
  io.min_range = 0.1;
  iv::ScanInserter inserter(io);
  const double nan = std::nan("");
  const std::vector<iv::Beam> bad = {{{nan, 0, 0}, {1, 0, 0}, true},     // NaN origin
                                     {{0, 0, 0}, {0, 0, 0}, true},       // zero length
                                     {{0, 0, 0}, {0.05, 0, 0}, true},    // closer than min_range
                                     {{0, 0, 0}, {1e100, 0, 0}, true}};  // cut at max range
  std::vector<iv::BeamClass> classes;
  const iv::InsertStats st = space.insert_beams(inserter, grid, std::span<const iv::Beam>(bad), &classes);
  CHECK(st.skipped() == 3);  // the far return is cut at max range: misses only
  CHECK(classes[0] == iv::BeamClass::Skipped);
  CHECK(classes[1] == iv::BeamClass::Skipped);
  CHECK(classes[2] == iv::BeamClass::Skipped);
  CHECK(classes[3] == iv::BeamClass::Trusted);
  CHECK(st.beams_trusted == 1);
  // An empty scan changes nothing.
  const std::size_t before = space.size();
  CHECK(space.insert_beams(inserter, grid, std::span<const iv::Beam>()).rays == 0);
  CHECK(space.size() == before);
  // A beam that starts inside a supported surface is classed like any other (its own voxel is
  // not before its end by more than the tolerance unless it is long).
  CHECK(space.classify(iv::Beam{{1.0, 0, 0}, {1.0, 0.5, 0}, true}, io) != iv::BeamClass::Skipped);
  // Mismatches are refused.
  std::vector<iv::BeamClass> one_class(1);
  CHECK_THROWS_AS(space.add(std::span<const iv::Beam>(bad), one_class, io), iv::InvalidArgument);
  iv::VoxelGrid<iv::BayesLogOdds> other(0.1);
  CHECK_THROWS_WITH(space.insert_beams(inserter, other, std::span<const iv::Beam>(bad)), Catch::Contains("geometry"));
  CHECK_THROWS_AS(space.counts(iv::BeamClass::Skipped), iv::InvalidArgument);
  space.clear();
  CHECK(space.size() == 0);
  CHECK(!space.trusted_extent());
}

TEST_CASE("a depth frame is classed pixel by pixel and inserted as the plain insertion inserts it", "[explain][grid]") {
  iv::PinholeIntrinsics k;
  k.width = 32;
  k.height = 24;
  k.fx = k.fy = 30.0;
  k.cx = 15.5;
  k.cy = 11.5;
  iv::DepthFrame f;
  f.intrinsics = k;
  f.image.width = 32;
  f.image.height = 24;
  f.image.depth.assign(32 * 24, 2.0f);
  f.image.depth[5] = std::numeric_limits<float>::infinity();  // no return
  f.image.depth[6] = std::nanf("");                           // invalid
  f.max_range = 4.0;
  iv::VoxelGrid<iv::BayesLogOdds> plain(0.05), explained(0.05);
  iv::ExplainedSpace space(explained.geometry());
  iv::ScanInserter a, b;
  const iv::InsertStats sa = a.insert_depth_image(plain, f);
  std::vector<iv::BeamClass> classes;
  iv::InsertStats sb = space.insert_depth_image(b, explained, f, &classes);
  REQUIRE(classes.size() == 32u * 24u);
  CHECK(classes[5] == iv::BeamClass::NoReturn);
  CHECK(classes[6] == iv::BeamClass::Skipped);
  CHECK(sb.beams_trusted == 32u * 24u - 2u);
  sb.beams_trusted = sb.beams_suspect = sb.beams_no_return = 0;
  CHECK(sa == sb);
  CHECK(plain.observed_count() == explained.observed_count());
  CHECK(!b.options().has_max_range());  // the caller's inserter keeps its own options
}
