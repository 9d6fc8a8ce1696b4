#pragma once
// The explained channel's beam classes against the simulator's labels: which returned beams the
// channel holds suspect at the end of a run, by their true path (direct, reflected, passed through
// glass). Scores the classes the revision ledger holds (docs/concepts.md, "Revision: the order of
// arrival"): those of the scans it keeps, after every revision.
#include <intervox/core/error.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/explain/beam_ledger.hpp>
#include <intervox/sim/simulate.hpp>

#include <cstddef>
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

namespace experiments {

namespace iv = intervox;

/// The beams of one batch the map's channel classed (a scan, or the evidence-only floor returns),
/// with the simulator's path of each.
struct LabelledBatch {
  std::vector<iv::Beam> beams;
  std::vector<iv::sim::BeamPath> paths;  ///< one per beam
};

/// Returned beams the ledger keeps, counted by true path and by whether they are suspect.
/// "Lying" beams are those that returned after a reflection or through glass: their end is not
/// where the beam first met a surface.
struct BeamClassScore {
  std::uint64_t scans = 0;  ///< ledger scans scored
  std::uint64_t direct = 0, direct_suspect = 0;
  std::uint64_t reflected = 0, reflected_suspect = 0;
  std::uint64_t passed = 0, passed_suspect = 0;

  /// Of the suspect returned beams, the share that lie; -1 if none is suspect.
  double precision() const noexcept {
    const std::uint64_t s = direct_suspect + reflected_suspect + passed_suspect;
    return s == 0 ? -1.0 : static_cast<double>(reflected_suspect + passed_suspect) / static_cast<double>(s);
  }
  /// Of the lying returned beams, the share held suspect; -1 if none lies.
  double recall() const noexcept {
    const std::uint64_t l = reflected + passed;
    return l == 0 ? -1.0 : static_cast<double>(reflected_suspect + passed_suspect) / static_cast<double>(l);
  }
  /// Share of the direct (or reflected) returned beams held suspect; -1 if there are none.
  double direct_share() const noexcept { return share(direct_suspect, direct); }
  double reflected_share() const noexcept { return share(reflected_suspect, reflected); }

 private:
  static double share(std::uint64_t a, std::uint64_t b) noexcept {
    return b == 0 ? -1.0 : static_cast<double>(a) / static_cast<double>(b);
  }
};

/// Scores the classes \p scans (a ledger's, oldest first) hold now against \p log, every batch
/// the planner observed, oldest first. A ledger scan holds its batch's beams in order without
/// the skipped ones; batches the ledger refused or forgot have no scan. So each scan, newest
/// first, is matched to the newest batch not yet matched whose beams hold its beams, equal and
/// in order (passing over batches that do not). Beams without a return are not scored.
/// \throws intervox::InvalidArgument if a batch's beams and paths differ in number, or a scan
///         matches no batch (the log is not the one the planner observed).
inline BeamClassScore score_beam_classes(const std::deque<iv::LedgerScan>& scans,
                                         const std::deque<LabelledBatch>& log) {
  for (const LabelledBatch& b : log)
    if (b.beams.size() != b.paths.size())
      throw iv::InvalidArgument("experiments::score_beam_classes: a batch of " + std::to_string(b.beams.size()) +
                                " beams has " + std::to_string(b.paths.size()) + " paths");
  BeamClassScore score;
  std::vector<iv::sim::BeamPath> matched;
  // Matches scan \p s against batch \p b: the path of each of its beams, or false.
  const auto match = [&](const iv::LedgerScan& s, const LabelledBatch& b) {
    matched.clear();
    std::size_t k = 0;
    bool ok = true;
    s.for_each([&](std::size_t, const iv::Beam& beam, iv::BeamClass) {
      while (ok && k < b.beams.size() &&
             !(b.beams[k].end == beam.end && b.beams[k].origin == beam.origin && b.beams[k].hit == beam.hit))
        ++k;
      if (k == b.beams.size()) ok = false;
      if (!ok) return;
      matched.push_back(b.paths[k++]);
    });
    return ok;
  };
  std::size_t next = log.size();  // batches [0, next) are not matched yet
  for (auto s = scans.rbegin(); s != scans.rend(); ++s) {
    if (s->size() == 0) continue;
    bool found = false;
    while (!found && next > 0) found = match(*s, log[--next]);
    if (!found) throw iv::InvalidArgument("experiments::score_beam_classes: a ledger scan matches no observed batch");
    ++score.scans;
    s->for_each([&](std::size_t i, const iv::Beam& beam, iv::BeamClass c) {
      if (!beam.hit) return;
      std::uint64_t* counts[2] = {nullptr, nullptr};  // the path's beams, and those of them held suspect
      if (matched[i] == iv::sim::BeamPath::Direct) counts[0] = &score.direct, counts[1] = &score.direct_suspect;
      if (matched[i] == iv::sim::BeamPath::Reflected)
        counts[0] = &score.reflected, counts[1] = &score.reflected_suspect;
      if (matched[i] == iv::sim::BeamPath::Passed) counts[0] = &score.passed, counts[1] = &score.passed_suspect;
      if (!counts[0]) return;  // a return the simulator calls no return or invalid: not scored
      ++*counts[0];
      if (c == iv::BeamClass::Suspect) ++*counts[1];
    });
  }
  return score;
}

}  // namespace experiments
