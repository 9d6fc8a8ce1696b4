#pragma once
/// \file
/// Autonomous object modelling with the arm's laser striper (thesis 5.1, 5.5): candidate views
/// are scan paths (straight striper sweeps) aimed at the object's centre from points sampled on a
/// sphere around it; a candidate whose path enters the collision space around occupied voxels or
/// comes down to the table top is rejected; the arm scans the candidate of highest information
/// gain and repeats until no view gains enough (a gain threshold) or the view budget is used up.
/// No exploration map and no frontier: the sphere is sampled regardless of what is known.

#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/plan/information_gain.hpp>
#include <intervox/plan/mobile_explorer.hpp>
#include <intervox/plan/rig_rays.hpp>
#include <intervox/plan/view_sampling.hpp>
#include <intervox/raycast/insert.hpp>
#include <intervox/sim/rig.hpp>
#include <intervox/sim/scene.hpp>
#include <intervox/sim/sensors.hpp>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace intervox {

/// Parameters of arm object modelling. Defaults fit the ring-shaped part of the built-in
/// workcell (sim::make_workcell) and the arm's striper (sim::SensorRig::arm).
struct ArmModellerParams {
  /// The box around the object: the gain counts voxels inside it only (unless `gain.bounds` is
  /// set), and the metrics (voxel_errors(), coverage()) compare it against the scene.
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
  double initial_azimuth = -1.5707963267948966;
  /// Gain options; bounds default to object_region, max range to the striper's.
  GainOptions gain{1.0, GainCount::PerView, std::nullopt};
  int gain_stride = 8;            ///< every n-th striper sample is cast for the gain, >= 1
  int gain_profile_stride = 2;    ///< every n-th profile of a path is cast for the gain, >= 1
  double min_gain = 3.0;          ///< the episode ends when the best candidate gains less
  int max_views = 12;             ///< view budget, the initial view included, >= 1
  InsertOptions insert{};         ///< max range is taken from the gain's max range if unset
  unsigned threads = 0;           ///< candidate evaluation threads (0: all cores)
  std::uint64_t seed = 1;         ///< candidate sampling and sensor noise

  /// \throws InvalidArgument naming the first invalid parameter.
  void validate() const {
    auto fail = [](const std::string& what) { throw InvalidArgument("intervox::ArmModellerParams: " + what); };
    if (!object_region.valid()) fail("object_region is not valid");
    if (center && !is_finite(*center)) fail("center must be finite");
    if (!(std::isfinite(sphere_radius) && sphere_radius > 0)) fail("sphere_radius must be finite and > 0");
    if (candidates < 1) fail("candidates must be >= 1");
    if (!(min_elevation >= -1.5707963267948966 && min_elevation <= max_elevation && max_elevation <= 1.5707963267948966))
      fail("need -pi/2 <= min_elevation <= max_elevation <= pi/2");
    if (!(std::isfinite(sweep_length) && sweep_length >= 0)) fail("sweep_length must be finite and >= 0");
    if (profiles < 1) fail("profiles must be >= 1");
    if (!(std::isfinite(collision_margin) && collision_margin >= 0)) fail("collision_margin must be finite and >= 0");
    if (!std::isfinite(support_height)) fail("support_height must be finite");
    if (!(std::isfinite(initial_elevation) && std::isfinite(initial_azimuth))) fail("initial view angles must be finite");
    if (gain_stride < 1 || gain_profile_stride < 1) fail("gain_stride and gain_profile_stride must be >= 1");
    if (!std::isfinite(min_gain)) fail("min_gain must be finite");
    if (max_views < 1) fail("max_views must be >= 1");
    gain.validate();
    insert.validate();
  }
};

/// What one step of arm modelling did.
struct ArmStepReport {
  int step = 0;                                   ///< 0 for the initial view
  Termination termination = Termination::Running; ///< set when the episode ended at this step
  int views = 0;                                  ///< views scanned so far (after this step)
  std::size_t sampled = 0;                        ///< viewpoints drawn on the sphere
  /// Accepted candidates: the striper pose at the middle of each sweep (sampled minus rejected).
  std::vector<Pose> candidates;
  std::vector<ViewGain> gains;                    ///< their gains
  std::optional<std::size_t> selected;            ///< index into candidates
  Pose view = Pose::Identity();                   ///< striper pose at the middle of the scanned sweep
  double seconds_planning = 0;                    ///< sampling, rejection and candidate evaluation
  double seconds_total = 0;                       ///< including the sweep and its insertion
  std::size_t beams = 0;                          ///< beams inserted
};

/// An object-modelling episode of the arm in a simulated scene.
///
/// A view is a straight sweep of the striper (sensor 0 of the rig): sim::linear_sweep of
/// `profiles` poses over `sweep_length` around the striper pose `look_at(eye, centre)`, eye on
/// the sphere; the flange follows through the rig's mount. Each step samples `candidates` eyes on
/// the sphere (seeded by the seed and the step), rejects sweeps that enter the collision space or
/// come down to the table, evaluates the gain of the rest with evaluate_paths(), scans the best
/// one profile by profile, and inserts every profile as one scan. The first step scans the fixed
/// initial view (ArmModellerParams::initial_elevation / initial_azimuth) without planning.
///
/// Termination: Explored when the best candidate gains less than `min_gain`; Blocked when every
/// sampled candidate was rejected; Budget when `max_views` views are scanned.
///
/// \tparam Grid a VoxelGrid (any update, utility and storage)
///
/// Thread safety: not thread-safe; one modeller per thread. Candidate evaluation inside a step
/// uses `params.threads` threads, with results independent of that number.
template <class Grid>
class ArmModeller {
 public:
  /// \param grid the map to fill (kept by reference; must outlive the modeller)
  /// \param scene the simulated world (kept by reference)
  /// \param rig the arm's rig; its sensor 0 must be a laser striper (copied)
  /// \throws InvalidArgument for invalid parameters or a rig without a striper at index 0.
  ArmModeller(Grid& grid, const sim::Scene& scene, sim::SensorRig rig = sim::SensorRig::arm(), ArmModellerParams params = {})
      : grid_(grid), scene_(scene), rig_(std::move(rig)), params_(std::move(params)) {
    if (rig_.size() == 0 || !std::holds_alternative<sim::LaserStriper>(rig_.sensors()[0].sensor))
      throw InvalidArgument("intervox::ArmModeller: the rig's sensor 0 must be a laser striper");
    if (!params_.gain.bounds) params_.gain.bounds = params_.object_region;
    params_.validate();
    if (!params_.center) params_.center = 0.5 * (params_.object_region.min + params_.object_region.max);
    if (!params_.insert.has_max_range()) params_.insert.max_range = params_.gain.max_range;
    rays_ = rig_bundle(rig_, params_.gain_stride);
  }

  /// Runs one step (the initial view first). Does nothing once the episode has ended.
  ArmStepReport step() {
    const auto t0 = std::chrono::steady_clock::now();
    ArmStepReport r;
    r.step = steps_;
    r.views = views_;
    if (termination_ != Termination::Running) {
      r.termination = termination_;
      return r;
    }
    if (views_ >= params_.max_views) return finish(r, Termination::Budget, t0);
    if (steps_ == 0) {
      const double e = params_.initial_elevation, a = params_.initial_azimuth;
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
      const std::uint64_t seed = SeededRandom(params_.seed ^ (0x51ED270B27E9ULL * static_cast<std::uint64_t>(steps_))).next();
      r.sampled = static_cast<std::size_t>(params_.candidates);
      std::vector<std::vector<Pose>> paths;
      for (const Pose& v : sample_sphere(grid_, sp, seed)) {
        std::vector<Pose> body = body_path(v);
        if (!collision_free(v, body)) continue;
        std::vector<Pose> cast;
        for (std::size_t k = 0; k < body.size(); k += static_cast<std::size_t>(params_.gain_profile_stride)) cast.push_back(body[k]);
        r.candidates.push_back(v);
        paths.push_back(std::move(cast));
      }
      if (r.candidates.empty()) return finish(r, Termination::Blocked, t0);
      r.gains = evaluate_paths(grid_, rays_, paths, params_.gain, params_.threads);
      r.selected = best_view(r.gains);
      if (r.gains[*r.selected].gain < params_.min_gain) {
        r.selected.reset();
        return finish(r, Termination::Explored, t0);
      }
      r.view = r.candidates[*r.selected];
    }
    r.seconds_planning = seconds_since(t0);
    r.beams = scan(r.view);
    r.views = ++views_;
    ++steps_;
    r.seconds_total = seconds_since(t0);
    reports_.push_back(r);
    return r;
  }

  /// Steps until termination; returns the reason.
  Termination run() {
    while (termination_ == Termination::Running) step();
    return termination_;
  }

  /// The striper poses of the sweep around the striper pose \p view (see the class comment).
  std::vector<Pose> sweep(const Pose& view) const { return sim::linear_sweep(view, params_.sweep_length, params_.profiles); }
  /// The flange (body) poses of the sweep around the striper pose \p view.
  std::vector<Pose> body_path(const Pose& view) const {
    std::vector<Pose> out;
    for (const Pose& s : sweep(view)) out.push_back(rig_.body_pose_for(0, s));
    return out;
  }
  /// True if neither striper nor flange enters the collision space (no occupied voxel within
  /// collision_margin) or comes within collision_margin of the support height at any pose of the
  /// sweep around \p view (checked at every pose for margins wider than the profile spacing,
  /// else at poses about one margin apart, and at both ends).
  bool collision_free(const Pose& view) const { return collision_free(view, body_path(view)); }

  /// Voxel errors inside the object region against the scene.
  VoxelErrors voxel_errors() const { return evaluate_voxels(grid_, scene_, params_.object_region); }

  /// Fraction of the object's visible surface that the grid classifies occupied: among the
  /// voxels inside object_region that the scene occupies, those with a face neighbour that is
  /// free in the scene and whose centre lies above support_height (a face the striper can see
  /// from the sphere; interior voxels and the underside on the table are left out). 1 if there
  /// are none.
  double coverage() const {
    std::size_t n = 0, known = 0;
    for_each_surface_voxel([&](const Key& k) {
      ++n;
      if (grid_.occupancy(k) == Occupancy::Occupied) ++known;
    });
    return n ? double(known) / double(n) : 1.0;
  }
  /// Number of surface voxels coverage() counts.
  std::size_t surface_voxels() const {
    std::size_t n = 0;
    for_each_surface_voxel([&](const Key&) { ++n; });
    return n;
  }

  Termination termination() const noexcept { return termination_; }
  int steps() const noexcept { return steps_; }
  int views() const noexcept { return views_; }
  /// Reports of the steps taken, the final (terminating) step included.
  const std::vector<ArmStepReport>& reports() const noexcept { return reports_; }
  /// The parameters, with defaults resolved (center, gain bounds, insert max range).
  const ArmModellerParams& params() const noexcept { return params_; }
  const Grid& grid() const noexcept { return grid_; }
  const sim::SensorRig& rig() const noexcept { return rig_; }

 private:
  static double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  ArmStepReport finish(ArmStepReport& r, Termination t, std::chrono::steady_clock::time_point t0) {
    termination_ = r.termination = t;
    r.seconds_planning = r.seconds_total = seconds_since(t0);
    reports_.push_back(r);
    return r;
  }
  bool collision_free(const Pose& view, const std::vector<Pose>& body) const {
    const std::vector<Pose> sensor = sweep(view);
    const double m = params_.collision_margin;
    const double spacing = params_.profiles > 1 ? params_.sweep_length / (params_.profiles - 1) : 0.0;
    const std::size_t every = spacing > 0 && m > spacing ? static_cast<std::size_t>(m / spacing) : 1;
    for (std::size_t k = 0; k < sensor.size(); ++k) {
      const bool check = k % every == 0 || k + 1 == sensor.size();
      for (const Point3& p : {Point3(sensor[k].translation()), Point3(body[k].translation())}) {
        if (p.z() < params_.support_height + m) return false;
        if (check && !outside_collision_space(grid_, p, m)) return false;
      }
    }
    return true;
  }

 public:
  /// Scans the sweep around the striper pose \p view and inserts it profile by profile, outside
  /// the planning loop (for scripted views; not counted in views() or the reports). Returns the
  /// number of beams inserted. The noise streams continue those of the episode.
  /// \throws InvalidArgument for a non-finite pose.
  std::size_t scan(const Pose& view) {
    std::size_t n = 0;
    for (const Pose& body : body_path(view)) {
      const std::uint64_t seed = SeededRandom(params_.seed + 0x9E3779B97F4A7C15ULL * static_cast<std::uint64_t>(++scans_)).next();
      const std::vector<Beam> beams = rig_.simulate(scene_, body, seed);
      insert_beams(grid_, std::span<const Beam>(beams), params_.insert);
      n += beams.size();
    }
    return n;
  }

 private:
  template <class F>
  void for_each_surface_voxel(F&& f) const {
    const GridGeometry& g = grid_.geometry();
    const std::vector<Key> truth = scene_.ground_truth(g, params_.object_region);
    for (const Key& k : truth) {
      bool exposed = false;
      for (int a = 0; a < 3 && !exposed; ++a)
        for (int d : {-1, 1}) {
          Key nb = k;
          nb[a] += d;
          if (g.center(nb).z() > params_.support_height && !scene_.occupied(g, nb)) {
            exposed = true;
            break;
          }
        }
      if (exposed) f(k);
    }
  }

  Grid& grid_;
  const sim::Scene& scene_;
  sim::SensorRig rig_;
  ArmModellerParams params_;
  RayBundle rays_;
  int steps_ = 0;
  int views_ = 0;
  std::uint64_t scans_ = 0;
  Termination termination_ = Termination::Running;
  std::vector<ArmStepReport> reports_;
};

}  // namespace intervox
