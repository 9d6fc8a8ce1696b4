#pragma once
/// \file
/// The per-grid bindings of python/src/planners.cpp (the template bind_/add_ functions and their
/// helpers), shared with credal.cpp, which instantiates them for the credal grids.

#include "common.hpp"
#include <intervox/plan/arm_planner.hpp>
#include <intervox/plan/episode.hpp>
#include <intervox/plan/mobile_planner.hpp>
#include <cmath>
#include <memory>

namespace intervox::python {
namespace bind {
struct PyEpisode;
}  // namespace bind
template <>
inline constexpr const char* kGuardedName<MobilePlanner> = "MobilePlanner";
template <>
inline constexpr const char* kGuardedName<ArmPlanner> = "ArmPlanner";
template <>
inline constexpr const char* kGuardedName<bind::PyEpisode> = "Episode";
}  // namespace intervox::python

#include "guard.hpp"

namespace intervox::python::bind {

/// A SensorSource that calls a Python callable with the body pose (4x4) and expects the beams back
/// as (origins, ends) or (origins, ends, hits) (origins (N, 3) or one (3,) origin).
struct PySource {
  py::object fn;
  std::vector<Beam> operator()(const Pose& body) {
    py::gil_scoped_acquire gil;
    const py::object r = fn(from_pose(body));
    if (!py::isinstance<py::tuple>(r) && !py::isinstance<py::list>(r))
      throw InvalidArgument("episode source: the callable must return (origins, ends) or (origins, ends, hits)");
    const auto seq = py::reinterpret_borrow<py::sequence>(r);
    if (seq.size() == 2) return beams_from_numpy(seq[0], seq[1], py::none());
    if (seq.size() == 3) return beams_from_numpy(seq[0], seq[1], seq[2]);
    throw InvalidArgument("episode source: the callable must return (origins, ends) or (origins, ends, hits)");
  }
};

/// One step of an episode, for Python.
struct PyStep {
  int step = 0;
  py::object plan;
  Pose pose = Pose::Identity();
  std::size_t beams = 0;
  double seconds_planning = 0, seconds_sensing = 0, seconds_inserting = 0, seconds_total = 0;
};

/// The episode runner behind one Python class, whatever the grid and planner.
class EpisodeBase {
 public:
  virtual ~EpisodeBase() = default;
  virtual PyStep step() = 0;
  virtual Termination run() = 0;
  virtual std::size_t sense(const std::vector<Pose>& scans) = 0;
  virtual Termination termination() const = 0;
  virtual Pose pose() const = 0;
  virtual std::vector<Pose> trajectory() const = 0;
  virtual double distance_driven() const = 0;
  virtual std::vector<PyStep> steps() const = 0;
  /// A copy of the map's explained channel, or None without it.
  virtual py::object explained_space() const = 0;
};

/// The runner over an ExplainedMap that refers to the user's grid and owns the evidence the
/// planner reads (its map_options(): none for the plain planners, whose map is the grid alone).
template <class G, class P>
class EpisodeImpl final : public EpisodeBase {
 public:
  EpisodeImpl(G& grid, P& planner, PySource source, const Pose& start, const InsertOptions& insert)
      : map_(grid, planner.map_options(), insert), ep_(map_, planner, std::move(source), start) {}
  PyStep step() override {
    const typename Ep::Step* s = nullptr;
    {
      py::gil_scoped_release release;
      s = &ep_.step();
    }
    return convert(*s);
  }
  Termination run() override {
    py::gil_scoped_release release;
    return ep_.run();
  }
  std::size_t sense(const std::vector<Pose>& scans) override {
    py::gil_scoped_release release;
    return ep_.sense(scans);
  }
  Termination termination() const override { return ep_.termination(); }
  Pose pose() const override { return ep_.pose(); }
  std::vector<Pose> trajectory() const override { return ep_.trajectory(); }
  double distance_driven() const override { return ep_.distance_driven(); }
  std::vector<PyStep> steps() const override {
    std::vector<PyStep> out;
    for (const auto& s : ep_.steps()) out.push_back(convert(s));
    return out;
  }
  py::object explained_space() const override {
    if (!map_.explained()) return py::none();
    return py::cast(ExplainedSpace(*map_.explained()));
  }

 private:
  using Map = ExplainedMap<G&>;
  using Ep = Episode<Map, P, PySource>;
  static PyStep convert(const typename Ep::Step& s) {
    return {
        s.step,         py::cast(s.plan), s.pose, s.beams, s.seconds_planning, s.seconds_sensing, s.seconds_inserting,
        s.seconds_total};
  }
  Map map_;
  Ep ep_;
};

/// The Python Episode: the runner plus the objects it refers to (the grid and the planner, kept
/// alive by keep_alive; held exclusively by every call that steps or senses: hold()).
struct PyEpisode {
  std::unique_ptr<EpisodeBase> impl;
  const void* grid = nullptr;
  const char* grid_name = "";
  const void* planner = nullptr;
  const char* planner_name = "";

  /// Holds the grid and the planner for a call that changes them.
  struct Hold {
    ObjectHold grid, planner;
    explicit Hold(const PyEpisode& e) : grid(e.grid, true, e.grid_name), planner(e.planner, true, e.planner_name) {}
  };
};

/// max_range of an Episode: None (the planner's range) or a number > 0 (+inf: none).
inline double episode_max_range(const py::object& max_range) {
  if (max_range.is_none()) return -1.0;
  const double r = py::cast<double>(max_range);
  if (!(r > 0.0))
    throw InvalidArgument("Episode: max_range must be None (the planner's range) or > 0, got " + std::to_string(r));
  return r;
}

/// The insertion's options of an Episode: \p max_range (< 0: the planner's) on \p threads threads.
template <class P>
InsertOptions episode_insert(const P& planner, double max_range, unsigned threads) {
  InsertOptions o;
  o.max_range = max_range >= 0 ? max_range : planner.max_range();
  o.threads = threads;
  return o;
}

inline std::optional<Bounds> optional_bounds(const py::object& obj) {
  if (obj.is_none()) return std::nullopt;
  return to_bounds(obj);
}

template <class G>
void add_planning(guarded_class<MobilePlanner>& mobile, guarded_class<ArmPlanner>& arm,
                  guarded_class<PyEpisode>& episode) {
  mobile.def(
      "plan",
      [](MobilePlanner& p, const G& grid, const py::object& pose) {
        const Pose body = to_pose(pose, "pose");
        py::gil_scoped_release release;
        return p.plan(grid, body);
      },
      py::arg("grid"), py::arg("pose"),
      "The next view for the robot at `pose` (4x4 body pose) on `grid` (MobilePlan). The first call returns the\n"
      "look-around. The grid must not change during the call (the GIL is released). Explained planning reads the\n"
      "evidence of a map, not a grid alone: run it in an Episode, which keeps that evidence.");
  arm.def(
      "plan",
      [](ArmPlanner& p, const G& grid, const py::object& pose) {
        const Pose flange = pose.is_none() ? Pose::Identity() : to_pose(pose, "pose");
        py::gil_scoped_release release;
        return p.plan(grid, flange);
      },
      py::arg("grid"), py::arg("pose") = py::none(),
      "The next sweep on `grid` (ArmPlan). Explained planning and views that seek normals read the evidence of a\n"
      "map, not a grid alone: run them in an Episode, which keeps that evidence.");
  const auto make = [](auto& grid, auto& planner, const py::object& source, const py::object& start,
                       const py::object& max_range, unsigned threads) {
    using Grid = std::remove_reference_t<decltype(grid)>;
    using Planner = std::remove_reference_t<decltype(planner)>;
    if (!PyCallable_Check(source.ptr())) throw InvalidArgument("Episode: source must be callable");
    const Pose s = to_pose(start, "start pose");
    const InsertOptions insert = episode_insert(planner, episode_max_range(max_range), threads);
    return PyEpisode{std::make_unique<EpisodeImpl<Grid, Planner>>(grid, planner, PySource{source}, s, insert), &grid,
                     kGuardedName<Grid>, &planner, kGuardedName<Planner>};
  };
  episode.def(py::init([make](G& grid, MobilePlanner& planner, const py::object& source, const py::object& start,
                              const py::object& max_range, unsigned threads) {
                const ObjectHold hold_grid(&grid, true, kGridName<G>);
                const ObjectHold hold_planner(&planner, true, kGuardedName<std::remove_cvref_t<decltype(planner)>>);
                return make(grid, planner, source, start, max_range, threads);
              }),
              py::arg("grid"), py::arg("planner"), py::arg("source"), py::arg("start"), py::kw_only(),
              py::arg("max_range") = py::none(), py::arg("threads") = 1u, py::keep_alive<1, 2>(),
              py::keep_alive<1, 3>());
  episode.def(py::init([make](G& grid, ArmPlanner& planner, const py::object& source, const py::object& start,
                              const py::object& max_range, unsigned threads) {
                const ObjectHold hold_grid(&grid, true, kGridName<G>);
                const ObjectHold hold_planner(&planner, true, kGuardedName<std::remove_cvref_t<decltype(planner)>>);
                return make(grid, planner, source, start, max_range, threads);
              }),
              py::arg("grid"), py::arg("planner"), py::arg("source"), py::arg("start"), py::kw_only(),
              py::arg("max_range") = py::none(), py::arg("threads") = 1u, py::keep_alive<1, 2>(),
              py::keep_alive<1, 3>());
}

}  // namespace intervox::python::bind
