#pragma once
// The apartments benchmark: every run of a shard on a pool of workers, each finished run appended
// to results.csv and timings.csv at once (an interrupted run keeps what finished; --resume skips
// it), a top view for the first worlds and for every run that met the true world, and the final
// files sorted in one canonical order, so that results.csv is the same for any number of workers
// and threads (docs/experiments.md, "Random apartments").
#include "config.hpp"
#include "episode.hpp"
#include "rows.hpp"
#include "top_view.hpp"

#include <intervox/core/parallel.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

namespace apartments {

/// The canonical order of runs: seed, then world, planner, rig and update in the order of their
/// lists (kWorlds, kPlanners, kRigs, kUpdates).
inline auto rank(const Run& r) {
  const auto at = [](const std::string& v, const auto& list) {
    return static_cast<std::size_t>(std::ranges::find(list, v) - std::begin(list));
  };
  return std::tuple{r.seed, at(r.world, kWorlds), at(r.planner, kPlanners), at(r.rig, kRigs), at(r.update, kUpdates)};
}

inline void sort_runs(std::vector<Result>& rows) {
  std::stable_sort(rows.begin(), rows.end(),
                   [](const Result& a, const Result& b) { return rank(a.run) < rank(b.run); });
}

/// The file name of a run's top view.
inline std::string figure_name(const Run& r) {
  std::string name = r.key();
  std::replace(name.begin(), name.end(), '/', '_');
  return name + ".png";
}

/// Writes the top view of \p result (from \p capture) into \p path.
inline void write_top_view(const std::string& path, const Result& result, const Capture& capture, const Options& o) {
  const iv::sim::Apartment a = iv::sim::make_apartment(result.run.seed);
  const iv::sim::Scene twin = a.honest_twin();
  const iv::sim::Scene& world = result.run.world == "honest" ? twin : a.scene;
  const iv::GridGeometry g(capture.resolution);
  iv::write_png(path, top_view(a, world, capture.columns ? &*capture.columns : nullptr, g, capture.trajectory, result,
                               planner_params(result.run, o)));
}

/// What a benchmark call did.
struct Report {
  std::vector<Result> results;  ///< every run of this shard with a result (resumed ones included), in canonical order
  std::size_t ran = 0;          ///< runs executed by this call
  std::size_t resumed = 0;      ///< runs taken over from an existing results.csv
  std::vector<std::string> failed;  ///< "key: message" of each run that threw
};

/// Runs this shard on o.workers threads (see the file comment). \throws iv::IoError if the
/// results cannot be read (resume) or written.
inline Report run_benchmark(const Options& o) {
  namespace fs = std::filesystem;
  fs::create_directories(o.out);
  const std::string csv = (fs::path(o.out) / "results.csv").string(),
                    times = (fs::path(o.out) / "timings.csv").string();
  const std::vector<Run> mine = shard_runs(o);
  std::set<std::string> wanted, done;
  for (const Run& r : mine) wanted.insert(r.key());
  Report report;
  std::vector<Result> kept;
  if (o.resume && fs::exists(csv))
    for (Result& r : read_results(csv, times))
      if (wanted.count(r.run.key()) && done.insert(r.run.key()).second) kept.push_back(std::move(r));
  if (!o.resume)
    for (const std::string& f : {csv, times})
      if (fs::exists(f)) fs::rename(f, f + ".previous");  // never overwritten unasked
  write_results(o.out, kept);
  report.resumed = kept.size();
  std::vector<Run> todo;
  for (const Run& r : mine)
    if (!done.count(r.key())) todo.push_back(r);
  const fs::path figures = fs::path(o.out) / "figures";
  if (o.figure_worlds > 0) fs::create_directories(figures);

  Appender out(o.out);
  std::vector<Result> results(todo.size());
  std::vector<char> ok(todo.size(), 0);
  const unsigned workers =
      std::min<unsigned>(iv::resolve_threads(o.workers), static_cast<unsigned>(std::max<std::size_t>(1, todo.size())));
  std::atomic<std::size_t> next{0};
  std::size_t finished = 0;
  std::mutex lock;
  std::exception_ptr write_error;
  const auto t0 = std::chrono::steady_clock::now();
  const auto work = [&] {
    for (;;) {
      const std::size_t i = next++;
      if (i >= todo.size()) return;
      const Run& r = todo[i];
      std::string failure;
      try {
        Capture capture;
        results[i] = run_one(r, o, &capture);
        const bool first_worlds = r.seed < o.first_seed + static_cast<std::uint64_t>(std::max(0, o.figure_worlds));
        const bool collided = results[i].collision_poses > 0 || results[i].collision_segments > 0;
        if (o.figure_worlds > 0 && (first_worlds || collided))
          write_top_view((figures / figure_name(r)).string(), results[i], capture, o);
      } catch (const std::exception& e) {
        failure = e.what();
      }
      const std::lock_guard guard(lock);
      ++finished;
      if (!failure.empty()) {
        report.failed.push_back(r.key() + ": " + failure);
        std::fprintf(stderr, "apartments: run %s failed: %s\n", r.key().c_str(), failure.c_str());
        continue;
      }
      ok[i] = 1;
      try {
        if (!write_error) out.append(results[i]);
      } catch (...) {
        write_error = std::current_exception();
      }
      if (o.progress) {
        const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        const Result& x = results[i];
        std::printf("[%4zu/%zu, %6.0f s] %-44s %-22s %2d steps, known %5.1f %%, %3zu poses in collision, %.1f s\n",
                    finished, todo.size(), elapsed, r.key().c_str(), x.termination.c_str(), x.steps, 100 * x.known,
                    x.collision_poses, x.seconds_total);
        std::fflush(stdout);
      }
    }
  };
  std::vector<std::thread> pool;
  for (unsigned w = 1; w < workers; ++w) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
  if (write_error) std::rethrow_exception(write_error);
  report.ran = todo.size() - report.failed.size();
  report.results = std::move(kept);
  for (std::size_t i = 0; i < todo.size(); ++i)
    if (ok[i]) report.results.push_back(std::move(results[i]));
  sort_runs(report.results);
  write_results(o.out, report.results);
  return report;
}

}  // namespace apartments
