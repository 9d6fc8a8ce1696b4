// Information gain of a view (thesis 3.4, 4.3.2) on hand-built grids.
#include <catch2/catch.hpp>
#include <intervox/intervox.hpp>
#include <intervox/plan/information_gain.hpp>
#include <intervox/plan/view_sampling.hpp>

#include <cmath>
#include <numbers>
#include <type_traits>

namespace iv = intervox;
using Approx = Catch::Detail::Approx;

namespace {
using BayesSparse = iv::VoxelGrid<iv::BayesLogOdds, iv::Entropy, iv::SparseStorage>;
using BayesDense = iv::VoxelGrid<iv::BayesLogOdds, iv::Entropy, iv::DenseStorage>;
using MeanMaxSparse = iv::VoxelGrid<iv::IntervalUpdate<iv::MeanState>, iv::MaxEntropy, iv::SparseStorage>;
using MeanEntropyDense = iv::VoxelGrid<iv::IntervalUpdate<iv::MeanState>, iv::Entropy, iv::DenseStorage>;
using LowerMaxDense = iv::VoxelGrid<iv::IntervalUpdate<iv::LowerState>, iv::MaxEntropy, iv::DenseStorage>;
using UpperEntropySparse = iv::VoxelGrid<iv::IntervalUpdate<iv::UpperState>, iv::Entropy, iv::SparseStorage>;

const iv::Bounds kBox{{-10, -10, -10}, {10, 10, 10}};

template <class Grid>
void observe(Grid& g, const iv::Key& k, iv::Observation o, int times) {
  for (int i = 0; i < times; ++i) g.update(k, o);
}

// A body-frame bundle of one ray along +x from the body origin.
iv::RayBundle ray_x() {
  iv::RayBundle b;
  b.add(iv::Point3::Zero(), iv::Point3::UnitX());
  return b;
}

iv::Pose at(double x, double y, double z) {
  iv::Pose p = iv::Pose::Identity();
  p.translation() = iv::Point3(x, y, z);
  return p;
}
}  // namespace

TEMPLATE_TEST_CASE("the gain of a beam is the hand count of the utilities up to and including the first occupied voxel",
                   "[plan][gain]", BayesSparse, BayesDense, MeanMaxSparse, MeanEntropyDense, LowerMaxDense,
                   UpperEntropySparse) {
  TestType g(1.0, kBox);
  // Voxels along +x from (0.5, 0.5, 0.5): x = 0 unobserved, 1 free, 2 unobserved, 3 occupied, 4 free.
  observe(g, iv::Key{1, 0, 0}, iv::Observation::Miss, 3);
  observe(g, iv::Key{3, 0, 0}, iv::Observation::Hit, 12);
  observe(g, iv::Key{4, 0, 0}, iv::Observation::Miss, 3);
  REQUIRE(g.occupancy(iv::Key{3, 0, 0}) == iv::Occupancy::Occupied);
  iv::GainOptions opt;
  opt.max_range = 8.0;
  const auto r = iv::view_gain(g, ray_x(), at(0.5, 0.5, 0.5), opt);
  double hand = 0;
  for (int x = 0; x <= 3; ++x) hand += g.utility(iv::Key{x, 0, 0});
  CHECK(r.gain == Approx(hand));
  CHECK(r.steps == 4);
  CHECK(r.voxels == 4);
  // An unobserved voxel is worth 1 bit under max-entropy (0.5 lies in the initial interval) and
  // under entropy when its state is 0.5 (not for the upper state, whose prior is 0.95).
  if (g.probability(iv::Key{0, 0, 0}) == 0.5 || std::is_same_v<typename TestType::UtilityType, iv::MaxEntropy>)
    CHECK(g.utility(iv::Key{0, 0, 0}) == Approx(1.0));

  SECTION("max range ends the beam") {
    opt.max_range = 1.2;  // ends in voxel x = 1
    const auto s = iv::view_gain(g, ray_x(), at(0.5, 0.5, 0.5), opt);
    CHECK(s.steps == 2);
    CHECK(s.gain == Approx(g.utility(iv::Key{0, 0, 0}) + g.utility(iv::Key{1, 0, 0})));
  }
  SECTION("bounds clip the beam: voxels outside never count") {
    opt.bounds = iv::Bounds{{-1, -1, -1}, {2.0, 1, 1}};
    const auto s = iv::view_gain(g, ray_x(), at(0.5, 0.5, 0.5), opt);
    CHECK(s.steps == 3);  // x = 0, 1 and the face voxel x = 2 (a point on a face belongs to the voxel above)
    opt.bounds = iv::Bounds{{5, 5, 5}, {6, 6, 6}};
    CHECK(iv::view_gain(g, ray_x(), at(0.5, 0.5, 0.5), opt).steps == 0);
  }
}

TEMPLATE_TEST_CASE(
    "the thesis' gain counts only voxels of unknown state, per beam and per view", "[plan][gain]", BayesSparse,
    MeanMaxSparse, LowerMaxDense,
    (iv::VoxelGrid<iv::ImpreciseDirichletUpdate<iv::MeanState>, iv::TotalUncertainty, iv::DenseStorage>)) {
  TestType g(1.0, kBox);
  // Along +x: x = 0 unobserved, 1 free, 2 observed once (unknown), 3 occupied (stops the beam), 4 unobserved.
  observe(g, iv::Key{1, 0, 0}, iv::Observation::Miss, 40);
  observe(g, iv::Key{2, 0, 0}, iv::Observation::Hit, 1);
  observe(g, iv::Key{3, 0, 0}, iv::Observation::Hit, 40);
  REQUIRE(g.occupancy(iv::Key{1, 0, 0}) == iv::Occupancy::Free);
  REQUIRE(g.occupancy(iv::Key{2, 0, 0}) == iv::Occupancy::Unknown);
  REQUIRE(g.occupancy(iv::Key{3, 0, 0}) == iv::Occupancy::Occupied);
  iv::GainOptions opt;
  opt.max_range = 8.0;
  opt.voxels = iv::GainVoxels::Unknown;
  for (const auto count : {iv::GainCount::PerBeam, iv::GainCount::PerView}) {
    opt.count = count;
    const auto r = iv::view_gain(g, ray_x(), at(0.5, 0.5, 0.5), opt);
    // Brute force: the voxels up to the first occupied one whose state is unknown.
    double hand = 0;
    std::uint64_t counted = 0;
    for (int x = 0; x <= 3; ++x)
      if (g.occupancy(iv::Key{x, 0, 0}) == iv::Occupancy::Unknown) {
        hand += g.utility(iv::Key{x, 0, 0});
        ++counted;
      }
    CHECK(counted == 2);
    CHECK(r.gain == Approx(hand));
    CHECK(r.voxels == counted);
    CHECK(r.steps == 4);  // the traversal is the same; only the sum differs
  }
  opt.voxels = iv::GainVoxels::All;
  opt.count = iv::GainCount::PerBeam;
  CHECK(iv::view_gain(g, ray_x(), at(0.5, 0.5, 0.5), opt).voxels == 4);
}

TEMPLATE_TEST_CASE("counting per view counts a voxel crossed by several beams once", "[plan][gain]", BayesSparse,
                   MeanMaxSparse) {
  TestType g(1.0, kBox);
  iv::RayBundle b;
  b.add(iv::Point3::Zero(), iv::Point3::UnitX());
  b.add(iv::Point3::Zero(), iv::Point3::UnitX());
  b.add(iv::Point3(0, 1, 0), iv::Point3::UnitX());
  iv::GainOptions opt;
  opt.max_range = 2.2;  // three voxels per beam, all unobserved
  opt.count = iv::GainCount::PerBeam;
  const auto per_beam = iv::view_gain(g, b, at(0.5, 0.5, 0.5), opt);
  CHECK(per_beam.gain == Approx(9.0));
  CHECK(per_beam.voxels == 9);
  opt.count = iv::GainCount::PerView;
  const auto per_view = iv::view_gain(g, b, at(0.5, 0.5, 0.5), opt);
  CHECK(per_view.gain == Approx(6.0));
  CHECK(per_view.voxels == 6);
  CHECK(per_view.steps == 9);
}

TEST_CASE("known voxels still carry gain under max-entropy but almost none under entropy", "[plan][gain]") {
  // A voxel hit and missed alike: Bayes settles near 0.5 only if balanced; here 6 misses make it
  // free for both, but the interval of the interval update still straddles 0.5 for a while.
  iv::VoxelGrid<iv::IntervalUpdate<iv::MeanState>, iv::MaxEntropy> max_h(1.0);
  iv::VoxelGrid<iv::IntervalUpdate<iv::MeanState>, iv::Entropy> h(1.0);
  iv::VoxelGrid<iv::BayesLogOdds, iv::Entropy> bayes(1.0);
  for (int i = 0; i < 2; ++i) {
    max_h.update(iv::Key{0, 0, 0}, iv::Observation::Miss);
    h.update(iv::Key{0, 0, 0}, iv::Observation::Miss);
    bayes.update(iv::Key{0, 0, 0}, iv::Observation::Miss);
  }
  REQUIRE(max_h.interval(iv::Key{0, 0, 0}).contains(0.5));
  CHECK(max_h.utility(iv::Key{0, 0, 0}) == Approx(1.0));
  CHECK(h.utility(iv::Key{0, 0, 0}) < 1.0);
  CHECK(bayes.utility(iv::Key{0, 0, 0}) < 0.6);
}

TEMPLATE_TEST_CASE("the planner picks the view that looks into unknown space", "[plan][gain]", BayesSparse, BayesDense,
                   MeanMaxSparse, MeanEntropyDense, LowerMaxDense, UpperEntropySparse) {
  TestType g(0.5, kBox);
  // Half space x < 0 well observed free, x >= 0 unobserved; a wall at y = 4 in both halves.
  for (int z = -2; z <= 2; ++z)
    for (int y = -6; y <= 8; ++y)
      for (int x = -8; x < 0; ++x)
        observe(g, iv::Key{x, y, z}, y == 8 ? iv::Observation::Hit : iv::Observation::Miss, 12);
  iv::RayBundle cam;
  const auto k = iv::PinholeIntrinsics::from_fov(16, 12, 0.6, 0.5);
  iv::Pose mount = iv::Pose::Identity();
  mount.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;  // optical z along body +x, x to body -y, y down
  cam.add_camera(k, mount, 2);
  CHECK(cam.size() == 48);
  iv::GainOptions opt;
  opt.max_range = 3.0;
  // View 0 looks into the known half (-x), view 1 into the unknown half (+x), view 2 again -x.
  const std::vector<iv::Pose> views{iv::planar_pose({-0.2, 0, 0}, std::numbers::pi), iv::planar_pose({-0.2, 0, 0}, 0.0),
                                    iv::planar_pose({-0.2, 0.1, 0}, std::numbers::pi)};
  const auto gains = iv::evaluate_views(g, cam, views, opt, 1);
  REQUIRE(gains.size() == 3);
  CHECK(gains[1].gain > 2 * gains[0].gain);
  CHECK(iv::best_view(gains) == std::optional<std::size_t>(1));

  SECTION("results do not depend on the thread count") {
    std::vector<iv::Pose> many;
    for (int i = 0; i < 23; ++i) many.push_back(iv::planar_pose({-0.2 + 0.05 * i, 0.03 * i, 0}, 0.3 * i));
    const auto one = iv::evaluate_views(g, cam, many, opt, 1);
    for (unsigned t : {2u, 3u, 8u, 0u}) {
      const auto other = iv::evaluate_views(g, cam, many, opt, t);
      REQUIRE(other.size() == one.size());
      for (std::size_t i = 0; i < one.size(); ++i) {
        CHECK(other[i].gain == one[i].gain);
        CHECK(other[i].steps == one[i].steps);
      }
    }
  }
}

TEST_CASE("ties between views go to the lowest index", "[plan][gain]") {
  CHECK_FALSE(iv::best_view({}).has_value());
  std::vector<iv::ViewGain> g(4);
  g[1].gain = 2.0;
  g[3].gain = 2.0;
  CHECK(*iv::best_view(g) == 1);
}

TEST_CASE("bad gain input throws", "[plan][gain]") {
  iv::BayesGrid g(0.1);
  iv::GainOptions opt;
  opt.max_range = 0;
  CHECK_THROWS_AS(iv::view_gain(g, ray_x(), at(0, 0, 0), opt), iv::InvalidArgument);
  opt.max_range = NAN;
  CHECK_THROWS_AS(iv::evaluate_views(g, ray_x(), {at(0, 0, 0)}, opt), iv::InvalidArgument);
  opt.max_range = 1;
  CHECK_THROWS_AS(iv::view_gain(g, ray_x(), at(NAN, 0, 0), opt), iv::InvalidArgument);
  iv::RayBundle b;
  CHECK_THROWS_AS(b.add(iv::Point3::Zero(), iv::Point3::Zero()), iv::InvalidArgument);
  CHECK_THROWS_AS(b.add(iv::Point3(NAN, 0, 0), iv::Point3::UnitX()), iv::InvalidArgument);
  CHECK_THROWS_AS(b.add_camera(iv::PinholeIntrinsics{}, iv::Pose::Identity()), iv::InvalidArgument);
  // An error inside a worker thread reaches the caller.
  std::vector<iv::Pose> poses(5, at(0, 0, 0));
  poses[3] = at(INFINITY, 0, 0);
  opt.max_range = 1;
  CHECK_THROWS_AS(iv::evaluate_views(g, ray_x(), poses, opt, 3), iv::InvalidArgument);
}

TEMPLATE_TEST_CASE("the gain in an unobserved world bounds the gain and equals it on an empty grid", "[plan][gain]",
                   BayesSparse, BayesDense, MeanMaxSparse, MeanEntropyDense) {
  TestType g(0.5, kBox);
  iv::RayBundle cam;
  cam.add_camera(iv::PinholeIntrinsics::from_fov(8, 6, 0.6, 0.5), iv::Pose::Identity(), 1);
  for (const iv::GainCount count : {iv::GainCount::PerBeam, iv::GainCount::PerView}) {
    iv::GainOptions opt;
    opt.max_range = 3.0;
    opt.count = count;
    const std::vector<iv::Pose> path{at(0.1, 0.2, 0.3), at(0.4, 0.2, 0.3)};
    const auto empty = iv::path_gain(g, cam, path, opt);
    const auto unknown = iv::unknown_path_gain(g, cam, path, opt);
    CHECK(unknown.gain == Approx(empty.gain));
    CHECK(unknown.voxels == empty.voxels);
  }
  // A wall in front: the beams stop there, the unobserved world's beams do not.
  for (int y = -8; y <= 8; ++y)
    for (int x = -8; x <= 8; ++x) observe(g, iv::Key{x, y, 3}, iv::Observation::Hit, 12);
  iv::GainOptions opt;
  opt.max_range = 3.0;
  const auto seen = iv::view_gain(g, cam, at(0.1, 0.2, 0.3), opt);
  const auto unknown = iv::unknown_path_gain(g, cam, {at(0.1, 0.2, 0.3)}, opt);
  CHECK(seen.gain < 0.8 * unknown.gain);
  CHECK(seen.gain > 0.0);
}
