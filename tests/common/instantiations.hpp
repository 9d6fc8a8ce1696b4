#pragma once
// The test-support library's instantiations (tests/CMakeLists.txt, intervox_test_support): the
// insertion entry points, ray casting and the information gain for every grid type the typed
// tests use, compiled once in tests/common/instantiate_*.cpp instead of in every test file that
// calls them. Included by the suites' precompiled header (pch.hpp), so every test file sees the
// explicit instantiation declarations below; a call with other types (another point range, a
// grid of its own) is instantiated implicitly as usual.
#include "grid_types.hpp"

#include <intervox/grid/named_grids.hpp>
#include <intervox/plan/information_gain.hpp>
#include <intervox/raycast/cast.hpp>
#include <intervox/raycast/insert.hpp>

#include <span>
#include <vector>

namespace test {
using NamedIntervalGrid = intervox::IntervalGrid;
using NamedDenseIntervalGrid = intervox::DenseIntervalGrid;
using NamedDirichletGrid = intervox::DirichletGrid;
using NamedBeliefGrid = intervox::BeliefGrid;
}  // namespace test

// X(G) for every instantiated grid type: the typed tests' list and the named configurations
// the tests use beside it (BayesGrid, DenseBayesGrid and CompactIntervalGrid are in the list).
// (clang-format 14 reflows this list differently on every pass: kept by hand)
// clang-format off
#define INTERVOX_TEST_INSTANTIATED_GRIDS(X)                                                           \
  X(test::BayesSparse) X(test::BayesDense) X(test::BayesBoundedSparse) X(test::LowerSparse)            \
  X(test::MeanDense) X(test::MeanBoundedSparse) X(test::UpperSparse) X(test::UpperDense)               \
  X(test::CompactSparse) X(test::CompactBoundedSparse) X(test::DirichletDense) X(test::BeliefSparse)   \
  X(test::NamedIntervalGrid) X(test::NamedDenseIntervalGrid) X(test::NamedDirichletGrid)               \
  X(test::NamedBeliefGrid)
// clang-format on

// The instantiations of one grid type G; EXTERN is `extern` for the declarations, empty for the
// definitions.
#define INTERVOX_TEST_INSTANTIATIONS(EXTERN, G)                                                                       \
  EXTERN template intervox::InsertStats                                                                               \
  intervox::ScanInserter::insert_point_cloud<G, intervox::Point3, std::vector<intervox::Point3>>(                     \
      G&, const intervox::Point3&, const std::vector<intervox::Point3>&);                                             \
  EXTERN template intervox::InsertStats intervox::ScanInserter::insert_depth_image<G>(                                \
      G&, const intervox::DepthImage&, const intervox::PinholeIntrinsics&, const intervox::Pose&);                    \
  EXTERN template intervox::InsertStats intervox::ScanInserter::insert_depth_image<G>(G&,                             \
                                                                                      const intervox::DepthFrame&);   \
  EXTERN template intervox::InsertStats intervox::ScanInserter::insert_beams<G>(G&, std::span<const intervox::Beam>); \
  EXTERN template intervox::InsertStats intervox::ScanInserter::insert_ray<G, intervox::Point3, intervox::Point3>(    \
      G&, const intervox::Point3&, const intervox::Point3&);                                                          \
  EXTERN template intervox::CastResult intervox::cast_ray<G, intervox::Point3, intervox::Point3>(                     \
      const G&, const intervox::Point3&, const intervox::Point3&, const intervox::CastOptions&);                      \
  EXTERN template intervox::ViewGain intervox::path_gain<G>(                                                          \
      const G&, const intervox::RayBundle&, const std::vector<intervox::Pose>&, const intervox::GainOptions&);        \
  EXTERN template intervox::ViewGain intervox::unknown_path_gain<G>(                                                  \
      const G&, const intervox::RayBundle&, const std::vector<intervox::Pose>&, const intervox::GainOptions&);        \
  EXTERN template std::vector<intervox::ViewGain> intervox::evaluate_paths<G>(                                        \
      const G&, const intervox::RayBundle&, const std::vector<std::vector<intervox::Pose>>&,                          \
      const intervox::GainOptions&, unsigned);                                                                        \
  EXTERN template std::vector<intervox::ViewGain> intervox::evaluate_views<G>(const G&, const intervox::RayBundle&,   \
                                                                              const std::vector<intervox::Pose>&,     \
                                                                              const intervox::GainOptions&, unsigned);

#define INTERVOX_TEST_EXTERN(G) INTERVOX_TEST_INSTANTIATIONS(extern, G)
INTERVOX_TEST_INSTANTIATED_GRIDS(INTERVOX_TEST_EXTERN)
#undef INTERVOX_TEST_EXTERN
