#pragma once
/// \file
/// The options of the explained channel (ExplainedSpace, explain/explained_space.hpp, whose file
/// comment says what each threshold decides): the belief model, the crossing and mid-air
/// thresholds of the classes, and the revision ledger's budget and rhythm.

#include <intervox/core/validate.hpp>
#include <intervox/explain/evidence.hpp>

#include <cstddef>

namespace intervox {

/// The classification thresholds and the belief model of ExplainedSpace (see its file comment).
struct ExplainOptions {
  /// The belief combination (masses, class reliabilities, state thresholds).
  EvidenceModel model{};
  /// Trusted hits a voxel needs to be a supported surface, >= 1.
  int min_surface_hits = 2;
  /// ... and trusted hits >= this x trusted misses (so that a voxel at an edge, crossed more often
  /// than hit, is no surface), >= 0.
  double surface_hit_ratio = 1.0;
  /// m: how far before a beam's end a supported voxel must lie to count as a crossing, and the
  /// reach along the beam around its end of the grazing and mid-air tests; finite, >= 0.
  double crossing_tolerance = 0.15;
  /// Trusted misses every voxel near a beam's end needs (with no trusted hit) for the end to lie
  /// in mid-air; >= 1.
  int mid_air_misses = 3;
  /// Degrees: a beam without a return counts as passing a supported surface only where it meets
  /// the surface's inside (every neighbour across its local plane supported, the plane fitted to
  /// the supported voxels within one voxel) at this angle to the plane or steeper; a sensor loses
  /// grazing returns, and a beam that skims a surface, an edge, a corner or a thin rod is no
  /// evidence that the surface lied. In [0, 90].
  double no_return_crossing_angle = 20.0;
  /// Suspect misses a voxel needs to be free only by lying beams (free_only_by_lying_beams()), in
  /// [1, 65535]. With 2, one stray suspect miss in space that beams without a return crossed (out
  /// of range, no lie) does not make it lying, but a black surface's space that one suspect beam
  /// crossed is not lying either. Measured on the explained planner with hazards in
  /// docs/planning.md ("Two variants, measured"): 2 brings the lab room's floor known
  /// from 94-97 % to 99.7-99.9 % for every closet, at 17-21 steps instead of 13-15, with one run of
  /// ten meeting the front-only mirror closet (none with 1). 1 by default.
  int min_lying_misses = 1;
  /// A returned beam's crossing (the crossing test of the file comment) counts, as a beam
  /// without a return's does, only at a supported voxel of a surface's *inside* met at
  /// no_return_crossing_angle or steeper: the supported voxels within one voxel span a plane,
  /// the beam meets it that steeply, and every neighbour across the plane is supported. A beam
  /// that passes a door's jamb, a desk's leg, an edge, a corner or a lone voxel (whose hits sit
  /// in the voxel beside the real face), or a surface at a flatter angle, is then no crossing.
  /// Revision stays exact: a change within one voxel of a kept beam's path counts as a change on
  /// it. On the room frame it costs 2 % more without the ledger and a third less with it (fewer
  /// beams move; docs/performance.md, "Explained free space"). Off by default: any supported
  /// voxel counts (docs/concepts.md, "The inside rule for returned beams", measures both).
  bool returned_crossing_inside = false;
  /// Bytes the revision ledger may hold (the newest scans, classed again when the map changes
  /// where their beams pass; see the file comment and explain/beam_ledger.hpp); 0 turns revision
  /// off, and every beam keeps the class of its arrival. 48 MiB holds one to three million beams,
  /// depending on how many blocks their scans touch (LedgerScan::bytes()).
  std::size_t ledger_bytes = std::size_t{48} << 20;
  /// Rounds of one revision at most, >= 1 (a move changes trusted evidence, which can change
  /// another kept beam's class; the rounds stop as soon as one changes nothing).
  int revision_rounds = 4;
  /// Scans between two revisions, >= 1: add() revises after every revision_interval-th scan (the
  /// changes of the scans in between wait for it; ExplainedSpace::revise() runs one at any time,
  /// e.g. before planning). A revision costs about one insertion of every kept scan whose beams
  /// a change concerns, so revising after every scan costs several times the insertion (measured
  /// in docs/performance.md, "Explained free space"); 8 by default.
  int revision_interval = 8;

  /// \throws InvalidArgument naming the first invalid parameter.
  void validate() const {
    model.validate();
    const ParamCheck check("intervox::ExplainOptions");
    check.at_least("min_surface_hits", min_surface_hits, 1);
    check.nonnegative("surface_hit_ratio", surface_hit_ratio);
    check.nonnegative("crossing_tolerance", crossing_tolerance);
    check.at_least("mid_air_misses", mid_air_misses, 1);
    check.in_range("no_return_crossing_angle", no_return_crossing_angle, 0, 90);
    check.in_range("min_lying_misses", min_lying_misses, 1, 65535);
    check.at_least("revision_rounds", revision_rounds, 1);
    check.at_least("revision_interval", revision_interval, 1);
  }
};

}  // namespace intervox
