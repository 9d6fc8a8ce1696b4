#pragma once
/// \file
/// The next view of the arm's laser striper (thesis 5.1, 5.5), decided from the map alone:
/// candidate views are scan paths (straight striper sweeps) aimed at the object's centre from
/// points sampled on a sphere around it; a candidate whose path enters the collision space around
/// occupied voxels or comes down to the table top is rejected; the planner returns the candidate
/// of highest information gain, or Explored when it gains too little. No exploration map and no
/// frontier: the sphere is sampled regardless of what is known. The planner neither moves the arm
/// nor senses: an episode runner (plan/episode.hpp) or the user's loop does.

#include <intervox/analysis/conflicts.hpp>
#include <intervox/core/error.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/sensors.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/grid/occupancy_grid.hpp>
#include <intervox/plan/candidate_scoring.hpp>
#include <intervox/plan/conflict_planning.hpp>
#include <intervox/map/explained_map.hpp>
#include <intervox/plan/explained_planning.hpp>
#include <intervox/plan/information_gain.hpp>
#include <intervox/plan/normal_seeking.hpp>
#include <intervox/plan/planner.hpp>
#include <intervox/plan/planner_maps.hpp>
#include <intervox/plan/rig_rays.hpp>
#include <intervox/plan/view_sampling.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>
#include <span>
#include <string>
#include <string_view>
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
  double sphere_radius = 0.45;  ///< m; distance of the striper from the centre, > 0
  int candidates = 16;          ///< viewpoints drawn on the sphere per step (before rejection), >= 1
  double min_elevation = 0.2;   ///< rad above the horizontal through the centre
  double max_elevation = 1.45;  ///< rad (pi/2: straight down)
  double sweep_length = 0.2;    ///< m; the striper moves this far across the view direction, >= 0
  /// Profiles per sweep, >= 1. Each profile is one scan for the update (the striper delivers
  /// profile after profile), so a voxel crossed by n profiles of a sweep is updated n times:
  /// keep the spacing `sweep_length / (profiles - 1)` below the voxel size.
  int profiles = 41;
  /// m; no occupied voxel (centre) may lie within this distance of the striper or the flange at
  /// any pose of a candidate's path, and both must stay this far above `support_height`.
  double collision_margin = 0.06;
  double support_height = 0.74;  ///< m; the table top the object stands on
  /// The first, fixed view (documented so that episodes are comparable): a sweep from the sphere
  /// point at this elevation and azimuth (rad; -pi/2 looks from -y towards +y, i.e. from the
  /// front of the workcell towards its backdrop).
  double initial_elevation = 1.0;
  double initial_azimuth = -std::numbers::pi / 2;
  /// Gain options; bounds default to object_region.
  GainOptions gain{1.0, GainCount::PerView, std::nullopt};
  int gain_stride = 8;          ///< every n-th striper sample is cast for the gain, >= 1
  int gain_profile_stride = 2;  ///< every n-th profile of a path is cast for the gain, >= 1
  /// The episode ends when the best candidate gains less than this fraction of its gain in an
  /// unobserved world (ViewPlan::relative_gain); the same for every sensor and stride.
  double min_relative_gain = 0.002;
  int max_views = 12;      ///< view budget, the initial view included, >= 1
  unsigned threads = 0;    ///< candidate evaluation threads (0: all cores)
  std::uint64_t seed = 1;  ///< candidate sampling
  /// Conflict-aware modelling (interval grids only; `conflicts.enabled = false`, the default,
  /// gives the plain planner): see the class comment. Detection is limited to the gain bounds;
  /// `conflicts.safety_margin` is added to collision_margin around conflict voxels;
  /// `conflicts.observe.max_range` defaults to the gain's max range; region_reach is not used.
  ConflictPlanningParams conflicts{};
  /// rad; conflict views are sampled in the cone of this half-angle around a region's normal
  /// (polished metal returns light to the sensor near normal incidence only), in (0, pi/2].
  double normal_cone = 0.35;
  /// Planning on explained free space (plan/explained_planning.hpp); disabled by default. Reads
  /// an ExplainedMap's channel (plan(map, pose); make_map()). Any update policy.
  ExplainedPlanningParams explained{};
  /// Views that seek normals (plan/normal_seeking.hpp; disabled by default): candidates are
  /// scored by gain and by how close to the striper's specular condition they would see surfaces
  /// with hits but no decided state (see the class comment). Reads an ExplainedMap's hit record
  /// (plan(map, pose); make_map()).
  NormalSeekingParams normals{};

  /// \throws InvalidArgument naming the first invalid parameter.
  void validate() const {
    const ParamCheck check("intervox::ArmPlannerParams");
    check.valid_bounds("object_region", object_region);
    if (center && !is_finite(*center)) check.fail("center must be finite");
    check.positive("sphere_radius", sphere_radius);
    check.at_least("candidates", candidates, 1);
    if (!(min_elevation >= -std::numbers::pi / 2 && min_elevation <= max_elevation &&
          max_elevation <= std::numbers::pi / 2))
      check.fail("need -pi/2 <= min_elevation <= max_elevation <= pi/2");
    check.nonnegative("sweep_length", sweep_length);
    check.at_least("profiles", profiles, 1);
    check.nonnegative("collision_margin", collision_margin);
    check.finite("support_height", support_height);
    check.finite("initial_elevation", initial_elevation);
    check.finite("initial_azimuth", initial_azimuth);
    check.at_least("gain_stride", gain_stride, 1);
    check.at_least("gain_profile_stride", gain_profile_stride, 1);
    check.nonnegative("min_relative_gain", min_relative_gain);
    check.at_least("max_views", max_views, 1);
    check.in_range("normal_cone", normal_cone, 0, std::numbers::pi / 2, RangeEnds::OpenClosed);
    gain.validate();
    conflicts.validate();
    explained.validate();
    normals.validate();
  }
};

/// Why the arm planner refused a candidate sweep (ArmPlan::refused).
enum class SweepRefusal : std::uint8_t {
  Table = 0,           ///< the striper or the flange comes within collision_margin of the support
  Occupied = 1,        ///< an occupied voxel of the grid lies within collision_margin
  Unexplained = 2,     ///< explained planning: an explained-occupied or unexplained voxel lies within collision_margin
  ConflictMargin = 3,  ///< conflict-aware: a conflict voxel lies within collision_margin + safety_margin
};
inline constexpr std::size_t kSweepRefusalCount = 4;

/// Name of a refusal ("table", "occupied", "unexplained", "conflict margin").
constexpr std::string_view to_string(SweepRefusal r) noexcept {
  switch (r) {
    case SweepRefusal::Table:
      return "table";
    case SweepRefusal::Occupied:
      return "occupied";
    case SweepRefusal::Unexplained:
      return "unexplained";
    case SweepRefusal::ConflictMargin:
      return "conflict margin";
  }
  return "?";
}

/// One decision of the arm planner. `scans` holds the flange poses of the sweep, one per profile.
struct ArmPlan : ViewPlan {
  std::size_t sampled = 0;  ///< viewpoints drawn on the sphere
  /// Accepted candidates: the striper pose at the middle of each sweep (sampled minus rejected).
  std::vector<Pose> candidates;
  std::vector<ViewGain> gains;          ///< their gains
  std::optional<std::size_t> selected;  ///< index into candidates
  Pose view = Pose::Identity();         ///< striper pose at the middle of the sweep
  /// Conflict-aware modelling only: the conflict regions found inside the gain bounds, with their
  /// views and state, and the index of the region the view aims at (reason Conflict).
  std::vector<PlannedRegion> regions;
  std::optional<std::size_t> conflict_region;
  std::size_t retired = 0;  ///< regions given up as unresolvable in this call
  /// Sampled sweeps of the gain rule refused, per SweepRefusal (indexed by its value; the first
  /// reason found along the sweep counts; eyes on the sphere next to an occupied voxel count as
  /// Occupied): sampled = candidates.size() + their sum.
  std::array<std::size_t, kSweepRefusalCount> refused{};
  /// Views that seek normals only: the glint score of each candidate (glint_score(); parallel to
  /// candidates) and the number of glint targets it was computed over.
  std::vector<double> glint;
  std::size_t glint_targets = 0;
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
/// is empty (the motion between sweeps is left to the arm's controller). Candidates are drawn,
/// scored and their relative gain computed by the step MobilePlanner shares
/// (plan/candidate_scoring.hpp).
///
/// Termination: Explored when the best candidate's relative gain is below `min_relative_gain`;
/// Blocked when every sampled candidate was rejected; Budget when `max_views` views were planned.
///
/// Conflict-aware modelling (`params.conflicts.enabled`, interval grids only; thesis ch. 6): the
/// planner records the striper's position at every profile of the sweeps it plans (it assumes
/// every plan is carried out). Each call after the initial view detects the conflict regions
/// inside the gain bounds (detect_conflicts) and which recorded positions saw them
/// (observe_regions). A region seen from `resolve_directions` distinct directions inside its cone
/// (below), or aimed at `max_region_views` times, is unresolvable: views outside the cone do not
/// count, since a polished surface returns no light to them. Sweeps are rejected that come within
/// collision_margin + safety_margin of a conflict voxel (space seen wrongly may hide a surface).
/// Open regions, largest first, are then offered a view before the gain rule: `candidates` eyes at
/// `sphere_radius` from the region's centroid, drawn in the cone of half-angle `normal_cone`
/// around its normal (turned away from the sphere's centre; without a normal: around the
/// direction from the sphere's centre to the centroid), the cone's axis raised or lowered into the elevation band
/// [min_elevation, max_elevation] and eyes outside the band dropped, each looking at the centroid; kept if its
/// direction to the centroid is new (new_direction) and its sweep collision-free; the best by (0.5 + 0.5 cos angle to
/// the normal) (1 + gain / max gain) is returned (reason Conflict). A region without such a candidate is given up.
/// Without an open region the gain rule decides. The final model can drop conflict voxels with model_voxels() ("discard
/// before meshing").
///
/// Views that seek normals (`params.normals.enabled`, any update policy): the planner records the
/// voxels where beams returned (the map's HitRecord, ExplainedMapOptions::record_hits). Each gain step finds the glint
/// targets among them inside the gain bounds, voxels the grid does not classify occupied, with normals fitted to the
/// hit voxels around them and turned away from the sphere's centre (glint_targets()), and scores
/// each accepted sweep by glint_score(): the sum over targets of cos^n θ_h at the profile crossing
/// them, θ_h the angle between the normal and the half-vector of the laser and camera directions
/// (the triangulation striper's specular condition). The candidate with the highest
/// gain / max gain + weight * glint / max glint is chosen; the reason is Normals when it differs
/// from the candidate of highest gain, else Gain. The relative gain (and so Explored) is that of
/// the chosen candidate.
///
/// Safety contract: a sweep is planned only if, at the striper's and the flange's poses along it
/// (every pose where the margin is wider than the profile spacing, else poses about one margin
/// apart, and both ends), (1) both stay collision_margin above support_height, (2) no occupied
/// voxel of the grid lies within collision_margin, (3) with explained planning
/// (`params.explained`), no explained-occupied or unexplained voxel lies within collision_margin
/// (space only suspect beams or beams without a return crossed is maybe-collision), and (4) with
/// conflict-aware modelling, no conflict voxel lies within collision_margin + safety_margin. The
/// exception: voxels that no beam has reached block nothing, since the arm's workspace around the
/// object is taken as free unless the map says otherwise (thesis 5.1); the sphere of views must
/// lie in reachable, obstacle-free space, which the user's arm controller checks. The plan counts
/// the refused sweeps by reason (ArmPlan::refused), and the initial view is not checked (it is
/// planned before any measurement).
///
/// Thread safety: not thread-safe (plan() counts the views); the grid must not be modified during
/// plan(). Candidate evaluation uses `params.threads` threads, with results independent of that number.
class ArmPlanner : public detail::PlannerMapMaking<ArmPlanner> {
 public:
  /// \param rig the arm's rig; its sensor 0 must be a laser striper (copied)
  /// \throws InvalidArgument for invalid parameters or a rig without a striper at index 0.
  explicit ArmPlanner(SensorRig rig = SensorRig::arm(), ArmPlannerParams params = {})
      : rig_(std::move(rig)), params_(std::move(params)) {
    if (rig_.size() == 0 || !std::holds_alternative<LaserStriper>(rig_.sensors()[0].sensor))
      ParamCheck("intervox::ArmPlanner").fail("the rig's sensor 0 must be a laser striper");
    if (!params_.gain.bounds) params_.gain.bounds = params_.object_region;
    params_.validate();
    if (!params_.center) params_.center = 0.5 * (params_.object_region.min + params_.object_region.max);
    if (params_.conflicts.observe.max_range == ObservationParams{}.max_range)
      params_.conflicts.observe.max_range = params_.gain.max_range;
    rays_ = rig_bundle(rig_, params_.gain_stride);
  }

  /// The next sweep on \p grid (see the class comment). \p pose, the flange's current pose, is
  /// not used: every sweep is reachable for the arm.
  /// \tparam Grid a VoxelGrid (any update, utility and storage)
  template <OccupancyGrid Grid>
  ArmPlan plan(const Grid& grid, const Pose& pose = Pose::Identity()) {
    if (params_.explained.enabled || params_.normals.enabled)
      ParamCheck("intervox::ArmPlanner::plan")
          .fail("planning on explained free space and views that seek normals read "
                "the evidence of an ExplainedMap (planner.make_map(grid)), not a plain grid");
    static const HitRecord none;
    return plan_on(grid, pose, nullptr, none);
  }

  /// The next sweep on \p map: its grid and, as the parameters ask, its explained channel
  /// (explained planning) and the voxels that returned a beam (views that seek normals). The
  /// planner only reads the map; make_map() gives one with what it reads.
  /// \tparam Grid a VoxelGrid
  /// \throws InvalidArgument as plan(grid, pose), or if the map lacks what the parameters read.
  template <class Grid>
  ArmPlan plan(const ExplainedMap<Grid>& map, const Pose& pose = Pose::Identity()) {
    if (params_.explained.enabled && !map.explained())
      ParamCheck("intervox::ArmPlanner::plan")
          .fail("planning on explained free space needs a map with the explained "
                "channel (ExplainedMapOptions::explained; planner.make_map(grid) makes one)");
    if (params_.normals.enabled && !map.options().record_hits)
      ParamCheck("intervox::ArmPlanner::plan")
          .fail("views that seek normals need a map that records hits "
                "(ExplainedMapOptions::record_hits; planner.make_map(grid) makes one)");
    return plan_on(map.grid(), pose, params_.explained.enabled ? map.explained() : nullptr, map.hits());
  }

  /// What an ExplainedMap for this planner keeps: the explained channel with the classing options
  /// and known surfaces of params().explained if explained planning is on, the hit record for
  /// views that seek normals.
  ExplainedMapOptions map_options() const {
    ExplainedMapOptions o = explained_map_options(params_.explained);
    o.record_hits = params_.normals.enabled;
    return o;
  }
  // insert_options() and make_map(grid) come from detail::PlannerMapMaking (plan/planner_maps.hpp).

 private:
  /// plan() on \p grid with the map's \p explained channel (or null) and \p hits read: the initial
  /// view, else the conflict step (conflict-aware modelling), else the gain rule.
  template <OccupancyGrid Grid>
  ArmPlan plan_on(const Grid& grid, const Pose& pose, const ExplainedSpace* explained, const HitRecord& hits) {
    (void)pose;
    const auto t0 = std::chrono::steady_clock::now();
    if constexpr (!IntervalPolicy<typename Grid::UpdateType>) {
      if (params_.conflicts.enabled)
        ParamCheck("intervox::ArmPlanner::plan")
            .fail("conflict-aware modelling needs an interval grid "
                  "(a Bayes grid cannot tell conflicts from ignorance)");
    }
    ArmPlan r;
    if (views_ >= params_.max_views) return finish(r, Termination::Budget, t0);
    if (views_ == 0) {
      initial_view(r);
    } else {
      std::vector<Point3> hazard;  // conflict voxel centres (conflict-aware only)
      if (!conflict_step(grid, r, hazard, explained)) {
        const std::vector<std::vector<Pose>> paths = sphere_candidates(grid, r, hazard, explained);
        if (r.candidates.empty()) return finish(r, Termination::Blocked, t0);
        ScoredCandidates scored = score_sweeps(grid, r, paths, hits);
        r.gains = std::move(scored.gains);
        r.considered = r.gains.size();
        const std::size_t best = *scored.best;
        r.gain = r.gains[best].gain;
        r.relative_gain = scored.relative_gain;
        if (r.relative_gain < params_.min_relative_gain) return finish(r, Termination::Explored, t0);
        r.selected = best;
        r.reason = best_view(r.gains) == best ? ViewReason::Gain : ViewReason::Normals;
        r.view = r.candidates[best];
      }
    }
    r.scans = body_path(r.view);
    record_sweep(r.view);
    ++views_;
    r.seconds = seconds_since(t0);
    return r;
  }

  /// The fixed initial view (ArmPlannerParams::initial_elevation, initial_azimuth; reason Initial).
  void initial_view(ArmPlan& r) const {
    const double e = params_.initial_elevation, a = params_.initial_azimuth;
    r.reason = ViewReason::Initial;
    r.view = look_at(*params_.center + params_.sphere_radius *
                                           Point3(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e)),
                     *params_.center);
  }

  /// Conflict-aware modelling (an interval grid, conflicts enabled): the regions (r.regions, their
  /// voxel centres appended to \p hazard), then a view of the first open region that has one
  /// (conflict_view); an open region without one is given up. True if r holds the view.
  template <OccupancyGrid Grid>
  bool conflict_step([[maybe_unused]] const Grid& grid, [[maybe_unused]] ArmPlan& r,
                     [[maybe_unused]] std::vector<Point3>& hazard, [[maybe_unused]] const ExplainedSpace* explained) {
    if constexpr (IntervalPolicy<typename Grid::UpdateType>) {
      if (params_.conflicts.enabled) {
        find_regions(grid, r, hazard);
        for (std::size_t i = 0; i < r.regions.size(); ++i) {
          if (r.regions[i].unresolvable) continue;
          if (conflict_view(grid, r, i, hazard, explained)) return true;
          regions_.give_up(r.regions[i].region);
          r.regions[i].unresolvable = true;
          ++r.retired;
        }
      }
    }
    return false;
  }

  /// The gain rule's candidates: `candidates` eyes on the sphere (seeded by the seed and the view
  /// count), those whose sweep keeps the safety contract in r.candidates (the others counted in
  /// r.refused); returns their paths for the gain (every gain_profile_stride-th flange pose).
  template <OccupancyGrid Grid>
  std::vector<std::vector<Pose>> sphere_candidates(const Grid& grid, ArmPlan& r, const std::vector<Point3>& hazard,
                                                   const ExplainedSpace* explained) const {
    SphereSamplerParams sp;
    sp.center = *params_.center;
    sp.radius = params_.sphere_radius;
    sp.views = params_.candidates;
    sp.min_elevation = params_.min_elevation;
    sp.max_elevation = params_.max_elevation;
    sp.clearance = params_.collision_margin;
    const std::uint64_t seed =
        candidate_random(params_.seed, static_cast<std::uint64_t>(views_), CandidateStream::Gain, 0).next();
    r.sampled = static_cast<std::size_t>(params_.candidates);
    const std::vector<Pose> eyes = sample_sphere(grid, sp, seed);
    r.refused[static_cast<std::size_t>(SweepRefusal::Occupied)] +=
        r.sampled - eyes.size();  // eyes next to an occupied voxel
    std::vector<std::vector<Pose>> paths;
    for (const Pose& v : eyes) {
      std::vector<Pose> body = body_path(v);
      if (const std::optional<SweepRefusal> why = refusal(grid, v, body, hazard, explained)) {
        ++r.refused[static_cast<std::size_t>(*why)];
        continue;
      }
      std::vector<Pose> cast;
      for (std::size_t k = 0; k < body.size(); k += static_cast<std::size_t>(params_.gain_profile_stride))
        cast.push_back(body[k]);
      r.candidates.push_back(v);
      paths.push_back(std::move(cast));
    }
    return paths;
  }

  /// The candidates' scores (score_candidates over \p paths): by gain, or, with views that seek
  /// normals, by gain / max gain + weight * glint / max glint (r.glint, r.glint_targets filled).
  template <OccupancyGrid Grid>
  ScoredCandidates score_sweeps(const Grid& grid, ArmPlan& r, const std::vector<std::vector<Pose>>& paths,
                                const HitRecord& hits) const {
    if (!params_.normals.enabled) return score_candidates(grid, rays_, paths, params_.gain, params_.threads);
    const std::vector<GlintTarget> targets =
        glint_targets(grid, hits, *params_.gain.bounds, *params_.center, params_.normals);
    r.glint_targets = targets.size();
    const LaserStriper& striper = std::get<LaserStriper>(rig_.sensors()[0].sensor);
    double max_glint = 0;
    for (const Pose& v : r.candidates) {
      r.glint.push_back(glint_score(striper, sweep(v), targets, params_.normals.lobe_exponent, grid.resolution()));
      max_glint = std::max(max_glint, r.glint.back());
    }
    const double w = params_.normals.weight;
    return score_candidates(
        grid, rays_, paths, params_.gain, params_.threads, [&](std::size_t k, double gain, double max_gain) {
          return (max_gain > 0 ? gain / max_gain : 0.0) + (max_glint > 0 ? w * r.glint[k] / max_glint : 0.0);
        });
  }

 public:
  /// The striper poses of the sweep around the striper pose \p view (see the class comment).
  std::vector<Pose> sweep(const Pose& view) const { return linear_sweep(view, params_.sweep_length, params_.profiles); }
  /// The flange (body) poses of the sweep around the striper pose \p view.
  std::vector<Pose> body_path(const Pose& view) const {
    std::vector<Pose> out;
    for (const Pose& s : sweep(view)) out.push_back(rig_.body_pose_for(0, s));
    return out;
  }
  /// True if the sweep around \p view keeps the safety contract (class comment) without conflict
  /// voxels: neither striper nor flange enters the collision space of \p grid (no occupied voxel
  /// within collision_margin; with explained planning, no explained-occupied or unexplained one
  /// either) or comes within collision_margin of the support height at any pose of the sweep
  /// (checked at every pose for margins wider than the profile spacing, else at poses about one
  /// margin apart, and at both ends).
  /// \tparam Grid a VoxelGrid
  template <OccupancyGrid Grid>
  bool collision_free(const Grid& grid, const Pose& view) const {
    return collision_free(grid, view, body_path(view), {}, nullptr);
  }
  /// collision_free() on \p map: with explained planning, the map's explained-occupied and
  /// unexplained voxels within collision_margin refuse the sweep too.
  template <class Grid>
  bool collision_free(const ExplainedMap<Grid>& map, const Pose& view) const {
    return collision_free(map.grid(), view, body_path(view), {}, params_.explained.enabled ? map.explained() : nullptr);
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
  /// Striper positions of the sweeps planned so far, one per profile (conflict-aware modelling
  /// counts the directions a region was seen from with them; empty for the plain planner).
  const std::vector<Point3>& scan_origins() const noexcept { return origins_; }

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
  /// Conflict-aware: the regions inside the gain bounds with their views and state (r.regions)
  /// and the centres of their voxels (\p hazard).
  template <OccupancyGrid Grid>
  void find_regions(const Grid& grid, ArmPlan& r, std::vector<Point3>& hazard) const {
    const ConflictPlanningParams& cp = params_.conflicts;
    ConflictReport rep = detect_conflicts(grid, cp.detect, params_.gain.bounds);
    observe_regions(grid, std::span<const Point3>(origins_), rep.regions, cp.observe);
    const double cos_cone = std::cos(params_.normal_cone);
    for (ConflictRegion& reg : rep.regions) {
      PlannedRegion pr;
      // Only directions inside the cone around the region's axis can resolve it.
      const Point3 axis = region_axis(reg);
      std::vector<RegionView> near;
      for (const RegionView& v : reg.views)
        if (v.direction.dot(axis) >= cos_cone - 1e-12) near.push_back(v);
      pr.directions = distinct_directions(near, cp.min_angle);
      pr.unresolvable = pr.directions >= cp.resolve_directions || regions_.given_up(reg);
      for (const Key& k : reg.voxels) hazard.push_back(grid.geometry().center(k));
      pr.region = std::move(reg);
      r.regions.push_back(std::move(pr));
    }
  }
  /// The surface direction of a region: its normal turned away from the sphere's centre (outwards
  /// on an object around the centre), else the direction from the centre to its centroid, else up.
  Point3 region_normal(const ConflictRegion& reg) const {
    const Point3 out = reg.centroid - *params_.center;
    Point3 n = reg.normal ? *reg.normal : out;
    if (reg.normal && n.dot(out) < 0) n = -n;
    if (!(n.norm() > 1e-9)) n = Point3::UnitZ();
    return n.normalized();
  }
  /// The axis of a region's cone of views: region_normal() with its elevation clamped to
  /// [min_elevation, max_elevation] (the arm reaches no eye below the band: a region on the table
  /// top with a horizontal normal is viewed from as flat as the band allows).
  Point3 region_axis(const ConflictRegion& reg) const {
    const Point3 n = region_normal(reg);
    const double el = std::clamp(std::asin(std::clamp(n.z(), -1.0, 1.0)), params_.min_elevation, params_.max_elevation);
    const double h = std::hypot(n.x(), n.y());
    const double az = h > 1e-9 ? std::atan2(n.y(), n.x()) : 0.0;
    return Point3(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
  }
  /// A view of the open region r.regions[i] near its normal from a new direction (see the class
  /// comment). Fills r and returns true, or returns false if there is none or the region was
  /// aimed at max_region_views times.
  template <OccupancyGrid Grid>
  bool conflict_view(const Grid& grid, ArmPlan& r, std::size_t i, const std::vector<Point3>& hazard,
                     const ExplainedSpace* explained) {
    const ConflictRegion& reg = r.regions[i].region;
    int& aimed = regions_.views(reg);
    if (aimed >= params_.conflicts.max_region_views) return false;
    const Point3 axis = region_axis(reg), normal = region_normal(reg);
    // An orthonormal frame around the axis for the cone.
    const Point3 u =
        (std::abs(axis.z()) < 0.9 ? axis.cross(Point3::UnitZ()) : axis.cross(Point3::UnitX())).normalized();
    const Point3 w = axis.cross(u);
    SeededRandom rng =
        candidate_random(params_.seed, static_cast<std::uint64_t>(views_), CandidateStream::Conflict, i + 1);
    const double cos_max = std::cos(params_.normal_cone);
    std::vector<Pose> views;
    std::vector<std::vector<Pose>> paths;
    for (int k = 0; k < params_.candidates; ++k) {
      // Uniform in solid angle over the cone.
      const double c = 1.0 - rng.uniform() * (1.0 - cos_max), phi = 2 * std::numbers::pi * rng.uniform();
      const double sn = std::sqrt(std::max(0.0, 1.0 - c * c));
      const Point3 d = c * axis + sn * (std::cos(phi) * u + std::sin(phi) * w);
      if (std::asin(std::clamp(d.z(), -1.0, 1.0)) < params_.min_elevation - 1e-12 ||
          std::asin(std::clamp(d.z(), -1.0, 1.0)) > params_.max_elevation + 1e-12)
        continue;  // outside the arm's elevation band
      const Point3 eye = reg.centroid + params_.sphere_radius * d;
      if (!new_direction(reg.centroid, eye, reg.views, params_.conflicts.min_angle)) continue;
      const Pose v = look_at(eye, reg.centroid);
      std::vector<Pose> body = body_path(v);
      if (!collision_free(grid, v, body, hazard, explained)) continue;
      std::vector<Pose> cast;
      for (std::size_t p = 0; p < body.size(); p += static_cast<std::size_t>(params_.gain_profile_stride))
        cast.push_back(body[p]);
      views.push_back(v);
      paths.push_back(std::move(cast));
    }
    r.sampled += static_cast<std::size_t>(params_.candidates);
    if (views.empty()) return false;
    // Near the normal first, then by gain: (0.5 + 0.5 cos angle to the normal) (1 + gain / max gain).
    ScoredCandidates scored = score_candidates(
        grid, rays_, paths, params_.gain, params_.threads, [&](std::size_t k, double gain, double max_gain) {
          const Point3 d = (Point3(views[k].translation()) - reg.centroid).normalized();
          return (0.5 + 0.5 * std::max(0.0, d.dot(normal))) * (1.0 + (max_gain > 0 ? gain / max_gain : 0.0));
        });
    const std::size_t best = *scored.best;
    ++aimed;
    r.considered += scored.gains.size();
    r.candidates = std::move(views);
    r.gains = std::move(scored.gains);
    r.selected = best;
    r.reason = ViewReason::Conflict;
    r.conflict_region = i;
    r.view = r.candidates[best];
    r.gain = r.gains[best].gain;
    r.relative_gain = scored.relative_gain;
    return true;
  }
  /// Records the striper positions of the sweep around \p view (conflict-aware modelling only).
  void record_sweep(const Pose& view) {
    if (!params_.conflicts.enabled) return;
    for (const Pose& s : sweep(view)) origins_.push_back(s.translation());
  }
  template <OccupancyGrid Grid>
  bool collision_free(const Grid& grid, const Pose& view, const std::vector<Pose>& body,
                      const std::vector<Point3>& hazard, const ExplainedSpace* explained) const {
    return !refusal(grid, view, body, hazard, explained).has_value();
  }
  /// The first reason along the sweep around \p view (flange poses \p body) why it breaks the
  /// safety contract (class comment), or nothing if it keeps it.
  template <OccupancyGrid Grid>
  std::optional<SweepRefusal> refusal(const Grid& grid, const Pose& view, const std::vector<Pose>& body,
                                      const std::vector<Point3>& hazard, const ExplainedSpace* explained) const {
    const std::vector<Pose> sensor = sweep(view);
    const double m = params_.collision_margin;
    const double hm = m + params_.conflicts.safety_margin;
    const double spacing = params_.profiles > 1 ? params_.sweep_length / (params_.profiles - 1) : 0.0;
    const std::size_t every = spacing > 0 && m > spacing ? static_cast<std::size_t>(m / spacing) : 1;
    for (std::size_t k = 0; k < sensor.size(); ++k) {
      const bool check = k % every == 0 || k + 1 == sensor.size();
      for (const Point3& p : {Point3(sensor[k].translation()), Point3(body[k].translation())}) {
        if (p.z() < params_.support_height + m) return SweepRefusal::Table;
        if (check && !outside_collision_space(grid, p, m)) return SweepRefusal::Occupied;
        if (check && explained && !outside_explained_collision_space(grid, *explained, p, m))
          return SweepRefusal::Unexplained;
        for (const Point3& h : hazard)
          if ((h - p).squaredNorm() <= hm * hm) return SweepRefusal::ConflictMargin;
      }
    }
    return std::nullopt;
  }

  SensorRig rig_;
  ArmPlannerParams params_;
  RayBundle rays_;
  int views_ = 0;
  std::vector<Point3> origins_;
  RegionMemory regions_{0.1 * params_.sphere_radius};  ///< regions are recognised within a tenth of the sphere's radius
};

}  // namespace intervox
