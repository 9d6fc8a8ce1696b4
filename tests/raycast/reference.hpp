#pragma once
// Shared helpers of the raycast tests: grid configurations and a slow, obviously correct
// reference insertion (std::set de-duplication over traverse()).
#include <intervox/raycast/raycast.hpp>

#include "../common/grid_types.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cstring>
#include <utility>
#include <map>
#include <random>
#include <set>
#include <vector>

namespace rt {
namespace iv = intervox;
// The typed tests' grid types (tests/common/grid_types.hpp), by their short names.
using test::BayesBoundedSparse;
using test::BayesDense;
using test::BayesSparse;
using test::BeliefSparse;
using test::CompactBoundedSparse;
using test::CompactSparse;
using test::DirichletDense;
using test::LowerSparse;
using test::MeanBoundedSparse;
using test::MeanDense;
using test::UpperDense;
using test::UpperSparse;

/// Bounds used for dense grids: a 6 m cube around the origin.
inline const iv::Bounds kBounds{{-3.0, -3.0, -3.0}, {3.0, 3.0, 3.0}};

/// A grid of type Grid at \p resolution, bounded by kBounds if dense or bounded sparse.
template <class Grid>
Grid make_grid(double resolution) {
  return test::make_grid_for<Grid>(resolution, kBounds);
}

/// \p n seeded points around \p origin at distances in [0.05, radius), directions flattened in z
/// by \p z_scale (a room-like scan).
inline std::vector<iv::Point3> random_scan(std::mt19937_64& rng, const iv::Point3& origin, int n, double radius,
                                           double z_scale = 0.3) {
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> r(0.05, radius);
  std::vector<iv::Point3> pts;
  for (int i = 0; i < n; ++i) {
    iv::Point3 d(gauss(rng), gauss(rng), z_scale * gauss(rng));
    pts.push_back(origin + d.normalized() * r(rng));
  }
  return pts;
}

/// Every observed voxel of a grid with its cell, in iteration (block allocation) order.
template <class Grid>
std::vector<std::pair<iv::Key, typename Grid::Cell>> cells_of(const Grid& g) {
  std::vector<std::pair<iv::Key, typename Grid::Cell>> c;
  g.for_each_observed([&](const iv::Key& k, const auto& v) { c.emplace_back(k, v); });
  return c;
}

/// The reference: per scan, the set of miss keys minus the set of hit keys gets a miss, the hit
/// keys a hit, each once; rays follow OctoMap's rules (origin voxel in, end voxel out, cut at
/// max range without a hit).
template <class Grid>
struct ReferenceMap {
  std::map<iv::Key, typename Grid::Cell> cells;

  void insert(const Grid& g, const iv::Point3& origin, const std::vector<iv::Point3>& points, double max_range) {
    std::set<iv::Key> miss, hit;
    for (const auto& p : points) {
      iv::Point3 end = p;
      bool is_hit = true;
      const double len = (p - origin).norm();
      if (max_range >= 0 && len > max_range) {
        end = origin + (p - origin) * (max_range / len);
        is_hit = false;
      }
      const iv::Key ke = g.geometry().key(end);
      iv::traverse(g.geometry(), origin, end, [&](const iv::Key& k) {
        if (k != ke) miss.insert(k);
        return true;
      });
      if (is_hit) hit.insert(ke);
    }
    const auto& u = g.update_policy();
    for (const auto& k : miss) {
      if (hit.count(k) || !g.contains(k)) continue;
      auto it = cells.emplace(k, u.unobserved()).first;
      u.update(it->second, iv::Observation::Miss);
    }
    for (const auto& k : hit) {
      if (!g.contains(k)) continue;
      auto it = cells.emplace(k, u.unobserved()).first;
      u.update(it->second, iv::Observation::Hit);
    }
  }
};

template <class Cell>
bool same_cell(const Cell& a, const Cell& b) {
  return std::memcmp(&a, &b, sizeof(Cell)) == 0;
}

/// Requires every observed voxel of \p g to equal the reference, and the reference to hold no more.
template <class Grid>
void require_equal(const Grid& g, const ReferenceMap<Grid>& ref) {
  std::size_t n = 0;
  g.for_each_observed([&](const iv::Key& k, const typename Grid::Cell& c) {
    ++n;
    auto it = ref.cells.find(k);
    REQUIRE(it != ref.cells.end());
    INFO("key " << k.x << " " << k.y << " " << k.z);
    REQUIRE(same_cell(c, it->second));
  });
  REQUIRE(n == ref.cells.size());
}

/// Length of segment a-b inside the box [lo, hi] (slab clipping): the brute-force geometry the
/// traversal and oracle tests check voxels against.
inline double length_in_box(const iv::Point3& a, const iv::Point3& b, const iv::Point3& lo, const iv::Point3& hi) {
  double t0 = 0.0, t1 = 1.0;
  const iv::Point3 d = b - a;
  for (int i = 0; i < 3; ++i) {
    if (d[i] == 0.0) {
      if (a[i] < lo[i] || a[i] > hi[i]) return 0.0;
      continue;
    }
    double ta = (lo[i] - a[i]) / d[i], tb = (hi[i] - a[i]) / d[i];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  return t1 > t0 ? (t1 - t0) * d.norm() : 0.0;
}

}  // namespace rt
