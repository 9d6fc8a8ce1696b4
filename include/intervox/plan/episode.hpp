#pragma once
/// \file
/// The episode runner: joins a map (a plain grid, or an ExplainedMap that owns the grid and its
/// evidence), a planner (MobilePlanner, ArmPlanner or any type with the same shape) and any sensor
/// source — the simulator (sim::SimulatedRig), a recorded sequence, or the user's robot through a
/// callback — and repeats update the map's analysis, plan, drive, sense, insert until the planner
/// ends the episode. The planner only reads the map. It records every plan, the poses driven
/// through, the beams inserted and the timings.
///
/// Motion: the robot follows the plan's path (no teleporting): the runner passes through every
/// pose of the path in order and records it in trajectory(); how the robot gets from one pose to
/// the next is the robot's business (a real robot's source moves it when asked to sense at a pose).
/// Sensing: the runner senses only at the plan's scan poses (the views), not along the path, as in
/// the thesis' experiments, so that a simulated episode gives the same map whatever the path; a
/// user loop that wants data from the drive senses along `plan.path` itself.

#include <intervox/core/error.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/map/explained_map.hpp>
#include <intervox/plan/planner.hpp>
#include <intervox/raycast/insert.hpp>

#include <chrono>
#include <concepts>
#include <cstddef>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

namespace intervox {

/// A sensor source: given the body pose the robot is at, return the beams it measured there
/// (world frame, ready for insert_beams). The simulator's SimulatedRig is one; a lambda that
/// commands a real robot and converts its depth images is another.
template <class S>
concept SensorSource = requires(S& source, const Pose& body) {
  { source(body) } -> std::convertible_to<std::vector<Beam>>;
};

/// What an episode maps into: a VoxelGrid, or an ExplainedMap of one.
template <class M>
concept EpisodeMap = OccupancyGrid<M> || kIsExplainedMap<M>;

/// A planner the runner can drive: `plan(map, pose)` returns a ViewPlan (or a type derived from
/// it), and `max_range()` is the range up to which beams without a return count as free.
template <class P, class Map>
concept EpisodePlanner = requires(P& planner, const P& cp, const Map& map, const Pose& pose) {
  { planner.plan(map, pose) } -> std::derived_from<ViewPlan>;
  { cp.max_range() } -> std::convertible_to<double>;
};

/// Options of the runner.
struct EpisodeOptions {
  /// Insertion options for a plain grid; the max range is taken from the planner's max_range() if
  /// unset. An ExplainedMap inserts with its own (given when it was made).
  InsertOptions insert{};
};

/// What one step of an episode did.
/// \tparam Plan the planner's plan type (MobilePlan, ArmPlan)
template <class Plan>
struct EpisodeStep {
  int step = 0;                  ///< 0 for the planner's initial view
  Plan plan;                     ///< the decision (its path, scans, gains, termination)
  Pose pose = Pose::Identity();  ///< body pose after the step
  std::size_t beams = 0;         ///< beams inserted
  double seconds_planning = 0;   ///< plan()
  double seconds_sensing = 0;    ///< the source's calls
  double seconds_inserting = 0;  ///< insertion of what the source returned into the map (grid and evidence)
  double seconds_total = 0;
};

/// Runs a planner against a sensor source on one map.
///
/// \tparam Map a VoxelGrid, or an ExplainedMap (then every scan goes through its insert(), and
///         its update_analysis() runs before every plan)
/// \tparam Planner an EpisodePlanner for Map (kept by reference)
/// \tparam Source a SensorSource (kept by value; pass std::ref to keep your own)
///
/// Thread safety: not thread-safe; one runner per map. The planner and the source may use
/// threads inside their calls.
template <class Map, class Planner, class Source>
requires EpisodeMap<Map> && EpisodePlanner<Planner, Map> && SensorSource<Source>
class Episode {
 public:
  using Plan = std::remove_cvref_t<decltype(std::declval<Planner&>().plan(std::declval<const Map&>(),
                                                                          std::declval<const Pose&>()))>;
  using Step = EpisodeStep<Plan>;

  /// \param map the map to fill (kept by reference; must outlive the runner)
  /// \param planner the planner (kept by reference)
  /// \param source the sensor source
  /// \param start the robot's body pose at the start
  /// \throws InvalidArgument for a non-finite start pose or invalid insertion options.
  Episode(Map& map, Planner& planner, Source source, const Pose& start, EpisodeOptions options = {})
      : map_(map), planner_(planner), source_(std::move(source)), options_(std::move(options)), pose_(start) {
    if (!start.matrix().allFinite()) ParamCheck("intervox::Episode").fail("start pose is not finite");
    if (!options_.insert.has_max_range()) options_.insert.max_range = planner_.max_range();
    options_.insert.validate();
    trajectory_.push_back(pose_);
  }

  /// Plans, drives the plan's path, senses and inserts at its scan poses. Does nothing once the
  /// episode has ended (returns a step holding the termination).
  const Step& step() {
    const auto t0 = std::chrono::steady_clock::now();
    Step s;
    s.step = static_cast<int>(steps_.size());
    if (termination_ != Termination::Running) {
      s.plan.termination = termination_;
      s.pose = pose_;
      last_ = std::move(s);
      return last_;
    }
    if constexpr (kIsExplainedMap<Map>) map_.update_analysis();
    s.plan = planner_.plan(std::as_const(map_), pose_);
    s.seconds_planning = seconds_since(t0);
    if (s.plan.termination != Termination::Running) {
      termination_ = s.plan.termination;
    } else {
      for (const Pose& p : s.plan.path) drive(p);
      for (const Pose& p : s.plan.scans) {
        drive(p);
        s.beams += sense_and_insert(p, s.seconds_sensing, s.seconds_inserting);
      }
    }
    s.pose = pose_;
    s.seconds_total = seconds_since(t0);
    steps_.push_back(std::move(s));
    return steps_.back();
  }

  /// Steps until the planner ends the episode; returns the reason.
  Termination run() {
    while (termination_ == Termination::Running) step();
    return termination_;
  }

  /// Senses at the body poses \p scans and inserts each scan, outside the planning loop (scripted
  /// views; recorded in trajectory(), not in steps()). Returns the number of beams inserted.
  std::size_t sense(const std::vector<Pose>& scans) {
    double sensing = 0, inserting = 0;
    std::size_t n = 0;
    for (const Pose& p : scans) {
      drive(p);
      n += sense_and_insert(p, sensing, inserting);
    }
    return n;
  }

  Termination termination() const noexcept { return termination_; }
  /// The robot's body pose now.
  const Pose& pose() const noexcept { return pose_; }
  /// Every body pose the robot passed through, in order: the start, each path's poses, each scan pose.
  const std::vector<Pose>& trajectory() const noexcept { return trajectory_; }
  /// The steps taken, the terminating one included.
  const std::vector<Step>& steps() const noexcept { return steps_; }
  /// Metres driven along the trajectory (positions only).
  double distance_driven() const noexcept {
    double d = 0;
    for (std::size_t i = 1; i < trajectory_.size(); ++i)
      d += (trajectory_[i].translation() - trajectory_[i - 1].translation()).norm();
    return d;
  }
  const EpisodeOptions& options() const noexcept { return options_; }
  Source& source() noexcept { return source_; }
  /// The map the episode fills (a grid or an ExplainedMap).
  const Map& map() const noexcept { return map_; }
  /// The map's grid.
  const auto& grid() const noexcept {
    if constexpr (kIsExplainedMap<Map>)
      return map_.grid();
    else
      return map_;
  }

 private:
  static double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  void drive(const Pose& p) {
    if (!(p.matrix() == pose_.matrix())) trajectory_.push_back(p);
    pose_ = p;
  }
  std::size_t sense_and_insert(const Pose& p, double& sensing, double& inserting) {
    const auto t0 = std::chrono::steady_clock::now();
    const std::vector<Beam> beams = source_(p);
    const auto t1 = std::chrono::steady_clock::now();
    if constexpr (kIsExplainedMap<Map>)
      map_.insert(std::span<const Beam>(beams));
    else
      insert_beams(map_, std::span<const Beam>(beams), options_.insert);
    sensing += std::chrono::duration<double>(t1 - t0).count();
    inserting += seconds_since(t1);
    return beams.size();
  }

  Map& map_;
  Planner& planner_;
  Source source_;
  EpisodeOptions options_;
  Pose pose_;
  Termination termination_ = Termination::Running;
  std::vector<Pose> trajectory_;
  std::vector<Step> steps_;
  Step last_;
};

}  // namespace intervox
