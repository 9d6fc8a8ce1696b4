// The program scripts/walk_count.py traces: a depth scan into the map and one planning step of the
// safe configuration (docs/experiments.md, "What to choose"), in the room with a pillar of
// examples/robot_loop.cpp, the eight-camera base. Built with -finstrument-functions; the hooks below
// record, while tracing is on, each function entered and left, in order; walk_count.py turns the
// record into the files a reader enters (docs/notes/code-walks.md).
//
// INTERVOX_WALK_API selects the API of the tree it is built against: 1 for the planners that kept
// their own evidence (planner.observe(), before issue 73's one map), 2 for ExplainedMap.
#include <intervox/grid/named_grids.hpp>
#include <intervox/plan/mobile_planner.hpp>
#include <intervox/raycast/insert.hpp>
#if INTERVOX_WALK_API >= 2
#include <intervox/map/explained_map.hpp>
#endif

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <span>
#include <string_view>
#include <unordered_set>
#include <vector>

namespace iv = intervox;

namespace {
bool g_tracing = false;
std::FILE* g_out = nullptr;
std::unordered_set<void*>* g_seen = nullptr;  // the functions entered so far (standard library: not instrumented)
}  // namespace

// The first entry of each function while tracing is on, in order: what walk_count.py reads.
extern "C" {
__attribute__((no_instrument_function)) void __cyg_profile_func_enter(void* fn, void* /*site*/) {
  if (g_tracing && g_seen->insert(fn).second) std::fprintf(g_out, "> %p\n", fn);
}
__attribute__((no_instrument_function)) void __cyg_profile_func_exit(void*, void*) {}
}

namespace {
const iv::Point3 kRoomLo(0.0, 0.0, 0.0), kRoomHi(6.0, 4.0, 2.5);
const iv::Point3 kPillarLo(3.0, 1.6, 0.0), kPillarHi(3.6, 2.2, 2.5);

__attribute__((no_instrument_function)) double exit_distance(const iv::Point3& o, const iv::Point3& d) {
  double t = 1e9;
  for (int k = 0; k < 3; ++k) {
    if (d[k] > 1e-12) t = std::min(t, (kRoomHi[k] - o[k]) / d[k]);
    if (d[k] < -1e-12) t = std::min(t, (kRoomLo[k] - o[k]) / d[k]);
  }
  return t;
}
__attribute__((no_instrument_function)) double entry_distance(const iv::Point3& o, const iv::Point3& d) {
  double t0 = 0, t1 = 1e9;
  for (int k = 0; k < 3; ++k) {
    if (std::abs(d[k]) < 1e-12) {
      if (o[k] < kPillarLo[k] || o[k] > kPillarHi[k]) return 1e9;
      continue;
    }
    double a = (kPillarLo[k] - o[k]) / d[k], b = (kPillarHi[k] - o[k]) / d[k];
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
  }
  return t0 <= t1 ? t0 : 1e9;
}

std::vector<iv::Beam> sense(const iv::SensorRig& rig, const iv::Pose& body) {
  std::vector<iv::Beam> beams;
  for (const iv::SensorRay& s : rig.rays(body)) {
    const iv::Ray& r = s.ray;
    const double t = std::min(exit_distance(r.origin, r.direction), entry_distance(r.origin, r.direction));
    if (t < s.min_range) continue;
    beams.push_back({r.origin, r.at(std::min(t, r.range)), t <= r.range});
  }
  return beams;
}
}  // namespace

/// argv[1]: the file the trace goes to; argv[2]: "frame" (trace one scan into the map), "plan"
/// (trace one planning step: the map's analyses and the planner's decision) or "decide" (the
/// planner's plan() alone). The planner runs kWarmSteps steps untraced first.
int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: walk_driver OUT frame|plan|decide\n");
    return 2;
  }
  g_out = std::fopen(argv[1], "w");
  if (!g_out) return 2;
  const std::string_view mode = argv[2];
  if (mode != "frame" && mode != "plan" && mode != "decide") {
    std::fprintf(stderr, "walk_driver: unknown mode (frame, plan or decide)\n");
    return 2;
  }
  const bool trace_frame = mode == "frame";
  std::unordered_set<void*> seen;
  g_seen = &seen;
  constexpr int kWarmSteps = 3;

  iv::MobilePlannerParams p;
  p.seed = 1;
  p.threads = 1;
  p.max_steps = kWarmSteps + 2;
  p.explained.enabled = true;
  p.explained.unexplained_hazards = true;
  p.explained.open_group_hazards = true;
  p.explained.close_wall_gaps = true;
  const iv::SensorRig rig = iv::SensorRig::mobile_base();
  iv::MobilePlanner planner(rig, p);
#if INTERVOX_WALK_API >= 2
  iv::ExplainedMap<iv::IntervalGrid> map = planner.make_map(iv::IntervalGrid(0.1));
#else
  iv::IntervalGrid grid(0.1);
  iv::InsertOptions insert;
  insert.max_range = planner.max_range();
  insert.threads = 1;
#endif
  iv::Pose pose = iv::planar_pose(iv::Point3(1.0, 1.0, 0.0), 0.0);
  for (int step = 0; step <= kWarmSteps; ++step) {
    const bool traced_step = step == kWarmSteps;
    g_tracing = traced_step && mode == "plan";
#if INTERVOX_WALK_API >= 2
    map.update_analysis();
    g_tracing = traced_step && !trace_frame;
    const iv::MobilePlan plan = planner.plan(map, pose);
#else
    g_tracing = traced_step && !trace_frame;
    const iv::MobilePlan plan = planner.plan(grid, pose);
#endif
    g_tracing = false;
    if (plan.termination != iv::Termination::Running) {
      std::fprintf(stderr, "walk_driver: the planner stopped before the traced step\n");
      return 1;
    }
    bool first_scan = true;
    for (const iv::Pose& scan : plan.scans) {
      pose = scan;
      const std::vector<iv::Beam> b = sense(rig, pose);
      g_tracing = traced_step && trace_frame && first_scan;
#if INTERVOX_WALK_API >= 2
      map.insert(std::span<const iv::Beam>(b));
#else
      iv::insert_beams(grid, std::span<const iv::Beam>(b), insert);
      planner.observe(grid, std::span<const iv::Beam>(b));
#endif
      g_tracing = false;
      first_scan = false;
    }
  }
  std::fclose(g_out);
  return 0;
}
