#pragma once
/// \file
/// One map that owns its evidence: a voxel grid, its explained-free-space channel and the
/// no-return evidence behind one insert(), and the analyses that change evidence (revision, the
/// mirrors the region analysis finds, the gaps of seen walls) as an explicit step of the map,
/// update_analysis(). Planners, the episode runner, the viewer, the ROS node and Python take the
/// map (a const reference) and only read it (docs/concepts.md, "One map").
///
/// ```cpp
/// iv::ExplainedMap<iv::IntervalGrid> map(iv::IntervalGrid(0.05), planner.map_options());
/// map.insert(beams);          // the grid's update (the thesis', bit for bit) and the channel
/// map.update_analysis();      // before planning: revision, mirrors, wall gaps (as the options say)
/// auto plan = planner.plan(map, pose);
/// ```
///
/// A plain grid still works everywhere (the thesis' configuration): the planners take a grid too,
/// and without the channel (ExplainedMapOptions::explained off) the map is the grid alone.
///
/// Thread safety: the const members may run concurrently with each other; insert() and
/// update_analysis() need exclusive access. Both use InsertOptions::threads threads inside, with
/// the same result for any count.

#include <intervox/analysis/hit_record.hpp>
#include <intervox/analysis/lying_surfaces.hpp>
#include <intervox/analysis/no_return_evidence.hpp>
#include <intervox/analysis/wall_gaps.hpp>
#include <intervox/core/error.hpp>
#include <intervox/core/plane_patch.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/explain/explained_space.hpp>
#include <intervox/grid/occupancy_grid.hpp>
#include <intervox/raycast/insert.hpp>
#include <intervox/raycast/insert_options.hpp>

#include <cstdint>
#include <optional>
#include <type_traits>
#include <span>
#include <utility>
#include <vector>

namespace intervox {

/// What an ExplainedMap keeps besides its grid, and what update_analysis() does.
struct ExplainedMapOptions {
  /// Keep the explained-free-space channel (ExplainedSpace, explain/explained_space.hpp): every
  /// scan's beams are classed and their evidence kept. Off: the map is its grid alone.
  bool explained = true;
  /// How beams are classed and their evidence combined.
  ExplainOptions explain{};
  /// Opaque surfaces the user knows (mirrors, glass, black panels, a floor plan's walls), told to
  /// the channel when the map is made (ExplainedSpace::add_mirror() with MirrorMerge::Keep): every
  /// beam through one is suspect and its voxels are explained occupied.
  std::vector<PlanePatch> known_surfaces{};
  /// Keep the space beams without a return crossed (NoReturnEvidence; conflict-aware planning
  /// with ConflictPlanningParams::no_return_unknown reads it).
  bool no_return_evidence = false;
  /// Keep the voxels that returned a beam (HitRecord; views that seek normals read it).
  bool record_hits = false;
  /// update_analysis(): revise the channel and tell it of the mirrors the region analysis finds
  /// (find_lying_surfaces() with `lying`, then resolve_mirrors()). Needs the channel.
  bool find_mirrors = false;
  LyingSurfaceParams lying{};
  /// update_analysis(): find the gaps of seen walls (find_wall_gaps() with `wall_gaps`) in the
  /// channel as it stands; nothing is told to the channel (wall_gaps() holds them for planners
  /// that close them). Needs the channel.
  bool find_wall_gaps = false;
  WallGapParams wall_gaps{};

  /// \throws InvalidArgument naming the first invalid option (an analysis without the channel, an
  ///         invalid threshold or known surface).
  void validate() const {
    const ParamCheck check("intervox::ExplainedMapOptions");
    explain.validate();
    lying.validate();
    wall_gaps.validate();
    for (const PlanePatch& p : known_surfaces) p.validate();
    if (!explained && (find_mirrors || find_wall_gaps || !known_surfaces.empty()))
      check.fail("find_mirrors, find_wall_gaps and known_surfaces need the explained channel (explained = true)");
  }
};

/// A grid and its evidence behind one insertion (see the file comment).
/// \tparam Grid a VoxelGrid (any update, utility and storage), owned by the map; or a reference
///         to one (`ExplainedMap<G&>`), for a grid the caller owns and keeps alive while the map is
///         in use (the Python episode runner maps into the user's grid so)
template <class Grid>
requires OccupancyGrid<std::remove_cvref_t<Grid>>
class ExplainedMap {
 public:
  using GridType = std::remove_cvref_t<Grid>;

  /// \param grid the grid to fill (moved in, or referred to; its geometry is the channel's)
  /// \param options what the map keeps and analyses
  /// \param insert the insertion's options (max range, threads, budget) for every scan; beams
  ///        without a return count as free up to the max range
  /// \throws InvalidArgument for invalid options.
  explicit ExplainedMap(Grid grid, ExplainedMapOptions options = {}, InsertOptions insert = {})
      : grid_(std::forward<Grid>(grid)), options_(std::move(options)), inserter_(insert) {
    options_.validate();
    insert.validate();
    if (options_.explained) {
      explained_.emplace(grid_.geometry(), options_.explain);
      for (const PlanePatch& p : options_.known_surfaces) explained_->add_mirror(p, MirrorMerge::Keep);
    }
    if (options_.no_return_evidence) {
      if (!insert.has_max_range())
        ParamCheck("intervox::ExplainedMap")
            .fail("no-return evidence needs the insertion's max range (InsertOptions::max_range)");
      no_returns_.emplace(grid_.geometry(), insert.max_range);
    }
  }

  /// One scan of beams (world frame): the grid's insertion (InsertOptions as given to the map),
  /// each beam classed against the channel's evidence before the scan and its evidence kept, the
  /// no-return evidence. Returns the insertion's statistics with the beam classes counted.
  /// \throws InvalidArgument as the insertion throws (a budget refused: then nothing changed).
  InsertStats insert(std::span<const Beam> beams) {
    InsertStats st =
        explained_ ? explained_->insert_beams(inserter_, grid_, beams) : inserter_.insert_beams(grid_, beams);
    if (no_returns_) no_returns_->add(beams);
    if (options_.record_hits) hits_.add(grid_.geometry(), beams);
    ++scans_;
    return st;
  }

  /// Beams that the evidence sees and the grid does not: returns kept out of the grid (e.g. the
  /// floor returns a mobile robot cuts out, thesis 3.3.1: remove_returns_below) confirm the space
  /// they crossed just the same. The channel classes them and keeps their evidence as a scan of
  /// its own, the no-return evidence records them; the grid is untouched. Without the channel and
  /// the no-return evidence it does nothing.
  /// \throws InvalidArgument as insert(beams).
  void add_evidence(std::span<const Beam> beams) {
    if (explained_) explained_->add(beams, explained_->classify(beams, inserter_.options()), inserter_.options());
    if (no_returns_) no_returns_->add(beams);
    if (options_.record_hits) hits_.add(grid_.geometry(), beams);
  }

  /// A point cloud seen from \p origin (every point a return), as insert(beams) (without the
  /// channel, the insertion's own point-cloud path: insert_point_cloud()).
  /// \tparam O PointLike; \tparam R a PointRange
  template <PointLike O, PointRange R>
  InsertStats insert(const O& origin, const R& points) {
    const Point3 o = to_point(origin);
    InsertStats st = explained_ ? explained_->insert_point_cloud(inserter_, grid_, o, points)
                                : inserter_.insert_point_cloud(grid_, o, points);
    if (no_returns_ || options_.record_hits) {
      std::vector<Beam> beams;
      beams.reserve(static_cast<std::size_t>(std::ranges::size(points)));
      for (const auto& p : points) beams.push_back(Beam{o, to_point(p), true});
      if (no_returns_) no_returns_->add(beams);
      if (options_.record_hits) hits_.add(grid_.geometry(), beams);
    }
    ++scans_;
    return st;
  }

  /// Forgets everything: the grid cleared, the channel, the no-return evidence, the hits and the
  /// analyses emptied (the known surfaces told again).
  void clear() {
    grid_.clear();
    if (explained_) {
      explained_.emplace(grid_.geometry(), options_.explain);
      for (const PlanePatch& p : options_.known_surfaces) explained_->add_mirror(p, MirrorMerge::Keep);
    }
    if (no_returns_) no_returns_.emplace(grid_.geometry(), inserter_.options().max_range);
    hits_ = HitRecord{};
    gaps_.clear();
    lying_.clear();
    scans_ = analysed_ = 0;
  }

  /// A depth frame (insert_depth_image()'s pixel rule; the max range the smaller of the frame's
  /// and the map's), as insert(beams).
  /// \throws InvalidArgument for an invalid frame, or as insert(beams).
  InsertStats insert(const DepthFrame& frame) {
    InsertStats st;
    if (explained_) {
      st = explained_->insert_depth_image(inserter_, grid_, frame);
    } else {
      st = inserter_.insert_depth_image(grid_, frame);
    }
    if (no_returns_ || options_.record_hits) {
      const std::vector<Beam> beams = depth_frame_beams(frame);
      if (no_returns_) no_returns_->add(beams);
      if (options_.record_hits) hits_.add(grid_.geometry(), beams);
    }
    ++scans_;
    return st;
  }

  /// The analyses that change evidence, as the options say: with find_mirrors, the channel
  /// revised (ExplainedSpace::revise()) and told of every mirror the region analysis finds; with
  /// find_wall_gaps, the gaps of seen walls found anew (wall_gaps()). Call it before planning (the
  /// episode runner does). Costs about one region analysis (about 1.2 s at 5 cm in the lab room)
  /// with find_mirrors, and one wall-gap search with find_wall_gaps (docs/performance.md).
  void update_analysis() {
    if (!explained_) return;
    if (options_.find_mirrors) {
      explained_->revise();
      LyingSurfaceParams lp = options_.lying;
      lp.threads = inserter_.options().threads;
      lying_ = find_lying_surfaces(*explained_, lp);
      resolve_mirrors(*explained_, lying_);
    }
    if (options_.find_wall_gaps) {
      WallGapParams wp = options_.wall_gaps;
      wp.threads = inserter_.options().threads;
      gaps_ = find_wall_gaps(*explained_, wp);
    }
    analysed_ = scans_;
  }

  /// The grid (its update the policy's own, bit for bit).
  const GridType& grid() const noexcept { return grid_; }
  const GridGeometry& geometry() const noexcept { return grid_.geometry(); }
  /// The explained channel, or null without it.
  const ExplainedSpace* explained() const noexcept { return explained_ ? &*explained_ : nullptr; }
  /// The space beams without a return crossed, or null without it.
  const NoReturnEvidence* no_returns() const noexcept { return no_returns_ ? &*no_returns_ : nullptr; }
  /// The voxels that returned a beam (empty without record_hits).
  const HitRecord& hits() const noexcept { return hits_; }
  /// The gaps of seen walls of the last update_analysis() (find_wall_gaps), empty before.
  const std::vector<WallGap>& wall_gaps() const noexcept { return gaps_; }
  /// The lying surfaces of the last update_analysis() (find_mirrors), empty before.
  const std::vector<LyingSurface>& lying_surfaces() const noexcept { return lying_; }
  const ExplainedMapOptions& options() const noexcept { return options_; }
  const InsertOptions& insert_options() const noexcept { return inserter_.options(); }
  /// Scans inserted so far, and the count at the last update_analysis().
  std::uint64_t scans() const noexcept { return scans_; }
  std::uint64_t analysed_scans() const noexcept { return analysed_; }

 private:
  Grid grid_;
  ExplainedMapOptions options_;
  ScanInserter inserter_;
  std::optional<ExplainedSpace> explained_;
  std::optional<NoReturnEvidence> no_returns_;
  HitRecord hits_;
  std::vector<WallGap> gaps_;
  std::vector<LyingSurface> lying_;
  std::uint64_t scans_ = 0, analysed_ = 0;
};

/// True for an ExplainedMap (the episode runner and the planners tell a map from a plain grid).
template <class T>
inline constexpr bool kIsExplainedMap = false;
template <class G>
inline constexpr bool kIsExplainedMap<ExplainedMap<G>> = true;

}  // namespace intervox
