#pragma once
// Aggregates of the sweep: mean and sample standard deviation per configuration over the seeds,
// results.json and the Markdown tables of docs/experiments.md.
#include "results.hpp"

#include <intervox/io/text_file.hpp>

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace experiments {

/// A completion rule shared by every platform: the run ended on its own (not by budget or
/// blocking) and the part of the world it is responsible for is known to `kCompleteFraction`.
inline constexpr double kCompleteFraction = 0.95;
/// Interval width below which an observed, unknown voxel counts as a conflict (thesis ch. 6).
inline constexpr double kConflictWidth = 0.2;

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

/// Aggregates per configuration (mean +- sd over seeds), in first-appearance order.
struct GroupSummary {
  RunConfig config;  // seed unused
  int runs = 0, completed = 0, runs_with_collision = 0;
  Stat steps, known, wrongly_occupied, wrongly_free, band_wrongly_occupied, band_wrongly_free, conflicts, views_to_80,
      conflict_precision, conflict_recall, seconds_per_step;
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
    std::vector<double> st, kn, wo, wf, bo, bf, cf, v80, cp, cr, sp;
    for (const RunResult* r : rs) {
      s.completed += r->completed;
      s.runs_with_collision += (r->collision_poses + r->collision_segments) > 0;
      ++s.terminations[r->termination];
      st.push_back(r->steps);
      kn.push_back(r->known);
      wo.push_back(static_cast<double>(r->wrongly_occupied));
      wf.push_back(static_cast<double>(r->wrongly_free));
      bo.push_back(static_cast<double>(r->band_wrongly_occupied));
      bf.push_back(static_cast<double>(r->band_wrongly_free));
      if (r->conflicts >= 0) cf.push_back(static_cast<double>(r->conflicts));
      if (r->views_to_80 >= 0) v80.push_back(r->views_to_80);
      if (r->conflict_precision >= 0) cp.push_back(r->conflict_precision);
      if (r->conflict_recall >= 0) cr.push_back(r->conflict_recall);
      sp.push_back(r->seconds_per_step);
    }
    s.steps = stat(st);
    s.known = stat(kn);
    s.wrongly_occupied = stat(wo);
    s.wrongly_free = stat(wf);
    s.band_wrongly_occupied = stat(bo);
    s.band_wrongly_free = stat(bf);
    s.conflicts = stat(cf);
    s.views_to_80 = stat(v80);
    s.conflict_precision = stat(cp);
    s.conflict_recall = stat(cr);
    s.seconds_per_step = stat(sp);
    out.push_back(std::move(s));
  }
  return out;
}

/// collision_objects as JSON: one object per scene object met, {"object", "poses", "segments"}.
inline nlohmann::json collision_objects_json(const std::vector<RunResult::ObjectCollisions>& v) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& c : v) a.push_back({{"object", c.object}, {"poses", c.poses}, {"segments", c.segments}});
  return a;
}

/// Writes results.json: the options, every run and the per-configuration summary.
inline void write_json(const std::string& path, const SweepOptions& o, const std::vector<RunResult>& results) {
  nlohmann::json j;
  j["options"] = {{"seeds", o.seeds},
                  {"resolution", o.resolution},
                  {"max_steps", o.max_steps},
                  {"gain_stride", o.gain_stride},
                  {"floor_cut", o.floor_cut},
                  {"complete_fraction", kCompleteFraction},
                  {"conflict_width", kConflictWidth}};
  auto stat_json = [](const Stat& s) { return nlohmann::json{{"mean", s.mean}, {"sd", s.sd}, {"n", s.n}}; };
  j["runs"] = nlohmann::json::array();
  for (const RunResult& r : results) {
    const RunConfig& c = r.config;
    j["runs"].push_back({{"platform", c.platform},
                         {"surface", c.surface},
                         {"update", c.update},
                         {"utility", c.utility},
                         {"policies", c.policies},
                         {"floor", c.floor},
                         {"gain", c.gain},
                         {"planner", c.planner},
                         {"unobserved", c.unobserved},
                         {"room", c.room},
                         {"rules", c.rules},
                         {"sensor", c.sensor},
                         {"seed", c.seed},
                         {"steps", r.steps},
                         {"termination", r.termination},
                         {"completed", r.completed},
                         {"known", r.known},
                         {"area_m2", r.area},
                         {"wrongly_occupied", r.wrongly_occupied},
                         {"wrongly_free", r.wrongly_free},
                         {"true_occupied", r.true_occupied},
                         {"region_voxels", r.region_voxels},
                         {"band_wrongly_occupied", r.band_wrongly_occupied},
                         {"band_wrongly_free", r.band_wrongly_free},
                         {"band_voxels", r.band_voxels},
                         {"collision_poses", r.collision_poses},
                         {"collision_segments", r.collision_segments},
                         {"collision_objects", collision_objects_json(r.collision_objects)},
                         {"conflicts", r.conflicts},
                         {"conflict_precision", r.conflict_precision},
                         {"conflict_recall", r.conflict_recall},
                         {"conflict_truth", r.conflict_truth},
                         {"signature_voxels", r.signature_voxels},
                         {"signature_band", r.signature_band},
                         {"flagged_voxels", r.flagged_voxels},
                         {"flagged_band", r.flagged_band},
                         {"truth_band", r.truth_band},
                         {"views_to_80", r.views_to_80},
                         {"coverage_curve", r.coverage_curve},
                         {"distance", r.distance},
                         {"annex_known", r.annex_known},
                         {"closet_free_curve", r.closet_free_curve},
                         {"direct_suspect", r.direct_suspect},
                         {"reflected_suspect", r.reflected_suspect},
                         {"suspect_precision", r.suspect_precision},
                         {"suspect_recall", r.suspect_recall},
                         {"explained_free_share", r.explained_free_share},
                         {"annex_explained_free_share", r.annex_explained_free_share},
                         {"door_plans", r.door_plans},
                         {"door_opening_plans", r.door_opening_plans},
                         {"door_last_opening", r.door_last_opening},
                         {"seconds_per_step", r.seconds_per_step},
                         {"seconds_total", r.seconds_total}});
  }
  j["summary"] = nlohmann::json::array();
  for (const GroupSummary& s : summarise(results)) {
    j["summary"].push_back({{"configuration", s.config.group()},
                            {"runs", s.runs},
                            {"completed", s.completed},
                            {"runs_with_collision", s.runs_with_collision},
                            {"terminations", s.terminations},
                            {"steps", stat_json(s.steps)},
                            {"known", stat_json(s.known)},
                            {"wrongly_occupied", stat_json(s.wrongly_occupied)},
                            {"wrongly_free", stat_json(s.wrongly_free)},
                            {"band_wrongly_occupied", stat_json(s.band_wrongly_occupied)},
                            {"band_wrongly_free", stat_json(s.band_wrongly_free)},
                            {"conflicts", stat_json(s.conflicts)},
                            {"views_to_80", stat_json(s.views_to_80)},
                            {"conflict_precision", stat_json(s.conflict_precision)},
                            {"conflict_recall", stat_json(s.conflict_recall)},
                            {"seconds_per_step", stat_json(s.seconds_per_step)}});
  }
  iv::write_text_file(path, j.dump(1) + "\n");
}

/// The tables of docs/experiments.md: one row per configuration, mean +- sd over the seeds.
inline std::string tables_markdown(const std::vector<RunResult>& results) {
  std::ostringstream m;
  char buf[1024];
  std::string platform;
  for (const GroupSummary& s : summarise(results)) {
    const bool mobile = s.config.platform == "mobile";
    if (s.config.platform != platform) {
      platform = s.config.platform;
      m << "\n### " << (mobile ? "Mobile exploration of the lab room" : "Arm object modelling") << "\n\n";
      if (mobile) {
        m << "| closet | update | criterion | policies | floor | gain | planner | runs | completed | steps | known % | "
             "wrongly occupied (band) | wrongly free (band) | wrongly occupied (room) | wrongly free (room) | runs "
             "with "
             "collision | conflicts | detection precision / recall | s / step | terminations |\n";
        m << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
      } else {
        m << "| object | update | criterion | policies | gain | runs | completed | views | coverage % | views to 80 % "
             "| "
             "wrongly occupied | wrongly free | conflicts | s / view | terminations |\n";
        m << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
      }
    }
    // The thesis' classification of never-observed space is marked on the update.
    const std::string update = s.config.update + (s.config.unobserved == "by-rule" ? " (unobserved by rule)" : "");
    // The room is marked on the closet, the rules and the sensor condition on the planner.
    const std::string closet = s.config.surface + (s.config.room == "lab" ? "" : " (" + s.config.room + ")");
    const std::string planner = s.config.planner +
                                (s.config.rules == "thesis" ? "" : ", " + s.config.rules + " rules") +
                                (s.config.sensor == "plain" ? "" : ", " + s.config.sensor);
    std::string terms;
    for (const auto& [t, n] : s.terminations) terms += (terms.empty() ? "" : ", ") + t + " " + std::to_string(n);
    char conflicts[64] = "–";
    if (s.conflicts.n > 0) std::snprintf(conflicts, sizeof conflicts, "%.0f ± %.0f", s.conflicts.mean, s.conflicts.sd);
    if (mobile) {
      char detection[96] = "–";
      if (s.conflict_precision.n > 0)
        std::snprintf(detection, sizeof detection, "%.2f ± %.2f / %.2f ± %.2f", s.conflict_precision.mean,
                      s.conflict_precision.sd, s.conflict_recall.mean, s.conflict_recall.sd);
      std::snprintf(
          buf, sizeof buf,
          "| %s | %s | %s | %s | %s | %s | %s | %d | %d | %.1f ± %.1f | %.1f ± %.1f | %.0f ± %.0f | %.0f ± %.0f | "
          "%.0f ± %.0f | %.0f ± %.0f | %d | %s | %s | %.2f | %s |\n",
          closet.c_str(), update.c_str(), s.config.utility.c_str(), s.config.policies.c_str(), s.config.floor.c_str(),
          s.config.gain.c_str(), planner.c_str(), s.runs, s.completed, s.steps.mean, s.steps.sd, 100 * s.known.mean,
          100 * s.known.sd, s.band_wrongly_occupied.mean, s.band_wrongly_occupied.sd, s.band_wrongly_free.mean,
          s.band_wrongly_free.sd, s.wrongly_occupied.mean, s.wrongly_occupied.sd, s.wrongly_free.mean,
          s.wrongly_free.sd, s.runs_with_collision, conflicts, detection, s.seconds_per_step.mean, terms.c_str());
    } else {
      char v80[64] = "never";
      if (s.views_to_80.n > 0)
        std::snprintf(v80, sizeof v80, "%.1f ± %.1f (%d of %d)", s.views_to_80.mean, s.views_to_80.sd, s.views_to_80.n,
                      s.runs);
      std::snprintf(
          buf, sizeof buf,
          "| %s | %s | %s | %s | %s | %d | %d | %.1f ± %.1f | %.1f ± %.1f | %s | %.0f ± %.0f | %.0f ± %.0f | %s | "
          "%.2f | %s |\n",
          s.config.surface.c_str(), update.c_str(), s.config.utility.c_str(), s.config.policies.c_str(),
          s.config.gain.c_str(), s.runs, s.completed, s.steps.mean, s.steps.sd, 100 * s.known.mean, 100 * s.known.sd,
          v80, s.wrongly_occupied.mean, s.wrongly_occupied.sd, s.wrongly_free.mean, s.wrongly_free.sd, conflicts,
          s.seconds_per_step.mean, terms.c_str());
    }
    m << buf;
  }
  return m.str();
}

}  // namespace experiments
