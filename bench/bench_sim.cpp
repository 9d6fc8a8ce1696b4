// Simulated beams per second: one view of the mobile rig in the lab room (8 x 64 x 48 beams) and
// in a random apartment of 80 m² with four rooms and every kind of lying surface it has room for,
// a striper sweep over the workcell (100 profiles x 640 samples), and the BVH against testing
// every primitive (the baseline) and the per-tile cones of the camera path on the same beams; with
// and without mirrors in the scene.
#include <benchmark/benchmark.h>
#include <intervox/sim/apartment.hpp>
#include <intervox/sim/sim.hpp>

#include <algorithm>
#include <cstdint>
#include <map>
#include <tuple>
#include <variant>
#include <vector>
#include "bench_main.hpp"

namespace iv = intervox;
namespace sim = intervox::sim;

namespace {
const sim::LabRoom& lab() {
  static const sim::LabRoom l = sim::make_lab_room({sim::Material::transparent()});
  return l;
}
// The lab room with a mirror closet and the thesis' reflective door (mirror).
const sim::LabRoom& mirror_lab() {
  static const sim::LabRoom l = [] {
    sim::LabRoomOptions o;
    o.closet_material = sim::Material::mirror();
    o.door_material = sim::Material::mirror();
    return sim::make_lab_room(o);
  }();
  return l;
}
// The workcell with its defaults (polished-metal ring, glass bottle) and with the first
// edition's materials (random-range ring, glass without Fresnel).
const sim::Workcell& cell(bool first_edition = false) {
  static const sim::Workcell w = sim::make_workcell();
  static const sim::Workcell old = [] {
    sim::WorkcellOptions o;
    o.part_material = sim::Material::specular_random_range();
    o.bottle_material = sim::Material::transparent_without_fresnel();
    return sim::make_workcell(o);
  }();
  return first_edition ? old : w;
}
iv::Pose start_pose() {
  iv::Pose p = iv::Pose::Identity();
  p.translation() = lab().start;
  return p;
}

// Mobile rig view; args: threads, scene (0: transparent closet, body at the start; 1: mirror
// closet and mirror door, body at the start; 2: the same mirrors, body 1 m in front of the closet).
void BM_MobileRigView(benchmark::State& state) {
  const auto rig = sim::SensorRig::mobile_base();
  const int scene = static_cast<int>(state.range(1));
  iv::Pose body = start_pose();
  if (scene == 2) body.translation() = iv::Point3(1.6, 4.0, 0.0);
  const sim::Scene& world = scene == 0 ? lab().scene : mirror_lab().scene;
  std::uint64_t seed = 0;
  std::vector<sim::BeamPath> paths;
  for (auto _ : state) {
    auto beams = sim::simulate(rig, world, body, ++seed, {static_cast<unsigned>(state.range(0))}, &paths);
    benchmark::DoNotOptimize(beams.data());
  }
  state.counters["beams/s"] =
      benchmark::Counter(double(state.iterations()) * rig.beam_count(), benchmark::Counter::kIsRate);
  state.counters["reflected"] = double(std::count(paths.begin(), paths.end(), sim::BeamPath::Reflected));
}
BENCHMARK(BM_MobileRigView)
    ->ArgsProduct({{1, 2}, {0, 1, 2}})
    ->ArgNames({"threads", "scene"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// A random apartment of 80 m² (four rooms, every fixture kind drawn): the worlds of the
// apartments benchmark at their largest.
const sim::Apartment& large_apartment() {
  static const sim::Apartment a = [] {
    sim::ApartmentOptions o;
    o.min_rooms = 4;
    o.room_area_min = o.room_area_max = 22.0;  // 88 m² drawn: clamped to max_area
    o.mix.fill(1.0);
    return sim::make_apartment(1, o);
  }();
  return a;
}

// The mobile rig's view at the apartment's start, against the lab room's (BM_MobileRigView,
// scene 0) in the same run; args: threads.
void BM_ApartmentRigView(benchmark::State& state) {
  const auto rig = sim::SensorRig::mobile_base();
  const sim::Apartment& a = large_apartment();
  iv::Pose body = iv::Pose::Identity();
  body.translation() = a.start;
  std::uint64_t seed = 0;
  for (auto _ : state) {
    auto beams = sim::simulate(rig, a.scene, body, ++seed, {static_cast<unsigned>(state.range(0))});
    benchmark::DoNotOptimize(beams.data());
  }
  state.counters["beams/s"] =
      benchmark::Counter(double(state.iterations()) * rig.beam_count(), benchmark::Counter::kIsRate);
  state.counters["m2"] = (a.footprint.max.x() - a.footprint.min.x()) * (a.footprint.max.y() - a.footprint.min.y());
  state.counters["objects"] = double(a.scene.size());
}
BENCHMARK(BM_ApartmentRigView)->Arg(1)->Arg(2)->ArgName("threads")->Unit(benchmark::kMillisecond)->UseRealTime();

// The same view as eight depth images (for insert_depth_image).
void BM_MobileRigImages(benchmark::State& state) {
  const auto rig = sim::SensorRig::mobile_base();
  const iv::Pose body = start_pose();
  std::uint64_t seed = 0;
  for (auto _ : state) {
    auto images = sim::simulate_images(rig, lab().scene, body, ++seed, {1});
    benchmark::DoNotOptimize(images.data());
  }
  state.counters["beams/s"] =
      benchmark::Counter(double(state.iterations()) * rig.beam_count(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_MobileRigImages)->Unit(benchmark::kMillisecond)->UseRealTime();

// Arm striper sweep of 100 profiles over the workcell (394 primitives, mostly the ring mesh);
// args: threads, materials (0: the defaults, polished-metal ring reflecting; 1: the first edition's).
void BM_StriperSweep(benchmark::State& state) {
  const auto striper = sim::LaserStriper::scancontrol_2700();
  const sim::Workcell& w = cell(state.range(1) == 1);
  const auto path = sim::sweep_towards({0.75, 0.25, 1.3}, w.table_center, 0.3, 100);
  std::uint64_t seed = 0;
  std::size_t reflected = 0;
  for (auto _ : state) {
    auto m = sim::simulate_sweep(striper, w.scene, path, ++seed, {static_cast<unsigned>(state.range(0))});
    reflected = static_cast<std::size_t>(std::count(m.paths.begin(), m.paths.end(), sim::BeamPath::Reflected));
    benchmark::DoNotOptimize(m.beams.data());
  }
  state.counters["beams/s"] = benchmark::Counter(double(state.iterations()) * 100 * 640, benchmark::Counter::kIsRate);
  state.counters["reflected"] = double(reflected);
}
BENCHMARK(BM_StriperSweep)
    ->ArgsProduct({{1, 2}, {0, 1}})
    ->ArgNames({"threads", "materials"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// First-hit queries only (no noise), BVH vs every primitive; arg 0: lab room, 1: workcell.
template <bool kBruteForce>
void BM_FirstHit(benchmark::State& state) {
  const sim::Scene& scene = state.range(0) == 0 ? lab().scene : cell().scene;
  std::vector<sim::SensorRay> rays;
  if (state.range(0) == 0) {
    rays = sim::SensorRig::mobile_base().rays(start_pose(), 2);
  } else {
    const auto arm = sim::SensorRig::arm();
    for (const auto& p : sim::sweep_towards({0.75, 0.25, 1.3}, cell().table_center, 0.3, 10)) {
      auto r = arm.rays(arm.body_pose_for(0, p), 1);
      rays.insert(rays.end(), r.begin(), r.end());
    }
  }
  for (auto _ : state) {
    double sum = 0;
    for (const auto& r : rays) {
      const auto h = kBruteForce ? scene.intersect_brute_force(r.ray.origin, r.ray.direction, 0, r.ray.range)
                                 : scene.intersect(r.ray.origin, r.ray.direction, 0, r.ray.range);
      if (h) sum += h->t;
    }
    benchmark::DoNotOptimize(sum);
  }
  state.counters["beams/s"] = benchmark::Counter(double(state.iterations()) * rays.size(), benchmark::Counter::kIsRate);
}
// First-hit queries of the same lab-room rays through the cones of 8 x 8 pixel tiles (what the
// simulator does for camera beams): one Scene::cone_primitives() per tile, intersect_among() per ray.
void BM_FirstHit_Cone(benchmark::State& state) {
  const sim::Scene& scene = lab().scene;
  const auto rig = sim::SensorRig::mobile_base();
  const auto rays = rig.rays(start_pose(), 2);
  struct Tile {
    std::uint32_t sensor = 0;
    int u0 = 0, v0 = 0, u1 = 0, v1 = 0;
    std::vector<std::size_t> rays;
  };
  std::map<std::tuple<std::uint32_t, int, int>, Tile> by_tile;
  const int k = sim::detail::kTileSize;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const auto& cam = std::get<sim::DepthCamera>(rig.sensors()[rays[i].sensor].sensor);
    const int w = cam.intrinsics.width, h = cam.intrinsics.height;
    const int u0 = static_cast<int>(rays[i].beam) % w / k * k, v0 = static_cast<int>(rays[i].beam) / w / k * k;
    Tile& t = by_tile[{rays[i].sensor, v0, u0}];
    t = {rays[i].sensor, u0, v0, std::min(w, u0 + k) - 1, std::min(h, v0 + k) - 1, std::move(t.rays)};
    t.rays.push_back(i);
  }
  std::vector<Tile> tiles;
  for (auto& [key, t] : by_tile) tiles.push_back(std::move(t));
  std::vector<sim::ConeCandidate> candidates;
  for (auto _ : state) {
    double sum = 0;
    for (const Tile& t : tiles) {
      const auto& cam = std::get<sim::DepthCamera>(rig.sensors()[t.sensor].sensor);
      scene.cone_primitives(
          sim::detail::pixel_cone(cam.intrinsics, rig.sensor_pose(t.sensor, start_pose()), t.u0, t.v0, t.u1, t.v1),
          candidates);
      for (const std::size_t i : t.rays) {
        const auto h =
            scene.intersect_among(candidates, rays[i].ray.origin, rays[i].ray.direction, 0, rays[i].ray.range);
        if (h) sum += h->t;
      }
    }
    benchmark::DoNotOptimize(sum);
  }
  state.counters["beams/s"] = benchmark::Counter(double(state.iterations()) * rays.size(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_FirstHit_Cone)->Arg(0)->Unit(benchmark::kMicrosecond);

BENCHMARK_TEMPLATE(BM_FirstHit, false)->Name("BM_FirstHit_Bvh")->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);
BENCHMARK_TEMPLATE(BM_FirstHit, true)->Name("BM_FirstHit_BruteForce")->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);
}  // namespace

int main(int argc, char** argv) { return bench::run_main(argc, argv); }
