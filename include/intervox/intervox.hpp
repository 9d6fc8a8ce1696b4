#pragma once
/// \file
/// Umbrella header: everything Intervox offers, except what needs libpng (io/png.hpp and
/// view/exploration_image.hpp: include them and link intervox::png).

#include <intervox/version.hpp>
#include <intervox/core/error.hpp>
#include <intervox/core/interval.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/parallel.hpp>
#include <intervox/core/point.hpp>
#include <intervox/core/probability.hpp>
#include <intervox/core/random.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/core/sensors.hpp>
#include <intervox/core/types.hpp>
#include <intervox/update/concepts.hpp>
#include <intervox/update/bayes_log_odds.hpp>
#include <intervox/update/interval_update.hpp>
#include <intervox/update/imprecise_dirichlet.hpp>
#include <intervox/update/dempster_shafer.hpp>
#include <intervox/utility/utility_policies.hpp>
#include <intervox/grid/storage.hpp>
#include <intervox/grid/dense_storage.hpp>
#include <intervox/grid/sparse_storage.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/grid/named_grids.hpp>
#include <intervox/grid/coarse_summary.hpp>
#include <intervox/raycast/raycast.hpp>
#include <intervox/explain/explain.hpp>
#include <intervox/sim/sim.hpp>
#include <intervox/plan/plan.hpp>
#include <intervox/eval/ground_truth.hpp>
#include <intervox/io/io.hpp>
#include <intervox/view/view.hpp>
