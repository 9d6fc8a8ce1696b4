// Label-free per-voxel evidence against the simulator's conflict ground truth (issue 15's
// detector study, docs/notes/label-free-detector-study.md; in short in docs/experiments.md).
//
// Runs one mobile episode in the lab room under the sweep's conditions (interval-mean +
// max-entropy, plain planner, floor removed, gain over unknown voxels) and, for every beam the
// map receives, replays the insertion's traversal *before* the insertion, recording per voxel what
// any user's data would give: hits, misses, hits landing on a voxel the map then classified free,
// misses crossing a voxel it classified occupied (the contradictions latching makes the map
// ignore), misses of occupied voxels by beams that end more than 0.25 m beyond them, and returns
// whose beam crossed a map-occupied voxel first. Beside them, the simulator's labels
// (eval/conflict_scoring.hpp). Writes one row per voxel the beams reached; scripts/conflict_features.py
// scores detection rules on the rows.
//
//   ./build/examples/experiments/conflict_features --surface specular --seed 1 --out specular_1.csv
#include "runs.hpp"

#include "common/cli.hpp"

#include <intervox/io/text_file.hpp>
#include <intervox/raycast/vector_walks.hpp>
#include <intervox/update/interval_update.hpp>

#include <cstdint>
#include <filesystem>
#include <cstdio>
#include <sstream>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace {

namespace iv = intervox;

// What the beams told one voxel, label-free: everything a user's own scans give.
struct Features {
  std::uint32_t hits = 0;                 // returns ending in the voxel
  std::uint32_t misses = 0;               // beams crossing it before their end voxel
  std::uint32_t hit_on_free = 0;          // returns ending in it while the map classified it free
  std::uint32_t miss_on_occupied = 0;     // beams crossing it while the map classified it occupied
  std::uint32_t pass_occupied = 0;        // of those, beams ending more than 0.25 m beyond its centre
  std::uint32_t hit_behind_occupied = 0;  // returns ending in it after crossing a map-occupied voxel
};

struct Study {
  std::string surface = "specular";
  std::uint64_t seed = 1;
  std::string policies = "thesis";
  int max_steps = 30;
  std::string out;
};

int run(const Study& s) {
  // Refuse an output folder that does not exist before the episode, not after it.
  const std::filesystem::path parent = std::filesystem::absolute(s.out).parent_path();
  if (!std::filesystem::is_directory(parent))
    throw iv::IoError("cannot write " + s.out + ": " + parent.string() + " is not a folder");
  using Update = iv::IntervalUpdate<iv::MeanState>;
  using Grid = iv::VoxelGrid<Update, iv::MaxEntropy, iv::SparseStorage>;
  iv::sim::LabRoomOptions room;
  room.closet_material = iv::sim::material_from_string(s.surface);
  const iv::sim::LabRoom lab = iv::sim::make_lab_room(room);
  experiments::SweepOptions sweep;  // the sweep's resolution, stride and floor cut
  sweep.max_steps = s.max_steps;
  experiments::RunConfig config;  // the sweep's defaults: floor removed, gain over unknown voxels, plain planner
  config.surface = s.surface;
  config.update = "interval-mean";
  config.utility = "max-entropy";
  config.policies = s.policies;
  config.seed = s.seed;
  Grid grid(sweep.resolution, experiments::detail::make_policy<Update>(config.policies, config.unobserved));
  const iv::MobilePlannerParams p = experiments::detail::mobile_params(config, sweep);
  const iv::SensorRig rig = iv::SensorRig::mobile_base();
  iv::MobilePlanner planner(rig, p);
  iv::ConflictEvidence evidence(grid.geometry(), lab.scene, lab.scene.bounds(), planner.max_range());
  experiments::FloorCutSource cut{iv::sim::SimulatedRig(lab.scene, rig, s.seed), true, sweep.floor_cut, &evidence, {}};
  const iv::GridGeometry& g = grid.geometry();
  const double max_range = planner.max_range();
  std::unordered_map<iv::Key, Features, iv::KeyHash> features;
  // The source returns the scan the episode inserts next: the map is still as before it here.
  auto source = [&](const iv::Pose& body) {
    std::vector<iv::Beam> beams = cut(body);
    for (const iv::Beam& b : beams) {
      if (!iv::is_finite(b.origin) || !iv::is_finite(b.end)) continue;
      iv::Point3 end = b.end;
      bool hit = b.hit;
      const iv::Point3 d = b.end - b.origin;
      const double len = d.norm();
      if (!(len > 0)) continue;
      if (len > max_range) {  // the insertion's cut at the max range
        end = b.origin + d * (max_range / len);
        hit = false;
      }
      const auto end_key = g.try_key(end);
      if (!end_key) continue;
      bool crossed_occupied = false;
      iv::traverse(g, b.origin, end, [&](const iv::Key& k) {
        const bool is_end = k == *end_key;
        if (is_end && !hit) return false;
        const iv::Occupancy o = grid.occupancy(k);
        Features& f = features[k];
        if (is_end) {
          ++f.hits;
          f.hit_on_free += o == iv::Occupancy::Free;
          f.hit_behind_occupied += crossed_occupied;
          return false;
        }
        ++f.misses;
        if (o == iv::Occupancy::Occupied) {
          ++f.miss_on_occupied;
          crossed_occupied = true;
          f.pass_occupied += (end - g.center(k)).norm() > 0.25;
        }
        return true;
      });
    }
    return beams;
  };
  iv::Episode episode(grid, planner, source, iv::planar_pose(lab.start, 0.0));
  const iv::Termination t = episode.run();
  const std::vector<iv::Key> truth = evidence.conflict_voxels();
  const std::unordered_set<iv::Key, iv::KeyHash> is_truth(truth.begin(), truth.end());
  std::vector<iv::Key> keys;
  keys.reserve(features.size());
  for (const auto& [k, f] : features) keys.push_back(k);
  std::sort(keys.begin(), keys.end());  // rows in key order: the file does not depend on hashing
  std::ostringstream csv;
  csv << "x,y,z,scene_occupied,truth,phantom,true_evidence,observations,map,hits,misses,hit_on_free,miss_on_occupied,"
         "pass_occupied,hit_behind_occupied,fringe\n";
  const auto& counts = evidence.counts();
  for (const iv::Key& k : keys) {
    const Features& f = features.at(k);
    const iv::Point3 c = g.center(k);
    const auto it = counts.find(k);
    const iv::ConflictEvidence::Counts e = it == counts.end() ? iv::ConflictEvidence::Counts{} : it->second;
    char row[96];
    std::snprintf(row, sizeof row, "%.3f,%.3f,%.3f,", c.x(), c.y(), c.z());
    csv << row << evidence.occupied(k) << ',' << is_truth.count(k) << ',' << e.phantom << ',' << e.truth << ','
        << e.total << ',' << static_cast<int>(grid.occupancy(k)) << ',' << f.hits << ',' << f.misses << ','
        << f.hit_on_free << ',' << f.miss_on_occupied << ',' << f.pass_occupied << ',' << f.hit_behind_occupied << ','
        << iv::surface_fringe(grid, k, 1) << '\n';
  }
  iv::write_text_file(s.out, csv.str());
  std::printf("%s, seed %llu, %s: %d steps, %s; %zu voxels, %zu ground-truth conflict voxels -> %s\n",
              s.surface.c_str(), static_cast<unsigned long long>(s.seed), s.policies.c_str(),
              std::max(0, planner.steps() - 1), std::string(iv::to_string(t)).c_str(), keys.size(), truth.size(),
              s.out.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  intervox::use_vector_walks();  // the AVX-512 / AVX2 walks where the processor has them
  Study s;
  CLI::App app{"Intervox conflict_features: one mobile episode in the lab room; per voxel, label-free counts of what "
               "the beams told it and the simulator's conflict labels, as CSV (docs/experiments.md)."};
  app.add_option("--surface", s.surface, "closet surface")
      ->check(examples::one_of(intervox::sim::kMaterialNames))
      ->capture_default_str();
  app.add_option("--seed", s.seed, "seed of the simulator and the planner")
      ->check(examples::integer_in(1, 1000000))
      ->capture_default_str();
  app.add_option("--policies", s.policies, "policy preset: thesis (latching) or clamped")
      ->check(CLI::IsMember({"thesis", "clamped"}))
      ->capture_default_str();
  app.add_option("--max-steps", s.max_steps, "step budget")
      ->check(examples::integer_in(1, 1000))
      ->capture_default_str();
  app.add_option("--out", s.out, "CSV file to write")->required();
  return examples::cli_main("conflict_features", app, argc, argv, [&] { return run(s); });
}
