#pragma once
/// \file
/// Autonomous exploration with the mobile base (thesis 3.3.3–3.5): project the grid to the
/// exploration map, pick the closest reachable frontier, sample candidate poses in a ring around
/// it, move to the candidate of highest information gain, scan, repeat until termination.

#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/plan/exploration_map.hpp>
#include <intervox/plan/information_gain.hpp>
#include <intervox/plan/rig_rays.hpp>
#include <intervox/plan/view_sampling.hpp>
#include <intervox/raycast/insert.hpp>
#include <intervox/sim/random.hpp>
#include <intervox/sim/rig.hpp>
#include <intervox/sim/scene.hpp>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <unordered_set>
#include <vector>

namespace intervox {

/// Why an episode ended.
enum class Termination : std::uint8_t {
  Running = 0,          ///< not ended yet
  Explored,             ///< frontiers remain, but no view of any of them gains enough
  NoReachableFrontier,  ///< no reachable cell borders unknown space (the thesis' criterion)
  Blocked,              ///< frontiers remain, but no collision-free candidate pose was found
  Budget,               ///< the step (or view) budget is used up
};

/// Name of a termination reason, for reports.
constexpr std::string_view to_string(Termination t) noexcept {
  switch (t) {
    case Termination::Running: return "running";
    case Termination::Explored: return "explored";
    case Termination::NoReachableFrontier: return "no reachable frontier";
    case Termination::Blocked: return "blocked";
    case Termination::Budget: return "budget";
  }
  return "?";
}

/// Ground-truth comparison of a grid (see evaluate_voxels()).
struct VoxelErrors {
  std::size_t wrongly_occupied = 0;  ///< classified occupied, free in the scene
  std::size_t wrongly_free = 0;      ///< classified free, occupied in the scene
  std::size_t known_occupied = 0;    ///< occupied in the scene and classified occupied
  std::size_t true_occupied = 0;     ///< voxels occupied in the scene (inside the region)
};

/// Counts misclassified voxels of \p grid inside \p region against the scene's ground truth.
/// \tparam Grid a VoxelGrid
/// \throws InvalidArgument if region is not valid.
template <class Grid>
VoxelErrors evaluate_voxels(const Grid& grid, const sim::Scene& scene, const Bounds& region) {
  const auto truth = scene.ground_truth(grid.geometry(), region);
  std::unordered_set<Key, KeyHash> occ(truth.begin(), truth.end());
  const KeyBox box = grid.geometry().key_box(region);
  VoxelErrors e;
  e.true_occupied = occ.size();
  grid.for_each_observed([&](const Key& k, const typename Grid::Cell& c) {
    if (!box.contains(k)) return;
    const Occupancy o = grid.update_policy().occupancy(c);
    const bool is_occ = occ.count(k) != 0;
    if (o == Occupancy::Occupied && !is_occ) ++e.wrongly_occupied;
    if (o == Occupancy::Free && is_occ) ++e.wrongly_free;
    if (o == Occupancy::Occupied && is_occ) ++e.known_occupied;
  });
  return e;
}

/// Parameters of mobile exploration. Defaults fit the built-in lab room and the mobile base.
struct MobileExplorerParams {
  /// The floor area explored (x, y) and the heights projected onto the exploration map (z): the
  /// floor is excluded by starting above it, obstacles above the robot by ending at its height.
  /// The cameras at knee height (0.5 m, +-15 deg) see the layers 0.2-0.8 m of a column only from
  /// about 0.9 m on, so lower layers are left out: obstacles lower than 0.2 m are not mapped.
  Bounds region{{0.0, 0.0, 0.2}, {8.0, 6.0, 0.8}};
  ExplorationMapParams map{0.36};      ///< robot radius: the base's 0.6 x 0.4 m footprint turns in 0.36 m
  double footprint_radius = 0.2;       ///< m; cells the robot stood on count as free
  /// m; the operator starts the robot in a clear spot: columns within this radius of the start
  /// count as free unless seen occupied (the cameras' blind zone around the base, see region).
  double start_free_radius = 1.0;
  RingSamplerParams ring{1.4, 2.4, 12, 2};
  /// Gain options; bounds default to the room (set in the constructor if unset).
  GainOptions gain{4.0, GainCount::PerBeam, std::nullopt};
  int gain_stride = 4;                 ///< pixel stride of the rays cast for the gain (1/16 of them)
  double min_gain = 1.0;               ///< a frontier whose best view gains less is given up
  int max_visits_per_frontier = 3;     ///< a frontier selected this often is given up
  double frontier_radius = 0.5;        ///< m; frontiers closer than this count as the same one
  int frontier_attempts = 6;           ///< frontiers tried per step before giving up the step
  int max_steps = 40;                  ///< exploration steps after the look-around
  int look_around_scans = 4;           ///< scans at the start, turning by 45° / n between them
  /// Scans taken at each view, turning by 45° / n between them (the cameras deliver frames while
  /// the base turns on the spot; with the default thresholds a voxel needs three misses to be free).
  int scans_per_view = 3;
  InsertOptions insert{};              ///< max range is taken from the gain's max range if unset
  unsigned threads = 0;                ///< candidate evaluation threads (0: all cores)
  std::uint64_t seed = 1;              ///< candidate sampling and sensor noise
};

/// What one step did.
struct StepReport {
  int step = 0;                                   ///< 0 for the look-around
  Termination termination = Termination::Running; ///< set when the episode ended at this step
  std::optional<Cell2> frontier;                  ///< the selected frontier
  std::vector<PlanarCandidate> candidates;        ///< sampled poses at the selected frontier
  std::vector<ViewGain> gains;                    ///< their gains
  std::optional<std::size_t> selected;            ///< index into candidates
  Pose pose = Pose::Identity();                   ///< body pose after the step
  double path_length = 0;                         ///< m driven (path distance on the map)
  double seconds_planning = 0;                    ///< map, frontier and candidate evaluation
  double seconds_total = 0;                       ///< including the scan and its insertion
  std::size_t beams = 0;                          ///< beams inserted
};

/// An exploration episode of the mobile base in a simulated scene.
///
/// \tparam Grid a VoxelGrid (any update, utility and storage)
///
/// Thread safety: not thread-safe; one explorer per thread. Candidate evaluation inside a step
/// uses `params.threads` threads, with results independent of that number.
template <class Grid>
class MobileExplorer {
 public:
  /// \param grid the map to fill (kept by reference; must outlive the explorer)
  /// \param scene the simulated world (kept by reference)
  /// \param rig the sensor rig on the base (copied)
  /// \param start the body pose at the start (z = 0 on the floor)
  /// \throws InvalidArgument for invalid parameters or a start outside the region.
  MobileExplorer(Grid& grid, const sim::Scene& scene, sim::SensorRig rig, const Pose& start,
                 MobileExplorerParams params = {})
      : grid_(grid), scene_(scene), rig_(std::move(rig)), params_(std::move(params)), pose_(start) {
    if (!params_.region.valid()) throw InvalidArgument("intervox::MobileExplorer: region is not valid");
    if (!params_.gain.bounds) {
      Bounds b = params_.region;
      b.min.z() = -1e-6;
      b.max.z() = params_.region.max.z() + 2.5;
      params_.gain.bounds = b;
    }
    params_.gain.validate();
    params_.ring.validate();
    if (params_.gain_stride < 1 || params_.max_steps < 0 || params_.look_around_scans < 1 || params_.scans_per_view < 1)
      throw InvalidArgument("intervox::MobileExplorer: gain_stride, look_around_scans and scans_per_view must be >= 1, max_steps >= 0");
    if (!(std::isfinite(params_.start_free_radius) && params_.start_free_radius >= 0 &&
          std::isfinite(params_.footprint_radius) && params_.footprint_radius >= 0))
      throw InvalidArgument("intervox::MobileExplorer: start_free_radius and footprint_radius must be finite and >= 0");
    if (!params_.insert.has_max_range()) params_.insert.max_range = params_.gain.max_range;
    const Point3 p = start.translation();
    if (!is_finite(p) || p.x() < params_.region.min.x() || p.y() < params_.region.min.y() ||
        p.x() > params_.region.max.x() || p.y() > params_.region.max.y())
      throw InvalidArgument("intervox::MobileExplorer: the start lies outside the region");
    rays_ = rig_bundle(rig_, params_.gain_stride);
  }

  /// Runs one step (the look-around first). Does nothing once the episode has ended.
  StepReport step() {
    const auto t0 = std::chrono::steady_clock::now();
    StepReport r;
    r.step = steps_;
    if (termination_ != Termination::Running) {
      r.termination = termination_;
      r.pose = pose_;
      return r;
    }
    if (steps_ == 0) {
      for (int i = 0; i < params_.look_around_scans; ++i) {
        const double yaw = 0.7853981633974483 * i / params_.look_around_scans;
        r.beams += scan(pose_ * Pose(Eigen::AngleAxisd(yaw, Point3::UnitZ())));
      }
      visited_.push_back(pose_.translation());
      r.pose = pose_;
      ++steps_;
      r.seconds_total = seconds_since(t0);
      reports_.push_back(r);
      return r;
    }
    if (steps_ > params_.max_steps) {
      termination_ = r.termination = Termination::Budget;
      r.pose = pose_;
      return r;
    }
    const ExplorationMap map = exploration_map();
    bool any_candidate = false, any_frontier = false;
    std::vector<Cell2> tried;
    const double fr = params_.frontier_radius / map.resolution();
    auto near = [&](const Cell2& a, const Cell2& b) {
      return double((a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y)) <= fr * fr;
    };
    for (const Cell2& f : map.borders()) {
      if (static_cast<int>(tried.size()) >= params_.frontier_attempts) break;
      bool skip = false;
      for (const Cell2& t : tried) skip = skip || near(t, f);
      for (const Cell2& g : given_up_) skip = skip || near(g, f);
      if (skip) continue;
      any_frontier = true;
      tried.push_back(f);
      const std::uint64_t seed = SeededRandom(params_.seed ^ (0x51ED270B27E9ULL * static_cast<std::uint64_t>(steps_)) ^
                                            (0x2545F4914F6CDD1DULL * tried.size())).next();
      std::vector<PlanarCandidate> cands = sample_ring(map, grid_.geometry(), f, params_.ring, seed);
      if (cands.empty()) continue;
      any_candidate = true;
      std::vector<Pose> poses;
      poses.reserve(cands.size());
      for (const PlanarCandidate& c : cands) poses.push_back(planar_pose(c.position, c.yaw));
      std::vector<ViewGain> gains = evaluate_views(grid_, rays_, poses, params_.gain, params_.threads);
      const auto best = best_view(gains);
      int& visits = visits_for(f);
      if (!best || gains[*best].gain < params_.min_gain || visits >= params_.max_visits_per_frontier) {
        given_up_.push_back(f);
        continue;
      }
      ++visits;
      r.frontier = f;
      r.candidates = std::move(cands);
      r.gains = std::move(gains);
      r.selected = best;
      break;
    }
    if (!r.selected) {
      termination_ = r.termination = map.borders().empty()  ? Termination::NoReachableFrontier
                                     : !any_frontier        ? Termination::Explored
                                     : any_candidate        ? Termination::Explored
                                                            : Termination::Blocked;
      r.pose = pose_;
      r.seconds_planning = r.seconds_total = seconds_since(t0);
      last_map_.emplace(map);
      reports_.push_back(r);
      return r;
    }
    r.seconds_planning = seconds_since(t0);
    const PlanarCandidate& c = r.candidates[*r.selected];
    r.path_length = map.path_distance(c.cell);
    pose_ = planar_pose(c.position, c.yaw);
    visited_.push_back(pose_.translation());
    for (int i = 0; i < params_.scans_per_view; ++i) {
      const double yaw = 0.7853981633974483 * i / params_.scans_per_view;
      r.beams += scan(pose_ * Pose(Eigen::AngleAxisd(yaw, Point3::UnitZ())));
    }
    r.pose = pose_;
    ++steps_;
    r.seconds_total = seconds_since(t0);
    last_map_.emplace(map);
    reports_.push_back(r);
    return r;
  }

  /// Steps until termination; returns the reason.
  Termination run() {
    while (termination_ == Termination::Running) step();
    return termination_;
  }

  /// The exploration map for the current grid and robot position.
  ExplorationMap exploration_map() const {
    ColumnMap cols = project_columns(grid_, params_.region);
    std::vector<Cell2> footprint;
    for (std::size_t i = 0; i < visited_.size(); ++i) {
      const Point3& v = visited_[i];
      const double radius = i == 0 ? std::max(params_.start_free_radius, params_.footprint_radius) : params_.footprint_radius;
      const int rc = static_cast<int>(std::floor(radius / cols.resolution()));
      const Cell2 c = cols.cell_of_key(grid_.geometry().key(Point3(v.x(), v.y(), params_.region.min.z())));
      for (int dy = -rc; dy <= rc; ++dy)
        for (int dx = -rc; dx <= rc; ++dx)
          if (dx * dx + dy * dy <= rc * rc) footprint.push_back({c.x + dx, c.y + dy});
    }
    return ExplorationMap(std::move(cols), robot_cell(), params_.map, footprint);
  }

  /// The map the last planning step used (with its frontier and candidates in reports().back()).
  const std::optional<ExplorationMap>& last_map() const noexcept { return last_map_; }
  /// The map cell of the robot.
  Cell2 robot_cell() const {
    const Key k = grid_.geometry().key(Point3(pose_.translation().x(), pose_.translation().y(), params_.region.min.z()));
    const KeyBox box = grid_.geometry().key_box(params_.region);
    return {k.x - box.min.x, k.y - box.min.y};
  }

  /// Fraction of the floor cells reachable in the ground truth (with the same robot radius, from
  /// the start) whose column the grid now classifies as free. The ground-truth map extends a
  /// margin beyond the region, so that walls just outside it make their collision space inside.
  double reachable_area_known() const {
    const TruthMap t = truth_map();
    const ColumnMap now = project_columns(grid_, params_.region);
    std::size_t reach = 0, known = 0;
    for (int y = 0; y < now.height(); ++y)
      for (int x = 0; x < now.width(); ++x)
        if (t.gt.reachable({x + t.margin, y + t.margin})) {
          ++reach;
          if (now.at({x, y}) == Occupancy::Free) ++known;
        }
    return reach ? double(known) / double(reach) : 1.0;
  }
  /// Reachable free floor area of the ground truth inside the region, m².
  double reachable_area() const {
    const TruthMap t = truth_map();
    const int w = t.gt.width() - 2 * t.margin, h = t.gt.height() - 2 * t.margin;
    std::size_t reach = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) reach += t.gt.reachable({x + t.margin, y + t.margin});
    return double(reach) * t.gt.resolution() * t.gt.resolution();
  }
  /// Voxel errors inside the room (gain bounds) against the scene.
  VoxelErrors voxel_errors() const { return evaluate_voxels(grid_, scene_, *params_.gain.bounds); }

  Termination termination() const noexcept { return termination_; }
  int steps() const noexcept { return steps_; }
  const Pose& pose() const noexcept { return pose_; }
  const std::vector<StepReport>& reports() const noexcept { return reports_; }
  const MobileExplorerParams& params() const noexcept { return params_; }
  const Grid& grid() const noexcept { return grid_; }

 private:
  static double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  std::size_t scan(const Pose& body) {
    const std::uint64_t seed = SeededRandom(params_.seed + 0x9E3779B97F4A7C15ULL * static_cast<std::uint64_t>(++scans_)).next();
    const std::vector<Beam> beams = rig_.simulate(scene_, body, seed);
    insert_beams(grid_, std::span<const Beam>(beams), params_.insert);
    return beams.size();
  }
  int& visits_for(const Cell2& f) {
    const double fr = params_.frontier_radius / grid_.resolution();
    for (auto& [c, n] : visits_)
      if (double((c.x - f.x) * (c.x - f.x) + (c.y - f.y) * (c.y - f.y)) <= fr * fr) return n;
    visits_.push_back({f, 0});
    return visits_.back().second;
  }
  /// The ground-truth exploration map over the region grown by `margin` cells on each side.
  struct TruthMap {
    int margin;
    ExplorationMap gt;
  };
  TruthMap truth_map() const {
    const GridGeometry& g = grid_.geometry();
    const int margin = static_cast<int>(std::ceil(params_.map.robot_radius / g.resolution())) + 1;
    KeyBox box = g.key_box(params_.region);
    box.min.x -= margin;
    box.min.y -= margin;
    box.max.x += margin;
    box.max.y += margin;
    ColumnMap m(static_cast<int>(box.extent(0)), static_cast<int>(box.extent(1)), g.resolution(), Key{box.min.x, box.min.y, 0});
    for (int y = 0; y < m.height(); ++y)
      for (int x = 0; x < m.width(); ++x) m.set({x, y}, Occupancy::Free);
    const Bounds grown{g.corner(box.min), g.corner(Key{box.max.x + 1, box.max.y + 1, box.max.z + 1})};
    for (const Key& k : scene_.ground_truth(g, grown)) {
      const Point3 c = g.center(k);
      if (c.z() >= params_.region.min.z() && c.z() <= params_.region.max.z()) m.set(m.cell_of_key(k), Occupancy::Occupied);
    }
    const Point3 s = visited_.empty() ? pose_.translation() : visited_.front();
    const Key sk = g.key(Point3(s.x(), s.y(), params_.region.min.z()));
    return {margin, ExplorationMap(std::move(m), Cell2{sk.x - box.min.x, sk.y - box.min.y}, params_.map)};
  }

  Grid& grid_;
  const sim::Scene& scene_;
  sim::SensorRig rig_;
  MobileExplorerParams params_;
  Pose pose_;
  RayBundle rays_;
  int steps_ = 0;
  std::uint64_t scans_ = 0;
  Termination termination_ = Termination::Running;
  std::vector<Point3> visited_;
  std::vector<Cell2> given_up_;
  std::vector<std::pair<Cell2, int>> visits_;
  std::vector<StepReport> reports_;
  std::optional<ExplorationMap> last_map_;
};

}  // namespace intervox
