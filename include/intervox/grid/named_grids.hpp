#pragma once
/// \file
/// The common VoxelGrid configurations, named (as OpenVDB names FloatGrid): BayesGrid,
/// DenseBayesGrid, IntervalGrid, DenseIntervalGrid, CompactIntervalGrid, DirichletGrid and
/// BeliefGrid.
///
/// This header includes every update policy. A program that uses one policy includes
/// `<intervox/grid/voxel_grid.hpp>` and that policy's header instead and names the grid by its
/// parameters (BayesGrid is `VoxelGrid<BayesLogOdds>`, the defaults being Entropy and
/// SparseStorage).
///
/// Thread safety: type names only.

#include <intervox/grid/dense_storage.hpp>
#include <intervox/grid/sparse_storage.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/update/bayes_log_odds.hpp>
#include <intervox/update/dempster_shafer.hpp>
#include <intervox/update/imprecise_dirichlet.hpp>
#include <intervox/update/interval_update.hpp>
#include <intervox/utility/utility_policies.hpp>

namespace intervox {

/// Bayesian log-odds (OctoMap's update) with entropy as utility, sparse storage.
using BayesGrid = VoxelGrid<BayesLogOdds, Entropy, SparseStorage>;
/// BayesGrid over a flat array within bounds given at construction.
using DenseBayesGrid = VoxelGrid<BayesLogOdds, Entropy, DenseStorage>;
/// Probability intervals (IntervalUpdate, mean state) with the maximum entropy as utility.
using IntervalGrid = VoxelGrid<IntervalUpdate<MeanState>, MaxEntropy, SparseStorage>;
/// IntervalGrid over a flat array within bounds given at construction.
using DenseIntervalGrid = VoxelGrid<IntervalUpdate<MeanState>, MaxEntropy, DenseStorage>;
/// IntervalGrid with 16-bit bounds: 4 bytes per voxel (CompactIntervalUpdate).
using CompactIntervalGrid = VoxelGrid<CompactIntervalUpdate<MeanState>, MaxEntropy, SparseStorage>;
/// Hit and miss counts with the imprecise Dirichlet interval: 4 bytes per voxel.
using DirichletGrid = VoxelGrid<ImpreciseDirichletUpdate<MeanState>, TotalUncertainty, SparseStorage>;
/// Dempster–Shafer belief masses, [Bel, Pl] as the interval: 12 bytes per voxel.
using BeliefGrid = VoxelGrid<DempsterShaferUpdate<MeanState>, TotalUncertainty, SparseStorage>;

static_assert(OccupancyGrid<BayesGrid> && OccupancyGrid<DenseIntervalGrid> && OccupancyGrid<const BeliefGrid>,
              "VoxelGrid must satisfy OccupancyGrid");

}  // namespace intervox
