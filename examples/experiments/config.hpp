#pragma once
// What the experiment sweep runs: one run's configuration (platform, surface, update, utility,
// conditions, seed), the sweep's options, the run list in a fixed order and its deterministic
// split into shards.
#include <intervox/core/error.hpp>

#include <charconv>
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

namespace experiments {

namespace iv = intervox;

/// The values of RunConfig's planner, room, rules and sensor: one list each, for the command line,
/// run_one() and results.csv.
inline constexpr std::string_view kPlanners[] = {"plain", "conflict-aware", "safe"};
inline constexpr std::string_view kRooms[] = {"lab", "annex", "front-only"};
inline constexpr std::string_view kRules[] = {"thesis", "library"};
inline constexpr std::string_view kSensorConditions[] = {"plain", "glint", "body", "one-camera"};

/// \p values as strings (a command-line option's allowed values).
template <std::size_t N>
std::vector<std::string> names(const std::string_view (&values)[N]) {
  return {std::begin(values), std::end(values)};
}

/// One run of the sweep.
struct RunConfig {
  std::string platform = "mobile";  ///< "mobile" (lab room) or "arm" (workcell)
  std::string surface = "diffuse";  ///< mobile: the closet's material; arm: the scanned object
  /// bayes, interval-lower, interval-mean, interval-upper, or the credal cells dirichlet-mean
  /// (ImpreciseDirichletUpdate) and belief-mean (DempsterShaferUpdate), which have no thesis
  /// preset and run with their defaults under either preset.
  std::string update = "bayes";
  std::string utility = "entropy";  ///< entropy, max-entropy
  /// Policy parameters: "thesis" (the thesis' presets with latching, Table 3.1 and 5.3.3, where the
  /// policy has them) or "clamped" (the library's defaults: clamping, no latching).
  std::string policies = "thesis";
  /// Mobile depth images: "removed" (floor returns cut out before insertion, thesis 3.3.1) or
  /// "kept". Arm runs have no floor in view and record "kept".
  std::string floor = "removed";
  /// Which voxels the gain sums over: "unknown" (voxels of unknown state, thesis 3.4) or "all".
  std::string gain = "unknown";
  /// "plain" (the thesis' planner), "conflict-aware" (docs/planning.md "Conflicts": the mobile
  /// planner's and the arm planner's conflict rules; interval and credal updates only) or "safe"
  /// (mobile, any update: the explained planner with enclosed and open lying columns as hazards
  /// and the gaps of seen walls closed, docs/planning.md "Planning on explained free space").
  std::string planner = "plain";
  std::uint64_t seed = 1;
  /// How never-observed voxels are classified: "unknown" (the library's default) or "by-rule" (the
  /// thesis, 4.1 / 5.3.4: IntervalParams::classify_unobserved, so that the lower rule calls them
  /// free and the upper rule occupied). Only the lower and upper interval rules run "by-rule" (for
  /// the others it changes nothing); every other run records "unknown".
  std::string unobserved = "unknown";
  /// Mobile: the room. "lab" (the thesis' lab room), "annex" (an open doorway in its east wall to
  /// an annex, sim::LabRoomOptions::annex; the region takes the annex in) or "front-only" (the
  /// closet's material on its front only, its body wood). The arm records "lab".
  std::string room = "lab";
  /// Mobile: the planner's start and map rules. "thesis" (whole columns within 1 m of the start
  /// free, hits not blocking: the thesis' rules, which both earlier editions ran) or "library"
  /// (the library's defaults: the rig's start rule, `hits_block`). The arm records "thesis".
  std::string rules = "thesis";
  /// Mobile: the sensing condition (kSensorConditions). "plain" (the thesis' eight cameras),
  /// "glint" (the near-normal glint of a time-of-flight camera at a specular surface,
  /// sim::SimOptions::glint), "body" (the robot's own body, which reflected beams can meet: the
  /// robot seen in a mirror, sim::SimOptions::body = RobotBody::mobile_base()) or "one-camera"
  /// (one forward camera, examples::front_camera_rig(), with the exact start rule and 5 frames
  /// per scan for the interval and credal updates, 3 for Bayes: docs/planning.md, "Any rig").
  /// The arm records "plain".
  std::string sensor = "plain";

  /// Configuration without the seed: the key that runs are aggregated under.
  std::string group() const {
    // The defaults ("unknown", "lab", "thesis", "plain") add nothing, so that keys and figure names
    // of earlier results stay as they were.
    return platform + "/" + surface + "/" + update + "/" + utility + "/" + policies + "/" + floor + "/" + gain + "/" +
           planner + (unobserved == "unknown" ? "" : "/unobserved-" + unobserved) +
           (room == "lab" ? "" : "/room-" + room) + (rules == "thesis" ? "" : "/rules-" + rules) +
           (sensor == "plain" ? "" : "/sensor-" + sensor);
  }
  /// The run's identity (configuration and seed), e.g. to skip finished runs on --resume.
  std::string key() const { return group() + "/" + std::to_string(seed); }
};

/// The sweep: the cross product of the lists, each over `seeds` seeds (1..seeds).
struct SweepOptions {
  std::vector<std::string> mobile_surfaces{"diffuse", "absorbing", "transparent", "specular"};
  std::vector<std::string> mobile_updates{"bayes", "interval-lower", "interval-mean", "interval-upper"};
  std::vector<std::string> utilities{"entropy", "max-entropy"};
  /// Arm runs: "part" (the ring-shaped mechanical part, polished metal) and "bottle" (glass).
  std::vector<std::string> arm_objects{"part", "bottle"};
  std::vector<std::string> arm_updates{"bayes", "interval-mean"};
  /// Policy presets to run ("thesis", "clamped"); the thesis condition first.
  std::vector<std::string> policies{"thesis"};
  /// Floor handling of the mobile runs ("removed", "kept").
  std::vector<std::string> floors{"removed"};
  /// Gain rules ("unknown": the thesis, "all").
  std::vector<std::string> gains{"unknown"};
  /// Planners ("plain", "conflict-aware" on both platforms, "safe" on the mobile robot);
  /// conflict-aware is skipped for Bayes, which cannot tell conflicts from ignorance, and safe for
  /// the arm.
  std::vector<std::string> planners{"plain"};
  /// Classification of never-observed voxels ("unknown", "by-rule"); "by-rule" runs only for
  /// interval-lower and interval-upper.
  std::vector<std::string> unobserved{"unknown"};
  /// Mobile rooms ("lab", "annex", "front-only"), start and map rules ("thesis", "library") and
  /// sensing conditions (kSensorConditions); see RunConfig.
  std::vector<std::string> rooms{"lab"};
  std::vector<std::string> rules{"thesis"};
  std::vector<std::string> sensors{"plain"};
  /// Arm runs with the first edition's workcell materials: the part a random-range specular
  /// surface (Material::specular_random_range()), the bottle glass without Fresnel reflection.
  bool arm_first_edition_materials = false;
  int seeds = 10;
  double resolution = 0.05;      ///< m, mobile grid
  double arm_resolution = 0.01;  ///< m, arm grid (dense, the 1.5 m workcell)
  int arm_max_views = 12;        ///< arm view budget, the initial view included
  int max_steps = 30;            ///< mobile step budget
  int gain_stride = 4;           ///< pixel stride of the gain rays
  double floor_cut = 0.05;       ///< m: with floor "removed", returns at or below this height are dropped
  unsigned workers = 0;  ///< runs in parallel (0: all cores, more are capped at them); each run is single-threaded
  std::string out = "out/experiments";
  bool figures = true;   ///< write the per-configuration pictures (first seed)
  bool progress = true;  ///< print a line per finished run
  bool resume = false;   ///< keep the runs already in out/results.csv and run only the others
  int shard_index = 1;   ///< this process runs shard shard_index of shard_count (1-based)
  int shard_count = 1;
};

/// Parses "K/N" (1 <= K <= N) into \p index and \p count.
/// \throws iv::InvalidArgument for anything else.
inline void parse_shard(std::string_view text, int& index, int& count) {
  const auto slash = text.find('/');
  const auto whole = [&](std::string_view s, int& v) {
    const auto [p, e] = std::from_chars(s.data(), s.data() + s.size(), v);
    return !s.empty() && e == std::errc{} && p == s.data() + s.size();
  };
  int k = 0, n = 0;
  if (slash == std::string_view::npos || !whole(text.substr(0, slash), k) || !whole(text.substr(slash + 1), n) ||
      n < 1 || k < 1 || k > n)
    throw iv::InvalidArgument("--shard: expected K/N with 1 <= K <= N, got '" + std::string(text) + "'");
  index = k;
  count = n;
}

/// True if classification \p unobserved is run for update \p update (see RunConfig::unobserved).
inline bool runs_unobserved(const std::string& update, const std::string& unobserved) {
  return unobserved == "unknown" || update == "interval-lower" || update == "interval-upper";
}

/// Every run of the sweep, in a fixed order (mobile, then arm; surfaces, updates, utilities,
/// policies, floors, gains, planners, classifications of never-observed space, rooms, rules,
/// sensors, seeds; the arm without floors, rooms, rules and sensors). Bayes runs have no
/// conflict-aware planner, the arm no safe one; only the lower and upper rules run "by-rule".
inline std::vector<RunConfig> sweep_configs(const SweepOptions& o) {
  std::vector<RunConfig> runs;
  for (const auto& s : o.mobile_surfaces)
    for (const auto& u : o.mobile_updates)
      for (const auto& h : o.utilities)
        for (const auto& pol : o.policies)
          for (const auto& fl : o.floors)
            for (const auto& g : o.gains)
              for (const auto& pl : o.planners) {
                if (pl == "conflict-aware" && u == "bayes") continue;
                for (const auto& un : o.unobserved) {
                  if (!runs_unobserved(u, un)) continue;
                  for (const auto& room : o.rooms)
                    for (const auto& ru : o.rules)
                      for (const auto& se : o.sensors)
                        for (int seed = 1; seed <= o.seeds; ++seed)
                          runs.push_back(
                              {"mobile", s, u, h, pol, fl, g, pl, static_cast<std::uint64_t>(seed), un, room, ru, se});
                }
              }
  for (const auto& obj : o.arm_objects)
    for (const auto& u : o.arm_updates)
      for (const auto& h : o.utilities)
        for (const auto& pol : o.policies)
          for (const auto& g : o.gains)
            for (const auto& pl : o.planners) {
              if ((pl == "conflict-aware" && u == "bayes") || pl == "safe") continue;
              for (const auto& un : o.unobserved) {
                if (!runs_unobserved(u, un)) continue;
                for (int seed = 1; seed <= o.seeds; ++seed)
                  runs.push_back({"arm", obj, u, h, pol, "kept", g, pl, static_cast<std::uint64_t>(seed), un});
              }
            }
  return runs;
}

/// The runs of shard o.shard_index of o.shard_count: run i of sweep_configs() belongs to shard
/// (i mod count) + 1, so the shards partition the sweep and each gets a mix of configurations.
inline std::vector<RunConfig> shard_configs(const SweepOptions& o) {
  if (o.shard_count < 1 || o.shard_index < 1 || o.shard_index > o.shard_count)
    throw iv::InvalidArgument("experiments: shard " + std::to_string(o.shard_index) + "/" +
                              std::to_string(o.shard_count) + " is not valid");
  const std::vector<RunConfig> all = sweep_configs(o);
  std::vector<RunConfig> mine;
  for (std::size_t i = 0; i < all.size(); ++i)
    if (static_cast<int>(i % static_cast<std::size_t>(o.shard_count)) + 1 == o.shard_index) mine.push_back(all[i]);
  return mine;
}

}  // namespace experiments
