#pragma once
// A planted mirror scene with closed-form phantoms, no simulator: a ray tracer of boxes and one
// mirror rectangle (a free-standing panel in a room), for the lying-surface analysis' tests and
// the planner's find_mirrors test.
#include <intervox/core/point.hpp>
#include <intervox/core/key.hpp>
#include <intervox/core/sensor_data.hpp>
#include <intervox/raycast/insert.hpp>

#include "ray_box.hpp"

#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <span>
#include <utility>
#include <vector>

namespace test::planted_mirror {

namespace iv = intervox;

struct Box {
  iv::Point3 lo, hi;
};

// Where the ray o + t d (t > 0) enters the box, or nothing (also from inside).
inline std::optional<double> enter(const Box& b, const iv::Point3& o, const iv::Point3& d) {
  const auto t = test::ray_box<3>({o.x(), o.y(), o.z()}, {d.x(), d.y(), d.z()}, {b.lo.x(), b.lo.y(), b.lo.z()},
                                  {b.hi.x(), b.hi.y(), b.hi.z()}, std::numeric_limits<double>::infinity());
  if (!t || t->first <= 1e-9) return std::nullopt;
  return t->first;
}

// A room 4.5 x 5 x 2.5 m with two boxes whose faces look along x, and a free-standing panel in
// the plane x = 1 (y in [1.8, 3.2], z in [0, 1.6]), a perfect mirror on its east face or, with
// mirror false, a diffuse slab x in [0.98, 1].
struct Room {
  bool mirror = true;
  bool panel = true;  // false: no panel at all (beams pass its plane)
  std::vector<Box> boxes{
      {{-0.1, -0.1, -0.1}, {4.6, 5.1, 0.0}},  // floor
      {{-0.1, -0.1, 2.5}, {4.6, 5.1, 2.6}},   // ceiling
      {{-0.1, -0.1, 0.0}, {0.0, 5.1, 2.5}},   // west wall
      {{4.5, -0.1, 0.0}, {4.6, 5.1, 2.5}},    // east wall
      {{-0.1, -0.1, 0.0}, {4.6, 0.0, 2.5}},   // south wall
      {{-0.1, 5.0, 0.0}, {4.6, 5.1, 2.5}},    // north wall
      {{3.0, 0.5, 0.0}, {3.4, 1.5, 1.2}},     // shelf
      {{2.5, 3.5, 0.0}, {2.9, 4.5, 0.9}},     // crate
  };
  static constexpr double kPanelX = 1.0, kY0 = 1.8, kY1 = 3.2, kZ1 = 1.6;

  // The first surface along o + t d: its distance and whether it is the mirror's face.
  std::pair<double, bool> first(const iv::Point3& o, const iv::Point3& d, bool may_mirror) const {
    double best = std::numeric_limits<double>::infinity();
    bool at_mirror = false;
    for (const Box& b : boxes)
      if (const auto t = enter(b, o, d); t && *t < best) best = *t;
    if (panel && mirror && may_mirror && d.x() < -1e-12) {
      const double t = (kPanelX - o.x()) / d.x();
      const iv::Point3 p = o + t * d;
      if (t > 1e-9 && t < best && p.y() >= kY0 && p.y() <= kY1 && p.z() >= 0.0 && p.z() <= kZ1) {
        best = t;
        at_mirror = true;
      }
    }
    if (panel && !mirror)
      if (const auto t = enter(Box{{0.98, kY0, 0.0}, {kPanelX, kY1, kZ1}}, o, d); t && *t < best) best = *t;
    return {best, at_mirror};
  }

  // One beam: a direct return, or the mirror's phantom (reported at the folded range along the
  // beam's own direction), or no return beyond max_range (its end at the range).
  iv::Beam beam(const iv::Point3& o, const iv::Point3& d, double max_range, bool& phantom) const {
    auto [t, at_mirror] = first(o, d, true);
    phantom = false;
    if (at_mirror) {
      const iv::Point3 m = o + t * d;
      const iv::Point3 r(-d.x(), d.y(), d.z());
      t += first(m, r, false).first;
      phantom = true;
    }
    if (t > max_range) return {o, o + d * max_range, false};
    return {o, o + d * t, true};
  }

  std::vector<iv::Point3> origins() const {
    return {{3.5, 2.5, 0.5}, {4.0, 1.5, 0.5}, {4.0, 3.8, 0.5}, {2.2, 2.5, 0.5},
            {4.2, 2.5, 0.8}, {2.0, 1.0, 0.5}, {2.0, 4.2, 0.5}, {1.6, 0.6, 0.5}};
  }

  // One scan from o: azimuth every degree in [az0, az1), elevation -30..30 every degree; ph tells
  // which beams are the mirror's.
  std::vector<iv::Beam> scan_from(const iv::Point3& o, double max_range, int az0, int az1,
                                  std::vector<bool>& ph) const {
    std::vector<iv::Beam> s;
    ph.clear();
    const double deg = std::numbers::pi / 180.0;
    for (int az = az0; az < az1; ++az)
      for (int el = -30; el <= 30; ++el) {
        const double a = az * deg, e = el * deg;
        bool p = false;
        s.push_back(
            beam(o, iv::Point3(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e)), max_range, p));
        ph.push_back(p);
      }
    return s;
  }

  // One scan per origin, all around; phantom[s][i] tells which beams are the mirror's.
  std::vector<std::vector<iv::Beam>> scans(double max_range, std::vector<std::vector<bool>>& phantom) const {
    std::vector<std::vector<iv::Beam>> out;
    phantom.assign(origins().size(), {});
    for (std::size_t i = 0; i < origins().size(); ++i)
      out.push_back(scan_from(origins()[i], max_range, 0, 360, phantom[i]));
    return out;
  }
};

// The explained mobile planner's parameters for the room (its floor band, the beams' range, one
// thread); a template so that this header needs no planner.
template <class MobileParams>
void set_explained_params(MobileParams& p, double max_range) {
  p.region = iv::Bounds{{0.0, 0.0, 0.2}, {4.5, 5.0, 0.8}};
  p.gain.max_range = max_range;
  p.explained.enabled = true;
  p.threads = 1;
}

// The map the planner reads (planner.make_map()) with each scan inserted, as the episode runner
// inserts them, and its analysis updated, as the runner updates it before a plan.
template <class Planner, class Grid>
auto map_of_scans(const Planner& planner, Grid grid, const std::vector<std::vector<iv::Beam>>& scans) {
  auto map = planner.make_map(std::move(grid));
  for (const auto& s : scans) map.insert(std::span<const iv::Beam>(s));
  map.update_analysis();
  return map;
}

}  // namespace test::planted_mirror
