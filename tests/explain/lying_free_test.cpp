// ExplainedSpace::free_only_by_lying_beams(): the voxels that only beams which lie made free
// (what the explained mobile planner keeps its radius from), on hand-classed beams along one line
// of voxels, against the model's own state of the pooled counts (no simulator).
#include <intervox/explain/explain.hpp>

#include <catch2/catch.hpp>

#include <vector>

namespace iv = intervox;

namespace lying_free_test {
/// One beam along +x through voxel centres (0.1 m voxels), from x = 0.05 to x = 1.05.
iv::Beam along(bool hit) { return {{0.05, 0.05, 0.05}, {1.05, 0.05, 0.05}, hit}; }

void add(iv::ExplainedSpace& s, const iv::Beam& b, iv::BeamClass c) {
  iv::InsertOptions insert;
  insert.max_range = 1.0;
  const std::vector<iv::Beam> beams{b};
  const std::vector<iv::BeamClass> classes{c};
  s.add(beams, classes, insert);
}

/// The rule written out: min_lying_misses suspect misses or more, unexplained, and free with
/// every count trusted.
bool oracle(const iv::ExplainedSpace& s, const iv::Key& k) {
  const iv::EvidenceCell c = s.evidence(k);
  if (c.suspect_misses < s.options().min_lying_misses) return false;
  if (s.options().model.state(c) != iv::ExplainedState::Unexplained) return false;
  iv::EvidenceCell pooled;
  pooled.trusted_hits = static_cast<std::uint16_t>(c.trusted_hits + c.suspect_hits);
  pooled.trusted_misses = static_cast<std::uint16_t>(c.trusted_misses + c.suspect_misses + c.no_return_misses);
  return s.options().model.state(pooled) == iv::ExplainedState::Free;
}
}  // namespace lying_free_test

TEST_CASE("space that suspect beams crossed is free only by lying beams, until a trusted beam explains it",
          "[explain][lying-free]") {
  iv::ExplainOptions o;
  o.ledger_bytes = 0;  // classes as given
  iv::ExplainedSpace s(iv::GridGeometry(0.1), o);
  const iv::Key mid{5, 0, 0};
  CHECK_FALSE(s.free_only_by_lying_beams(mid));  // no evidence
  // Beams without a return that met no supported surface: beyond what was seen, not lied about.
  lying_free_test::add(s, lying_free_test::along(false), iv::BeamClass::NoReturn);
  CHECK(s.state(mid) == iv::ExplainedState::Unexplained);
  CHECK_FALSE(s.free_only_by_lying_beams(mid));
  CHECK(s.free_only_by_lying_beams(mid) == lying_free_test::oracle(s, mid));
  lying_free_test::add(s, lying_free_test::along(true), iv::BeamClass::Suspect);
  CHECK(s.state(mid) == iv::ExplainedState::Unexplained);
  CHECK(s.free_only_by_lying_beams(mid));
  CHECK(s.free_only_by_lying_beams(mid) == lying_free_test::oracle(s, mid));
  // The end voxel got the suspect hit and, pooled, is no free space: not carved.
  const iv::Key end{10, 0, 0};
  CHECK(s.evidence(end).suspect_hits == 1);
  CHECK(s.free_only_by_lying_beams(end) == lying_free_test::oracle(s, end));
  // A trusted beam along the line explains the space: no longer.
  lying_free_test::add(s, lying_free_test::along(true), iv::BeamClass::Trusted);
  CHECK(s.state(mid) == iv::ExplainedState::Free);
  CHECK_FALSE(s.free_only_by_lying_beams(mid));
}

TEST_CASE("a voxel whose trusted evidence merely conflicts is not free only by lying beams", "[explain][lying-free]") {
  iv::ExplainOptions o;
  o.ledger_bytes = 0;
  iv::ExplainedSpace s(iv::GridGeometry(0.1), o);
  // Voxel 9 (x in [0.9, 1.0)): trusted hits from beams ending there, trusted misses from beams
  // passing it, and no lying evidence.
  for (int i = 0; i < 2; ++i) {
    lying_free_test::add(s, {{0.05, 0.05, 0.05}, {0.95, 0.05, 0.05}, true}, iv::BeamClass::Trusted);
    lying_free_test::add(s, lying_free_test::along(true), iv::BeamClass::Trusted);
  }
  const iv::Key k{9, 0, 0};
  CHECK(s.evidence(k).trusted_hits == 2);
  CHECK(s.evidence(k).trusted_misses == 2);
  CHECK_FALSE(s.free_only_by_lying_beams(k));
  // Suspect misses on top: the answer is the rule's on the pooled counts, whatever the state.
  for (int i = 0; i < 3; ++i) lying_free_test::add(s, lying_free_test::along(true), iv::BeamClass::Suspect);
  CHECK(s.free_only_by_lying_beams(k) == lying_free_test::oracle(s, k));
  for (std::int32_t x = 0; x <= 10; ++x)
    CHECK(s.free_only_by_lying_beams({x, 0, 0}) == lying_free_test::oracle(s, {x, 0, 0}));
}

TEST_CASE("min_lying_misses sets how many suspect misses make a voxel lying, and is validated",
          "[explain][lying-free]") {
  for (const int n : {1, 2, 3}) {
    iv::ExplainOptions o;
    o.ledger_bytes = 0;
    o.min_lying_misses = n;
    iv::ExplainedSpace s(iv::GridGeometry(0.1), o);
    lying_free_test::add(s, lying_free_test::along(false), iv::BeamClass::NoReturn);
    const iv::Key mid{5, 0, 0};
    for (int i = 1; i <= 3; ++i) {
      lying_free_test::add(s, lying_free_test::along(true), iv::BeamClass::Suspect);
      CHECK(s.free_only_by_lying_beams(mid) == (i >= n));
      CHECK(s.free_only_by_lying_beams(mid) == lying_free_test::oracle(s, mid));
    }
  }
  iv::ExplainOptions bad;
  bad.min_lying_misses = 0;
  CHECK_THROWS_WITH(bad.validate(), Catch::Contains("min_lying_misses"));
  bad.min_lying_misses = 65536;
  CHECK_THROWS_WITH(bad.validate(), Catch::Contains("min_lying_misses"));
}
