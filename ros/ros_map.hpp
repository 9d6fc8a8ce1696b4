#pragma once
// The map of the ROS programs (intervox_server, intervox_bag): a grid of any named update and
// utility policy (examples/common/policies.hpp, chosen at run time through with_policies) behind
// one run-time interface, so that the ROS code is written once and not per grid type.
#include "common/policies.hpp"
#include "ros_conversions.hpp"

#include <intervox/core/sensor_data.hpp>
#include <intervox/core/sensors.hpp>
#include <intervox/explain/explained_space.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/io/color.hpp>
#include <intervox/io/explained_file.hpp>
#include <intervox/io/grid_file.hpp>
#include <intervox/io/octomap.hpp>
#include <intervox/plan/exploration_map.hpp>
#include <intervox/plan/mobile_planner.hpp>
#include <intervox/raycast/insert.hpp>

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

namespace intervox_ros {

namespace iv = intervox;

/// The update / utility pairs the ROS programs offer: those of mobile_exploration (every update
/// with entropy and max-entropy; the credal cells with max-entropy and total uncertainty).
struct RosOffer {
  template <class U, class H>
  static constexpr bool offers() {
    if constexpr (examples::kCredalUpdate<U>)
      return !std::is_same_v<H, iv::Entropy>;
    else
      return !std::is_same_v<H, iv::TotalUncertainty>;
  }
};

/// How the occupied voxels' markers are coloured: one of the grid's schemes (io/color.hpp), or
/// by the voxel's explained state (explain/explained_space.hpp; needs a map with the evidence
/// channel): explained occupied blue, unexplained (only suspect or no-return beams, or conflict)
/// orange, explained free white (the grid calls it occupied, the explained evidence free), no
/// evidence light gray.
struct Colouring {
  iv::ColorBy by = iv::ColorBy::State;
  bool explained = false;
};

/// What AnyMap::save() wrote.
struct SaveReport {
  std::vector<std::string> written;      ///< the files written (replaced or created), in order
  std::vector<std::string> not_written;  ///< the files not written (an existing one is left as it was)
  std::string error;                     ///< empty if every file was written, else why the rest was not
  std::uint64_t bt_out_of_range = 0;     ///< voxels the .bt left out: beyond OctoMap's 16-bit key range

  bool ok() const noexcept { return error.empty(); }
  /// "saved a, b and c" with the .bt's left-out voxels if any; on a failure which files were
  /// written, which not, and why.
  std::string text() const {
    const auto list = [](const std::vector<std::string>& v) {
      std::string t;
      for (std::size_t i = 0; i < v.size(); ++i) t += (i == 0 ? "" : i + 1 == v.size() ? " and " : ", ") + v[i];
      return t;
    };
    std::string t;
    if (ok()) {
      t = "saved " + list(written);
    } else {
      t = "save failed: " + error + "; " +
          (written.empty() ? std::string("nothing was written") : "written: " + list(written)) +
          (not_written.empty() ? std::string() : "; not written (left as they were): " + list(not_written));
    }
    if (bt_out_of_range > 0 && !written.empty())
      t += " (the .bt leaves out " + std::to_string(bt_out_of_range) + " voxels beyond OctoMap's 16-bit key range)";
    return t;
  }
};

/// What the map holds, for messages.
struct MapSummary {
  std::string type;  ///< e.g. "interval-mean / max-entropy"
  iv::OccupancyCounts counts;
  std::size_t memory_bytes = 0;
};

/// A grid of a policy pair chosen at run time.
class AnyMap {
 public:
  virtual ~AnyMap() = default;
  /// Inserts points given in the sensor frame, seen from \p sensor (sensor to map): each point
  /// is moved to the map frame (sensor * p) and inserted with the origin sensor.translation().
  virtual iv::InsertStats insert_points(const iv::Pose& sensor, std::span<const iv::Point3> points) = 0;
  /// Inserts a depth frame (intervox::insert_depth_image with the map's options).
  virtual iv::InsertStats insert_depth(const iv::DepthFrame& frame) = 0;
  /// Forgets every observation (and the planner's state).
  virtual void clear() = 0;
  /// Saves the map in the own format (io/grid_file.hpp) and as OctoMap .bt (io/octomap.hpp; voxels
  /// beyond OctoMap's key range are left out and counted), and, with the evidence channel, its
  /// explained evidence (io/explained_file.hpp). An empty path skips that file. All or nothing as
  /// far as files allow: every file's bytes are made and every target checked (a regular file the
  /// process may write, or none: intervox::detail::check_save_target()) before the first is
  /// written, so an encoding failure or a bad target writes nothing; then each file is written
  /// atomically in turn, and a failure while writing (a full disk) stops there: the report names
  /// the files written and those left as they were. Every failure of encoding, checking or writing
  /// is in the report, not thrown (only a failure to allocate the report itself escapes).
  virtual SaveReport save(const std::string& ivx_path, const std::string& bt_path,
                          const std::string& explained_path) const = 0;
  /// True if the map keeps the explained-free-space evidence channel (make_map's \p explain).
  virtual bool explained() const noexcept = 0;
  /// The centres of the occupied voxels and their colours by \p colouring, in the grid's order.
  /// \throws intervox::InvalidArgument for the explained colouring of a map without the channel.
  virtual void occupied(const Colouring& colouring, std::vector<iv::Point3>& centres,
                        std::vector<iv::Rgb>& colours) const = 0;
  /// The observed voxels' extent (x, y) with the height band [z_min, z_max] projected along z
  /// (project_columns: any occupied voxel makes a column occupied, all free makes it free);
  /// nothing while no voxel is observed.
  virtual std::optional<iv::ColumnMap> projected(double z_min, double z_max) const = 0;
  /// The exploration map for a robot at \p base (the planner's own when a planner exists, else
  /// the projection of the planner's default region with \p params' map settings).
  virtual std::optional<iv::ExplorationMap> exploration(const iv::Pose& base,
                                                        const iv::MobilePlannerParams& params) const = 0;
  /// The next view of the mobile planner for a base at \p base carrying \p rig. The first call
  /// creates the planner and runs its look-around (the data received so far stands for it), then
  /// plans; later calls plan on (the planner keeps its visited positions and frontier counts).
  virtual iv::MobilePlan plan_next_view(const iv::SensorRig& rig, const iv::MobilePlannerParams& params,
                                        const iv::Pose& base) = 0;
  virtual const iv::GridGeometry& geometry() const noexcept = 0;
  virtual MapSummary summary() const = 0;
};

/// A map of the pair named (examples/common/policies.hpp names, RosOffer), sparse storage.
/// \p explain, if set, adds the explained-free-space evidence channel (ExplainedSpace with these
/// options): every scan's beams are classed (trusted, suspect, no return) before the grid's own
/// update, which stays bit for bit what it is without the channel.
/// \throws intervox::InvalidArgument for a pair not offered, a bad resolution or bad options.
std::unique_ptr<AnyMap> make_map(const std::string& update, const std::string& utility, double resolution,
                                 const iv::InsertOptions& options,
                                 const std::optional<iv::ExplainOptions>& explain = std::nullopt);

/// Parses a colour scheme name: state, width, utility, table52 or explained.
/// \throws intervox::InvalidArgument for another name.
inline Colouring colouring(const std::string& name) {
  if (name == "state") return {iv::ColorBy::State, false};
  if (name == "width") return {iv::ColorBy::IntervalWidth, false};
  if (name == "utility") return {iv::ColorBy::Utility, false};
  if (name == "table52") return {iv::ColorBy::Table52, false};
  if (name == "explained") return {iv::ColorBy::State, true};
  throw iv::InvalidArgument("unknown colour scheme '" + name +
                            "' (expected state, width, utility, table52 or explained)");
}

}  // namespace intervox_ros
