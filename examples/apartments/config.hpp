#pragma once
// What the apartments benchmark runs: one run's configuration (world seed, world or its honest
// twin, planner, rig, update), the benchmark's options, the run list in a fixed order and its
// deterministic split into shards (docs/experiments.md, "Random apartments").
#include <intervox/core/error.hpp>

#include <charconv>
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

namespace apartments {

namespace iv = intervox;

/// The values of Run's fields: one list each, for the command line, the run list and the CSV.
inline constexpr std::string_view kPlanners[] = {"plain", "safe", "oracle"};
inline constexpr std::string_view kRigs[] = {"eight", "one"};
inline constexpr std::string_view kUpdates[] = {"interval-mean", "bayes"};
inline constexpr std::string_view kWorlds[] = {"lying", "honest"};

/// Seeds below this are for development; reports use seeds from it on, fixed before the runs
/// (docs/experiments.md, "Seeds").
inline constexpr std::uint64_t kFirstReportSeed = 10001;

template <std::size_t N>
std::vector<std::string> names(const std::string_view (&values)[N]) {
  return {std::begin(values), std::end(values)};
}

/// One run: a planner's episode in one world.
struct Run {
  std::uint64_t seed = 1;       ///< the apartment (sim::make_apartment) and the episode's noise
  std::string world = "lying";  ///< "lying": the apartment as drawn; "honest": its honest twin (every surface diffuse)
  std::string planner =
      "plain";  ///< "plain" (the thesis' planner), "safe" (docs/experiments.md's safe configuration) or "oracle"
  std::string rig = "eight";  ///< "eight": the thesis' eight cameras; "one": one forward camera on a differential drive
  std::string update = "interval-mean";  ///< "interval-mean" or "bayes"

  /// The configuration without the seed: the key results are grouped under.
  std::string group() const { return world + "/" + planner + "/" + rig + "/" + update; }
  /// The run's identity, e.g. to skip finished runs on --resume.
  std::string key() const { return group() + "/" + std::to_string(seed); }
};

/// The benchmark: seeds first_seed .. first_seed + worlds - 1, each with every planner, rig and
/// update listed, in the apartment and (with `twins`) in its honest twin, where the oracle is not
/// run (it would equal the plain planner there).
struct Options {
  std::uint64_t first_seed = 1;
  int worlds = 8;
  std::vector<std::string> planners{"plain", "safe", "oracle"};
  std::vector<std::string> rigs{"eight", "one"};
  std::vector<std::string> updates{"interval-mean", "bayes"};
  bool twins = true;
  double resolution = 0.1;  ///< m, the grid's voxels (unbounded, sparse)
  int max_steps = 30;       ///< views planned after the look-around
  unsigned threads = 1;     ///< threads of each run's planner and simulator (results do not depend on it)
  unsigned workers = 0;     ///< runs in parallel (0: all cores)
  std::string out = "out/apartments";
  int figure_worlds = 3;  ///< top views of every run of the first this many worlds (and of every run with a collision)
  bool progress = true;
  bool resume = false;
  int shard_index = 1;
  int shard_count = 1;
};

/// Parses "K/N" (1 <= K <= N). \throws iv::InvalidArgument for anything else.
inline void parse_shard(std::string_view text, int& index, int& count) {
  const auto slash = text.find('/');
  const auto whole = [](std::string_view s, int& v) {
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

/// Every run, in a fixed order: worlds (seeds), then lying before honest, planners, rigs, updates.
inline std::vector<Run> all_runs(const Options& o) {
  std::vector<Run> runs;
  for (int w = 0; w < o.worlds; ++w) {
    const std::uint64_t seed = o.first_seed + static_cast<std::uint64_t>(w);
    for (const std::string world : {"lying", "honest"}) {
      if (world == "honest" && !o.twins) continue;
      for (const std::string& planner : o.planners) {
        if (world == "honest" && planner == "oracle") continue;
        for (const std::string& rig : o.rigs)
          for (const std::string& update : o.updates) runs.push_back({seed, world, planner, rig, update});
      }
    }
  }
  return runs;
}

/// The runs of shard o.shard_index of o.shard_count: run i belongs to shard (i mod count) + 1.
inline std::vector<Run> shard_runs(const Options& o) {
  if (o.shard_count < 1 || o.shard_index < 1 || o.shard_index > o.shard_count)
    throw iv::InvalidArgument("apartments: shard " + std::to_string(o.shard_index) + "/" +
                              std::to_string(o.shard_count) + " is not valid");
  const std::vector<Run> all = all_runs(o);
  std::vector<Run> mine;
  for (std::size_t i = 0; i < all.size(); ++i)
    if (static_cast<int>(i % static_cast<std::size_t>(o.shard_count)) + 1 == o.shard_index) mine.push_back(all[i]);
  return mine;
}

}  // namespace apartments
