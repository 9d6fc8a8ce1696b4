#pragma once
// The top view of one run of the apartments benchmark: the true world in the robot's height band
// (obstacles dark gray), its lying surfaces coloured by kind, the floor the map knows free, the
// start, the path driven and the poses where the robot met the true world.
#include "episode.hpp"

#include <intervox/io/png.hpp>
#include <intervox/plan/column_map.hpp>
#include <intervox/view/image_annotation.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace apartments {

namespace detail {

inline constexpr double kPixelsPerMetre = 40.0;
inline constexpr iv::Rgb kObstacle{70, 70, 70}, kKnownFloor{200, 225, 255}, kFloor{245, 245, 245}, kPath{230, 110, 0},
    kStart{0, 160, 0}, kCollision{220, 0, 0}, kMirror{0, 70, 255}, kGlass{0, 200, 210}, kBlack{150, 0, 170},
    kMetal{255, 170, 0};

/// The colour of a lying surface of kind \p k.
inline iv::Rgb kind_colour(iv::sim::FixtureKind k) {
  using K = iv::sim::FixtureKind;
  switch (k) {
    case K::GlassPartition:
    case K::GlassDoor:
    case K::GlassWindow:
      return kGlass;
    case K::BlackFurniture:
      return kBlack;
    case K::MetalPanel:
      return kMetal;
    default:
      return kMirror;
  }
}

/// A canvas over the apartment's footprint with a margin, y up.
struct Canvas {
  iv::RgbImage image;
  iv::Point3 origin;  ///< the world point at the image's bottom-left corner
  int px(double x) const { return static_cast<int>(std::floor((x - origin.x()) * kPixelsPerMetre)); }
  int py(double y) const { return image.height - 1 - static_cast<int>(std::floor((y - origin.y()) * kPixelsPerMetre)); }
  void dot(int x, int y, iv::Rgb c) {
    if (x >= 0 && y >= 0 && x < image.width && y < image.height) image.set(x, y, c.r, c.g, c.b);
  }
  void disk(double x, double y, double r, iv::Rgb c, bool outline = false) {
    const int cx = px(x), cy = py(y), rp = std::max(1, static_cast<int>(std::lround(r * kPixelsPerMetre)));
    for (int dy = -rp; dy <= rp; ++dy)
      for (int dx = -rp; dx <= rp; ++dx) {
        const double d = std::hypot(dx, dy);
        if (d <= rp && (!outline || d >= rp - 1.5)) dot(cx + dx, cy + dy, c);
      }
  }
  void line(const iv::Point3& a, const iv::Point3& b, iv::Rgb c, int width) {
    const double len = (b - a).head<2>().norm();
    const int n = std::max(1, static_cast<int>(std::ceil(len * kPixelsPerMetre * 2)));
    for (int i = 0; i <= n; ++i) {
      const iv::Point3 p = a + (b - a) * (double(i) / n);
      for (int dy = -width / 2; dy <= width / 2; ++dy)
        for (int dx = -width / 2; dx <= width / 2; ++dx) dot(px(p.x()) + dx, py(p.y()) + dy, c);
    }
  }
  void rect(const iv::Bounds& b, iv::Rgb c) {
    for (int y = py(b.max.y()); y <= py(b.min.y()); ++y)
      for (int x = px(b.min.x()); x <= px(b.max.x()); ++x) dot(x, y, c);
  }
};

}  // namespace detail

/// Draws the top view of a run: \p free the map's columns known free (project_columns of the
/// final grid over the band; empty: none drawn), \p trajectory the poses driven, \p result the
/// scores (title and collisions).
inline iv::RgbImage top_view(const iv::sim::Apartment& a, const iv::sim::Scene& world, const iv::ColumnMap* free,
                             const iv::GridGeometry& map_geometry, const std::vector<iv::Pose>& trajectory,
                             const Result& result, const iv::MobilePlannerParams& p) {
  using detail::Canvas;
  const double margin = 0.4;
  Canvas c;
  c.origin = a.footprint.min - iv::Point3(margin, margin, 0.0);
  const int w =
      static_cast<int>(std::ceil((a.footprint.max.x() - a.footprint.min.x() + 2 * margin) * detail::kPixelsPerMetre));
  const int h =
      static_cast<int>(std::ceil((a.footprint.max.y() - a.footprint.min.y() + 2 * margin) * detail::kPixelsPerMetre));
  c.image = iv::RgbImage::filled(w, h, 255, 255, 255);
  for (const iv::Bounds& r : a.rooms) c.rect(r, detail::kFloor);
  // The floor the map knows free.
  if (free)
    for (int y = 0; y < free->height(); ++y)
      for (int x = 0; x < free->width(); ++x)
        if (free->at({x, y}) == iv::Occupancy::Free) {
          const iv::Point3 lo = map_geometry.corner(free->key_of({x, y}));
          c.rect({lo, lo + iv::Point3(map_geometry.resolution(), map_geometry.resolution(), 0.0)}, detail::kKnownFloor);
        }
  // The true obstacles in the robot's height band, at 2.5 cm.
  const iv::GridGeometry fine(1.0 / detail::kPixelsPerMetre);
  const iv::Bounds band{{c.origin.x(), c.origin.y(), p.floor_clearance},
                        {a.footprint.max.x() + margin, a.footprint.max.y() + margin, p.obstacle_height}};
  for (const iv::Key& k : world.ground_truth(fine, band)) {
    const iv::Point3 centre = fine.center(k);
    c.dot(c.px(centre.x()), c.py(centre.y()), detail::kObstacle);
  }
  // The lying surfaces (in the lying world: the honest twin's are diffuse and drawn as obstacles).
  for (const iv::sim::ApartmentFixture& f : a.fixtures) {
    if (world.material(f.surface).surface == iv::sim::Surface::Diffuse) continue;
    const iv::Rgb colour = detail::kind_colour(f.kind);
    if (f.plane) {
      const iv::Point3 u =
          f.plane->normal.z() == 0 ? iv::Point3(-f.plane->normal.y(), f.plane->normal.x(), 0.0) : f.plane->axis_u;
      c.line(f.plane->center - f.plane->half_u * u, f.plane->center + f.plane->half_u * u, colour, 4);
    } else {
      iv::Bounds b = f.bounds;
      c.rect(b, colour);
    }
  }
  // The path, the start and the poses in collision.
  for (std::size_t i = 1; i < trajectory.size(); ++i)
    c.line(trajectory[i - 1].translation(), trajectory[i].translation(), detail::kPath, 2);
  c.disk(a.start.x(), a.start.y(), 0.12, detail::kStart);
  for (const iv::Pose& q : trajectory) {
    const iv::Point3 t = q.translation();
    if (iv::count_collisions(world, map_geometry, {q}, p.map.robot_radius, p.floor_clearance, p.obstacle_height) > 0)
      c.disk(t.x(), t.y(), p.map.robot_radius, detail::kCollision, true);
  }
  iv::Legend legend;
  legend.title = "top view, " + std::to_string(static_cast<int>(std::lround(p.floor_clearance * 100))) + "-" +
                 std::to_string(static_cast<int>(std::lround(p.obstacle_height * 100))) + " cm";
  legend.swatches = {{detail::kObstacle, "true obstacle"},
                     {detail::kMirror, "mirror"},
                     {detail::kGlass, "glass"},
                     {detail::kBlack, "black (absorbing)"},
                     {detail::kMetal, "polished metal"},
                     {detail::kKnownFloor, "floor the map knows free"},
                     {detail::kPath, "path driven"},
                     {detail::kStart, "start"},
                     {detail::kCollision, "pose meeting the true world"}};
  iv::ImageLabels labels;
  char known[32];
  std::snprintf(known, sizeof known, "%.1f", 100.0 * result.known);
  labels.title = "apartment " + std::to_string(result.run.seed) + " (" + result.run.world + "), " + result.run.planner +
                 ", " + result.run.rig + (result.run.rig == "one" ? " camera" : " cameras") + ", " + result.run.update +
                 ": " + result.termination + ", " + known + " % of the floor known, " +
                 std::to_string(result.collision_poses) + " poses in collision";
  labels.legend = true;
  labels.scale_bar = true;
  return iv::annotate_image(c.image, labels, &legend, 1.0 / detail::kPixelsPerMetre);
}

}  // namespace apartments
