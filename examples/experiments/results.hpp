#pragma once
// What one run of the sweep measured, and results.csv: one row per run, written (and appended)
// and read back by column name, so that files of earlier editions, which lack later columns, still
// load with documented defaults.
#include "config.hpp"

#include <intervox/core/error.hpp>
#include <intervox/io/detail/text.hpp>
#include <intervox/io/text_file.hpp>
#include <intervox/sim/material.hpp>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

namespace experiments {

/// What one run measured.
struct RunResult {
  RunConfig config;
  int steps = 0;            ///< exploration steps (views for the arm) after the initial scan
  std::string termination;  ///< the planner's reason to stop
  bool completed = false;   ///< ended on its own with the reachable space explored (docs/experiments.md)
  double known = 0;         ///< mobile: fraction of reachable free floor known; arm: surface coverage
  double area = 0;          ///< mobile: reachable free floor, m^2
  /// Misclassified voxels of the evaluated region (mobile: the room above the floor layer; arm:
  /// the object region) and the scene's occupied voxels there.
  std::size_t wrongly_occupied = 0;
  std::size_t wrongly_free = 0;
  std::size_t true_occupied = 0;
  /// Mobile: the same counts in the closet band (the closet and 0.5 m in front of it, above the
  /// floor layer) and the band's size in voxels; 0 for the arm.
  std::size_t band_wrongly_occupied = 0;
  std::size_t band_wrongly_free = 0;
  std::size_t band_voxels = 0;
  std::size_t region_voxels = 0;  ///< the evaluated region's size in voxels
  /// Mobile: trajectory poses and path segments (between consecutive poses) where the robot's
  /// footprint meets the true scene; 0 for the arm.
  std::size_t collision_poses = 0;
  std::size_t collision_segments = 0;
  /// Mobile: the same by scene object (collisions_by_object() of eval/ground_truth.hpp), in the
  /// scene's object order; empty for the arm and for files without the column.
  struct ObjectCollisions {
    std::string object;  ///< the scene object's name
    std::size_t poses = 0;
    std::size_t segments = 0;
    bool operator==(const ObjectCollisions&) const = default;
  };
  std::vector<ObjectCollisions> collision_objects;
  /// Observed voxels with a narrow interval (width < kConflictWidth) but an unknown state: the
  /// conflict signature of thesis ch. 6. -1 for policies without an interval (Bayes).
  long long conflicts = -1;
  /// Mobile, interval and credal updates: the conflict detector (analysis/conflicts.hpp) against
  /// the simulator's ground truth (eval/conflict_scoring.hpp): precision, recall and the number of
  /// ground-truth conflict voxels; -1 where not computed (Bayes, the arm).
  double conflict_precision = -1;
  double conflict_recall = -1;
  long long conflict_truth = -1;
  /// Mobile, interval and credal updates: where the conflict evidence lies relative to the closet,
  /// counted in the conflict band (detail::conflict_band in runs.hpp: the closet's extent along y,
  /// from 1 m behind its back to 0.5 m in front of it, above the floor layer up to its top).
  /// Observed voxels with the conflict signature (analysis/conflicts.hpp), everywhere and in the
  /// band; voxels of the detector's regions, everywhere and in the band; ground-truth conflict
  /// voxels in the band (all of them: conflict_truth). -1 where not computed.
  long long signature_voxels = -1;
  long long signature_band = -1;
  long long flagged_voxels = -1;
  long long flagged_band = -1;
  long long truth_band = -1;
  /// Arm: surface coverage after every view, the initial one included; views to reach 80 %
  /// (-1: never). Mobile: empty and -1.
  std::vector<double> coverage_curve;
  int views_to_80 = -1;
  /// Metres the robot drove (mobile) or the sensor moved between views (arm), along the
  /// trajectory's straight segments (Episode::distance_driven()); -1 for files without the column.
  double distance = -1;
  /// Mobile, room "annex": the share of the annex's reachable free floor known at the end
  /// (floor_coverage over its part); -1 elsewhere.
  double annex_known = -1;
  /// Mobile: after every planning step's scans (the look-around first), the share of the closet's
  /// own voxels (those the scene occupies in its box, from above the floor layer to the top of the
  /// robot's band) that the planner may treat as free: the grid's free voxels, and for the safe
  /// planner only those its channel also explains free (ExplainedSpace::explained_free). Empty for
  /// the arm and for files without the column.
  std::vector<double> closet_free_curve;
  /// Mobile, planners with an explained channel (safe): the returned beams of the scans its
  /// revision ledger keeps at the end, scored by their classes then against the simulator's paths
  /// (score_beam_classes() in beam_class_score.hpp): the share of the direct and of the reflected
  /// beams held suspect, and the precision and recall of "suspect" for beams that lie (reflected
  /// or passed through glass). -1 where not computed (no channel, no such beams).
  double direct_suspect = -1;
  double reflected_suspect = -1;
  double suspect_precision = -1;
  double suspect_recall = -1;
  /// Mobile, planners with an explained channel (safe), at the end: of the voxels of the robot's
  /// band (the planning region above the floor layer) the grid classifies free, the share the
  /// channel also explains free; with room "annex" the same within the annex (from the doorway
  /// on). -1 where not computed (no channel, no free voxel).
  double explained_free_share = -1;
  double annex_explained_free_share = -1;
  /// Mobile, room "annex", planners that close wall gaps (safe): the plans whose wall gaps hold
  /// the doorway's (a gap whose floor segment comes within 0.25 m of the doorway), the plans of
  /// those that named it an opening (find_wall_gaps()), and the verdict of the last of them (1
  /// opening, 0 closed). -1 where not computed; door_last_opening also -1 if no plan found it.
  int door_plans = -1;
  int door_opening_plans = -1;
  int door_last_opening = -1;
  double seconds_per_step = 0;
  double seconds_total = 0;
};

/// The columns of results.csv, in order. Files of the first edition have only the columns up to
/// `conflicts` and the two timing columns; the others then take the defaults of RunConfig and
/// RunResult (policies "clamped", floor "kept", gain "all", planner "plain", unobserved "unknown",
/// room "lab", rules "thesis", sensor "plain", counts 0, scores, the signature / flagged / truth
/// band counts, views_to_80, distance, annex_known, the beam-class scores, the explained shares
/// and the doorway's counts -1, closet_free_curve empty).
/// Files of the second edition lack room, rules, sensor and every column after coverage_curve but
/// the timing.
inline constexpr std::string_view kCsvHeader =
    "platform,surface,update,utility,policies,floor,gain,planner,unobserved,room,rules,sensor,seed,steps,termination,"
    "completed,known,area_m2,"
    "wrongly_occupied,wrongly_free,true_occupied,region_voxels,band_wrongly_occupied,band_wrongly_free,band_voxels,"
    "collision_poses,collision_segments,collision_objects,conflicts,conflict_precision,conflict_recall,conflict_truth,"
    "signature_voxels,signature_band,flagged_voxels,flagged_band,truth_band,views_to_80,coverage_curve,distance,annex_"
    "known,closet_free_curve,"
    "direct_suspect,reflected_suspect,suspect_precision,suspect_recall,explained_free_share,annex_explained_free_share,"
    "door_plans,door_opening_plans,door_last_opening,seconds_per_step,seconds_total";

/// collision_objects as a field: `name=poses/segments` per object, separated by ';' (empty: none).
inline std::string collision_objects_text(const std::vector<RunResult::ObjectCollisions>& v) {
  std::string out;
  for (const auto& c : v)
    out += (out.empty() ? "" : ";") + c.object + '=' + std::to_string(c.poses) + '/' + std::to_string(c.segments);
  return out;
}

/// The numbers of a row, shortest exact text (round trip).
inline std::string number_text(double v) {
  char buf[64];
  const auto [p, e] = std::to_chars(buf, buf + sizeof buf, v);
  return e == std::errc{} ? std::string(buf, p) : std::string("nan");
}

/// One row of results.csv (no newline).
inline std::string csv_row(const RunResult& r) {
  const RunConfig& c = r.config;
  const auto curve_text = [](const std::vector<double>& v) {
    std::string out;
    for (double k : v) out += (out.empty() ? "" : ";") + number_text(k);
    return out;
  };
  std::ostringstream f;
  f << c.platform << ',' << c.surface << ',' << c.update << ',' << c.utility << ',' << c.policies << ',' << c.floor
    << ',' << c.gain << ',' << c.planner << ',' << c.unobserved << ',' << c.room << ',' << c.rules << ',' << c.sensor
    << ',' << c.seed << ',' << r.steps << ',' << r.termination << ',' << (r.completed ? 1 : 0) << ','
    << number_text(r.known) << ',' << number_text(r.area) << ',' << r.wrongly_occupied << ',' << r.wrongly_free << ','
    << r.true_occupied << ',' << r.region_voxels << ',' << r.band_wrongly_occupied << ',' << r.band_wrongly_free << ','
    << r.band_voxels << ',' << r.collision_poses << ',' << r.collision_segments << ','
    << collision_objects_text(r.collision_objects) << ',' << r.conflicts << ',' << number_text(r.conflict_precision)
    << ',' << number_text(r.conflict_recall) << ',' << r.conflict_truth << ',' << r.signature_voxels << ','
    << r.signature_band << ',' << r.flagged_voxels << ',' << r.flagged_band << ',' << r.truth_band << ','
    << r.views_to_80 << ',' << curve_text(r.coverage_curve) << ',' << number_text(r.distance) << ','
    << number_text(r.annex_known) << ',' << curve_text(r.closet_free_curve) << ',' << number_text(r.direct_suspect)
    << ',' << number_text(r.reflected_suspect) << ',' << number_text(r.suspect_precision) << ','
    << number_text(r.suspect_recall) << ',' << number_text(r.explained_free_share) << ','
    << number_text(r.annex_explained_free_share) << ',' << r.door_plans << ',' << r.door_opening_plans << ','
    << r.door_last_opening << ',' << number_text(r.seconds_per_step) << ',' << number_text(r.seconds_total);
  return f.str();
}

/// Writes results.csv (header and one row per run), atomically.
inline void write_csv(const std::string& path, const std::vector<RunResult>& results) {
  std::string text = std::string(kCsvHeader) + "\n";
  for (const RunResult& r : results) text += csv_row(r) + "\n";
  iv::write_text_file(path, text);
}

namespace detail {

/// One row of a results.csv being read, with errors that name the file, the line, the column and
/// the value.
class CsvRow {
 public:
  CsvRow(std::string path, int line, const std::vector<std::string>& header, std::vector<std::string> fields)
      : path_(std::move(path)), line_(line), header_(&header), fields_(std::move(fields)) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw iv::IoError(path_ + " line " + std::to_string(line_) + ": " + what);
  }

  /// Field `i`, which must be one of the range `allowed` of string views.
  template <class Range>
  const std::string& text_in(std::size_t i, const Range& allowed) const {
    const std::string& v = fields_[i];
    if (std::find(std::begin(allowed), std::end(allowed), v) == std::end(allowed))
      fail(column(i) + " is '" + iv::detail::quote_bytes(v) + "', expected " + list(allowed));
    return v;
  }
  const std::string& text(std::size_t i, std::initializer_list<std::string_view> allowed) const {
    return text_in(i, allowed);
  }

  /// Field `i` as a whole number of type T in [min, max] (no sign on unsigned types, no wrap-around).
  template <class T>
  T integer(std::size_t i, T min = std::numeric_limits<T>::min(), T max = std::numeric_limits<T>::max()) const {
    const std::string& v = fields_[i];
    T value{};
    const auto [stop, error] = std::from_chars(v.data(), v.data() + v.size(), value);
    if (v.empty() || error != std::errc{} || stop != v.data() + v.size() || value < min || value > max)
      fail(column(i) + " is '" + iv::detail::quote_bytes(v) + "', expected a whole number in [" + std::to_string(min) +
           ", " + std::to_string(max) + "]");
    return value;
  }

  /// Field `i` as collision_objects_text() writes it: `name=poses/segments` items separated by
  /// ';' (may be empty), names of letters, digits and '_', counts whole numbers.
  std::vector<RunResult::ObjectCollisions> object_collisions(std::size_t i) const {
    std::vector<RunResult::ObjectCollisions> out;
    const std::string& v = fields_[i];
    std::size_t b = 0;
    while (b < v.size()) {
      const std::size_t e = std::min(v.find(';', b), v.size());
      const std::string item = v.substr(b, e - b);
      const std::size_t eq = item.find('='), slash = item.find('/');
      RunResult::ObjectCollisions c;
      const auto count = [&](std::size_t from, std::size_t to, std::size_t& n) {
        const auto [stop, error] = std::from_chars(item.data() + from, item.data() + to, n);
        return from < to && error == std::errc{} && stop == item.data() + to;
      };
      const bool ok = eq != std::string::npos && eq > 0 && slash != std::string::npos && slash > eq &&
                      std::all_of(item.begin(), item.begin() + static_cast<std::ptrdiff_t>(eq),
                                  [](char ch) { return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_'; }) &&
                      count(eq + 1, slash, c.poses) && count(slash + 1, item.size(), c.segments);
      if (!ok)
        fail(column(i) + " is '" + iv::detail::quote_bytes(v) +
             "', expected name=poses/segments items separated by ';'");
      c.object = item.substr(0, eq);
      out.push_back(std::move(c));
      b = e + 1;
    }
    if (!v.empty() && v.back() == ';')
      fail(column(i) + " is '" + iv::detail::quote_bytes(v) + "', expected name=poses/segments items separated by ';'");
    return out;
  }

  /// Field `i` as a finite number in [min, max].
  double number(std::size_t i, double min, double max = std::numeric_limits<double>::max()) const {
    return parse_number(column(i), fields_[i], min, max);
  }
  /// Field `i` as numbers separated by ';' (may be empty), each in [min, max].
  std::vector<double> numbers(std::size_t i, double min, double max) const {
    std::vector<double> out;
    const std::string& v = fields_[i];
    std::size_t b = 0;
    while (b < v.size()) {
      const std::size_t e = std::min(v.find(';', b), v.size());
      out.push_back(parse_number(column(i), v.substr(b, e - b), min, max));
      b = e + 1;
    }
    return out;
  }

 private:
  double parse_number(const std::string& col, const std::string& v, double min, double max) const {
    double value = 0;
    const auto [stop, error] = std::from_chars(v.data(), v.data() + v.size(), value);
    if (v.empty() || error != std::errc{} || stop != v.data() + v.size() || !std::isfinite(value) || value < min ||
        value > max)
      fail(col + " is '" + iv::detail::quote_bytes(v) + "', expected a finite number in [" + std::to_string(min) +
           ", " + std::to_string(max) + "]");
    return value;
  }
  std::string column(std::size_t i) const { return (*header_)[i]; }
  template <class Range>
  static std::string list(const Range& names) {
    std::string out;
    for (std::string_view n : names) out += (out.empty() ? "" : ", ") + std::string(n);
    return "one of " + out;
  }

  std::string path_;
  int line_;
  const std::vector<std::string>* header_;
  std::vector<std::string> fields_;
};

inline std::vector<std::string> split(const std::string& line, char sep) {
  std::vector<std::string> v;
  std::size_t begin = 0;
  for (std::size_t at; (at = line.find(sep, begin)) != std::string::npos; begin = at + 1)
    v.push_back(line.substr(begin, at - begin));
  v.push_back(line.substr(begin));
  return v;
}

}  // namespace detail

/// Reads a results.csv written by write_csv or appended run by run (to regenerate the tables and
/// the JSON, to resume, or to merge sweeps and shards run separately). Columns are found by name:
/// every column of kCsvHeader up to `conflicts` and the two timing columns are required, the
/// others optional (files of the first edition; see kCsvHeader). Every field is checked: names
/// against the sweep's platforms, materials, objects, updates, criteria, presets and
/// terminations, counts as whole numbers (conflicts >= -1), fractions in [0, 1], the other figures
/// finite and >= 0.
/// \throws iv::IoError naming the file, the line, the column and the value for a missing file, an
/// unknown or duplicate or missing required column, a row with the wrong number of fields or a bad field.
inline std::vector<RunResult> read_csv(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw iv::IoError("cannot read " + path);
  std::string line;
  const auto strip_cr = [&] {
    if (!line.empty() && line.back() == '\r') line.pop_back();
  };
  if (!std::getline(f, line))
    throw iv::IoError(path + " is empty, expected the header line " + std::string(kCsvHeader));
  strip_cr();
  const std::vector<std::string> header = detail::split(line, ',');
  const std::vector<std::string> known = detail::split(std::string(kCsvHeader), ',');
  std::map<std::string, std::size_t> at;
  for (std::size_t i = 0; i < header.size(); ++i) {
    if (std::find(known.begin(), known.end(), header[i]) == known.end())
      throw iv::IoError(path + " line 1: unknown column '" + iv::detail::quote_bytes(header[i]) +
                        "' (expected the columns of " + std::string(kCsvHeader) + ")");
    if (!at.emplace(header[i], i).second)
      throw iv::IoError(path + " line 1: column '" + iv::detail::quote_bytes(header[i]) + "' appears twice");
  }
  for (const char* required :
       {"platform", "surface", "update", "utility", "seed", "steps", "termination", "completed", "known", "area_m2",
        "wrongly_occupied", "wrongly_free", "true_occupied", "conflicts", "seconds_per_step", "seconds_total"})
    if (!at.count(required))
      throw iv::IoError(path + " line 1: the required column '" + std::string(required) + "' is missing");
  const auto has = [&](const char* name) { return at.count(name) != 0; };
  std::vector<RunResult> out;
  for (int number = 2; std::getline(f, line); ++number) {
    strip_cr();
    if (line.empty()) continue;
    std::vector<std::string> v = detail::split(line, ',');
    if (v.size() != header.size())
      throw iv::IoError(path + " line " + std::to_string(number) + " has " + std::to_string(v.size()) +
                        " fields, expected " + std::to_string(header.size()));
    const detail::CsvRow row(path, number, header, std::move(v));
    RunResult r;
    RunConfig& c = r.config;
    c.platform = row.text(at["platform"], {"mobile", "arm"});
    c.surface = c.platform == "mobile" ? row.text_in(at["surface"], iv::sim::kMaterialNames)
                                       : row.text(at["surface"], {"part", "bottle", "box"});
    c.update = row.text(at["update"], {"bayes", "interval-lower", "interval-mean", "interval-upper",
                                       "compact-interval-mean", "dirichlet-mean", "belief-mean"});
    c.utility = row.text(at["utility"], {"entropy", "max-entropy"});
    c.policies = has("policies") ? row.text(at["policies"], {"thesis", "clamped"}) : "clamped";
    c.floor = has("floor") ? row.text(at["floor"], {"removed", "kept"}) : "kept";
    c.gain = has("gain") ? row.text(at["gain"], {"unknown", "all"}) : "all";
    c.planner = has("planner") ? row.text_in(at["planner"], kPlanners) : "plain";
    c.unobserved = has("unobserved") ? row.text(at["unobserved"], {"unknown", "by-rule"}) : "unknown";
    c.room = has("room") ? row.text_in(at["room"], kRooms) : "lab";
    c.rules = has("rules") ? row.text_in(at["rules"], kRules) : "thesis";
    c.sensor = has("sensor") ? row.text_in(at["sensor"], kSensorConditions) : "plain";
    c.seed = row.integer<std::uint64_t>(at["seed"]);
    r.steps = row.integer<int>(at["steps"], 0);
    r.termination = row.text(at["termination"], {"explored", "no reachable frontier", "blocked", "budget"});
    r.completed = row.integer<int>(at["completed"], 0, 1) == 1;
    r.known = row.number(at["known"], 0.0, 1.0);
    r.area = row.number(at["area_m2"], 0.0);
    r.wrongly_occupied = row.integer<std::size_t>(at["wrongly_occupied"]);
    r.wrongly_free = row.integer<std::size_t>(at["wrongly_free"]);
    r.true_occupied = row.integer<std::size_t>(at["true_occupied"]);
    if (has("region_voxels")) r.region_voxels = row.integer<std::size_t>(at["region_voxels"]);
    if (has("band_wrongly_occupied")) r.band_wrongly_occupied = row.integer<std::size_t>(at["band_wrongly_occupied"]);
    if (has("band_wrongly_free")) r.band_wrongly_free = row.integer<std::size_t>(at["band_wrongly_free"]);
    if (has("band_voxels")) r.band_voxels = row.integer<std::size_t>(at["band_voxels"]);
    if (has("collision_poses")) r.collision_poses = row.integer<std::size_t>(at["collision_poses"]);
    if (has("collision_segments")) r.collision_segments = row.integer<std::size_t>(at["collision_segments"]);
    if (has("collision_objects")) r.collision_objects = row.object_collisions(at["collision_objects"]);
    r.conflicts = row.integer<long long>(at["conflicts"], -1);
    if (has("conflict_precision")) r.conflict_precision = row.number(at["conflict_precision"], -1.0, 1.0);
    if (has("conflict_recall")) r.conflict_recall = row.number(at["conflict_recall"], -1.0, 1.0);
    if (has("conflict_truth")) r.conflict_truth = row.integer<long long>(at["conflict_truth"], -1);
    for (auto [name, field] :
         {std::pair{"signature_voxels", &r.signature_voxels}, std::pair{"signature_band", &r.signature_band},
          std::pair{"flagged_voxels", &r.flagged_voxels}, std::pair{"flagged_band", &r.flagged_band},
          std::pair{"truth_band", &r.truth_band}})
      if (has(name)) *field = row.integer<long long>(at[name], -1);
    if (has("views_to_80")) r.views_to_80 = row.integer<int>(at["views_to_80"], -1);
    if (has("coverage_curve")) r.coverage_curve = row.numbers(at["coverage_curve"], 0.0, 1.0);
    if (has("distance")) r.distance = row.number(at["distance"], -1.0);
    if (has("annex_known")) r.annex_known = row.number(at["annex_known"], -1.0, 1.0);
    if (has("closet_free_curve")) r.closet_free_curve = row.numbers(at["closet_free_curve"], 0.0, 1.0);
    for (auto [name, field] :
         {std::pair{"direct_suspect", &r.direct_suspect}, std::pair{"reflected_suspect", &r.reflected_suspect},
          std::pair{"suspect_precision", &r.suspect_precision}, std::pair{"suspect_recall", &r.suspect_recall},
          std::pair{"explained_free_share", &r.explained_free_share},
          std::pair{"annex_explained_free_share", &r.annex_explained_free_share}})
      if (has(name)) *field = row.number(at[name], -1.0, 1.0);
    for (auto [name, field] :
         {std::pair{"door_plans", &r.door_plans}, std::pair{"door_opening_plans", &r.door_opening_plans}})
      if (has(name)) *field = row.integer<int>(at[name], -1);
    if (has("door_last_opening")) r.door_last_opening = row.integer<int>(at["door_last_opening"], -1, 1);
    r.seconds_per_step = row.number(at["seconds_per_step"], 0.0);
    r.seconds_total = row.number(at["seconds_total"], 0.0);
    out.push_back(std::move(r));
  }
  return out;
}

/// results.csv appended run by run: a sweep that crashes or is interrupted keeps every run that
/// finished. Not thread-safe: callers serialise append().
class CsvAppender {
 public:
  /// Opens \p path for appending; writes the header first if the file is new or empty.
  /// \throws iv::IoError if the file cannot be opened.
  explicit CsvAppender(const std::string& path) : path_(path) {
    bool empty = true;
    {
      std::ifstream in(path);
      empty = !in || in.peek() == std::ifstream::traits_type::eof();
    }
    file_.open(path, std::ios::app);
    if (!file_) throw iv::IoError("cannot append to " + path);
    if (empty) write(std::string(kCsvHeader));
  }
  /// Appends one row and flushes it to the file. \throws iv::IoError on a failed write.
  void append(const RunResult& r) { write(csv_row(r)); }

 private:
  void write(const std::string& line) {
    file_ << line << '\n';
    file_.flush();
    if (!file_) throw iv::IoError("cannot write to " + path_);
  }
  std::string path_;
  std::ofstream file_;
};

}  // namespace experiments
