#pragma once
/// \file
/// How the mobile planner turns a map path into body poses (drive_path: holonomic, or turning to
/// face along the path), and the way back it remembers (DrivenPaths, MobilePlannerParams::
/// driven_paths): the columns of the paths the robot drove.
///
/// Thread safety: drive_path() only reads; DrivenPaths is a value type.

#include <intervox/core/key.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/plan/column_map.hpp>
#include <intervox/plan/exploration_map.hpp>
#include <intervox/plan/view_sampling.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <vector>

namespace intervox {

/// The body poses along the map path to \p cell: the current pose, the centres of the cells
/// between, the view. Holonomic (\p face_along false): the heading is kept while translating
/// and the view's is taken at the end. Facing along the path: before each straight segment the
/// body turns on the spot (a pose at the same position) to face it, drives forward to its end,
/// and at the view position turns to the view's heading; every translation is along the body's
/// x axis.
inline std::vector<Pose> drive_path(const ExplorationMap& map, const GridGeometry& g, const Pose& from,
                                    const Pose& view, const Cell2& cell, bool face_along = false) {
  std::vector<Pose> out{from};
  const std::vector<Cell2> cells = map.path_to(cell);
  std::vector<Point3> points;
  for (std::size_t i = 1; i + 1 < cells.size(); ++i) {
    const Point3 c = cell_center(map.columns(), g, cells[i]);
    points.emplace_back(c.x(), c.y(), from.translation().z());
  }
  points.push_back(view.translation());
  if (!face_along) {
    for (std::size_t i = 0; i + 1 < points.size(); ++i) {
      Pose p = from;
      p.translation() = points[i];
      out.push_back(p);
    }
    out.push_back(view);
    return out;
  }
  // Merge collinear steps into straight segments, then turn and drive along each.
  for (const Point3& next : points) {
    const Pose& at = out.back();
    const Point3 step = next - at.translation();
    if (step.head<2>().norm() < 1e-9) continue;
    const double heading = std::atan2(step.y(), step.x());
    const Point3 x = at.linear().col(0);
    if (std::abs(std::remainder(std::atan2(x.y(), x.x()) - heading, 2 * std::numbers::pi)) > 1e-9)
      out.push_back(planar_pose(at.translation(), heading));
    if (out.size() >= 2) {
      // Extend the last segment when this step continues it in the same direction.
      const Pose& prev = out[out.size() - 2];
      const Point3 last = out.back().translation() - prev.translation();
      if (last.head<2>().norm() > 1e-9 && prev.linear().isApprox(out.back().linear()) &&
          std::abs(last.x() * step.y() - last.y() * step.x()) < 1e-9 * last.head<2>().norm() * step.head<2>().norm()) {
        out.back().translation() = next;
        continue;
      }
    }
    out.push_back(planar_pose(next, heading));
  }
  if (!out.back().linear().isApprox(view.linear(), 1e-12) || out.back().translation() != view.translation())
    out.push_back(view);
  return out;
}

/// The way back (MobilePlannerParams::driven_paths): the path of the last plan, held until the next
/// call says whether the robot reached its view, and the columns (keys at z 0) of the paths
/// driven, each once (bounded by the area the robot covered).
class DrivenPaths {
 public:
  /// Keeps the columns (keys at z 0) the centre passes on \p path, sampled every half voxel along
  /// its straight segments, for the next call (an empty path holds nothing). Where it crosses from
  /// a column to a diagonal neighbour (through their shared corner, well inside the footprint),
  /// the two columns beside the corner too, so that the way back never needs a diagonal step past
  /// unpassable cells.
  void hold(const GridGeometry& g, const std::vector<Pose>& path) {
    pending_path_.clear();
    pending_view_.reset();
    if (path.empty()) return;
    const auto add = [&](const Point3& p) {
      Key k = g.key(p);
      k.z = 0;
      if (!pending_path_.empty()) {
        const Key b = pending_path_.back();
        if (b == k) return;
        if (std::abs(k.x - b.x) == 1 && std::abs(k.y - b.y) == 1) {
          pending_path_.push_back(Key{k.x, b.y, 0});
          pending_path_.push_back(Key{b.x, k.y, 0});
        }
      }
      pending_path_.push_back(k);
    };
    const double step = 0.5 * g.resolution();
    for (std::size_t k = 0; k + 1 < path.size(); ++k) {
      const Point3 a = path[k].translation(), b = path[k + 1].translation();
      const int m = std::max(1, static_cast<int>(std::ceil((b - a).head<2>().norm() / step)));
      for (int j = 0; j < m; ++j) add(a + (b - a) * (double(j) / m));
    }
    add(path.back().translation());
    pending_view_ = path.back().translation();
  }
  /// The held path counts as driven if \p pose lies within \p footprint_radius of its end (the
  /// robot reached the view); the columns driven are kept once each.
  void take(const Pose& pose, double footprint_radius) {
    if (pending_view_ && (pose.translation() - *pending_view_).head<2>().norm() <= footprint_radius + 1e-9) {
      driven_.insert(driven_.end(), pending_path_.begin(), pending_path_.end());
      std::sort(driven_.begin(), driven_.end());
      driven_.erase(std::unique(driven_.begin(), driven_.end()), driven_.end());
    }
    pending_path_.clear();
    pending_view_.reset();
  }
  /// The columns of the paths driven, sorted, without duplicates.
  const std::vector<Key>& driven() const noexcept { return driven_; }

 private:
  std::vector<Key> pending_path_, driven_;
  std::optional<Point3> pending_view_;
};

}  // namespace intervox
