#pragma once
// results.csv and timings.csv of the apartments benchmark: one row per run, read back by column
// name (for --resume and the merge of shards). results.csv holds what does not depend on the
// machine (the same for any number of threads and workers); timings.csv the seconds.
#include "episode.hpp"

#include <intervox/core/error.hpp>
#include <intervox/io/detail/text.hpp>
#include <intervox/io/text_file.hpp>

#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace apartments {

inline constexpr const char* kResultsHeader =
    "seed,world,planner,rig,update,rooms,kinds,floor_area,termination,completed,steps,distance,known,collision_poses,"
    "collision_segments,first_collision,met,met_lying";
inline constexpr const char* kTimingsHeader =
    "seed,world,planner,rig,update,seconds_per_plan,seconds_per_insert,seconds_total";

namespace detail {

/// A double printed so that reading it back gives the same row (6 significant digits suffice
/// for every measure here and keep the file stable).
inline std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}

inline std::vector<std::string> split(const std::string& line, char sep = ',') {
  std::vector<std::string> out;
  std::string cell;
  std::istringstream in(line);
  while (std::getline(in, cell, sep)) out.push_back(cell);
  if (!line.empty() && line.back() == sep) out.emplace_back();
  return out;
}

}  // namespace detail

inline std::string run_columns(const Run& r) {
  return std::to_string(r.seed) + "," + r.world + "," + r.planner + "," + r.rig + "," + r.update;
}

inline std::string results_row(const Result& r) {
  using detail::num;
  return run_columns(r.run) + "," + std::to_string(r.rooms) + "," + r.kinds + "," + num(r.floor_area) + "," +
         r.termination + "," + (r.completed ? "1" : "0") + "," + std::to_string(r.steps) + "," + num(r.distance) + "," +
         num(r.known) + "," + std::to_string(r.collision_poses) + "," + std::to_string(r.collision_segments) + "," +
         std::to_string(r.first_collision) + "," + r.met + "," + (r.met_lying ? "1" : "0");
}

inline std::string timings_row(const Result& r) {
  using detail::num;
  return run_columns(r.run) + "," + num(r.seconds_per_plan) + "," + num(r.seconds_per_insert) + "," +
         num(r.seconds_total);
}

/// The rows of a results.csv (and, where \p timings is given and has the run, its seconds).
/// \throws iv::IoError naming the file and line for a file that cannot be read or a malformed row.
inline std::vector<Result> read_results(const std::string& path, const std::string& timings = {}) {
  std::ifstream in(path);
  if (!in) throw iv::IoError("apartments: cannot read '" + path + "'");
  std::string line;
  if (!std::getline(in, line) || line != kResultsHeader)
    throw iv::IoError("apartments: '" + path + "' is not a results.csv of this program (header differs)");
  std::map<std::string, std::vector<std::string>> seconds;
  if (!timings.empty()) {
    std::ifstream t(timings);
    std::string tl;
    if (t && std::getline(t, tl) && tl == kTimingsHeader)
      while (std::getline(t, tl)) {
        const std::vector<std::string> c = detail::split(tl);
        if (c.size() == 8) seconds[Run{0, c[1], c[2], c[3], c[4]}.group() + "/" + c[0]] = c;  // Run::key()
      }
  }
  std::vector<Result> out;
  for (int n = 2; std::getline(in, line); ++n) {
    if (line.empty()) continue;
    const std::vector<std::string> c = detail::split(line);
    const auto bad = [&](const std::string& what) {
      return iv::IoError("apartments: '" + path + "' line " + std::to_string(n) + ": " + what);
    };
    if (c.size() != 18) throw bad("expected 18 columns, got " + std::to_string(c.size()));
    Result r;
    std::uint64_t u = 0;
    double d = 0;
    const auto size = [&](const std::string& s) {
      if (!iv::detail::parse_size(s, u)) throw bad("'" + iv::detail::quote_bytes(s) + "' is not a whole number");
      return u;
    };
    const auto real = [&](const std::string& s) {
      if (!iv::detail::parse_double(s, d)) throw bad("'" + iv::detail::quote_bytes(s) + "' is not a number");
      return d;
    };
    const auto integer = [&](const std::string& s) { return s == "-1" ? -1 : static_cast<int>(size(s)); };
    r.run = {size(c[0]), c[1], c[2], c[3], c[4]};
    r.rooms = static_cast<int>(size(c[5]));
    r.kinds = c[6];
    r.floor_area = real(c[7]);
    r.termination = c[8];
    r.completed = c[9] == "1";
    r.steps = static_cast<int>(size(c[10]));
    r.distance = real(c[11]);
    r.known = real(c[12]);
    r.collision_poses = size(c[13]);
    r.collision_segments = size(c[14]);
    r.first_collision = integer(c[15]);
    r.met = c[16];
    r.met_lying = c[17] == "1";
    if (const auto t = seconds.find(r.run.key()); t != seconds.end()) {
      r.seconds_per_plan = real(t->second[5]);
      r.seconds_per_insert = real(t->second[6]);
      r.seconds_total = real(t->second[7]);
    }
    out.push_back(std::move(r));
  }
  return out;
}

/// Writes results.csv and timings.csv of \p rows into folder \p out (atomically, each).
inline void write_results(const std::string& out, const std::vector<Result>& rows) {
  std::string results = std::string(kResultsHeader) + "\n", timings = std::string(kTimingsHeader) + "\n";
  for (const Result& r : rows) {
    results += results_row(r) + "\n";
    timings += timings_row(r) + "\n";
  }
  iv::write_text_file(out + "/results.csv", results);
  iv::write_text_file(out + "/timings.csv", timings);
}

/// Appends rows to results.csv and timings.csv as runs finish (an interrupted benchmark keeps
/// them); starts each file with its header if it is new or empty.
class Appender {
 public:
  explicit Appender(const std::string& out)
      : results_(open(out + "/results.csv", kResultsHeader)), timings_(open(out + "/timings.csv", kTimingsHeader)) {}
  /// \throws iv::IoError on a failed write.
  void append(const Result& r) {
    put(results_, results_row(r));
    put(timings_, timings_row(r));
  }

 private:
  static std::ofstream open(const std::string& path, const char* header) {
    bool empty = true;
    {
      std::ifstream in(path);
      empty = !in || in.peek() == std::ifstream::traits_type::eof();
    }
    std::ofstream f(path, std::ios::app);
    if (!f) throw iv::IoError("apartments: cannot append to '" + path + "'");
    if (empty) put(f, header);
    return f;
  }
  static void put(std::ofstream& f, const std::string& line) {
    f << line << '\n';
    f.flush();
    if (!f) throw iv::IoError("apartments: a row could not be written");
  }
  std::ofstream results_, timings_;
};

}  // namespace apartments
