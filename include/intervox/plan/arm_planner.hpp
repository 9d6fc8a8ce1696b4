#pragma once
/// \file
/// The next view of the arm's laser striper (thesis 5.1, 5.5), decided from the map alone:
/// candidate views are scan paths (straight striper sweeps) aimed at the object's centre from
/// points sampled on a sphere around it; a candidate whose path enters the collision space around
/// occupied voxels or comes down to the table top is rejected; the planner returns the candidate
/// of highest information gain, or Explored when it gains too little. No exploration map and no
/// frontier: the sphere is sampled regardless of what is known. The planner neither moves the arm
/// nor senses: an episode runner (plan/episode.hpp) or the user's loop does.

#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/sensors.hpp>
#include <intervox/plan/information_gain.hpp>
#include <intervox/plan/planner.hpp>
#include <intervox/plan/rig_rays.hpp>
#include <intervox/plan/view_sampling.hpp>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace intervox {

/// Parameters of the arm planner. Defaults fit the ring-shaped part of the built-in workcell
/// (sim::make_workcell) and the arm's striper (SensorRig::arm).
struct ArmPlannerParams {
  /// The box around the object: the gain counts voxels inside it only (unless `gain.bounds` is
  /// set); its centre is the default centre of the sphere of views.
  Bounds object_region{{0.64, 0.64, 0.74}, {0.86, 0.86, 0.80}};
  /// Centre of the sphere of viewpoints; every view looks at it. Default: object_region's centre.
  std::optional<Point3> center;
  double sphere_radius = 0.45;    ///< m; distance of the striper from the centre, > 0
  int candidates = 16;            ///< viewpoints drawn on the sphere per step (before rejection), >= 1
  double min_elevation = 0.2;     ///< rad above the horizontal through the centre
  double max_elevation = 1.45;    ///< rad (pi/2: straight down)
  double sweep_length = 0.2;      ///< m; the striper moves this far across the view direction, >= 0
  /// Profiles per sweep, >= 1. Each profile is one scan for the update (the striper delivers
  /// profile after profile), so a voxel crossed by n profiles of a sweep is updated n times:
  /// keep the spacing `sweep_length / (profiles - 1)` below the voxel size.
  int profiles = 41;
  /// m; no occupied voxel (centre) may lie within this distance of the striper or the flange at
  /// any pose of a candidate's path, and both must stay this far above `support_height`.
  double collision_margin = 0.06;
  double support_height = 0.74;   ///< m; the table top the object stands on
  /// The first, fixed view (documented so that episodes are comparable): a sweep from the sphere
  /// point at this elevation and azimuth (rad; -pi/2 looks from -y towards +y, i.e. from the
  /// front of the workcell towards its backdrop).
  double initial_elevation = 1.0;
  double initial_azimuth = -std::numbers::pi / 2;
  /// Gain options; bounds default to object_region.
  GainOptions gain{1.0, GainCount::PerView, std::nullopt};
  int gain_stride = 8;            ///< every n-th striper sample is cast for the gain, >= 1
  int gain_profile_stride = 2;    ///< every n-th profile of a path is cast for the gain, >= 1
  /// The episode ends when the best candidate gains less than this fraction of its gain in an
  /// unobserved world (ViewPlan::relative_gain); the same for every sensor and stride.
  double min_relative_gain = 0.002;
  int max_views = 12;             ///< view budget, the initial view included, >= 1
  unsigned threads = 0;           ///< candidate evaluation threads (0: all cores)
  std::uint64_t seed = 1;         ///< candidate sampling

  /// \throws InvalidArgument naming the first invalid parameter.
  void validate() const {
    auto fail = [](const std::string& what) { throw InvalidArgument("intervox::ArmPlannerParams: " + what); };
    if (!object_region.valid()) fail("object_region is not valid");
    if (center && !is_finite(*center)) fail("center must be finite");
    if (!(std::isfinite(sphere_radius) && sphere_radius > 0)) fail("sphere_radius must be finite and > 0");
    if (candidates < 1) fail("candidates must be >= 1");
    if (!(min_elevation >= -std::numbers::pi / 2 && min_elevation <= max_elevation && max_elevation <= std::numbers::pi / 2))
      fail("need -pi/2 <= min_elevation <= max_elevation <= pi/2");
    if (!(std::isfinite(sweep_length) && sweep_length >= 0)) fail("sweep_length must be finite and >= 0");
    if (profiles < 1) fail("profiles must be >= 1");
    if (!(std::isfinite(collision_margin) && collision_margin >= 0)) fail("collision_margin must be finite and >= 0");
    if (!std::isfinite(support_height)) fail("support_height must be finite");
    if (!(std::isfinite(initial_elevation) && std::isfinite(initial_azimuth))) fail("initial view angles must be finite");
    if (gain_stride < 1 || gain_profile_stride < 1) fail("gain_stride and gain_profile_stride must be >= 1");
    if (!(std::isfinite(min_relative_gain) && min_relative_gain >= 0)) fail("min_relative_gain must be finite and >= 0");
    if (max_views < 1) fail("max_views must be >= 1");
    gain.validate();
  }
};

/// One decision of the arm planner. `scans` holds the flange poses of the sweep, one per profile.
struct ArmPlan : ViewPlan {
  std::size_t sampled = 0;              ///< viewpoints drawn on the sphere
  /// Accepted candidates: the striper pose at the middle of each sweep (sampled minus rejected).
  std::vector<Pose> candidates;
  std::vector<ViewGain> gains;          ///< their gains
  std::optional<std::size_t> selected;  ///< index into candidates
  Pose view = Pose::Identity();         ///< striper pose at the middle of the sweep
};

/// Decides the next sweep of an arm carrying a laser striper.
///
/// A view is a straight sweep of the striper (sensor 0 of the rig): linear_sweep of `profiles`
/// poses over `sweep_length` around the striper pose `look_at(eye, centre)`, eye on the sphere;
/// the flange follows through the rig's mount. The first call returns the fixed initial view
/// (ArmPlannerParams::initial_elevation / initial_azimuth, reason Initial); each later call samples
/// `candidates` eyes on the sphere (seeded by the seed and the step), rejects sweeps that enter the
/// collision space or come down to the table, evaluates the gain of the rest with evaluate_paths(),
/// and returns the best (reason Gain). The plan's scans are the flange poses of the sweep; its path
/// is empty (the motion between sweeps is left to the arm's controller).
///
/// Termination: Explored when the best candidate's relative gain is below `min_relative_gain`;
/// Blocked when every sampled candidate was rejected; Budget when `max_views` views were planned.
///
/// Thread safety: not thread-safe (plan() counts the views); the grid must not be modified during
/// plan(). Candidate evaluation uses `params.threads` threads, with results independent of that number.
class ArmPlanner {
 public:
  /// \param rig the arm's rig; its sensor 0 must be a laser striper (copied)
  /// \throws InvalidArgument for invalid parameters or a rig without a striper at index 0.
  explicit ArmPlanner(SensorRig rig = SensorRig::arm(), ArmPlannerParams params = {})
      : rig_(std::move(rig)), params_(std::move(params)) {
    if (rig_.size() == 0 || !std::holds_alternative<LaserStriper>(rig_.sensors()[0].sensor))
      throw InvalidArgument("intervox::ArmPlanner: the rig's sensor 0 must be a laser striper");
    if (!params_.gain.bounds) params_.gain.bounds = params_.object_region;
    params_.validate();
    if (!params_.center) params_.center = 0.5 * (params_.object_region.min + params_.object_region.max);
    rays_ = rig_bundle(rig_, params_.gain_stride);
  }

  /// The next sweep on \p grid (see the class comment). \p pose, the flange's current pose, is
  /// not used: every sweep is reachable for the arm.
  /// \tparam Grid a VoxelGrid (any update, utility and storage)
  template <class Grid>
  ArmPlan plan(const Grid& grid, const Pose& pose = Pose::Identity()) {
    (void)pose;
    const auto t0 = std::chrono::steady_clock::now();
    ArmPlan r;
    if (views_ >= params_.max_views) return finish(r, Termination::Budget, t0);
    if (views_ == 0) {
      const double e = params_.initial_elevation, a = params_.initial_azimuth;
      r.reason = ViewReason::Initial;
      r.view = look_at(*params_.center + params_.sphere_radius * Point3(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e)),
                       *params_.center);
    } else {
      SphereSamplerParams sp;
      sp.center = *params_.center;
      sp.radius = params_.sphere_radius;
      sp.views = params_.candidates;
      sp.min_elevation = params_.min_elevation;
      sp.max_elevation = params_.max_elevation;
      sp.clearance = params_.collision_margin;
      const std::uint64_t seed = SeededRandom(params_.seed ^ (0x51ED270B27E9ULL * static_cast<std::uint64_t>(views_))).next();
      r.sampled = static_cast<std::size_t>(params_.candidates);
      std::vector<std::vector<Pose>> paths;
      for (const Pose& v : sample_sphere(grid, sp, seed)) {
        std::vector<Pose> body = body_path(v);
        if (!collision_free(grid, v, body)) continue;
        std::vector<Pose> cast;
        for (std::size_t k = 0; k < body.size(); k += static_cast<std::size_t>(params_.gain_profile_stride)) cast.push_back(body[k]);
        r.candidates.push_back(v);
        paths.push_back(std::move(cast));
      }
      if (r.candidates.empty()) return finish(r, Termination::Blocked, t0);
      r.gains = evaluate_paths(grid, rays_, paths, params_.gain, params_.threads);
      r.considered = r.gains.size();
      const std::size_t best = *best_view(r.gains);
      const double unknown = unknown_path_gain(grid, rays_, paths[best], params_.gain).gain;
      r.gain = r.gains[best].gain;
      r.relative_gain = unknown > 0 ? r.gain / unknown : 0.0;
      if (r.relative_gain < params_.min_relative_gain) return finish(r, Termination::Explored, t0);
      r.selected = best;
      r.reason = ViewReason::Gain;
      r.view = r.candidates[best];
    }
    r.scans = body_path(r.view);
    ++views_;
    r.seconds = seconds_since(t0);
    return r;
  }

  /// The striper poses of the sweep around the striper pose \p view (see the class comment).
  std::vector<Pose> sweep(const Pose& view) const { return linear_sweep(view, params_.sweep_length, params_.profiles); }
  /// The flange (body) poses of the sweep around the striper pose \p view.
  std::vector<Pose> body_path(const Pose& view) const {
    std::vector<Pose> out;
    for (const Pose& s : sweep(view)) out.push_back(rig_.body_pose_for(0, s));
    return out;
  }
  /// True if neither striper nor flange enters the collision space of \p grid (no occupied voxel
  /// within collision_margin) or comes within collision_margin of the support height at any pose
  /// of the sweep around \p view (checked at every pose for margins wider than the profile
  /// spacing, else at poses about one margin apart, and at both ends).
  /// \tparam Grid a VoxelGrid
  template <class Grid>
  bool collision_free(const Grid& grid, const Pose& view) const {
    return collision_free(grid, view, body_path(view));
  }

  /// The gain rays' reach (the striper's range clipped by the gain options), and so the
  /// insertion's max range for beams without a return.
  double max_range() const noexcept { return params_.gain.max_range; }
  /// The parameters, with defaults resolved (center, gain bounds).
  const ArmPlannerParams& params() const noexcept { return params_; }
  const SensorRig& rig() const noexcept { return rig_; }
  const RayBundle& rays() const noexcept { return rays_; }
  /// Views planned so far, the initial view included.
  int views() const noexcept { return views_; }

 private:
  static double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  ArmPlan finish(ArmPlan& r, Termination t, std::chrono::steady_clock::time_point t0) const {
    r.termination = t;
    r.reason = ViewReason::None;
    r.seconds = seconds_since(t0);
    return r;
  }
  template <class Grid>
  bool collision_free(const Grid& grid, const Pose& view, const std::vector<Pose>& body) const {
    const std::vector<Pose> sensor = sweep(view);
    const double m = params_.collision_margin;
    const double spacing = params_.profiles > 1 ? params_.sweep_length / (params_.profiles - 1) : 0.0;
    const std::size_t every = spacing > 0 && m > spacing ? static_cast<std::size_t>(m / spacing) : 1;
    for (std::size_t k = 0; k < sensor.size(); ++k) {
      const bool check = k % every == 0 || k + 1 == sensor.size();
      for (const Point3& p : {Point3(sensor[k].translation()), Point3(body[k].translation())}) {
        if (p.z() < params_.support_height + m) return false;
        if (check && !outside_collision_space(grid, p, m)) return false;
      }
    }
    return true;
  }

  SensorRig rig_;
  ArmPlannerParams params_;
  RayBundle rays_;
  int views_ = 0;
};

}  // namespace intervox
