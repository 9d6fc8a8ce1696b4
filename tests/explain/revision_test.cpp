// The revision ledger: a phantom that arrives before the wall behind the mirror is classed again
// when the wall is seen (phantom first and wall later ends as wall first, evidence included), a
// return in mid-air becomes trusted once a surface is seen there, the budget is enforced and
// what it forgets keeps its last class, thread-count independence. Planted scenes with
// closed-form phantoms, no simulator.
#include <intervox/explain/explain.hpp>
#include <intervox/raycast/insert.hpp>
#include <intervox/update/bayes_log_odds.hpp>

#include "../common/grid_types.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

namespace iv = intervox;

namespace revision_test {

iv::Beam rv_ret(const iv::Point3& o, const iv::Point3& e) { return {o, e, true}; }

// A wall in the plane x = 2 seen straight on from (0, y0, 0), skipping the points a mirror panel
// in the plane x = 1 over y in [0.5, 1.5] hides.
std::vector<iv::Beam> wall_scan(double y0) {
  std::vector<iv::Beam> out;
  const iv::Point3 o(0.0, y0, 0.0);
  for (double y = -2.0; y <= 2.0; y += 0.02)
    for (double z = -0.5; z <= 0.5; z += 0.05) {
      const iv::Point3 w(2.0, y, z);
      const double at = o.y() + (w.y() - o.y()) * (1.0 - o.x()) / (w.x() - o.x());
      if (at >= 0.5 && at <= 1.5) continue;
      out.push_back(rv_ret(o, w));
    }
  return out;
}

// The mirror panel's phantoms seen from (0, 1, 0): each beam meets the panel at m, reflects to the
// back wall x = -1 and is reported at its folded range along its own direction, i.e. at the real
// point reflected about x = 1 (closed form: x = 3).
std::vector<iv::Beam> phantom_scan() {
  const iv::Point3 o(0.0, 1.0, 0.0);
  std::vector<iv::Beam> out;
  for (double y = 0.55; y <= 1.45; y += 0.05)
    for (double z = -0.2; z <= 0.2; z += 0.1) {
      const iv::Point3 m(1.0, y, z);
      const iv::Point3 d = (m - o).normalized();
      const iv::Point3 rd(-d.x(), d.y(), d.z());
      const iv::Point3 r = m + rd * ((m.x() + 1.0) / d.x());
      out.push_back(rv_ret(o, o + d * ((m - o).norm() + (r - m).norm())));
    }
  return out;
}

std::vector<std::vector<iv::Beam>> wall_scans() {
  std::vector<std::vector<iv::Beam>> out;
  for (int round = 0; round < 2; ++round)
    for (const double y0 : {-1.5, 0.0, 1.0, 3.0}) out.push_back(wall_scan(y0));
  return out;
}

struct Outcome {
  std::vector<std::vector<iv::BeamClass>> classes;  // per scan in the order given, classes now
  std::map<iv::Key, iv::EvidenceCell> evidence;
  iv::ExplainedSpace::RevisionStats stats;
  std::size_t ledger_bytes = 0;
};

// Inserts \p scans in order and reads back each scan's classes now (from the ledger, which keeps
// them all unless its budget is too small; then the arrival classes of the forgotten ones).
Outcome run(const std::vector<std::vector<iv::Beam>>& scans, const iv::ExplainOptions& options, unsigned threads = 1) {
  iv::VoxelGrid<iv::BayesLogOdds> grid(0.05);
  iv::ExplainedSpace space(grid.geometry(), options);
  iv::InsertOptions io;
  io.max_range = 6.0;
  io.threads = threads;
  iv::ScanInserter inserter(io);
  Outcome out;
  for (const auto& s : scans) {
    std::vector<iv::BeamClass> c;
    space.insert_beams(inserter, grid, std::span<const iv::Beam>(s), &c);
    out.classes.push_back(c);
  }
  space.revise();  // the scans since the last revision (ExplainOptions::revision_interval)
  const auto& kept = space.ledger().scans();
  const std::size_t first_kept = scans.size() - kept.size();
  for (std::size_t s = 0; s < kept.size(); ++s)
    kept[s].for_each([&](std::size_t i, const iv::Beam&, iv::BeamClass c) { out.classes[first_kept + s][i] = c; });
  space.for_each([&](const iv::Key& k, const iv::EvidenceCell& e) { out.evidence[k] = e; });
  out.stats = space.revision_stats();
  out.ledger_bytes = space.ledger().bytes();
  return out;
}

std::size_t count(const std::vector<iv::BeamClass>& c, iv::BeamClass which) {
  return static_cast<std::size_t>(std::count(c.begin(), c.end(), which));
}

}  // namespace revision_test

using namespace revision_test;

TEST_CASE("a phantom that arrives before the wall behind the mirror ends as if the wall had come first",
          "[explain][revision]") {
  const std::vector<std::vector<iv::Beam>> walls = wall_scans();
  const std::vector<iv::Beam> phantoms = phantom_scan();
  std::vector<std::vector<iv::Beam>> wall_first = walls, phantom_first{phantoms};
  wall_first.push_back(phantoms);
  phantom_first.insert(phantom_first.end(), walls.begin(), walls.end());

  const Outcome a = run(wall_first, {});
  const Outcome b = run(phantom_first, {});
  // Wall first: the phantoms are suspect on arrival, nothing to revise.
  CHECK(count(a.classes.back(), iv::BeamClass::Suspect) == phantoms.size());
  CHECK(a.stats.to_suspect == 0);
  // Phantom first: trusted on arrival, suspect once the wall is supported.
  CHECK(b.stats.to_suspect == phantoms.size());
  CHECK(b.stats.to_trusted == 0);
  CHECK(count(b.classes.front(), iv::BeamClass::Suspect) == phantoms.size());
  for (std::size_t s = 0; s < walls.size(); ++s) {
    CHECK(a.classes[s] == b.classes[s + 1]);  // the wall scans: trusted either way
    CHECK(count(a.classes[s], iv::BeamClass::Trusted) == walls[s].size());
  }
  // The evidence is the same voxel for voxel: the moves were exact.
  CHECK(a.evidence == b.evidence);

  // Without a ledger the phantom keeps its arrival class: the space behind the wall that only the
  // phantoms crossed stays explained free (what revision is for).
  iv::ExplainOptions off;
  off.ledger_bytes = 0;
  const Outcome c = run(phantom_first, off);
  CHECK(count(c.classes.front(), iv::BeamClass::Trusted) == phantoms.size());
  CHECK(c.evidence != a.evidence);
  CHECK(c.ledger_bytes == 0);
}

TEST_CASE("with the inside rule, a wall whose edge grows around a phantom's crossing ends as if it had come first",
          "[explain][revision]") {
  // The wall x = 2 seen in two strips, y <= 0.94 m first. Phantoms from (0, 1, 0) that end 1 m
  // behind it cross it in the middle of a voxel: in the strip's last column (y 0.90-0.95), where
  // the first strip leaves an edge (no crossing under the inside rule) and the second makes an
  // inside while that column itself changes nothing (its neighbours do), and in either strip's
  // inside. Revising after every scan, the phantom-first order must end as the phantoms-last one.
  const auto strip = [](double y0, double lo, double hi) {
    std::vector<iv::Beam> out;
    for (const iv::Beam& b : wall_scan(y0))
      if (b.end.y() >= lo && b.end.y() <= hi) out.push_back(b);
    return out;
  };
  std::vector<std::vector<iv::Beam>> walls;
  for (const auto& [lo, hi] : {std::pair{-2.0, 0.94}, std::pair{0.95, 2.0}})
    for (int round = 0; round < 2; ++round)
      for (const double y0 : {-1.5, 0.0, 1.0, 3.0}) walls.push_back(strip(y0, lo, hi));
  std::vector<iv::Beam> phantoms;
  const iv::Point3 from(0.0, 1.0, 0.0);
  for (const double y : {0.625, 0.925, 1.325})
    for (double z = -0.175; z <= 0.18; z += 0.05) {
      const iv::Point3 at(2.025, y, z);  // where it crosses the wall's voxels, mid-voxel
      phantoms.push_back(rv_ret(from, from + (at - from) * (3.0 / 2.025)));
    }
  std::vector<std::vector<iv::Beam>> wall_first = walls, phantom_first{phantoms};
  wall_first.push_back(phantoms);
  phantom_first.insert(phantom_first.end(), walls.begin(), walls.end());
  iv::ExplainOptions o;
  o.returned_crossing_inside = true;
  o.revision_interval = 1;
  const Outcome a = run(wall_first, o);
  const Outcome b = run(phantom_first, o);
  // The edge column's phantoms, suspect once the second strip is seen, are the case that needs a
  // neighbour's change; after the first strip only the others are.
  const std::vector<std::vector<iv::Beam>> first_strip(phantom_first.begin(), phantom_first.begin() + 9);
  CHECK(count(run(first_strip, o).classes.front(), iv::BeamClass::Suspect) == 8);
  CHECK(count(a.classes.back(), iv::BeamClass::Suspect) == phantoms.size());
  CHECK(a.classes.back() == b.classes.front());
  for (std::size_t s = 0; s < walls.size(); ++s) CHECK(a.classes[s] == b.classes[s + 1]);
  CHECK(a.evidence == b.evidence);
}

TEST_CASE("a beam suspect for crossing phantom returns becomes trusted when the phantoms are revised away",
          "[explain][revision]") {
  // Two phantom scans first: their ends (behind the wall, x = 3) get two trusted hits each and
  // look like a surface. A real beam along x through one of those ends, from a sensor behind the
  // wall, is then suspect (it crosses a supported voxel). When the wall is seen, the phantoms become suspect, the
  // "surface" loses its support, and in the next round of the same revision the real beam becomes trusted.
  const std::vector<iv::Beam> phantoms = phantom_scan();
  const auto mid = std::find_if(phantoms.begin(), phantoms.end(), [](const iv::Beam& b) {
    return std::abs(b.end.y() - 1.0) < 1e-9 && std::abs(b.end.z()) < 1e-9;
  });
  REQUIRE(mid != phantoms.end());
  const iv::Point3 e = mid->end + iv::Point3(0.0, 0.0, 0.01);
  const std::vector<iv::Beam> real = {rv_ret(e + iv::Point3(-0.8, 0.0, 0.0), e + iv::Point3(1.0, 0.0, 0.0))};
  std::vector<std::vector<iv::Beam>> scans = {phantoms, phantoms, real};
  for (const auto& w : wall_scans()) scans.push_back(w);
  const Outcome o = run(scans, {});
  CHECK(o.classes[2][0] == iv::BeamClass::Trusted);
  CHECK(count(o.classes[0], iv::BeamClass::Suspect) == phantoms.size());
  CHECK(count(o.classes[1], iv::BeamClass::Suspect) == phantoms.size());
  CHECK(o.stats.to_suspect == 2 * phantoms.size());
  CHECK(o.stats.to_trusted == 1);
  CHECK(o.stats.unsettled == 0);
  // Its arrival class was suspect (what the ledger changed).
  iv::ExplainOptions off;
  off.ledger_bytes = 0;
  CHECK(run(scans, off).classes[2][0] == iv::BeamClass::Suspect);
  // The same final classes if the wall comes first (then the real beam is trusted on arrival).
  std::vector<std::vector<iv::Beam>> wall_first = wall_scans();
  wall_first.insert(wall_first.end(), {phantoms, phantoms, real});
  const Outcome w = run(wall_first, {});
  for (std::size_t s = 0; s < 3; ++s) CHECK(w.classes[w.classes.size() - 3 + s] == o.classes[s]);
  CHECK(w.evidence == o.evidence);
}

TEST_CASE("the ledger keeps the newest scans within its budget and what it forgets keeps its last class",
          "[explain][revision][memory]") {
  const std::vector<std::vector<iv::Beam>> walls = wall_scans();
  std::vector<std::vector<iv::Beam>> phantom_first{phantom_scan()};
  phantom_first.insert(phantom_first.end(), walls.begin(), walls.end());
  // A budget for one wall scan and not two: the phantom scan is forgotten before the wall is
  // supported, and keeps its arrival class (trusted).
  std::size_t largest = 0;
  {
    iv::VoxelGrid<iv::BayesLogOdds> grid(0.05);
    iv::ExplainedSpace space(grid.geometry());
    iv::InsertOptions io;
    io.max_range = 6.0;
    iv::ScanInserter inserter(io);
    for (const auto& w : walls) space.insert_beams(inserter, grid, std::span<const iv::Beam>(w));
    REQUIRE(space.ledger().scans().size() == walls.size());
    std::size_t sum = 0;
    for (std::size_t s = 0; s < walls.size(); ++s) {
      const iv::LedgerScan& kept = space.ledger().scans()[s];
      // Beams, one origin, and the footprints of 136 bytes per block.
      const std::size_t blocks =
          kept.footprint(iv::BeamClass::Trusted).blocks() + kept.footprint(iv::BeamClass::Suspect).blocks();
      CHECK(blocks > 0);
      CHECK(kept.bytes() >= walls[s].size() * (sizeof(iv::Point3) + 1) + 136 * blocks);
      CHECK(kept.bytes() <= walls[s].size() * (sizeof(iv::Point3) + 1) + 136 * blocks + 512);
      largest = std::max(largest, kept.bytes());
      sum += kept.bytes();
    }
    CHECK(space.ledger().bytes() == sum);
  }
  iv::ExplainOptions small;
  small.ledger_bytes = largest + 100;
  const Outcome o = run(phantom_first, small);
  CHECK(o.ledger_bytes <= small.ledger_bytes);
  CHECK(count(o.classes.front(), iv::BeamClass::Trusted) == phantom_first.front().size());
  CHECK(o.stats.to_suspect == 0);

  iv::VoxelGrid<iv::BayesLogOdds> grid(0.05);
  iv::ExplainedSpace space(grid.geometry(), small);
  iv::InsertOptions io;
  io.max_range = 6.0;
  iv::ScanInserter inserter(io);
  for (const auto& s : walls) {
    space.insert_beams(inserter, grid, std::span<const iv::Beam>(s));
    CHECK(space.ledger().bytes() <= small.ledger_bytes);
    CHECK(space.ledger().scans().size() == 1);
  }
  CHECK(space.ledger().forgotten() == walls.size() - 1);
  CHECK(space.memory_bytes() >= space.ledger().bytes());
  // A scan larger than the whole budget is not kept and forgets nothing.
  std::vector<iv::Beam> big;
  for (int i = 0; i < 4; ++i) big.insert(big.end(), walls[0].begin(), walls[0].end());
  space.insert_beams(inserter, grid, std::span<const iv::Beam>(big));
  CHECK(space.ledger().refused() == 1);
  CHECK(space.ledger().scans().size() == 1);
  // A smaller budget forgets at once; clear() empties it.
  iv::ExplainOptions tiny = small;
  tiny.ledger_bytes = 100;
  space.set_options(tiny);
  CHECK(space.ledger().scans().empty());
  space.clear();
  CHECK(space.ledger().scans().empty());
  CHECK(space.ledger().bytes() == 0);
}

TEST_CASE("revision gives the same classes and evidence on any number of threads", "[explain][revision][threaded]") {
  test::ThreadCap cap(4);
  const std::vector<std::vector<iv::Beam>> walls = wall_scans();
  std::vector<std::vector<iv::Beam>> phantom_first{phantom_scan()};
  phantom_first.insert(phantom_first.end(), walls.begin(), walls.end());
  const Outcome one = run(phantom_first, {}, 1);
  const Outcome two = run(phantom_first, {}, 2);
  const Outcome four = run(phantom_first, {}, 4);
  CHECK(one.stats.to_suspect > 0);
  CHECK(one.classes == two.classes);
  CHECK(one.classes == four.classes);
  CHECK(one.evidence == two.evidence);
  CHECK(one.evidence == four.evidence);
}

TEST_CASE("revision runs every revision_interval scans, and at once when asked", "[explain][revision]") {
  std::vector<std::vector<iv::Beam>> phantom_first{phantom_scan()};
  for (const auto& w : wall_scans()) phantom_first.push_back(w);
  // Beams moved to suspect after each scan, revising after every scan (the reference), and every
  // 3 or 100 scans: a revision after the m-th scan reaches what revising after every scan had
  // reached there, and nothing moves in between.
  const auto moved_after = [&](int interval, bool finally) {
    iv::ExplainOptions eo;
    eo.revision_interval = interval;
    iv::VoxelGrid<iv::BayesLogOdds> grid(0.05);
    iv::ExplainedSpace space(grid.geometry(), eo);
    iv::InsertOptions io;
    io.max_range = 6.0;
    iv::ScanInserter inserter(io);
    std::vector<std::uint64_t> out;
    for (const auto& s : phantom_first) {
      space.insert_beams(inserter, grid, std::span<const iv::Beam>(s));
      out.push_back(space.revision_stats().to_suspect);
    }
    if (finally) {
      space.revise();
      out.push_back(space.revision_stats().to_suspect);
    }
    return out;
  };
  const std::vector<std::uint64_t> every = moved_after(1, false);
  CHECK(every.back() == phantom_first.front().size());
  CHECK(every.front() == 0);
  for (const int interval : {3, 100}) {
    CAPTURE(interval);
    const std::vector<std::uint64_t> batched = moved_after(interval, true);
    for (std::size_t n = 1; n <= phantom_first.size(); ++n) {
      const std::size_t m = (n / static_cast<std::size_t>(interval)) * static_cast<std::size_t>(interval);
      CHECK(batched[n - 1] == (m == 0 ? 0u : every[m - 1]));
    }
    CHECK(batched.back() == every.back());
  }
}

TEST_CASE("invalid revision options are refused with the parameter's name", "[explain][revision][errors]") {
  iv::ExplainOptions o;
  o.revision_rounds = 0;
  CHECK_THROWS_WITH(o.validate(), Catch::Contains("revision_rounds"));
  o.revision_rounds = 1;
  o.revision_interval = 0;
  CHECK_THROWS_WITH(o.validate(), Catch::Contains("revision_interval"));
  const std::vector<iv::Beam> two = {rv_ret({0, 0, 0}, {1, 0, 0}), rv_ret({0, 0, 0}, {0, 1, 0})};
  const std::vector<iv::BeamClass> one(1, iv::BeamClass::Trusted);
  CHECK_THROWS_AS(
      iv::LedgerScan(std::span<const iv::Beam>(two), std::span<const iv::BeamClass>(one), iv::InsertOptions{}),
      iv::InvalidArgument);
}
