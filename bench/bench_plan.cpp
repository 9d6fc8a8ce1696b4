// Candidate evaluation throughput: the gain of candidate views for the mobile rig (eight ToF
// cameras, every 4th pixel row and column) in the lab room after a look-around, and for the arm's
// striper sweep (30 profiles, every 4th sample) around the workcell; single- and multi-threaded.
// And one whole arm planning step (ArmPlanner::plan at its defaults, one thread) on the polished
// part after six views, with the gain rule alone and with views that seek normals; one whole
// mobile planning step (MobilePlanner::plan, one thread) in the lab room after three views, plain,
// on explained free space, with unexplained hazards, and with the mirrors found before each plan. And the start rule's
// blind zone, with and without the exact walk, for eight cameras and for one.
#include <benchmark/benchmark.h>

#include <array>

#include <intervox/intervox.hpp>
#include <intervox/plan/arm_planner.hpp>
#include <intervox/plan/episode.hpp>
#include <intervox/plan/information_gain.hpp>
#include <intervox/plan/mobile_planner.hpp>
#include <intervox/plan/rig_rays.hpp>
#include <intervox/plan/view_sampling.hpp>
#include <intervox/raycast/raycast.hpp>
#include <intervox/sim/sim.hpp>
#include "bench_main.hpp"

#include <span>

namespace iv = intervox;

namespace {
template <class Grid>
struct MobileSetup {
  iv::sim::LabRoom lab = iv::sim::make_lab_room();
  iv::sim::SensorRig rig = iv::sim::SensorRig::mobile_base();
  Grid grid{0.05};
  iv::RayBundle rays = iv::rig_bundle(rig, 4);
  std::vector<iv::Pose> poses;
  iv::GainOptions opt{4.0, iv::GainCount::PerBeam, iv::Bounds{{0, 0, 0}, {8, 6, 3}}};
  MobileSetup() {
    for (int i = 0; i < 4; ++i) {
      const auto beams = iv::sim::simulate(rig, lab.scene, iv::planar_pose(lab.start, 0.2 * i), 11 + i);
      iv::InsertOptions io;
      io.max_range = 4.0;
      iv::insert_beams(grid, std::span<const iv::Beam>(beams), io);
    }
    for (int i = 0; i < 24; ++i)
      poses.push_back(iv::planar_pose({4.5 + 0.1 * (i % 6), 1.2 + 0.2 * (i / 6), 0}, 0.5 * i));
  }
};

// Arguments: threads, gain count (0 per beam, 1 per view).
template <class Grid>
void BM_MobileCandidates(benchmark::State& state) {
  static MobileSetup<Grid> s;
  const unsigned threads = static_cast<unsigned>(state.range(0));
  iv::GainOptions opt = s.opt;
  opt.count = state.range(1) ? iv::GainCount::PerView : iv::GainCount::PerBeam;
  std::uint64_t steps = 0;
  for (auto _ : state) {
    auto g = iv::evaluate_views(s.grid, s.rays, s.poses, opt, threads);
    for (const auto& v : g) steps += v.steps;
    benchmark::DoNotOptimize(g.data());
  }
  state.counters["candidates/s"] =
      benchmark::Counter(double(state.iterations() * s.poses.size()), benchmark::Counter::kIsRate);
  state.counters["voxel steps/s"] = benchmark::Counter(double(steps), benchmark::Counter::kIsRate);
}

template <class Grid>
struct ArmSetup {
  iv::sim::Workcell cell = iv::sim::make_workcell();
  iv::sim::SensorRig rig = iv::sim::SensorRig::arm();
  Grid grid{0.01, iv::Bounds{{0, 0, 0}, {1.5, 1.5, 1.5}}};
  iv::RayBundle rays = iv::rig_bundle(rig, 4);
  std::vector<std::vector<iv::Pose>> paths;
  iv::GainOptions opt{1.0, iv::GainCount::PerBeam, iv::Bounds{{0, 0, 0}, {1.5, 1.5, 1.5}}};
  ArmSetup() {
    iv::SphereSamplerParams sp;
    sp.center = cell.table_center + iv::Point3(0, 0, 0.1);
    sp.radius = 0.5;
    sp.views = 16;
    for (const iv::Pose& view : iv::sample_sphere(grid, sp, 5)) {
      std::vector<iv::Pose> path;
      for (const iv::Pose& sensor : iv::sim::linear_sweep(view, 0.3, 30)) path.push_back(rig.body_pose_for(0, sensor));
      paths.push_back(std::move(path));
    }
  }
};

// Arguments: threads, gain count (0 per beam, 1 per view: the arm planner's default).
template <class Grid>
void BM_ArmCandidates(benchmark::State& state) {
  static ArmSetup<Grid> s;
  const unsigned threads = static_cast<unsigned>(state.range(0));
  iv::GainOptions opt = s.opt;
  opt.count = state.range(1) ? iv::GainCount::PerView : iv::GainCount::PerBeam;
  std::uint64_t steps = 0;
  for (auto _ : state) {
    auto g = iv::evaluate_paths(s.grid, s.rays, s.paths, opt, threads);
    for (const auto& v : g) steps += v.steps;
    benchmark::DoNotOptimize(g.data());
  }
  state.counters["candidates/s"] =
      benchmark::Counter(double(state.iterations() * s.paths.size()), benchmark::Counter::kIsRate);
  state.counters["voxel steps/s"] = benchmark::Counter(double(steps), benchmark::Counter::kIsRate);
}
// One ArmPlanner::plan() at the defaults (the polished part, one thread) after an episode of six
// views; argument: views that seek normals (0 off, 1 on). Each iteration plans from a copy of the
// planner as it stood after the six views.
void BM_ArmPlanStep(benchmark::State& state) {
  struct Setup {
    iv::sim::Workcell cell = iv::sim::make_workcell();
    iv::ArmPlanner planner;
    iv::ExplainedMap<iv::DenseIntervalGrid> map;
    explicit Setup(bool normals)
        : planner(iv::SensorRig::arm(), params(normals)),
          map(planner.make_map(iv::DenseIntervalGrid{0.01, iv::Bounds{{0, 0, 0}, {1.5, 1.5, 1.5}}})) {
      iv::Episode episode(map, planner, iv::sim::SimulatedRig(cell.scene, planner.rig(), 3), iv::Pose::Identity());
      for (int i = 0; i < 6; ++i) episode.step();
      map.update_analysis();
    }
    static iv::ArmPlannerParams params(bool normals) {
      iv::ArmPlannerParams p;
      p.threads = 1;
      p.max_views = 1000;
      p.normals.enabled = normals;
      return p;
    }
  };
  static Setup off(false), on(true);
  const Setup& s = state.range(0) ? on : off;
  for (auto _ : state) {
    iv::ArmPlanner planner = s.planner;
    const iv::ArmPlan r = planner.plan(s.map);
    benchmark::DoNotOptimize(r.gain);
  }
}

// One MobilePlanner::plan() at the library's defaults (one thread), in the lab room (diffuse
// closet, interval-mean, 5 cm, region given) after the look-around and three views of seed 1;
// argument: 0 the plain planner, 1 explained free space (ExplainedPlanningParams::enabled), 2 with
// unexplained hazards too, 3 with find_mirrors too (the map's mirror search, run by
// update_analysis() before the timed loop, is not part of plan()), 4 the
// plain planner with passage views (MobilePlannerParams::passage_views: the passages are found on
// every map; frontiers remain here, so no passage view is planned), 5 the plain planner with the
// way back (MobilePlannerParams::driven_paths: the three paths driven are the map's driven cells),
// 6 configuration 2 with close_wall_gaps (the map's wall-gap analysis, likewise untimed).
// Each iteration plans from a copy of the planner as it stood then.
void BM_MobilePlanStep(benchmark::State& state) {
  struct Setup {
    iv::sim::LabRoom lab = iv::sim::make_lab_room();
    iv::SensorRig rig = iv::SensorRig::mobile_base();
    iv::MobilePlanner planner;
    iv::ExplainedMap<iv::IntervalGrid> map;
    iv::Pose pose = iv::Pose::Identity();
    explicit Setup(int config) : planner(rig, params(config)), map(planner.make_map(iv::IntervalGrid{0.05})) {
      iv::Episode episode(map, planner, iv::sim::SimulatedRig(lab.scene, rig, 1), iv::planar_pose(lab.start, 0.0));
      for (int i = 0; i < 4 && episode.termination() == iv::Termination::Running; ++i) episode.step();
      map.update_analysis();
      pose = episode.pose();
    }
    static iv::MobilePlannerParams params(int config) {
      iv::MobilePlannerParams p;
      p.region = iv::Bounds{{0.0, 0.0, 0.2}, {8.0, 6.0, 0.8}};
      p.threads = 1;
      p.seed = 1;
      p.max_steps = 1000;
      p.explained.enabled = config >= 1;
      p.explained.unexplained_hazards = config >= 2;
      p.explained.find_mirrors = config == 3;
      p.explained.close_wall_gaps = config == 6;
      if (config == 4 || config == 5) {
        p.explained.enabled = false;
        p.explained.unexplained_hazards = false;
        p.passage_views.enabled = config == 4;
        p.driven_paths = config == 5;
      }
      return p;
    }
  };
  static Setup plain(0), explained(1), hazards(2), mirrors(3), passages(4), way_back(5), gaps(6);
  const std::array<const Setup*, 7> setups{&plain, &explained, &hazards, &mirrors, &passages, &way_back, &gaps};
  const Setup& s = *setups.at(static_cast<std::size_t>(state.range(0)));
  for (auto _ : state) {
    iv::MobilePlanner planner = s.planner;
    const iv::MobilePlan r = planner.plan(s.map, s.pose);
    benchmark::DoNotOptimize(r.selected);
  }
}

// A plan where only a passage is left: the lab room with the annex (interval-mean, 5 cm, region
// given, one thread), the plain planner's episode of seed 10 run to its end (the doorway closed,
// no reachable frontier); then a planner new to that grid, after its look-around call at the
// episode's last pose, plans once: argument 0 without passage views (the plan ends the
// exploration), 1 with them (a passage view at the doorway). Each iteration plans from a copy.
void BM_PassagePlanStep(benchmark::State& state) {
  struct Setup {
    iv::sim::LabRoom lab = iv::sim::make_lab_room({.annex = true});
    iv::IntervalGrid grid{0.05};
    iv::SensorRig rig = iv::SensorRig::mobile_base();
    iv::Pose pose = iv::Pose::Identity();
    Setup() {
      iv::MobilePlanner plain(rig, params(false));
      iv::Episode episode(grid, plain, iv::sim::SimulatedRig(lab.scene, rig, 10), iv::planar_pose(lab.start, 0.0));
      episode.run();
      pose = episode.pose();
    }
    static iv::MobilePlannerParams params(bool passages) {
      iv::MobilePlannerParams p;
      p.region = iv::Bounds{{0.0, 0.0, 0.2}, {11.1, 6.5, 0.8}};
      p.threads = 1;
      p.seed = 10;
      p.max_steps = 30;
      p.passage_views.enabled = passages;
      return p;
    }
  };
  static const Setup s;
  iv::MobilePlanner planner(s.rig, Setup::params(state.range(0) == 1));
  planner.plan(s.grid, s.pose);  // the look-around
  const iv::ViewReason expected = state.range(0) == 1 ? iv::ViewReason::Passage : iv::ViewReason::None;
  if (iv::MobilePlanner check = planner; check.plan(s.grid, s.pose).reason != expected) {
    state.SkipWithError("the annex episode did not end with only the doorway's passage left");
    return;
  }
  for (auto _ : state) {
    iv::MobilePlanner p = planner;
    const iv::MobilePlan r = p.plan(s.grid, s.pose);
    benchmark::DoNotOptimize(r.selected);
  }
}

// The start rule's blind zone, built once per episode: argument 0 the hull's table (BlindZone's
// constructor), 1 the table and the exact walk of every beam of the look-around through a 5 cm
// grid (BlindZone::trace, MobilePlannerParams::exact_blind_zone); second argument 0 the mobile
// base's eight cameras (4 turns), 1 one forward O3D-100 (15 turns).
void BM_BlindZone(benchmark::State& state) {
  iv::SensorRig rig = iv::SensorRig::mobile_base();
  if (state.range(1) == 1) {
    rig = iv::SensorRig();
    const iv::Point3 mount(0.3, 0.0, 0.5);
    rig.add(iv::DepthCamera::o3d100(), iv::look_at(mount, mount + iv::Point3::UnitX()), "front");
  }
  const std::vector<double> yaws = iv::look_around_yaws(rig, iv::MobilePlannerParams{}.look_around_scans);
  const double radius = *iv::blind_radius(rig, yaws, 0.2, 0.8);
  const iv::GridGeometry geometry(0.05);
  const iv::Pose start = iv::planar_pose(iv::Point3(6.0, 1.5, 0.0), 0.0);
  for (auto _ : state) {
    iv::BlindZone zone(rig, yaws, radius);
    if (state.range(0) == 1) zone.trace(geometry, start);
    benchmark::DoNotOptimize(zone.traced());
  }
}
}  // namespace

// The interval-mean update with the entropy of the state (the other criterion).
using IntervalEntropyGrid = iv::VoxelGrid<iv::IntervalUpdate<iv::MeanState>, iv::Entropy, iv::SparseStorage>;
BENCHMARK_TEMPLATE(BM_MobileCandidates, iv::BayesGrid)
    ->ArgsProduct({{1, 2}, {0, 1}})
    ->ArgNames({"threads", "per_view"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_TEMPLATE(BM_MobileCandidates, iv::IntervalGrid)
    ->ArgsProduct({{1, 2}, {0, 1}})
    ->ArgNames({"threads", "per_view"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_TEMPLATE(BM_MobileCandidates, IntervalEntropyGrid)
    ->Args({1, 0})
    ->ArgNames({"threads", "per_view"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_TEMPLATE(BM_MobileCandidates, iv::CompactIntervalGrid)
    ->ArgsProduct({{1}, {0, 1}})
    ->ArgNames({"threads", "per_view"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_TEMPLATE(BM_ArmCandidates, iv::DenseBayesGrid)
    ->ArgsProduct({{1, 2}, {0, 1}})
    ->ArgNames({"threads", "per_view"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_TEMPLATE(BM_ArmCandidates, iv::DenseIntervalGrid)
    ->ArgsProduct({{1, 2}, {0, 1}})
    ->ArgNames({"threads", "per_view"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_MobilePlanStep)->DenseRange(0, 6)->ArgName("config")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_PassagePlanStep)->Arg(0)->Arg(1)->ArgName("passages")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_ArmPlanStep)->Arg(0)->Arg(1)->ArgName("normals")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_BlindZone)
    ->ArgsProduct({{0, 1}, {0, 1}})
    ->ArgNames({"exact", "one_camera"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
int main(int argc, char** argv) { return bench::run_main(argc, argv); }
