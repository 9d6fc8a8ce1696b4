#pragma once
// The simulated rig with the floor returns cut out of every scan (thesis 3.3.1): the source of the
// experiments' mobile runs under the thesis condition (runs.hpp, map_rules.cpp).
#include "beam_class_score.hpp"

#include <intervox/core/sensor_data.hpp>
#include <intervox/eval/conflict_scoring.hpp>
#include <intervox/sim/sim.hpp>

#include <cstddef>
#include <deque>
#include <functional>
#include <span>
#include <vector>

namespace experiments {

namespace iv = intervox;

/// The lab room's rig in the simulator, with the floor returns cut out of every scan when asked
/// (thesis 3.3.1), feeding the simulator's label of every inserted beam to the conflict evidence.
/// The cut beams did return: `confirm` (if set) receives them, so that the map's evidence counts
/// the space they crossed as confirmed (ExplainedMap::add_evidence) although the grid never sees
/// them. With `log` set, every batch the map's evidence is given (the cut floor returns, then the
/// scan) is appended to it with the simulator's paths, in the order the channel classes them
/// (score_beam_classes()).
struct FloorCutSource {
  iv::sim::SimulatedRig rig;
  bool cut = true;
  double height = 0.05;
  iv::ConflictEvidence* evidence = nullptr;
  std::function<void(std::span<const iv::Beam>)> confirm;
  std::deque<LabelledBatch>* log = nullptr;
  std::vector<iv::Beam> operator()(const iv::Pose& body) {
    std::vector<iv::Beam> beams = rig(body);
    std::vector<iv::sim::BeamPath> paths = rig.last_paths();
    if (cut) {
      std::vector<iv::Beam> floor;
      std::vector<iv::sim::BeamPath> floor_paths;
      std::size_t kept = 0;
      for (std::size_t i = 0; i < beams.size(); ++i) {
        if (beams[i].hit && beams[i].end.z() <= height) {
          floor.push_back(beams[i]);
          floor_paths.push_back(paths[i]);
          continue;
        }
        beams[kept] = beams[i];
        paths[kept] = paths[i];
        ++kept;
      }
      beams.resize(kept);
      paths.resize(kept);
      if (log && confirm) log->push_back({floor, std::move(floor_paths)});
      if (confirm) confirm(floor);
    }
    if (evidence) evidence->add(beams, paths);
    if (log) log->push_back({beams, std::move(paths)});
    return beams;
  }
};

}  // namespace experiments
