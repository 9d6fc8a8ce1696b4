// VoxelGrid change detection: the voxels whose class (unobserved, free, occupied, unknown) an
// update changed, against a brute-force diff of every voxel before and after each insertion, on
// every policy and storage, any thread count and every insertion path.
#include "../common/grid_types.hpp"

#include <catch2/catch.hpp>
#include <intervox/grid/named_grids.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/raycast/insert.hpp>
#include <intervox/raycast/projective.hpp>

#include <Eigen/Geometry>
#include <map>
#include <random>
#include <set>
#include <vector>

namespace iv = intervox;

namespace {

const iv::Bounds kChangeBounds{{-3.0, -3.0, -1.0}, {3.0, 3.0, 2.0}};

// The class code of every voxel of the bounds' key box (-1 unobserved).
template <class G>
std::map<iv::Key, int> classes_of(const G& g) {
  std::map<iv::Key, int> out;
  g.for_each_observed([&](const iv::Key& k, const typename G::Cell& c) { out[k] = g.class_code(c); });
  return out;
}

// The keys whose class differs between two snapshots (a key missing from one is unobserved there).
std::set<iv::Key> diff(const std::map<iv::Key, int>& a, const std::map<iv::Key, int>& b) {
  std::set<iv::Key> out;
  for (const auto& [k, c] : b) {
    const auto it = a.find(k);
    if (it == a.end() || it->second != c) out.insert(k);
  }
  for (const auto& [k, c] : a)
    if (!b.contains(k)) out.insert(k);
  return out;
}

std::vector<iv::Point3> change_cloud(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-2.5, 2.5), z(-0.5, 1.5);
  std::vector<iv::Point3> pts(600);
  for (auto& p : pts) p = iv::Point3(u(rng), u(rng), z(rng));
  return pts;
}

// A sequence of scans (point clouds, single updates, a depth frame by projection), each followed
// by a check of the recorded set against the brute-force diff; returns the recorded keys.
template <class G>
std::vector<iv::Key> run_changes(unsigned threads) {
  test::ThreadCap cap(threads);
  G g = test::make_grid_for<G>(0.1, kChangeBounds);
  g.enable_change_detection();
  std::set<iv::Key> want;
  iv::ScanInserter ins({.max_range = 3.0, .threads = threads});
  auto check = [&](auto&& step) {
    const auto before = classes_of(g);
    step();
    for (const auto& k : diff(before, classes_of(g))) want.insert(k);
    const std::vector<iv::Key> got = g.changed_keys();
    REQUIRE(std::set<iv::Key>(got.begin(), got.end()) == want);
    REQUIRE(got.size() == want.size());  // each key once
    REQUIRE(g.changed_count() == want.size());
  };
  for (std::uint64_t s = 1; s <= 6; ++s)
    check([&] { ins.insert_point_cloud(g, iv::Point3(0.05, 0.1, 0.2), change_cloud(s)); });
  check([&] {
    for (int i = 0; i < 5; ++i) g.update(iv::Key{3, 4, 5}, iv::Observation::Hit);  // turns occupied on the way
    g.update(iv::Key{-4, 2, 0}, iv::Observation::Miss);
  });
  check([&] {
    iv::DepthFrame f;
    f.intrinsics = iv::PinholeIntrinsics::from_fov(32, 24, 1.0, 0.8);
    f.image = iv::DepthImage(32, 24);
    for (auto& d : f.image.depth) d = 1.7f;
    f.pose = iv::Pose::Identity();
    f.pose.rotate(Eigen::AngleAxisd(1.2, iv::Point3(1, 0, 0)));
    f.max_range = 3.0;
    iv::ProjectiveInserter({.threads = threads}).insert_depth_image(g, f);
  });
  REQUIRE(want.size() > 500);
  return g.changed_keys();
}

}  // namespace

TEMPLATE_TEST_CASE("change detection records exactly the voxels whose class an update changed",
                   "[grid][changes][typed]", INTERVOX_TEST_GRIDS) {
  const std::vector<iv::Key> one = run_changes<TestType>(1);
  // The same keys in the same order for any thread count.
  for (const unsigned t : {2u, 3u}) {
    CAPTURE(t);
    REQUIRE(run_changes<TestType>(t) == one);
  }
}

TEST_CASE("change detection is off by default, keeps its record when stopped and forgets it on reset",
          "[grid][changes]") {
  iv::BayesGrid g(0.1);
  g.update(iv::Key{0, 0, 0}, iv::Observation::Hit);
  CHECK_FALSE(g.change_detection_enabled());
  CHECK(g.changed_count() == 0);
  g.enable_change_detection();
  CHECK(g.change_detection_enabled());
  g.update(iv::Key{0, 0, 0}, iv::Observation::Hit);  // unknown after one hit and after two: no change
  CHECK(g.changed_count() == 0);
  g.update(iv::Key{1, 0, 0}, iv::Observation::Miss);  // newly observed
  g.update(iv::Key{-9, 7, 3}, iv::Observation::Hit);
  CHECK(g.changed_keys() == std::vector<iv::Key>{{1, 0, 0}, {-9, 7, 3}});
  const iv::BayesGrid copy = g;  // a copy carries the record
  CHECK(copy.changed_count() == 2);
  g.enable_change_detection(false);
  g.update(iv::Key{2, 0, 0}, iv::Observation::Miss);  // not recorded
  CHECK(g.changed_count() == 2);
  g.reset_change_detection();
  CHECK(g.changed_count() == 0);
  CHECK(g.changed_keys().empty());
  CHECK(copy.changed_count() == 2);
  // Many updates of one voxel that flips between free and occupied are one key.
  g.enable_change_detection();
  for (int i = 0; i < 20; ++i) g.update(iv::Key{5, 5, 5}, i % 4 < 2 ? iv::Observation::Hit : iv::Observation::Miss);
  CHECK(g.changed_keys() == std::vector<iv::Key>{{5, 5, 5}});
}

TEST_CASE("a change set holds each added key once, by block, against a std::set", "[grid][changes]") {
  iv::ChangeSet c;
  std::set<iv::Key> ref;
  std::mt19937_64 rng(9);
  std::uniform_int_distribution<int> d(-70, 70);
  for (int i = 0; i < 50000; ++i) {
    const iv::Key k{d(rng), d(rng), d(rng) / 8};
    c.add(k);
    ref.insert(k);
  }
  const std::vector<iv::Key> keys = c.keys();
  CHECK(c.size() == ref.size());
  CHECK(keys.size() == ref.size());
  CHECK(std::set<iv::Key>(keys.begin(), keys.end()) == ref);
  for (const iv::Key& k : ref) REQUIRE(c.contains(k));
  CHECK_FALSE(c.contains(iv::Key{500, 0, 0}));
  CHECK_FALSE(c.contains(iv::Key{-71, 0, 0}));
  c.clear();
  CHECK(c.empty());
  CHECK(c.keys().empty());
  CHECK_FALSE(c.contains(*ref.begin()));
}
