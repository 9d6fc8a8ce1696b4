#pragma once
// The experiment sweep of the thesis' chapter 5, made quantitative: every configuration of
// platform x surface x update x utility runs over several seeds; each run is one episode of the
// planner in the simulator, measured against the scene's ground truth.
//
// Used by experiments.cpp (the command line) and by tests/experiments (a tiny sweep).
#include <intervox/eval/ground_truth.hpp>
#include <intervox/intervox.hpp>
#include <intervox/io/exploration_image.hpp>
#include <intervox/io/png.hpp>
#include <intervox/io/slice.hpp>
#include <intervox/io/text_file.hpp>
#include <intervox/plan/arm_planner.hpp>
#include <intervox/plan/episode.hpp>
#include <intervox/plan/mobile_planner.hpp>
#include <intervox/raycast/raycast.hpp>
#include <intervox/sim/sim.hpp>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <limits>
#include <map>
#include <mutex>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <thread>
#include <vector>

namespace experiments {

namespace iv = intervox;

/// One run of the sweep.
struct RunConfig {
  std::string platform = "mobile";  ///< "mobile" (lab room) or "arm" (workcell)
  std::string surface = "diffuse";  ///< mobile: the closet's surface; arm: the scanned object
  std::string update = "bayes";     ///< bayes, interval-lower, interval-mean, interval-upper
  std::string utility = "entropy";  ///< entropy, max-entropy
  std::uint64_t seed = 1;

  /// Configuration without the seed: the key that runs are aggregated under.
  std::string group() const { return platform + "/" + surface + "/" + update + "/" + utility; }
};

/// What one run measured.
struct RunResult {
  RunConfig config;
  int steps = 0;                    ///< exploration steps (views for the arm) after the initial scan
  std::string termination;          ///< the planner's reason to stop
  bool completed = false;           ///< ended with the reachable space explored (see docs/experiments.md)
  double known = 0;                 ///< mobile: fraction of reachable free floor known; arm: surface coverage
  double area = 0;                  ///< mobile: reachable free floor, m^2
  std::size_t wrongly_occupied = 0;
  std::size_t wrongly_free = 0;
  std::size_t true_occupied = 0;
  /// Observed voxels with a narrow interval (width < kConflictWidth) but an unknown state: the
  /// conflict signature of thesis ch. 6. -1 for policies without an interval (Bayes), where a
  /// narrow interval cannot be told from ignorance.
  long long conflicts = -1;
  double seconds_per_step = 0;
  double seconds_total = 0;
};

/// The sweep: the cross product of the lists, each over `seeds` seeds (1..seeds).
struct SweepOptions {
  std::vector<std::string> mobile_surfaces{"diffuse", "absorbing", "transparent", "specular"};
  std::vector<std::string> mobile_updates{"bayes", "interval-lower", "interval-mean", "interval-upper"};
  std::vector<std::string> utilities{"entropy", "max-entropy"};
  /// Arm runs: "part" (the ring-shaped mechanical part, polished metal) and "bottle" (glass).
  std::vector<std::string> arm_objects{"part", "bottle"};
  /// Arm runs with the first edition's workcell materials: the part a random-range specular
  /// surface (Material::specular_random_range()), the bottle glass without Fresnel reflection.
  bool arm_first_edition_materials = false;
  std::vector<std::string> arm_updates{"bayes", "interval-mean"};
  int seeds = 10;
  double resolution = 0.05;   ///< m, mobile grid
  double arm_resolution = 0.01;  ///< m, arm grid (dense, the 1.5 m workcell)
  int arm_max_views = 12;     ///< arm view budget, the initial view included
  int max_steps = 30;         ///< mobile step budget
  int gain_stride = 4;        ///< pixel stride of the gain rays
  unsigned workers = 0;       ///< runs in parallel (0: all cores, more are capped at them); each run is single-threaded
  std::string out = "out/experiments";
  bool figures = true;        ///< write the per-configuration pictures (first seed)
  bool progress = true;       ///< print a line per finished run
};

/// A completion rule shared by every platform: the run ended on its own (not by budget or
/// blocking) and the part of the world it is responsible for is known to `kCompleteFraction`.
inline constexpr double kCompleteFraction = 0.95;
/// Interval width below which an observed, unknown voxel counts as a conflict (thesis ch. 6).
inline constexpr double kConflictWidth = 0.2;

namespace detail {

template <class Grid>
long long count_conflicts(const Grid& grid) {
  const auto& u = grid.update_policy();
  if (u.interval(u.unobserved()).width() < kConflictWidth) return -1;  // no ignorance to tell apart
  long long n = 0;
  grid.for_each_observed([&](const iv::Key&, const typename Grid::Cell& c) {
    n += u.occupancy(c) == iv::Occupancy::Unknown && u.interval(c).width() < kConflictWidth;
  });
  return n;
}

/// The voxel-space pictures of a finished run, as the thesis' Fig. 5.8 / 5.9: a horizontal slice
/// at knee height coloured by state (gray), interval width (blue narrow .. red broad) and the
/// combined code of Table 5.2.
template <class Grid>
void write_voxel_figures(const Grid& grid, const iv::Bounds& region, double z, const std::string& stem) {
  const iv::KeyBox box = grid.geometry().key_box(region);
  iv::SliceOptions o;
  o.window = box;
  o.z = grid.geometry().key(iv::Point3(region.min.x(), region.min.y(), z)).z;
  o.pixels_per_voxel = std::max(1, static_cast<int>(std::lround(0.02 / grid.resolution() * 4)));
  o.color = iv::ColorBy::State;
  iv::write_png(stem + "_state.png", iv::render_slice(grid, o));
  o.color = iv::ColorBy::IntervalWidth;
  iv::write_png(stem + "_width.png", iv::render_slice(grid, o));
  o.color = iv::ColorBy::Table52;
  iv::write_png(stem + "_table52.png", iv::render_slice(grid, o));
}

template <class Grid>
RunResult run_mobile(const RunConfig& c, const SweepOptions& o, const std::string& figure_stem) {
  iv::sim::LabRoomOptions room;
  room.closet_material = iv::sim::material_from_string(c.surface);
  const iv::sim::LabRoom lab = iv::sim::make_lab_room(room);
  Grid grid(o.resolution);
  iv::MobilePlannerParams p;
  p.region = iv::Bounds{{0.0, 0.0, 0.2}, {8.0, 6.0, 0.8}};  // the lab room's floor
  p.seed = c.seed;
  p.threads = 1;
  p.max_steps = o.max_steps;
  p.gain_stride = o.gain_stride;
  const iv::SensorRig rig = iv::SensorRig::mobile_base();
  const iv::Pose start = iv::planar_pose(lab.start, 0.0);
  iv::MobilePlanner planner(rig, p);
  iv::Episode ex(grid, planner, iv::sim::SimulatedRig(lab.scene, rig, c.seed), start);
  const auto t0 = std::chrono::steady_clock::now();
  const iv::Termination t = ex.run();
  RunResult r;
  r.config = c;
  r.seconds_total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.steps = std::max(0, planner.steps() - 1);  // the look-around is step 0
  r.termination = std::string(iv::to_string(t));
  const iv::FloorCoverage floor = iv::floor_coverage(grid, lab.scene, *p.region, p.map, start.translation());
  r.known = floor.known;
  r.area = floor.area;
  r.completed = (t == iv::Termination::NoReachableFrontier || t == iv::Termination::Explored) &&
                r.known >= kCompleteFraction;
  const iv::VoxelErrors e = iv::evaluate_voxels(grid, lab.scene, *planner.gain_options(*p.region).bounds);
  r.wrongly_occupied = e.wrongly_occupied;
  r.wrongly_free = e.wrongly_free;
  r.true_occupied = e.true_occupied;
  r.conflicts = count_conflicts(grid);
  r.seconds_per_step = planner.steps() > 0 ? r.seconds_total / planner.steps() : 0.0;
  if (!figure_stem.empty()) {
    iv::write_png(figure_stem + "_map.png", iv::render_exploration_map(planner.exploration_map(grid, ex.pose(), *p.region), {}, 4));
    write_voxel_figures(grid, *p.region, 0.5, figure_stem);
  }
  return r;
}

template <class U, class H>
using MobileGrid = iv::VoxelGrid<U, H, iv::SparseStorage>;

using Runner = RunResult (*)(const RunConfig&, const SweepOptions&, const std::string&);

/// The compile-time configurations, chosen at run time by name.
inline Runner mobile_runner(const std::string& update, const std::string& utility) {
  using E = iv::Entropy;
  using M = iv::MaxEntropy;
  static const std::map<std::string, Runner> table{
      {"bayes/entropy", &run_mobile<MobileGrid<iv::BayesLogOdds, E>>},
      {"bayes/max-entropy", &run_mobile<MobileGrid<iv::BayesLogOdds, M>>},
      {"interval-lower/entropy", &run_mobile<MobileGrid<iv::IntervalUpdate<iv::LowerState>, E>>},
      {"interval-lower/max-entropy", &run_mobile<MobileGrid<iv::IntervalUpdate<iv::LowerState>, M>>},
      {"interval-mean/entropy", &run_mobile<MobileGrid<iv::IntervalUpdate<iv::MeanState>, E>>},
      {"interval-mean/max-entropy", &run_mobile<MobileGrid<iv::IntervalUpdate<iv::MeanState>, M>>},
      {"interval-upper/entropy", &run_mobile<MobileGrid<iv::IntervalUpdate<iv::UpperState>, E>>},
      {"interval-upper/max-entropy", &run_mobile<MobileGrid<iv::IntervalUpdate<iv::UpperState>, M>>},
  };
  const auto it = table.find(update + "/" + utility);
  if (it == table.end()) throw iv::InvalidArgument("experiments: unknown update/utility '" + update + "/" + utility + "'");
  return it->second;
}

/// An arm run: the object keeps its workcell material (the part polished metal, the bottle glass;
/// or the first edition's materials, see SweepOptions::arm_first_edition_materials).
template <class Grid>
RunResult run_arm(const RunConfig& c, const SweepOptions& o, const std::string& figure_stem) {
  iv::sim::WorkcellOptions wo;
  if (o.arm_first_edition_materials) {
    wo.part_material = iv::sim::Material::specular_random_range();
    wo.bottle_material = iv::sim::Material::transparent_without_fresnel();
  }
  const iv::sim::Workcell cell = iv::sim::make_workcell(wo);
  Grid grid(o.arm_resolution, iv::Bounds{{0, 0, 0}, {1.5, 1.5, 1.5}});
  iv::ArmPlannerParams p;
  p.object_region = cell.object_region(c.surface, o.arm_resolution);
  p.support_height = cell.table_center.z();
  p.max_views = o.arm_max_views;
  p.threads = 1;
  p.seed = c.seed;
  iv::ArmPlanner m(iv::SensorRig::arm(), p);
  iv::Episode episode(grid, m, iv::sim::SimulatedRig(cell.scene, m.rig(), c.seed), iv::Pose::Identity());
  const auto t0 = std::chrono::steady_clock::now();
  const iv::Termination t = episode.run();
  RunResult r;
  r.config = c;
  r.seconds_total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.steps = m.views();
  r.termination = std::string(iv::to_string(t));
  r.known = iv::surface_coverage(grid, cell.scene, p.object_region, p.support_height).known;
  r.completed = t != iv::Termination::Blocked && r.known >= kCompleteFraction;
  const iv::VoxelErrors e = iv::evaluate_voxels(grid, cell.scene, p.object_region);
  r.wrongly_occupied = e.wrongly_occupied;
  r.wrongly_free = e.wrongly_free;
  r.true_occupied = e.true_occupied;
  r.conflicts = count_conflicts(grid);
  r.seconds_per_step = m.views() > 0 ? r.seconds_total / m.views() : 0.0;
  if (!figure_stem.empty()) {
    // Top view of the object region (maximum along z, without the table-top layer).
    iv::SliceOptions so;
    so.mode = iv::SliceMode::MaxProjection;
    iv::Bounds around = p.object_region;
    around.min -= iv::Point3(0.05, 0.05, 0.0);
    around.max += iv::Point3(0.05, 0.05, 0.0);
    so.window = grid.geometry().key_box(around);
    so.window->min.z = std::min(so.window->min.z + 1, so.window->max.z);
    so.pixels_per_voxel = 4;
    for (auto [color, name] : {std::pair{iv::ColorBy::State, "_state.png"}, std::pair{iv::ColorBy::IntervalWidth, "_width.png"},
                               std::pair{iv::ColorBy::Table52, "_table52.png"}}) {
      so.color = color;
      iv::write_png(figure_stem + name, iv::render_slice(grid, so));
    }
  }
  return r;
}

template <class U, class H>
using ArmGrid = iv::VoxelGrid<U, H, iv::DenseStorage>;

inline Runner arm_runner(const std::string& update, const std::string& utility) {
  using E = iv::Entropy;
  using M = iv::MaxEntropy;
  static const std::map<std::string, Runner> table{
      {"bayes/entropy", &run_arm<ArmGrid<iv::BayesLogOdds, E>>},
      {"bayes/max-entropy", &run_arm<ArmGrid<iv::BayesLogOdds, M>>},
      {"interval-mean/entropy", &run_arm<ArmGrid<iv::IntervalUpdate<iv::MeanState>, E>>},
      {"interval-mean/max-entropy", &run_arm<ArmGrid<iv::IntervalUpdate<iv::MeanState>, M>>},
  };
  const auto it = table.find(update + "/" + utility);
  if (it == table.end()) throw iv::InvalidArgument("experiments: unknown arm update/utility '" + update + "/" + utility + "'");
  return it->second;
}

}  // namespace detail

/// Every run of the sweep, in a fixed order.
inline std::vector<RunConfig> sweep_configs(const SweepOptions& o) {
  std::vector<RunConfig> runs;
  for (const auto& s : o.mobile_surfaces)
    for (const auto& u : o.mobile_updates)
      for (const auto& h : o.utilities)
        for (int seed = 1; seed <= o.seeds; ++seed) runs.push_back({"mobile", s, u, h, static_cast<std::uint64_t>(seed)});
  for (const auto& obj : o.arm_objects)
    for (const auto& u : o.arm_updates)
      for (const auto& h : o.utilities)
        for (int seed = 1; seed <= o.seeds; ++seed) runs.push_back({"arm", obj, u, h, static_cast<std::uint64_t>(seed)});
  return runs;
}

/// Runs one configuration (figures written when figure_stem is not empty).
inline RunResult run_one(const RunConfig& c, const SweepOptions& o, const std::string& figure_stem = {}) {
  if (c.platform == "mobile") return detail::mobile_runner(c.update, c.utility)(c, o, figure_stem);
  if (c.platform == "arm") return detail::arm_runner(c.update, c.utility)(c, o, figure_stem);
  throw iv::InvalidArgument("experiments: unknown platform '" + c.platform + "'");
}

/// Runs the whole sweep on `workers` threads; results come back in sweep_configs() order,
/// whatever the number of workers.
inline std::vector<RunResult> run_sweep(const SweepOptions& o) {
  const std::vector<RunConfig> configs = sweep_configs(o);
  std::vector<RunResult> results(configs.size());
  if (o.figures) std::filesystem::create_directories(std::filesystem::path(o.out) / "figures");
  unsigned workers = intervox::resolve_threads(o.workers);  // 0: all cores; capped at them
  workers = std::min<unsigned>(workers, static_cast<unsigned>(std::max<std::size_t>(1, configs.size())));
  std::atomic<std::size_t> next{0}, done{0};
  std::mutex print;
  std::exception_ptr error;
  auto work = [&] {
    for (;;) {
      const std::size_t i = next++;
      if (i >= configs.size()) return;
      const RunConfig& c = configs[i];
      std::string stem;
      if (o.figures && c.seed == 1) {
        std::string name = c.group();
        std::replace(name.begin(), name.end(), '/', '_');
        stem = (std::filesystem::path(o.out) / "figures" / name).string();
      }
      try {
        results[i] = run_one(c, o, stem);
      } catch (...) {
        const std::lock_guard lock(print);
        if (!error) error = std::current_exception();
        return;
      }
      const std::size_t n = ++done;
      if (o.progress) {
        const std::lock_guard lock(print);
        const RunResult& r = results[i];
        std::printf("[%3zu/%zu] %-44s seed %2llu: %2d steps, %-22s known %5.1f %%, wrong occ %5zu free %5zu, %.1f s\n", n,
                    configs.size(), c.group().c_str(), static_cast<unsigned long long>(c.seed), r.steps,
                    r.termination.c_str(), 100 * r.known, r.wrongly_occupied, r.wrongly_free, r.seconds_total);
        std::fflush(stdout);
      }
    }
  };
  std::vector<std::thread> pool;
  for (unsigned w = 1; w < workers; ++w) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
  return results;
}

/// Mean and sample standard deviation.
struct Stat {
  double mean = 0, sd = 0;
  int n = 0;
};
inline Stat stat(const std::vector<double>& v) {
  Stat s;
  s.n = static_cast<int>(v.size());
  if (v.empty()) return s;
  for (double x : v) s.mean += x;
  s.mean /= static_cast<double>(v.size());
  if (v.size() > 1) {
    double q = 0;
    for (double x : v) q += (x - s.mean) * (x - s.mean);
    s.sd = std::sqrt(q / static_cast<double>(v.size() - 1));
  }
  return s;
}

/// The columns of results.csv, in order.
inline constexpr std::string_view kCsvHeader =
    "platform,surface,update,utility,seed,steps,termination,completed,known,area_m2,wrongly_occupied,"
    "wrongly_free,true_occupied,conflicts,seconds_per_step,seconds_total";

/// Writes results.csv (one row per run).
inline void write_csv(const std::string& path, const std::vector<RunResult>& results) {
  std::ostringstream f;
  f << kCsvHeader << '\n';
  for (const RunResult& r : results) {
    const RunConfig& c = r.config;
    f << c.platform << ',' << c.surface << ',' << c.update << ',' << c.utility << ',' << c.seed << ',' << r.steps << ','
      << r.termination << ',' << (r.completed ? 1 : 0) << ',' << r.known << ',' << r.area << ',' << r.wrongly_occupied
      << ',' << r.wrongly_free << ',' << r.true_occupied << ',' << r.conflicts << ',' << r.seconds_per_step << ','
      << r.seconds_total << '\n';
  }
  iv::write_text_file(path, f.str());
}

namespace detail {

/// One row of a results.csv being read: every field is checked, and an error names the file, the
/// line, the column and the value.
class CsvRow {
 public:
  CsvRow(std::string path, int line, std::vector<std::string> fields)
      : path_(std::move(path)), line_(line), fields_(std::move(fields)) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw iv::IoError(path_ + " line " + std::to_string(line_) + ": " + what);
  }

  /// Field `i`, which must be one of `allowed`.
  const std::string& text(std::size_t i, std::initializer_list<std::string_view> allowed) const {
    return text_in(i, allowed);
  }
  /// Field `i`, which must be one of the range `allowed` of string views.
  template <class Range>
  const std::string& text_in(std::size_t i, const Range& allowed) const {
    const std::string& v = fields_[i];
    if (std::find(std::begin(allowed), std::end(allowed), v) == std::end(allowed)) {
      fail(column(i) + " is '" + v + "', expected " + list(allowed));
    }
    return v;
  }

  /// Field `i` as a whole number of type T in [min, max] (no sign on unsigned types, no wrap-around).
  template <class T>
  T integer(std::size_t i, T min = std::numeric_limits<T>::min(), T max = std::numeric_limits<T>::max()) const {
    const std::string& v = fields_[i];
    T value{};
    const auto [stop, error] = std::from_chars(v.data(), v.data() + v.size(), value);
    if (v.empty() || error != std::errc{} || stop != v.data() + v.size() || value < min || value > max) {
      fail(column(i) + " is '" + v + "', expected a whole number in [" + std::to_string(min) + ", " +
           std::to_string(max) + "]");
    }
    return value;
  }

  /// Field `i` as a finite number in [min, max].
  double number(std::size_t i, double min, double max = std::numeric_limits<double>::max()) const {
    const std::string& v = fields_[i];
    double value = 0;
    const auto [stop, error] = std::from_chars(v.data(), v.data() + v.size(), value);
    if (v.empty() || error != std::errc{} || stop != v.data() + v.size() || !std::isfinite(value) || value < min ||
        value > max) {
      std::ostringstream range;
      range << "a finite number >= " << min;
      if (max != std::numeric_limits<double>::max()) range << " and <= " << max;
      fail(column(i) + " is '" + v + "', expected " + range.str());
    }
    return value;
  }

 private:
  static std::string column(std::size_t i) {
    std::string_view header = kCsvHeader;
    for (std::size_t k = 0; k < i; ++k) header.remove_prefix(header.find(',') + 1);
    return std::string(header.substr(0, header.find(',')));
  }
  template <class Range>
  static std::string list(const Range& names) {
    std::string out;
    for (std::string_view n : names) out += (out.empty() ? "" : ", ") + std::string(n);
    return "one of " + out;
  }

  std::string path_;
  int line_;
  std::vector<std::string> fields_;
};

}  // namespace detail

/// Reads a results.csv written by write_csv (to regenerate the tables and the JSON, or to merge
/// sweeps run separately). Every field is checked: names against the sweep's platforms, surfaces,
/// objects, updates, criteria and terminations, counts as whole numbers (conflicts >= -1), the
/// known fraction in [0, 1], the other figures finite and >= 0. \throws IoError naming the file, the line, the column and the value for a missing
/// file, a wrong header, a row with too few or too many fields or a bad field.
inline std::vector<RunResult> read_csv(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw iv::IoError("cannot read " + path);
  std::vector<RunResult> out;
  std::string line;
  auto strip_cr = [&] {
    if (!line.empty() && line.back() == '\r') line.pop_back();
  };
  if (!std::getline(f, line)) throw iv::IoError(path + " is empty, expected the header line " + std::string(kCsvHeader));
  strip_cr();
  if (line != kCsvHeader) {
    throw iv::IoError(path + " line 1: the header is '" + line + "', expected '" + std::string(kCsvHeader) + "'");
  }
  constexpr std::size_t kColumns = 16;
  for (int number = 2; std::getline(f, line); ++number) {
    strip_cr();
    if (line.empty()) continue;
    std::vector<std::string> v;
    std::size_t begin = 0;
    for (std::size_t comma; (comma = line.find(',', begin)) != std::string::npos; begin = comma + 1) {
      v.push_back(line.substr(begin, comma - begin));
    }
    v.push_back(line.substr(begin));
    if (v.size() != kColumns) {
      throw iv::IoError(path + " line " + std::to_string(number) + " has " + std::to_string(v.size()) +
                        " fields, expected " + std::to_string(kColumns));
    }
    const detail::CsvRow row(path, number, std::move(v));
    RunResult r;
    r.config.platform = row.text(0, {"mobile", "arm"});
    r.config.surface = r.config.platform == "mobile" ? row.text_in(1, iv::sim::kMaterialNames)
                                                     : row.text(1, {"part", "bottle", "box"});
    r.config.update = row.text(2, {"bayes", "interval-lower", "interval-mean", "interval-upper", "compact-interval-mean"});
    r.config.utility = row.text(3, {"entropy", "max-entropy"});
    r.config.seed = row.integer<std::uint64_t>(4);
    r.steps = row.integer<int>(5, 0);
    r.termination = row.text(6, {"explored", "no reachable frontier", "blocked", "budget"});
    r.completed = row.integer<int>(7, 0, 1) == 1;
    r.known = row.number(8, 0.0, 1.0);
    r.area = row.number(9, 0.0);
    r.wrongly_occupied = row.integer<std::size_t>(10);
    r.wrongly_free = row.integer<std::size_t>(11);
    r.true_occupied = row.integer<std::size_t>(12);
    r.conflicts = row.integer<long long>(13, -1);
    r.seconds_per_step = row.number(14, 0.0);
    r.seconds_total = row.number(15, 0.0);
    out.push_back(std::move(r));
  }
  return out;
}

/// Aggregates per configuration (mean +- sd over seeds), in first-appearance order.
struct GroupSummary {
  RunConfig config;  // seed unused
  int runs = 0, completed = 0;
  Stat steps, known, wrongly_occupied, wrongly_free, conflicts, seconds_per_step;
  std::map<std::string, int> terminations;
};

inline std::vector<GroupSummary> summarise(const std::vector<RunResult>& results) {
  std::vector<std::string> order;
  std::map<std::string, std::vector<const RunResult*>> groups;
  for (const RunResult& r : results) {
    const std::string g = r.config.group();
    if (!groups.count(g)) order.push_back(g);
    groups[g].push_back(&r);
  }
  std::vector<GroupSummary> out;
  for (const std::string& g : order) {
    const auto& rs = groups[g];
    GroupSummary s;
    s.config = rs.front()->config;
    s.runs = static_cast<int>(rs.size());
    std::vector<double> st, kn, wo, wf, cf, sp;
    for (const RunResult* r : rs) {
      s.completed += r->completed;
      ++s.terminations[r->termination];
      st.push_back(r->steps);
      kn.push_back(r->known);
      wo.push_back(static_cast<double>(r->wrongly_occupied));
      wf.push_back(static_cast<double>(r->wrongly_free));
      if (r->conflicts >= 0) cf.push_back(static_cast<double>(r->conflicts));
      sp.push_back(r->seconds_per_step);
    }
    s.steps = stat(st);
    s.known = stat(kn);
    s.wrongly_occupied = stat(wo);
    s.wrongly_free = stat(wf);
    s.conflicts = stat(cf);
    s.seconds_per_step = stat(sp);
    out.push_back(std::move(s));
  }
  return out;
}

/// Writes results.json: the options, every run and the per-configuration summary.
inline void write_json(const std::string& path, const SweepOptions& o, const std::vector<RunResult>& results) {
  nlohmann::json j;
  j["options"] = {{"seeds", o.seeds}, {"resolution", o.resolution}, {"max_steps", o.max_steps},
                  {"gain_stride", o.gain_stride}, {"complete_fraction", kCompleteFraction},
                  {"conflict_width", kConflictWidth}};
  auto stat_json = [](const Stat& s) { return nlohmann::json{{"mean", s.mean}, {"sd", s.sd}, {"n", s.n}}; };
  for (const RunResult& r : results) {
    const RunConfig& c = r.config;
    j["runs"].push_back({{"platform", c.platform}, {"surface", c.surface}, {"update", c.update}, {"utility", c.utility},
                         {"seed", c.seed}, {"steps", r.steps}, {"termination", r.termination},
                         {"completed", r.completed}, {"known", r.known}, {"area_m2", r.area},
                         {"wrongly_occupied", r.wrongly_occupied}, {"wrongly_free", r.wrongly_free},
                         {"true_occupied", r.true_occupied}, {"conflicts", r.conflicts},
                         {"seconds_per_step", r.seconds_per_step}, {"seconds_total", r.seconds_total}});
  }
  for (const GroupSummary& s : summarise(results)) {
    j["summary"].push_back({{"configuration", s.config.group()}, {"runs", s.runs}, {"completed", s.completed},
                            {"terminations", s.terminations}, {"steps", stat_json(s.steps)}, {"known", stat_json(s.known)},
                            {"wrongly_occupied", stat_json(s.wrongly_occupied)},
                            {"wrongly_free", stat_json(s.wrongly_free)}, {"conflicts", stat_json(s.conflicts)},
                            {"seconds_per_step", stat_json(s.seconds_per_step)}});
  }
  iv::write_text_file(path, j.dump(1) + "\n");
}

/// The tables of docs/experiments.md: one row per configuration, mean +- sd over the seeds.
inline std::string tables_markdown(const std::vector<RunResult>& results) {
  std::ostringstream m;
  char buf[512];
  std::string platform;
  for (const GroupSummary& s : summarise(results)) {
    if (s.config.platform != platform) {
      platform = s.config.platform;
      m << "\n### " << (platform == "mobile" ? "Mobile exploration of the lab room" : "Arm object modelling") << "\n\n";
      m << "| " << (platform == "mobile" ? "closet" : "object")
        << " | update | criterion | runs | completed | steps | known % | wrongly occupied | wrongly free | conflicts | s / step | terminations |\n";
      m << "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    }
    std::string terms;
    for (const auto& [t, n] : s.terminations) terms += (terms.empty() ? "" : ", ") + t + " " + std::to_string(n);
    char conflicts[64] = "–";
    if (s.conflicts.n > 0) std::snprintf(conflicts, sizeof conflicts, "%.0f ± %.0f", s.conflicts.mean, s.conflicts.sd);
    std::snprintf(buf, sizeof buf,
                  "| %s | %s | %s | %d | %d | %.1f ± %.1f | %.1f ± %.1f | %.0f ± %.0f | %.0f ± %.0f | %s | %.2f | %s |\n",
                  s.config.surface.c_str(), s.config.update.c_str(), s.config.utility.c_str(), s.runs, s.completed,
                  s.steps.mean, s.steps.sd, 100 * s.known.mean, 100 * s.known.sd, s.wrongly_occupied.mean,
                  s.wrongly_occupied.sd, s.wrongly_free.mean, s.wrongly_free.sd, conflicts,
                  s.seconds_per_step.mean, terms.c_str());
    m << buf;
  }
  return m.str();
}

/// Writes results.csv, results.json and tables.md for \p results into o.out.
inline void write_results(const SweepOptions& o, const std::vector<RunResult>& results) {
  std::filesystem::create_directories(o.out);
  const std::filesystem::path out(o.out);
  write_csv((out / "results.csv").string(), results);
  write_json((out / "results.json").string(), o, results);
  iv::write_text_file((out / "tables.md").string(), tables_markdown(results));
}

/// Runs the sweep and writes results.csv, results.json, tables.md and figures/ into o.out.
inline std::vector<RunResult> run_and_write(const SweepOptions& o) {
  std::filesystem::create_directories(o.out);
  const std::vector<RunResult> results = run_sweep(o);
  write_results(o, results);
  return results;
}

}  // namespace experiments
