#pragma once
// The experiment sweep of the thesis' chapter 5, made quantitative: every configuration of
// platform x surface x update x utility x conditions runs over several seeds; each run is one
// episode of the planner in the simulator, measured against the scene's ground truth.
//
// Long sweeps: each finished run is appended to out/results.csv at once (an interrupted sweep
// keeps what finished), `resume` skips the runs already there, a failed run is reported and does
// not stop the others, and shards (`shard_index` of `shard_count`) split the run list for several
// processes or machines (merge their results.csv with read_csv + write_results).
//
// Used by experiments.cpp (the command line) and by tests/experiments (a tiny sweep).
#include "config.hpp"
#include "results.hpp"
#include "runs.hpp"
#include "summary.hpp"

#include <intervox/core/parallel.hpp>
#include <intervox/io/text_file.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

namespace experiments {

/// Runs in the order of sweep_configs() (runs of other sweeps after them, in their order).
inline void sort_like_sweep(const SweepOptions& o, std::vector<RunResult>& results) {
  std::map<std::string, std::size_t> rank;
  const auto all = sweep_configs(o);
  for (std::size_t i = 0; i < all.size(); ++i) rank.emplace(all[i].key(), i);
  std::stable_sort(results.begin(), results.end(), [&](const RunResult& a, const RunResult& b) {
    const auto ra = rank.find(a.config.key()), rb = rank.find(b.config.key());
    const std::size_t ia = ra == rank.end() ? all.size() : ra->second, ib = rb == rank.end() ? all.size() : rb->second;
    return ia < ib;
  });
}

/// What a sweep call did.
struct SweepReport {
  std::vector<RunResult>
      results;              ///< every run of this shard that has a result (resumed ones included), in sweep order
  std::size_t ran = 0;      ///< runs executed by this call
  std::size_t resumed = 0;  ///< runs taken over from an existing results.csv
  std::vector<std::string> failed;  ///< "key: message" of each run that threw
};

/// Runs this shard of the sweep on `workers` threads. Each finished run is appended to
/// o.out/results.csv at once; with o.resume, runs already in that file (by RunConfig::key()) are
/// kept and not run again, otherwise the file is started afresh. A run that throws is reported in
/// `failed` and the others go on. Results do not depend on the number of workers.
/// \throws iv::IoError if results.csv cannot be read (resume) or written.
inline SweepReport run_sweep(const SweepOptions& o) {
  namespace fs = std::filesystem;
  fs::create_directories(o.out);
  const std::string csv = (fs::path(o.out) / "results.csv").string();
  const std::vector<RunConfig> mine = shard_configs(o);
  SweepReport report;
  std::set<std::string> wanted;
  for (const auto& c : mine) wanted.insert(c.key());
  std::set<std::string> done_keys;
  std::vector<RunResult> kept;
  if (o.resume && fs::exists(csv)) {
    for (RunResult& r : read_csv(csv))
      if (wanted.count(r.config.key()) && done_keys.insert(r.config.key()).second) kept.push_back(std::move(r));
  }
  // Start the file afresh (or with the kept runs, in today's columns), then append. Without
  // resume an existing file is kept as results.csv.previous, not overwritten.
  if (!o.resume && fs::exists(csv)) fs::rename(csv, csv + ".previous");
  write_csv(csv, kept);
  report.resumed = kept.size();
  std::vector<RunConfig> todo;
  for (const auto& c : mine)
    if (!done_keys.count(c.key())) todo.push_back(c);
  if (o.figures) fs::create_directories(fs::path(o.out) / "figures");

  CsvAppender out(csv);
  std::vector<RunResult> results(todo.size());
  std::vector<char> ok(todo.size(), 0);
  unsigned workers = intervox::resolve_threads(o.workers);  // 0: all cores; capped at them
  workers = std::min<unsigned>(workers, static_cast<unsigned>(std::max<std::size_t>(1, todo.size())));
  std::atomic<std::size_t> next{0};
  std::size_t finished = 0;
  std::mutex lock;
  std::exception_ptr write_error;
  const auto t0 = std::chrono::steady_clock::now();
  auto work = [&] {
    for (;;) {
      const std::size_t i = next++;
      if (i >= todo.size()) return;
      const RunConfig& c = todo[i];
      std::string stem;
      if (o.figures && c.seed == 1) {
        std::string name = c.group();
        std::replace(name.begin(), name.end(), '/', '_');
        stem = (fs::path(o.out) / "figures" / name).string();
      }
      std::string failure;
      try {
        results[i] = run_one(c, o, stem);
      } catch (const std::exception& e) {
        failure = e.what();
      } catch (...) {
        failure = "unknown exception";
      }
      const std::lock_guard guard(lock);
      ++finished;
      if (!failure.empty()) {
        report.failed.push_back(c.key() + ": " + failure);
        std::fprintf(stderr, "experiments: run %s failed: %s\n", c.key().c_str(), failure.c_str());
      } else {
        ok[i] = 1;
        try {
          if (!write_error) out.append(results[i]);
        } catch (...) {
          write_error = std::current_exception();
        }
      }
      if (o.progress) {
        const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        const double left = elapsed / double(finished) * double(todo.size() - finished);
        const RunResult& r = results[i];
        std::printf("[%3zu/%zu, %5.0f s, ~%5.0f s left] %-58s seed %2llu: ", finished, todo.size(), elapsed, left,
                    c.group().c_str(), static_cast<unsigned long long>(c.seed));
        if (failure.empty())
          std::printf("%2d steps, %-22s known %5.1f %%, wrong occ %5zu free %5zu, %.1f s\n", r.steps,
                      r.termination.c_str(), 100 * r.known, r.wrongly_occupied, r.wrongly_free, r.seconds_total);
        else
          std::printf("FAILED\n");
        std::fflush(stdout);
      }
    }
  };
  std::vector<std::thread> pool;
  for (unsigned w = 1; w < workers; ++w) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  if (write_error) std::rethrow_exception(write_error);
  report.ran = todo.size() - report.failed.size();
  report.results = std::move(kept);
  for (std::size_t i = 0; i < todo.size(); ++i)
    if (ok[i]) report.results.push_back(std::move(results[i]));
  sort_like_sweep(o, report.results);
  return report;
}

/// Writes results.csv (in sweep order), results.json and tables.md for \p results into o.out.
inline void write_results(const SweepOptions& o, std::vector<RunResult> results) {
  std::filesystem::create_directories(o.out);
  sort_like_sweep(o, results);
  const std::filesystem::path out(o.out);
  write_csv((out / "results.csv").string(), results);
  write_json((out / "results.json").string(), o, results);
  iv::write_text_file((out / "tables.md").string(), tables_markdown(results));
}

/// Runs the sweep (this shard) and writes results.csv, results.json, tables.md and figures/ into o.out.
inline SweepReport run_and_write(const SweepOptions& o) {
  SweepReport report = run_sweep(o);
  write_results(o, report.results);
  return report;
}

}  // namespace experiments
