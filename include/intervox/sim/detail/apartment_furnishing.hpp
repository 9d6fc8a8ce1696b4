#pragma once
/// \file
/// Internal: what stands in a random apartment. The lying surfaces (each kind with the chance the
/// options' mix gives it: glass doors and windows in the walls between rooms, mirrors and metal
/// panels on walls, mirror-fronted wardrobes and cabinets, a free-standing mirror, a glass
/// partition, black furniture) and the plain furniture, each placed only where the Placer allows.
/// Not public API.

#include <intervox/core/plane_patch.hpp>
#include <intervox/sim/apartment_parts.hpp>
#include <intervox/sim/detail/apartment_draw.hpp>
#include <intervox/sim/detail/apartment_floor_plan.hpp>
#include <intervox/sim/detail/apartment_placer.hpp>
#include <intervox/sim/material.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

namespace intervox::sim::detail {

/// The fixtures and furniture of one apartment (see the file comment).
class Furnishing {
 public:
  Furnishing(const ApartmentOptions& o, Draws& draws, FloorPlan& plan) : o_(o), draws_(draws), plan_(plan) {}

  /// The glass door and the glass window, when drawn: they are openings of the walls, so they come
  /// before the Placer takes the walls' raster.
  void glass_openings() {
    if (drawn(FixtureKind::GlassDoor)) glass_opening(true);
    if (drawn(FixtureKind::GlassWindow)) glass_opening(false);
  }

  /// The other fixtures, each when drawn and where it fits.
  void fixtures(Placer& placer) {
    using K = FixtureKind;
    if (drawn(K::WallMirror))
      wall_quad(placer, K::WallMirror, Material::mirror(), snap(draws_.uniform(0.5, 1.0)), 0.05,
                snap(draws_.uniform(1.8, 2.0)));
    if (drawn(K::HalfMirror)) {
      const double zlo = snap(draws_.uniform(0.8, 1.1));
      wall_quad(placer, K::HalfMirror, Material::mirror(), snap(draws_.uniform(0.6, 1.2)), zlo,
                zlo + snap(draws_.uniform(0.6, 0.9)));
    }
    if (drawn(K::MirrorWardrobe))
      against_wall(placer, -1, "mirror_wardrobe", snap(draws_.uniform(1.0, 2.0)), 0.6,
                   below_ceiling(snap(draws_.uniform(1.9, 2.2))), Material::diffuse(), K::MirrorWardrobe, true);
    if (drawn(K::MirrorCabinet))
      against_wall(placer, -1, "mirror_cabinet", snap(draws_.uniform(0.8, 1.6)), 0.45, snap(draws_.uniform(0.8, 1.0)),
                   Material::diffuse(), K::MirrorCabinet, true);
    if (drawn(K::FreeMirror)) free_mirror(placer);
    if (drawn(K::GlassPartition)) glass_partition(placer);
    if (drawn(K::BlackFurniture)) {
      const int type = draws_.integer(0, 2);
      const Material black = Material::absorbing();
      if (type == 0)
        against_wall(placer, -1, "black_sofa", snap(draws_.uniform(1.6, 2.2)), 0.9, 0.85, black, K::BlackFurniture,
                     false);
      if (type == 1)
        against_wall(placer, -1, "black_cabinet", snap(draws_.uniform(0.8, 1.4)), 0.45, 0.9, black, K::BlackFurniture,
                     false);
      if (type == 2)
        against_wall(placer, -1, "black_wardrobe", snap(draws_.uniform(1.0, 1.8)), 0.6, below_ceiling(2.0), black,
                     K::BlackFurniture, false);
    }
    if (drawn(K::MetalPanel))
      wall_quad(placer, K::MetalPanel, Material::polished_metal(), snap(draws_.uniform(0.6, 1.2)), 0.1,
                snap(draws_.uniform(1.2, 1.9)));
  }

  /// Plain (diffuse) furniture: min_furniture..max_furniture pieces drawn per room.
  void furniture(Placer& placer) {
    const std::vector<Bounds>& rooms = plan_.rooms();
    for (std::size_t r = 0; r < rooms.size(); ++r) {
      const int n = draws_.integer(o_.min_furniture, o_.max_furniture);
      const int room = static_cast<int>(r);
      for (int i = 0; i < n; ++i) {
        const std::string name = "room" + std::to_string(r) + "_";
        const Material d = Material::diffuse();
        switch (draws_.integer(0, 5)) {
          case 0:
            against_wall(placer, room, name + "wardrobe", snap(draws_.uniform(1.0, 2.0)), 0.6, below_ceiling(2.0), d,
                         {}, false);
            break;
          case 1:
            against_wall(placer, room, name + "shelf", snap(draws_.uniform(0.8, 1.6)), 0.35, 1.8, d, {}, false);
            break;
          case 2:
            against_wall(placer, room, name + "sofa", snap(draws_.uniform(1.6, 2.2)), 0.9, 0.85, d, {}, false);
            break;
          case 3:
            against_wall(placer, room, name + "cabinet", snap(draws_.uniform(0.8, 1.4)), 0.45, 0.9, d, {}, false);
            break;
          case 4:
            table(placer, room, name + "table");
            break;
          default:
            const Bounds& b = rooms[r];
            if ((b.max.x() - b.min.x()) * (b.max.y() - b.min.y()) >= 14.0) island(placer, room, name + "island");
        }
      }
    }
  }

  const std::vector<ApartmentFixture>& fixtures() const noexcept { return fixtures_; }
  const std::vector<ObjectSpec>& objects() const noexcept { return planned_; }

 private:
  bool drawn(FixtureKind k) { return draws_.chance(o_.mix[static_cast<std::size_t>(k)]); }
  double below_ceiling(double h) const { return std::min(h, o_.wall_height - 0.05); }

  /// A new fixture of \p kind in \p room, with \p plane if it is planar; returns its index.
  int new_fixture(FixtureKind kind, int room, const PlanePatch* plane) {
    ApartmentFixture& f = fixtures_.emplace_back();
    f.kind = kind;
    f.room = room;
    if (plane) f.plane.emplace(*plane);
    return static_cast<int>(fixtures_.size()) - 1;
  }

  /// A glass door (\p door) or a glass window on a random shared wall piece with room for it.
  void glass_opening(bool door) {
    const double width =
        door ? snap(draws_.uniform(o_.door_width_min, o_.door_width_max)) : snap(draws_.uniform(0.8, 1.6));
    const double zlo = door ? 0.0 : snap(draws_.uniform(0.5, 0.9)),
                 zhi = door ? o_.door_height : snap(draws_.uniform(1.5, 1.9));
    const std::vector<std::pair<std::size_t, FloorPlan::Shared>> candidates = plan_.shared_pieces();
    for (std::size_t tries = 0; tries < 8 && !candidates.empty(); ++tries) {
      const auto& [wi, piece] = candidates[draws_.below(candidates.size())];
      const std::optional<double> at = plan_.free_spot(wi, piece, width);
      if (!at) continue;
      const InnerWall& w = plan_.walls()[wi];
      const int a = w.axis, t = 1 - a;
      PlanePatch plane;
      plane.normal = Point3::Unit(a);
      plane.axis_u = Point3::Unit(t);
      plane.center = Point3::Zero();
      plane.center[a] = w.at;
      plane.center[t] = *at + 0.5 * width;
      plane.center.z() = 0.5 * (zlo + zhi);
      plane.half_u = 0.5 * width;
      plane.half_v = 0.5 * (zhi - zlo);
      ObjectSpec pane;
      pane.shape = ObjectSpec::Shape::Quad;
      pane.fixture = new_fixture(door ? FixtureKind::GlassDoor : FixtureKind::GlassWindow, piece.low, &plane);
      pane.name = (door ? "glass_door_" : "glass_window_") + std::to_string(pane.fixture);
      pane.material = Material::transparent();
      pane.corner = plane.center - plane.half_u * Point3::Unit(t) - plane.half_v * Point3::UnitZ();
      pane.edge_u = width * Point3::Unit(t);
      pane.edge_v = (zhi - zlo) * Point3::UnitZ();
      if (door)
        pane.doorway = plan_.add_doorway(wi, piece, *at, width, DoorwayState::Glass, false);
      else
        plan_.add_window(wi, *at, width, zlo, zhi);
      planned_.push_back(pane);
      return;
    }
  }

  /// A quad on a wall (a mirror or a metal panel): it takes no floor.
  void wall_quad(Placer& placer, FixtureKind kind, const Material& m, double width, double zlo, double zhi) {
    const std::optional<WallSpot> spot = placer.wall_spot(width);
    if (!spot) return;
    PlanePatch plane;
    ObjectSpec q = placer.face_quad(*spot, 0.001, width, zlo, zhi, plane);
    q.material = m;
    q.fixture = new_fixture(kind, spot->room, &plane);
    q.name = (kind == FixtureKind::MetalPanel   ? "metal_panel_"
              : kind == FixtureKind::HalfMirror ? "half_mirror_"
                                                : "wall_mirror_") +
             std::to_string(q.fixture);
    placer.take(*spot, width);
    planned_.push_back(q);
  }

  /// A box against a wall of room \p room (-1: any room); a fixture of \p kind, its front a mirror
  /// quad with \p mirror_front (the box is then the fixture's body) or the box itself.
  void against_wall(Placer& placer, int room, const std::string& name, double width, double depth, double height,
                    const Material& body, std::optional<FixtureKind> kind, bool mirror_front) {
    for (int tries = 0; tries < (kind ? 6 : 4); ++tries) {
      const std::optional<WallSpot> spot = placer.wall_spot(width, room);
      if (!spot) return;
      const Bounds b = placer.against(*spot, width, depth, 0.0, height);
      const Footprint f = footprint_of(b);
      if (!placer.fits(f, 0.05)) continue;
      placer.commit(f);
      placer.take(*spot, width);
      ObjectSpec box = box_spec(name, b, body);
      if (kind && mirror_front) {
        PlanePatch p;
        WallSpot face = *spot;
        face.at += 0.02;
        ObjectSpec front = placer.face_quad(face, depth + 0.001, width - 0.04, 0.02, height - 0.02, p);
        front.material = Material::mirror();
        front.fixture = box.fixture = new_fixture(*kind, spot->room, &p);
        front.name = name + "_mirror_" + std::to_string(front.fixture);
        box.fixture_body = true;
        planned_.push_back(front);
      } else if (kind) {
        box.fixture = new_fixture(*kind, spot->room, nullptr);
      }
      planned_.push_back(box);
      return;
    }
  }

  /// A free-standing mirror (a thin box, mirror on every face) at any yaw, 0.9 m from walls.
  void free_mirror(Placer& placer) {
    const double w = snap(draws_.uniform(0.5, 0.8)), h = snap(draws_.uniform(1.5, 1.8));
    const std::optional<Footprint> f = placer.free_standing(0.5 * w, 0.02, true, 0.9);
    if (!f) return;
    placer.commit(*f);
    ObjectSpec m;
    m.shape = ObjectSpec::Shape::OrientedBox;
    m.pose.linear() = Eigen::AngleAxisd(std::atan2(f->u.y(), f->u.x()), Point3::UnitZ()).toRotationMatrix();
    m.pose.translation() = Point3(f->center.x(), f->center.y(), 0.5 * h);
    m.half = Point3(0.5 * w, 0.02, 0.5 * h);
    m.material = Material::mirror();
    PlanePatch plane;
    plane.center = m.pose.translation();
    plane.normal = Point3(-f->u.y(), f->u.x(), 0.0);
    plane.axis_u = PlanePatch::floor_axis(plane.normal);
    plane.half_u = 0.5 * w;
    plane.half_v = 0.5 * h;
    int room = 0;
    for (std::size_t r = 0; r < plan_.rooms().size(); ++r)
      if (inside_xy(plan_.rooms()[r], f->center)) room = static_cast<int>(r);
    m.fixture = new_fixture(FixtureKind::FreeMirror, room, &plane);
    m.name = "free_mirror_" + std::to_string(m.fixture);
    planned_.push_back(m);
  }

  /// A glass pane standing out from a wall into the room, from the floor to 2 m.
  void glass_partition(Placer& placer) {
    for (int tries = 0; tries < 6; ++tries) {
      const std::optional<WallSpot> spot = placer.wall_spot(0.1);
      if (!spot) return;
      const Bounds& r = plan_.rooms()[static_cast<std::size_t>(spot->room)];
      const RoomSide s = room_side(r, spot->side);
      const double length =
          std::min(snap(draws_.uniform(1.0, 1.6)), 0.45 * (r.max[s.normal_axis] - r.min[s.normal_axis]));
      if (length < 0.6) continue;
      const double along = spot->at + 0.05;
      Footprint f;
      f.u = Point3::Unit(s.normal_axis);
      f.hx = 0.5 * length;
      f.hy = 0.01;
      f.center = Point3::Zero();
      f.center[s.along] = along;
      f.center[s.normal_axis] = s.at + s.sign * (0.001 + 0.5 * length);
      if (!placer.fits(f, 0.05)) continue;
      placer.commit(f);
      placer.take(*spot, 0.1);
      ObjectSpec pane;
      pane.shape = ObjectSpec::Shape::Quad;
      pane.material = Material::transparent();
      pane.corner = Point3::Zero();
      pane.corner[s.along] = along;
      pane.corner[s.normal_axis] = s.at + s.sign * 0.001;
      pane.edge_u = s.sign * length * Point3::Unit(s.normal_axis);
      pane.edge_v = 2.0 * Point3::UnitZ();
      PlanePatch plane;
      plane.normal = Point3::Unit(s.along);
      plane.axis_u = PlanePatch::floor_axis(plane.normal);
      plane.center = pane.corner + 0.5 * pane.edge_u + 0.5 * pane.edge_v;
      plane.half_u = 0.5 * length;
      plane.half_v = 1.0;
      pane.fixture = new_fixture(FixtureKind::GlassPartition, spot->room, &plane);
      pane.name = "glass_partition_" + std::to_string(pane.fixture);
      planned_.push_back(pane);
      return;
    }
  }

  /// A table: a top at 0.72-0.76 m on four legs (the base cannot pass under it: the top is in its
  /// height band).
  void table(Placer& placer, int room, const std::string& name) {
    const std::optional<Footprint> f = placer.free_standing(0.5 * snap(draws_.uniform(1.0, 1.6)),
                                                            0.5 * snap(draws_.uniform(0.7, 0.9)), false, 0.9, room);
    if (!f) return;
    placer.commit(*f);
    planned_.push_back(box_spec(name + "_top", {{f->center.x() - f->hx, f->center.y() - f->hy, 0.72},
                                                {f->center.x() + f->hx, f->center.y() + f->hy, 0.76}}));
    int leg = 0;
    for (const double sx : {-1.0, 1.0})
      for (const double sy : {-1.0, 1.0}) {
        ObjectSpec l;
        l.shape = ObjectSpec::Shape::Cylinder;
        l.name = name + "_leg" + std::to_string(leg++);
        l.base = Point3(f->center.x() + sx * (f->hx - 0.05), f->center.y() + sy * (f->hy - 0.05), 0.0);
        l.top = l.base + Point3(0.0, 0.0, 0.72);
        l.radius = 0.03;
        planned_.push_back(l);
      }
  }

  /// A kitchen island: a box 0.9 m high standing free.
  void island(Placer& placer, int room, const std::string& name) {
    const std::optional<Footprint> f = placer.free_standing(0.5 * snap(draws_.uniform(1.2, 1.8)),
                                                            0.5 * snap(draws_.uniform(0.7, 0.9)), false, 0.9, room);
    if (!f) return;
    placer.commit(*f);
    planned_.push_back(box_spec(name, {{f->center.x() - f->hx, f->center.y() - f->hy, 0.0},
                                       {f->center.x() + f->hx, f->center.y() + f->hy, 0.9}}));
  }

  const ApartmentOptions& o_;
  Draws& draws_;
  FloorPlan& plan_;
  std::vector<ApartmentFixture> fixtures_;
  std::vector<ObjectSpec> planned_;
};

}  // namespace intervox::sim::detail
