#pragma once
/// \file
/// The candidate-scoring step every planner shares (MobilePlanner's frontier and lying-region
/// strategies, ArmPlanner's sphere and conflict views): candidates are drawn with one seed rule
/// (candidate_random), each is a scan path of body poses, their gains are evaluated together
/// (evaluate_paths), the best is chosen (highest gain, or a strategy's own score), and the chosen
/// candidate's relative gain is computed in one place (relative_gain):
///
///     relative gain = gain(path) / unknown_path_gain(path).gain   (0 if the denominator is 0)
///
/// the share of the gain the same path would have in a world of unobserved voxels, so that a
/// threshold (min_relative_gain) means the same for every sensor, stride and range.

#include <intervox/core/random.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/grid/occupancy_grid.hpp>
#include <intervox/plan/information_gain.hpp>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

namespace intervox {

/// Which kind of target a planner draws candidates for (candidate_random): each has its own
/// stream of seeds, so that adding a target of one kind never shifts the draws of the other.
enum class CandidateStream : std::uint8_t {
  Gain,      ///< the gain rule: a frontier's ring (mobile base), the sphere of views (arm)
  Conflict,  ///< a view of a conflict region from a new direction (conflict-aware planners)
  Passage,   ///< a view that opens a passage (the mobile base's PassageViewParams)
};

/// The one seed rule of the planners: the generator the candidates of planning step \p step for
/// target \p target of kind \p stream are drawn from, given the planner's \p seed:
///
///     SeededRandom(seed ^ (A * step) ^ (B * target))
///
/// with (A, B) = (0x51ED270B27E9, 0x2545F4914F6CDD1D) for CandidateStream::Gain,
/// (0x9E3779B97F4A7C15, 0xC2B2AE3D27D4EB4F) for CandidateStream::Conflict and
/// (0xD6E8FEB86659FD93, 0xA0761D6478BD642F) for CandidateStream::Passage. \p target numbers the
/// targets of one step (the mobile base: the k-th frontier or passage tried, from 1, or conflict
/// region i + 1; the arm's sphere: 0). Samplers that take a seed (sample_ring, sample_sphere) are given
/// the generator's first draw, next(); the arm's cone of conflict views draws from it directly.
/// The same arguments give the same candidates on every platform and thread count.
/// Thread safety: a pure function.
inline SeededRandom candidate_random(std::uint64_t seed, std::uint64_t step, CandidateStream stream,
                                     std::uint64_t target) noexcept {
  const std::uint64_t a = stream == CandidateStream::Gain       ? 0x51ED270B27E9ULL
                          : stream == CandidateStream::Conflict ? 0x9E3779B97F4A7C15ULL
                                                                : 0xD6E8FEB86659FD93ULL;
  const std::uint64_t b = stream == CandidateStream::Gain       ? 0x2545F4914F6CDD1DULL
                          : stream == CandidateStream::Conflict ? 0xC2B2AE3D27D4EB4FULL
                                                                : 0xA0761D6478BD642FULL;
  return SeededRandom(seed ^ (a * step) ^ (b * target));
}

/// The relative gain of the scan path \p path whose gain is \p gain (see the file comment): gain
/// / unknown_path_gain(grid, rays, path, options).gain, or 0 if that is 0. The one place the
/// planners compute ViewPlan::relative_gain.
/// \tparam Grid a VoxelGrid (its geometry and policies are used, not its cells)
/// \throws InvalidArgument if the options are invalid or a pose is not finite.
/// Thread safety: reads the grid's geometry and policies only.
template <OccupancyGrid Grid>
double relative_gain(const Grid& grid, const RayBundle& rays, const std::vector<Pose>& path, double gain,
                     const GainOptions& options) {
  const double unknown = unknown_path_gain(grid, rays, path, options).gain;
  return unknown > 0 ? gain / unknown : 0.0;
}

/// The outcome of the scoring step for one set of candidates.
struct ScoredCandidates {
  std::vector<ViewGain> gains;      ///< gains[i]: the gain of candidate i (its scan path)
  std::optional<std::size_t> best;  ///< the chosen candidate (unset if there were none)
  double relative_gain = 0;         ///< the chosen candidate's relative gain (0 without one)
};

/// The scoring step: the gains of the candidate scan paths \p paths (evaluate_paths on
/// \p threads threads; a single view is a path of one pose), the best candidate by \p score, and
/// its relative gain (relative_gain on its path).
///
/// \p score is called as `score(i, gain_i, max_gain)` for every candidate i in order, with
/// max_gain the largest gain of the set (at least 0); the candidate of the highest score wins,
/// ties going to the lower index (scores must be >= 0: the first candidate wins unless another
/// scores higher). The default, score_candidates without \p score, chooses by gain alone
/// (best_view).
/// \tparam Grid a VoxelGrid
/// \tparam Score callable as `double(std::size_t, double, double)`
/// \throws InvalidArgument if the options are invalid or a pose is not finite.
/// Thread safety: reads the grid only; the grid must not be modified meanwhile. Results do not
/// depend on the thread count.
template <OccupancyGrid Grid, class Score>
ScoredCandidates score_candidates(const Grid& grid, const RayBundle& rays, const std::vector<std::vector<Pose>>& paths,
                                  const GainOptions& options, unsigned threads, Score&& score) {
  ScoredCandidates out;
  out.gains = evaluate_paths(grid, rays, paths, options, threads);
  if (out.gains.empty()) return out;
  double max_gain = 0;
  for (const ViewGain& g : out.gains) max_gain = std::max(max_gain, g.gain);
  std::size_t best = 0;
  double best_score = -1;
  for (std::size_t k = 0; k < out.gains.size(); ++k) {
    const double s = score(k, out.gains[k].gain, max_gain);
    if (s > best_score) {
      best_score = s;
      best = k;
    }
  }
  out.best = best;
  out.relative_gain = relative_gain(grid, rays, paths[best], out.gains[best].gain, options);
  return out;
}

/// The scoring step choosing by gain alone: the highest gain wins, ties going to the lower index
/// (best_view). See the overload with a score.
template <OccupancyGrid Grid>
ScoredCandidates score_candidates(const Grid& grid, const RayBundle& rays, const std::vector<std::vector<Pose>>& paths,
                                  const GainOptions& options, unsigned threads) {
  ScoredCandidates out;
  out.gains = evaluate_paths(grid, rays, paths, options, threads);
  out.best = best_view(out.gains);
  if (out.best) out.relative_gain = relative_gain(grid, rays, paths[*out.best], out.gains[*out.best].gain, options);
  return out;
}

}  // namespace intervox
