// The oracle: the same seeded scans into a BayesLogOdds grid with OctoMap's parameters and into
// an octomap::OcTree must give the same log-odds and the same class for every voxel either one
// touched.
#include "reference.hpp"

#include <catch2/catch.hpp>
#include <intervox/grid/coarse_summary.hpp>
#include <intervox/grid/named_grids.hpp>
#include <octomap/octomap.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <map>
#include <random>
#include <set>
#include <utility>

namespace iv = intervox;

namespace {
struct Scan {
  iv::Point3 origin;
  std::vector<Eigen::Vector3f> points;
};

std::vector<Scan> random_scans(std::uint64_t seed, int scans, int points) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> o(-0.5f, 0.5f);
  std::normal_distribution<float> g(0.0f, 1.0f);
  std::uniform_real_distribution<float> r(0.02f, 5.0f);
  std::vector<Scan> out;
  for (int s = 0; s < scans; ++s) {
    Scan sc;
    const Eigen::Vector3f origin(o(rng), o(rng), o(rng));
    sc.origin = origin.cast<double>();  // float-exact, as OctoMap's point3d
    for (int i = 0; i < points; ++i) {
      Eigen::Vector3f d(g(rng), g(rng), 0.5f * g(rng));
      sc.points.push_back(origin + d.normalized() * r(rng));
    }
    out.push_back(std::move(sc));
  }
  return out;
}

/// True if some ray decides about voxel k only within a skin of width eps around its faces:
/// the segment grazes the voxel (touches it, but not its core), or the segment's end lies on
/// the voxel's skin. There the float arithmetic of OctoMap and the double arithmetic of
/// Intervox may legitimately disagree (a measure-zero tie in exact arithmetic).
bool numerical_tie(const iv::GridGeometry& g, const std::vector<std::pair<iv::Point3, iv::Point3>>& rays,
                   const iv::Key& k) {
  const double eps = 1e-4 * g.resolution();
  const iv::Point3 lo = g.corner(k), hi = lo + iv::Point3::Constant(g.resolution());
  const iv::Point3 e = iv::Point3::Constant(eps);
  for (const auto& [a, b] : rays) {
    const bool touches = rt::length_in_box(a, b, lo - e, hi + e) > 0.0;
    if (!touches) continue;
    const bool core = rt::length_in_box(a, b, lo + e, hi - e) > 0.0;
    const bool end_on_skin = ((b.array() >= (lo - e).array()).all() && (b.array() <= (hi + e).array()).all()) &&
                             !((b.array() > (lo + e).array()).all() && (b.array() < (hi - e).array()).all());
    if (!core || end_on_skin) return true;
  }
  return false;
}

template <class Grid>
void compare_with_octomap(double max_range, int threads) {
  const double res = 0.05;
  Grid grid(res, iv::BayesLogOdds::octomap());
  octomap::OcTree tree(res);
  iv::ScanInserter ins({.max_range = max_range, .min_range = 0.0, .threads = static_cast<unsigned>(threads)});
  std::vector<std::pair<iv::Point3, iv::Point3>> rays;
  for (const auto& scan : random_scans(2024, 12, 1500)) {
    octomap::Pointcloud cloud;
    for (const auto& p : scan.points) {
      cloud.push_back(p.x(), p.y(), p.z());
      const iv::Point3 q = p.cast<double>();
      const double len = (q - scan.origin).norm();
      rays.emplace_back(scan.origin, max_range >= 0 && len > max_range
                                         ? iv::Point3(scan.origin + (q - scan.origin) * (max_range / len))
                                         : q);
    }
    const octomap::point3d o(float(scan.origin.x()), float(scan.origin.y()), float(scan.origin.z()));
    tree.insertPointCloud(cloud, o, max_range);
    ins.insert_point_cloud(grid, scan.origin, scan.points);
  }
  // OctoMap keys are ours + 32768 (origin 0, 16-bit keys); expand pruned nodes to voxels.
  tree.expand();
  std::map<iv::Key, float> octo;
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    REQUIRE(it.getDepth() == tree.getTreeDepth());
    const octomap::OcTreeKey k = it.getKey();
    octo[iv::Key{int(k[0]) - 32768, int(k[1]) - 32768, int(k[2]) - 32768}] = it->getLogOdds();
  }
  const auto& policy = grid.update_policy();
  const float threshold = tree.getOccupancyThresLog();
  std::set<iv::Key> differ;
  std::size_t ours = 0, agree = 0;
  grid.for_each_observed([&](const iv::Key& k, float c) {
    ++ours;
    auto it = octo.find(k);
    if (it == octo.end()) {
      differ.insert(k);
      return;
    }
    const bool same_value = std::abs(policy.log_odds(c) - it->second) <= 1e-5f;
    const bool octo_occupied = it->second >= threshold;  // OctoMap: occupied at or above
    const bool same_class = (policy.occupancy(c) == iv::Occupancy::Occupied) == octo_occupied;
    if (same_value && same_class)
      ++agree;
    else
      differ.insert(k);
  });
  for (const auto& [k, v] : octo)
    if (!grid.is_observed(k)) differ.insert(k);
  std::size_t unexplained = 0;
  for (const auto& k : differ) {
    if (numerical_tie(grid.geometry(), rays, k)) continue;
    ++unexplained;
    WARN("voxel " << k.x << " " << k.y << " " << k.z << " differs: ours " << policy.log_odds(grid.cell(k)));
  }
  CHECK(ours > 100000);
  CHECK(agree + 10 >= octo.size());  // all but a handful of grazed voxels agree exactly
  CHECK(differ.size() <= 10);
  CHECK(unexplained == 0);
}
}  // namespace

TEST_CASE("ray insertion equals OctoMap's insertPointCloud voxel by voxel", "[raycast][oracle]") {
  SECTION("with a max range, sparse, one thread") { compare_with_octomap<iv::BayesGrid>(3.0, 1); }
  SECTION("without a max range, sparse, two threads") { compare_with_octomap<iv::BayesGrid>(-1.0, 2); }
}

TEST_CASE("a dense Bayes grid equals OctoMap too", "[raycast][oracle]") {
  const double res = 0.05;
  iv::DenseBayesGrid grid(res, rt::kBounds, iv::BayesLogOdds::octomap());
  iv::BayesGrid sparse(res, iv::BayesLogOdds::octomap());
  iv::ScanInserter ins({.max_range = 2.4});
  for (const auto& scan : random_scans(99, 4, 1500)) {
    ins.insert_point_cloud(grid, scan.origin, scan.points);
    ins.insert_point_cloud(sparse, scan.origin, scan.points);
  }
  std::size_t n = 0;
  sparse.for_each_observed([&](const iv::Key& k, float c) {
    ++n;
    REQUIRE(rt::same_cell(grid.cell(k), c));
  });
  CHECK(n == grid.observed_count());
}

TEST_CASE("change detection records the voxels OctoMap's changedKeys records, scan by scan",
          "[raycast][oracle][changes]") {
  const double res = 0.05, max_range = 3.0;
  iv::BayesGrid grid(res, iv::BayesLogOdds::octomap());
  octomap::OcTree tree(res);
  grid.enable_change_detection();
  tree.enableChangeDetection(true);
  iv::ScanInserter ins({.max_range = max_range, .threads = 2});
  std::size_t compared = 0, differ = 0;
  for (const auto& scan : random_scans(77, 6, 1500)) {
    octomap::Pointcloud cloud;
    std::vector<std::pair<iv::Point3, iv::Point3>> rays;  // this scan's rays, cut at max range
    for (const auto& p : scan.points) {
      cloud.push_back(p.x(), p.y(), p.z());
      const iv::Point3 q = p.cast<double>();
      const double len = (q - scan.origin).norm();
      rays.emplace_back(scan.origin,
                        len > max_range ? iv::Point3(scan.origin + (q - scan.origin) * (max_range / len)) : q);
    }
    tree.insertPointCloud(
        cloud, octomap::point3d(float(scan.origin.x()), float(scan.origin.y()), float(scan.origin.z())), max_range);
    ins.insert_point_cloud(grid, scan.origin, scan.points);
    std::set<iv::Key> octo;
    for (auto it = tree.changedKeysBegin(); it != tree.changedKeysEnd(); ++it)
      octo.insert(iv::Key{int(it->first[0]) - 32768, int(it->first[1]) - 32768, int(it->first[2]) - 32768});
    const std::vector<iv::Key> ours = grid.changed_keys();
    const std::set<iv::Key> mine(ours.begin(), ours.end());
    REQUIRE(mine.size() == ours.size());
    std::vector<iv::Key> only;
    std::set_symmetric_difference(mine.begin(), mine.end(), octo.begin(), octo.end(), std::back_inserter(only));
    for (const iv::Key& k : only) {
      INFO("voxel " << k.x << " " << k.y << " " << k.z << (mine.contains(k) ? " only ours" : " only OctoMap's"));
      REQUIRE(numerical_tie(grid.geometry(), rays, k));  // a float-vs-double tie, as in the value oracle
    }
    compared += octo.size();
    differ += only.size();
    grid.reset_change_detection();
    tree.resetChangeDetection();
  }
  CHECK(compared > 50000);
  CHECK(differ <= 10);
}

TEST_CASE("coarse summaries equal OctoMap's inner nodes at every depth", "[raycast][oracle][coarse]") {
  const double res = 0.05, max_range = 3.0;
  iv::BayesGrid grid(res, iv::BayesLogOdds::octomap());
  octomap::OcTree tree(res);
  iv::ScanInserter ins({.max_range = max_range});
  for (const auto& scan : random_scans(31, 3, 1500)) {
    octomap::Pointcloud cloud;
    for (const auto& p : scan.points) cloud.push_back(p.x(), p.y(), p.z());
    tree.insertPointCloud(cloud,
                          octomap::point3d(float(scan.origin.x()), float(scan.origin.y()), float(scan.origin.z())),
                          max_range);  // not lazy: OctoMap keeps every inner node at its children's maximum
    ins.insert_point_cloud(grid, scan.origin, scan.points);
  }
  const auto& policy = grid.update_policy();
  // The voxels whose leaves differ (float-vs-double ties on voxel edges, a handful, as above): the
  // cubes holding one are not compared.
  std::set<iv::Key> differ;
  octomap::OcTree expanded(tree);
  expanded.expand();
  for (auto it = expanded.begin_leafs(), end = expanded.end_leafs(); it != end; ++it) {
    const iv::Key k{int(it.getKey()[0]) - 32768, int(it.getKey()[1]) - 32768, int(it.getKey()[2]) - 32768};
    if (!grid.is_observed(k) || std::abs(policy.log_odds(grid.cell(k)) - it->getLogOdds()) > 1e-5f) differ.insert(k);
  }
  grid.for_each_observed([&](const iv::Key& k, float) {
    if (!expanded.search(octomap::OcTreeKey(k.x + 32768, k.y + 32768, k.z + 32768))) differ.insert(k);
  });
  CHECK(differ.size() <= 10);
  const iv::CoarseSummary<iv::BayesGrid> cs(grid);
  std::vector<iv::Key> observed;
  grid.for_each_observed([&](const iv::Key& k, float) { observed.push_back(k); });
  std::mt19937_64 rng(4);
  std::uniform_int_distribution<std::size_t> pick(0, observed.size() - 1);
  std::uniform_int_distribution<int> any(-80, 80);
  std::size_t compared = 0, inner = 0;
  for (int level = 0; level <= 15; ++level) {  // OctoMap's depth 16 - level (its depth 0 means the full depth)
    for (int i = 0; i < 600; ++i) {
      const iv::Key k = i % 4 ? observed[pick(rng)] : iv::Key{any(rng), any(rng), any(rng)};
      const iv::KeyBox cube = iv::CoarseSummary<iv::BayesGrid>::cube(k, level);
      if (std::any_of(differ.begin(), differ.end(), [&](const iv::Key& d) { return cube.contains(d); })) continue;
      const octomap::OcTreeNode* node =
          tree.search(octomap::OcTreeKey(k.x + 32768, k.y + 32768, k.z + 32768), 16 - level);
      const iv::CubeSummary s = cs.summary(k, level);
      CAPTURE(level, k.x, k.y, k.z);
      REQUIRE(s.any_observed() == (node != nullptr));
      if (!node) continue;
      // The inner node's log-odds is its children's maximum; occupied iff any voxel below is.
      REQUIRE(std::abs(std::log(s.max_probability / (1.0 - s.max_probability)) - node->getLogOdds()) < 1e-4);
      REQUIRE(s.any_occupied() == tree.isNodeOccupied(node));
      ++compared;
      inner += level > 0;
    }
  }
  CHECK(compared > 5000);
  CHECK(inner > 4000);
}
