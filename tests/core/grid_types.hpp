#pragma once
// The grid configurations every typed core test runs over: each update policy x each storage
// (the compact interval policy with one state rule per storage). make_grid() constructs every
// grid with bounds, so the sparse configurations here are bounded sparse grids.
#include <intervox/grid/voxel_grid.hpp>

namespace test {
namespace iv = intervox;
using BayesSparse = iv::VoxelGrid<iv::BayesLogOdds, iv::Entropy, iv::SparseStorage>;
using BayesDense = iv::VoxelGrid<iv::BayesLogOdds, iv::Entropy, iv::DenseStorage>;
using LowerSparse = iv::VoxelGrid<iv::IntervalUpdate<iv::LowerState>, iv::MaxEntropy, iv::SparseStorage>;
using LowerDense = iv::VoxelGrid<iv::IntervalUpdate<iv::LowerState>, iv::MaxEntropy, iv::DenseStorage>;
using MeanSparse = iv::VoxelGrid<iv::IntervalUpdate<iv::MeanState>, iv::MaxEntropy, iv::SparseStorage>;
using MeanDense = iv::VoxelGrid<iv::IntervalUpdate<iv::MeanState>, iv::Entropy, iv::DenseStorage>;
using UpperSparse = iv::VoxelGrid<iv::IntervalUpdate<iv::UpperState>, iv::Entropy, iv::SparseStorage>;
using UpperDense = iv::VoxelGrid<iv::IntervalUpdate<iv::UpperState>, iv::MaxEntropy, iv::DenseStorage>;
using CompactMeanSparse = iv::VoxelGrid<iv::CompactIntervalUpdate<iv::MeanState>, iv::MaxEntropy, iv::SparseStorage>;
using CompactLowerDense = iv::VoxelGrid<iv::CompactIntervalUpdate<iv::LowerState>, iv::Entropy, iv::DenseStorage>;
using DirichletMeanSparse = iv::VoxelGrid<iv::ImpreciseDirichletUpdate<iv::MeanState>, iv::TotalUncertainty, iv::SparseStorage>;
using BeliefUpperDense = iv::VoxelGrid<iv::DempsterShaferUpdate<iv::UpperState>, iv::MaxEntropy, iv::DenseStorage>;

/// A 2 m cube from (-1,-1,-1) at 0.1 m: 20^3 voxels, the same for both storages.
inline const iv::Bounds kTestBounds{{-1.0, -1.0, -1.0}, {1.0, 1.0, 1.0}};

template <class Grid>
Grid make_grid(double resolution = 0.1) {
  return Grid(resolution, kTestBounds);
}
}  // namespace test

#define INTERVOX_ALL_GRIDS                                                                   \
  test::BayesSparse, test::BayesDense, test::LowerSparse, test::LowerDense, test::MeanSparse, \
      test::MeanDense, test::UpperSparse, test::UpperDense, test::CompactMeanSparse, test::CompactLowerDense,    \
      test::DirichletMeanSparse, test::BeliefUpperDense
