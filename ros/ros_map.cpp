// The grids behind AnyMap (ros_map.hpp), instantiated once for every offered policy pair in this
// one translation unit, which intervox_server and intervox_bag link (the instantiations are what
// takes the compiler its time).
#include "ros_map.hpp"

#include <intervox/io/text_file.hpp>

#include <exception>
#include <utility>

namespace intervox_ros {

namespace {

/// The map of every offered grid: an ExplainedMap (the grid and, with \p explain, its explained
/// channel behind one insertion), which the planner only reads.
template <class Grid>
class GridMap final : public AnyMap {
 public:
  GridMap(std::string type, double resolution, const iv::InsertOptions& options,
          const std::optional<iv::ExplainOptions>& explain)
      : type_(std::move(type)), map_(Grid(resolution), map_options(explain), options), grid_(map_.grid()) {}

  iv::InsertStats insert_points(const iv::Pose& sensor, std::span<const iv::Point3> points) override {
    world_.resize(points.size());
    for (std::size_t i = 0; i < points.size(); ++i) world_[i] = sensor * points[i];
    return map_.insert(iv::Point3(sensor.translation()), world_);
  }
  iv::InsertStats insert_depth(const iv::DepthFrame& frame) override { return map_.insert(frame); }
  void clear() override {
    map_.clear();
    planner_.reset();
  }
  SaveReport save(const std::string& ivx_path, const std::string& bt_path,
                  const std::string& explained_path) const override {
    SaveReport report;
    std::vector<std::pair<std::string, std::string>> files;  // path, bytes
    try {
      // Every file's bytes, and every target checked, before the first is written.
      if (!ivx_path.empty()) files.emplace_back(ivx_path, iv::save_grid_to_memory(grid_));
      if (!bt_path.empty()) {
        iv::OctomapExportSummary bt;
        files.emplace_back(bt_path, iv::write_bt_to_memory(grid_, {}, &bt));
        report.bt_out_of_range = bt.out_of_range;
      }
      if (map_.explained() && !explained_path.empty())
        files.emplace_back(explained_path, iv::save_explained_to_memory(*map_.explained()));
      for (const auto& f : files) (void)iv::detail::check_save_target(f.first);
    } catch (const std::exception& e) {
      report.error = e.what();
    } catch (...) {
      report.error = "an unknown error";
    }
    if (!report.ok()) {
      for (const std::string& p : {ivx_path, bt_path, map_.explained() ? explained_path : std::string()})
        if (!p.empty()) report.not_written.push_back(p);
      return report;
    }
    for (std::size_t i = 0; i < files.size(); ++i) {
      try {
        iv::write_text_file(files[i].first, files[i].second);
        report.written.push_back(files[i].first);
      } catch (const std::exception& e) {
        report.error = e.what();
      } catch (...) {
        report.error = "an unknown error";
      }
      if (!report.ok()) {
        for (std::size_t j = i; j < files.size(); ++j) report.not_written.push_back(files[j].first);
        break;
      }
    }
    return report;
  }
  bool explained() const noexcept override { return map_.explained() != nullptr; }
  void occupied(const Colouring& colouring, std::vector<iv::Point3>& centres,
                std::vector<iv::Rgb>& colours) const override {
    if (colouring.explained && !map_.explained())
      throw iv::InvalidArgument("colouring by the explained state needs the explained evidence channel");
    centres.clear();
    colours.clear();
    const auto& u = grid_.update_policy();
    grid_.for_each_observed([&](const iv::Key& k, const auto& c) {
      if (u.occupancy(c) != iv::Occupancy::Occupied) return;
      centres.push_back(grid_.center(k));
      colours.push_back(colouring.explained
                            ? kExplainedMarkerColours[static_cast<std::size_t>(map_.explained()->state(k))]
                            : iv::cell_color(grid_, c, colouring.by));
    });
  }
  std::optional<iv::ColumnMap> projected(double z_min, double z_max) const override {
    std::optional<iv::Bounds> extent;
    grid_.for_each_observed([&](const iv::Key& k, const auto&) {
      const iv::Point3 c = grid_.center(k);
      if (!extent) extent = iv::Bounds{c, c};
      extent->min = extent->min.cwiseMin(c);
      extent->max = extent->max.cwiseMax(c);
    });
    if (!extent) return std::nullopt;
    extent->min.z() = z_min;
    extent->max.z() = z_max;
    return iv::project_columns(grid_, *extent);
  }
  std::optional<iv::ExplorationMap> exploration(const iv::Pose& base,
                                                const iv::MobilePlannerParams& params) const override {
    if (grid_.observed_count() == 0) return std::nullopt;
    if (planner_) return planner_->exploration_map(map_, base);
    // No planner yet: the projection of the region the planner would derive, without its start rules.
    const iv::Point3 p = base.translation();
    iv::Bounds b{p, p};
    grid_.for_each_observed([&](const iv::Key& k, const auto&) {
      b.min = b.min.cwiseMin(grid_.center(k) - iv::Point3::Constant(params.region_margin));
      b.max = b.max.cwiseMax(grid_.center(k) + iv::Point3::Constant(params.region_margin));
    });
    b.min.z() = p.z() + params.floor_clearance;
    b.max.z() = p.z() + params.obstacle_height;
    const iv::KeyBox box = grid_.geometry().key_box(b);
    const iv::Key k = grid_.geometry().key(iv::Point3(p.x(), p.y(), b.min.z()));
    return iv::ExplorationMap(iv::project_columns(grid_, b), iv::Cell2{k.x - box.min.x, k.y - box.min.y}, params.map);
  }
  iv::MobilePlan plan_next_view(const iv::SensorRig& rig, const iv::MobilePlannerParams& params,
                                const iv::Pose& base) override {
    if (!planner_) {
      planner_.emplace(rig, params);
      planner_->plan(map_, base);  // the look-around, which the data received so far stands for
    }
    map_.update_analysis();
    return planner_->plan(map_, base);
  }
  const iv::GridGeometry& geometry() const noexcept override { return grid_.geometry(); }
  MapSummary summary() const override { return {type_, grid_.counts(), grid_.memory_bytes()}; }

  const Grid& grid() const noexcept { return grid_; }

 private:
  static iv::ExplainedMapOptions map_options(const std::optional<iv::ExplainOptions>& explain) {
    iv::ExplainedMapOptions o;
    o.explained = explain.has_value();
    if (explain) o.explain = *explain;
    return o;
  }

  std::string type_;
  iv::ExplainedMap<Grid> map_;
  const Grid& grid_;  ///< map_'s grid
  std::vector<iv::Point3> world_;
  std::optional<iv::MobilePlanner> planner_;
};

}  // namespace

std::unique_ptr<AnyMap> make_map(const std::string& update, const std::string& utility, double resolution,
                                 const iv::InsertOptions& options, const std::optional<iv::ExplainOptions>& explain) {
  return examples::with_policies<RosOffer, std::unique_ptr<AnyMap>>(update, utility, [&]<class U, class H>() {
    return std::unique_ptr<AnyMap>(
        std::make_unique<GridMap<iv::VoxelGrid<U, H>>>(update + " / " + utility, resolution, options, explain));
  });
}

}  // namespace intervox_ros
