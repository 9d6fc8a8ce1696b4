// explain_survey: a scripted survey of a simulated world, mapped with the explained-free-space
// channel beside a plain grid, and scored against the simulator's ground truth: which beams it
// classed suspect by their true path (direct, reflected, passed), how much of the lying objects'
// inside each map calls free, how much truly free floor space stays explained free, and what the
// classing costs. The numbers of docs/concepts.md, "Explained free space".
//
//   explain_survey                                   lab room, mirror closet, the eight-camera base
//   explain_survey --world flat --rig one            a flat (mirror-fronted wardrobe, black sofa,
//                                                    doorway to an annex), one forward camera
//   explain_survey --world symmetric                 two mirror-symmetric rooms joined by a doorway,
//                                                    a mirror beside it (the hard case)
//   explain_survey --glint --body                    with the camera's near-normal glint and the
//                                                    robot's own body in the scene (it appears in mirrors)
//   explain_survey --closet diffuse --order reverse  the same poses backwards
//   explain_survey --annex --window --front-only     the lab with an open doorway to an annex, a
//                                                    window, and only the closet's front lying
//   explain_survey --inside-crossings                a returned beam's crossing counts only at a
//                                                    surface's inside (ExplainOptions::returned_crossing_inside)
//
// Writes to --out when given: per_scan.csv (scan, x, y, yaw, beams per class, the lying objects'
// explained-free and plain-free shares, insertion times) and final.png, the slice 0.45-0.55 m
// above the floor (the cameras' height) seen from above after the last scan: the plain map, the explained state and the
// simulator's truth side by side, with legends.
#include "common/cli.hpp"
#include "common/rigs.hpp"

#include <intervox/analysis/lying_surfaces.hpp>
#include <intervox/explain/explain.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/io/png.hpp>
#include <intervox/io/text_file.hpp>
#include <intervox/raycast/insert.hpp>
#include <intervox/raycast/vector_walks.hpp>
#include <intervox/sim/sim.hpp>
#include <intervox/update/bayes_log_odds.hpp>
#include <intervox/view/explained_image.hpp>
#include <intervox/view/image_annotation.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace iv = intervox;

namespace {
struct Options {
  std::string world = "lab";
  std::string closet = "mirror";
  std::string rig = "eight";
  std::string order = "forward";
  double resolution = 0.05;
  double max_range = 4.0;
  std::uint64_t seed = 1;
  double ledger_mb =
      double(iv::ExplainOptions{}.ledger_bytes) / (1024.0 * 1024.0);  ///< the ledger budget in MiB (0: no revision)
  int revision_rounds = iv::ExplainOptions{}.revision_rounds;
  int revision_interval = iv::ExplainOptions{}.revision_interval;
  bool inside_crossings = false;  ///< ExplainOptions::returned_crossing_inside
  std::string out;
  bool annex = false, window = false, front_only = false;  ///< the lab room's options (LabRoomOptions)
  bool glint = false, body = false;  ///< the simulator's mirror conditions (SimOptions::glint, SimOptions::body)
  bool find_mirrors = false;         ///< find the lying surfaces after every scan and tell the channel of the mirrors
  double max_inconsistent_share = iv::LyingSurfaceParams{}.max_inconsistent_share;  ///< the analysis' opacity test
};

iv::LyingSurfaceParams lying_params(const Options& o) {
  iv::LyingSurfaceParams p;
  p.max_inconsistent_share = o.max_inconsistent_share;
  return p;
}

/// A world: its scene, the boxes of the objects whose surfaces lie (for the scores), the free
/// region whose floor slab is scored, and the scripted body poses (x, y, yaw).
struct World {
  iv::sim::Scene scene;
  std::vector<iv::Bounds> lying;
  iv::Bounds interior;
  std::vector<std::array<double, 3>> poses;
  /// Real space seen only through an opening (the lab's annex, the ground outside its window):
  /// its floor slab is scored like the interior's.
  std::vector<std::pair<std::string, iv::Bounds>> beyond;
};

World lab_world(const Options& o) {
  iv::sim::LabRoomOptions ro;
  ro.closet_material = iv::sim::material_from_string(o.closet);
  ro.annex = o.annex;
  ro.window = o.window;
  ro.closet_front_only = o.front_only;
  const iv::sim::LabRoom lab = iv::sim::make_lab_room(ro);
  World w{lab.scene, {}, lab.interior, {}, {}};
  w.lying.push_back(lab.scene.object_bounds(lab.closet_body));  // the closet, [0.001, 0.601] x [3.4, 4.6] x [0, 2]
  w.poses = {{6.0, 1.5, 0.0}, {6.5, 4.0, 0.5}, {4.5, 4.2, 1.0}, {2.5, 4.2, 2.0}, {1.6, 4.0, 3.0}, {1.8, 1.5, 0.3},
             {3.8, 1.4, 1.5}, {2.2, 3.0, 2.5}, {1.4, 5.0, 0.7}, {1.5, 3.2, 4.0}, {3.5, 4.5, 5.0}, {6.8, 5.2, 3.3}};
  if (lab.annex_interior) {  // a look through the doorway, from 1.1 m before it
    w.poses.push_back({7.0, 5.3, 0.0});
    w.beyond.emplace_back("annex", *lab.annex_interior);
  }
  if (lab.window) {  // a look out of the window, from 1 m before it
    w.poses.push_back({5.7, 1.0, -0.5 * std::numbers::pi});
    w.beyond.emplace_back("outside the window", iv::Bounds{{3.5, -3.1, 0.0}, {7.9, -0.1, 3.0}});
  }
  return w;
}

/// A 9 m x 4 m flat of two rooms joined by a doorway: a wardrobe with a mirror front (wooden
/// sides and top) and a black (absorbing) sofa in the first room, a table and a cabinet in the
/// annex. Not the lab room: another shape, an opening, two lying objects.
World flat_world(const Options& o) {
  World w;
  iv::sim::Scene& s = w.scene;
  const iv::sim::Material wood = iv::sim::Material::diffuse();
  const auto box = [&](const char* name, iv::Point3 lo, iv::Point3 hi, const iv::sim::Material& m) {
    s.add_box({lo, hi}, m, name);
  };
  box("floor", {-0.1, -0.1, -0.1}, {9.1, 4.1, 0.0}, wood);
  box("wall_south", {-0.1, -0.1, 0.0}, {9.1, 0.0, 2.6}, wood);
  box("wall_north", {-0.1, 4.0, 0.0}, {9.1, 4.1, 2.6}, wood);
  box("wall_west", {-0.1, 0.0, 0.0}, {0.0, 4.0, 2.6}, wood);
  box("wall_east", {9.0, 0.0, 0.0}, {9.1, 4.0, 2.6}, wood);
  box("partition_south", {5.0, 0.0, 0.0}, {5.1, 1.5, 2.6}, wood);  // the doorway: y in [1.5, 2.4], up to 2.1 m
  box("partition_north", {5.0, 2.4, 0.0}, {5.1, 4.0, 2.6}, wood);
  box("lintel", {5.0, 1.5, 2.1}, {5.1, 2.4, 2.6}, wood);
  box("wardrobe", {1.0, 3.4, 0.0}, {2.5, 4.0, 2.0}, wood);
  s.add_quad({1.05, 3.399, 0.05}, {1.4, 0.0, 0.0}, {0.0, 0.0, 1.9}, iv::sim::material_from_string(o.closet),
             "wardrobe_front");
  box("sofa", {2.8, 0.0, 0.0}, {4.6, 0.9, 0.8}, iv::sim::Material::absorbing());
  box("table", {6.5, 2.5, 0.7}, {8.0, 3.5, 0.75}, wood);
  box("cabinet", {8.3, 0.3, 0.0}, {8.9, 1.0, 1.2}, wood);
  w.lying = {iv::Bounds{{1.0, 3.4, 0.0}, {2.5, 4.0, 2.0}}, iv::Bounds{{2.8, 0.0, 0.0}, {4.6, 0.9, 0.8}}};
  w.interior = iv::Bounds{{0, 0, 0}, {9, 4, 2.6}};
  w.poses = {{0.8, 1.5, 0.0}, {2.0, 2.2, 0.8}, {3.5, 2.2, 1.6}, {4.2, 1.6, 3.0}, {1.5, 1.2, 4.5},
             {5.6, 2.0, 0.0}, {7.0, 1.5, 1.0}, {7.5, 3.2, 2.5}, {4.0, 2.8, 3.8}};
  return w;
}

/// Two 4 x 4 m rooms, mirror images of each other about the wall they share, joined by a doorway,
/// with a doorway-sized panel of --closet's material beside it (sim::make_symmetric_rooms): the
/// hard case of mirror detection, since the mirror shows the west room's image, which is the east
/// room itself. Scored: the wall behind the panel (the lying object) and the east room's floor (real
/// space seen through the doorway). Poses in the west room first, then through the doorway.
World symmetric_world(const Options& o) {
  iv::sim::SymmetricRoomsOptions so;
  so.mirror = true;
  so.mirror_material = iv::sim::material_from_string(o.closet);
  const iv::sim::SymmetricRooms r = iv::sim::make_symmetric_rooms(so);
  World w{r.scene, {}, r.rooms[0], {}, {}};
  w.lying.push_back(r.scene.object_bounds(*r.scene.find("mirror_backing")));  // [4.101, 4.2] x [2.2, 3.2] x [0, 2.1]
  w.beyond.emplace_back("east room", r.rooms[1]);
  w.poses = {{2.0, 1.5, 0.0}, {3.0, 2.7, 0.0}, {3.0, 1.1, 0.0}, {1.0, 1.2, 0.6}, {3.2, 2.0, 0.4},
             {1.2, 2.0, 3.1}, {5.0, 1.1, 0.0}, {6.2, 2.0, 3.1}, {7.0, 1.2, 2.0}};
  return w;
}

iv::SensorRig make_rig(const std::string& name) {
  return name == "eight" ? iv::SensorRig::mobile_base() : examples::front_camera_rig();
}

/// Pictures side by side on white, top-aligned, 8 pixels apart.
iv::RgbImage side_by_side(const std::vector<iv::RgbImage>& parts) {
  int w = 0, h = 0;
  for (const auto& p : parts) {
    w += p.width + 8;
    h = std::max(h, p.height);
  }
  iv::RgbImage out = iv::RgbImage::filled(w - 8, h, 255, 255, 255);
  int x0 = 0;
  for (const auto& p : parts) {
    for (int y = 0; y < p.height; ++y)
      for (int x = 0; x < p.width; ++x) {
        const std::size_t i =
            3 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(p.width) + static_cast<std::size_t>(x));
        out.set(x0 + x, y, p.rgb[i], p.rgb[i + 1], p.rgb[i + 2]);
      }
    x0 += p.width + 8;
  }
  return out;
}

void save(const std::ostringstream& f, const std::filesystem::path& p) {
  if (!f) throw iv::IoError("explain_survey: cannot format " + p.string());
  iv::write_text_file(p.string(), f.str());
}

int run(const Options& o) {
  iv::use_vector_walks();
  World w = o.world == "lab" ? lab_world(o) : o.world == "flat" ? flat_world(o) : symmetric_world(o);
  iv::sim::SimOptions so;
  so.glint = o.glint;
  if (o.body) so.body = iv::sim::RobotBody::mobile_base();  // the base's footprint, also for --rig one
  const iv::SensorRig rig = make_rig(o.rig);
  // One camera sees a quarter of the circle: it turns on the spot, four views per position.
  std::vector<std::array<double, 3>> poses;
  for (const auto& p : w.poses)
    for (int turn = 0; turn < (o.rig == "one" ? 4 : 1); ++turn)
      poses.push_back({p[0], p[1], p[2] + turn * 0.5 * std::numbers::pi});
  if (o.order == "reverse") std::reverse(poses.begin(), poses.end());

  iv::VoxelGrid<iv::BayesLogOdds> plain(o.resolution), grid(o.resolution);  // unbounded
  iv::ExplainOptions eo;
  eo.ledger_bytes = static_cast<std::size_t>(o.ledger_mb * 1024.0 * 1024.0);
  eo.revision_rounds = o.revision_rounds;
  eo.revision_interval = o.revision_interval;
  eo.returned_crossing_inside = o.inside_crossings;
  iv::ExplainedSpace space(grid.geometry(), eo);
  iv::InsertOptions io;
  io.max_range = o.max_range;
  iv::ScanInserter plain_inserter(io), inserter(io);
  const iv::GridGeometry& g = grid.geometry();

  // The lying objects' voxels at the robot's height (z < 0.8 m), from the scene's truth.
  std::vector<iv::Key> lying;
  for (const iv::Bounds& b : w.lying) {
    const iv::Bounds band{b.min, {b.max.x(), b.max.y(), std::min(b.max.z(), 0.8)}};
    for (const iv::Key& k : w.scene.ground_truth(g, band)) lying.push_back(k);
  }
  std::sort(lying.begin(), lying.end());
  lying.erase(std::unique(lying.begin(), lying.end()), lying.end());

  std::uint64_t by_path[5][4] = {};
  // Every scan's true paths and classes (arrival classes, later those the ledger revised to), and
  // which scans the ledger keeps (oldest first, as it does).
  std::vector<std::vector<iv::sim::BeamPath>> scan_paths;
  std::vector<std::vector<iv::BeamClass>> scan_classes;
  std::vector<std::size_t> kept;
  double t_plain = 0, t_explained = 0, worst_band = 0;
  std::uint64_t refused = 0;
  std::ostringstream csv;
  csv << "scan,x,y,yaw,trusted,suspect,no_return,lying_explained_free,lying_plain_free,plain_ms,explained_ms\n";
  std::printf("%-5s %-22s %8s %8s %8s %12s %10s\n", "scan", "pose (x, y, yaw)", "trusted", "suspect", "no-ret",
              "lying: expl", "plain free");
  for (std::size_t s = 0; s < poses.size(); ++s) {
    iv::Pose body = iv::Pose::Identity();
    body.linear() = Eigen::AngleAxisd(poses[s][2], iv::Point3::UnitZ()).toRotationMatrix();
    body.translation() = iv::Point3(poses[s][0], poses[s][1], 0.0);
    if (w.scene.inside(body.translation() + iv::Point3(0, 0, 0.05)))
      throw iv::InvalidArgument("explain_survey: pose " + std::to_string(s) + " lies inside an object");
    std::vector<iv::sim::BeamPath> paths;
    const std::vector<iv::Beam> beams = iv::sim::simulate(rig, w.scene, body, o.seed * 1000 + s, so, &paths);
    const auto t0 = std::chrono::steady_clock::now();
    plain_inserter.insert_beams(plain, std::span<const iv::Beam>(beams));
    const auto t1 = std::chrono::steady_clock::now();
    std::vector<iv::BeamClass> classes;
    const iv::InsertStats st = space.insert_beams(inserter, grid, std::span<const iv::Beam>(beams), &classes);
    if (o.find_mirrors) iv::resolve_mirrors(space, iv::find_lying_surfaces(space, lying_params(o)));
    const auto t2 = std::chrono::steady_clock::now();
    const double ms_plain = 1e3 * std::chrono::duration<double>(t1 - t0).count();
    const double ms_explained = 1e3 * std::chrono::duration<double>(t2 - t1).count();
    t_plain += ms_plain;
    t_explained += ms_explained;
    for (std::size_t i = 0; i < beams.size(); ++i) ++by_path[static_cast<int>(paths[i])][static_cast<int>(classes[i])];
    if (space.ledger().refused() == refused) kept.push_back(s);  // the ledger's newest
    refused = space.ledger().refused();
    while (kept.size() > space.ledger().scans().size()) kept.erase(kept.begin());
    scan_paths.push_back(std::move(paths));
    scan_classes.push_back(std::move(classes));
    std::size_t expl_free = 0, plain_free = 0;
    for (const iv::Key& k : lying) {
      expl_free += space.state(k) == iv::ExplainedState::Free;
      plain_free += plain.occupancy(k) == iv::Occupancy::Free;
    }
    const double fe = lying.empty() ? 0.0 : 100.0 * double(expl_free) / double(lying.size());
    const double fp = lying.empty() ? 0.0 : 100.0 * double(plain_free) / double(lying.size());
    worst_band = std::max(worst_band, fe);
    char pose[64];
    std::snprintf(pose, sizeof pose, "(%.2f, %.2f, %.2f)", poses[s][0], poses[s][1], poses[s][2]);
    std::printf("%-5zu %-22s %8llu %8llu %8llu %11.1f%% %9.1f%%\n", s, pose, (unsigned long long)st.beams_trusted,
                (unsigned long long)st.beams_suspect, (unsigned long long)st.beams_no_return, fe, fp);
    csv << s << ',' << poses[s][0] << ',' << poses[s][1] << ',' << poses[s][2] << ',' << st.beams_trusted << ','
        << st.beams_suspect << ',' << st.beams_no_return << ',' << fe << ',' << fp << ',' << ms_plain << ','
        << ms_explained << '\n';
  }
  // One last revision for the scans since the last one (timed with the classed insertion), and
  // the lying regions as the analysis names them then (with --find-mirrors, the ones it resolves).
  std::vector<iv::LyingSurface> regions;
  {
    const auto t0 = std::chrono::steady_clock::now();
    space.revise();
    if (o.find_mirrors) {
      regions = iv::find_lying_surfaces(space, lying_params(o));
      iv::resolve_mirrors(space, regions);
    }
    t_explained += 1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  if (!o.find_mirrors) regions = iv::find_lying_surfaces(space, lying_params(o));
  // The lying regions, and the mirrors the channel knows.
  for (const iv::LyingSurface& r : regions) {
    const iv::Point3 c = r.surface.center, n = r.surface.normal;
    std::printf("  region: %-10s %6zu voxels, %5zu returned + %5zu silent suspect beams, votes %zu of %zu crossing; "
                "plane centre (%.2f, %.2f, %.2f) normal (%.2f, %.2f, %.2f) %.2f x %.2f m; best plane (%.2f, %.2f, "
                "%.2f) . p = %.2f\n",
                std::string(iv::to_string(r.kind)).c_str(), r.voxels, r.returned_beams, r.silent_beams, r.mirror_votes,
                r.mirror_crossing, c.x(), c.y(), c.z(), n.x(), n.y(), n.z(), 2 * r.surface.half_u, 2 * r.surface.half_v,
                r.best_normal.x(), r.best_normal.y(), r.best_normal.z(), r.best_offset);
  }
  for (const iv::PlanePatch& m : space.mirrors())
    std::printf("  mirror known to the channel: centre (%.2f, %.2f, %.2f) normal (%.2f, %.2f, %.2f) %.2f x %.2f m\n",
                m.center.x(), m.center.y(), m.center.z(), m.normal.x(), m.normal.y(), m.normal.z(), 2 * m.half_u,
                2 * m.half_v);
  // The final classes: those the ledger holds now for the scans it keeps (its beams are the
  // scan's beams without the skipped ones, in order), the last ones it held for the others.
  for (std::size_t j = 0; j < kept.size(); ++j) {
    std::vector<iv::BeamClass>& c = scan_classes[kept[j]];
    std::size_t i = 0;
    space.ledger().scans()[j].for_each([&](std::size_t, const iv::Beam&, iv::BeamClass now) {
      while (c[i] == iv::BeamClass::Skipped) ++i;
      c[i++] = now;
    });
  }
  std::uint64_t final_by_path[5][4] = {};
  for (std::size_t s = 0; s < scan_classes.size(); ++s)
    for (std::size_t i = 0; i < scan_classes[s].size(); ++i)
      ++final_by_path[static_cast<int>(scan_paths[s][i])][static_cast<int>(scan_classes[s][i])];
  std::printf(
      "\nbeams classed suspect, by true path (%zu lying-object voxels below 0.8 m): on arrival, and after revision\n",
      lying.size());
  for (const iv::sim::BeamPath p :
       {iv::sim::BeamPath::Direct, iv::sim::BeamPath::Reflected, iv::sim::BeamPath::Passed}) {
    const auto& n = by_path[static_cast<int>(p)];
    const auto& f = final_by_path[static_cast<int>(p)];
    const std::uint64_t returned = n[0] + n[1];
    if (returned == 0) continue;
    std::printf("  %-9s %8llu returned beams, %5.1f%% suspect on arrival, %5.1f%% after revision\n",
                std::string(iv::sim::to_string(p)).c_str(), (unsigned long long)returned,
                100.0 * double(n[1]) / double(returned), 100.0 * double(f[1]) / double(f[0] + f[1]));
  }
  {  // Beams without a return are classed on arrival only (suspect: they passed a surface the map supports).
    const auto& n = by_path[static_cast<int>(iv::sim::BeamPath::NoReturn)];
    const std::uint64_t none = n[1] + n[2];
    if (none > 0)
      std::printf(
          "  %-9s %8llu beams without a return, %5.1f%% suspect (passed a supported surface within the range)\n",
          "no-return", (unsigned long long)none, 100.0 * double(n[1]) / double(none));
  }
  const iv::ExplainedSpace::RevisionStats& rs = space.revision_stats();
  std::printf("  revision: %llu rounds, %llu scans classed again (%llu beams), %llu beams to suspect, %llu to trusted, "
              "%llu scans unsettled; ledger %.1f MiB of %.1f (%zu scans kept, %llu forgotten)\n",
              (unsigned long long)rs.rounds, (unsigned long long)rs.scans_revisited,
              (unsigned long long)rs.beams_revisited, (unsigned long long)rs.to_suspect,
              (unsigned long long)rs.to_trusted, (unsigned long long)rs.unsettled,
              double(space.ledger().bytes()) / (1024.0 * 1024.0), o.ledger_mb, space.ledger().scans().size(),
              (unsigned long long)space.ledger().forgotten());
  // Truly free space just above the floor that the plain map calls free: how much is explained free.
  const auto floor_slab = [&](const char* what, const iv::Bounds& region) {
    std::size_t plain_free = 0, explained_free = 0;
    plain.for_each_observed([&](const iv::Key& k, const auto&) {
      const iv::Point3 c = g.center(k);
      if (c.z() < 0.1 || c.z() > 0.5 || !region.contains(c) || w.scene.occupied(g, k)) return;
      if (plain.occupancy(k) != iv::Occupancy::Free) return;
      ++plain_free;
      explained_free += space.state(k) == iv::ExplainedState::Free;
    });
    std::printf(
        "  %s floor slab (0.1-0.5 m, truly free): %zu voxels free in the plain map, %.1f%% of them explained free\n",
        what, plain_free, plain_free ? 100.0 * double(explained_free) / double(plain_free) : 0.0);
  };
  floor_slab("interior", w.interior);
  for (const auto& [name, region] : w.beyond) floor_slab(name.c_str(), region);
  std::printf("  lying objects: at most %.1f%% explained free at any scan\n", worst_band);
  std::printf("  insertion time: plain %.1f ms, with classes %.1f ms (%.2fx); channel %.1f MB\n", t_plain, t_explained,
              t_explained / t_plain, double(space.memory_bytes()) / 1e6);
  if (!o.out.empty()) {
    std::filesystem::create_directories(o.out);
    save(csv, std::filesystem::path(o.out) / "per_scan.csv");
    // A slice at the cameras' height, with 1.5 m around the world to show phantoms outside it.
    const iv::Bounds band{{w.interior.min.x() - 1.5, w.interior.min.y() - 1.5, 0.45},
                          {w.interior.max.x() + 1.5, w.interior.max.y() + 1.5, 0.55}};
    const int ppv = 2;
    const double mpp = o.resolution / ppv;
    const iv::Legend lp = iv::occupancy_legend(), le = iv::explained_legend(), lt = iv::occupancy_legend();
    const auto panel = [&](const iv::RgbImage& im, const std::string& title, const iv::Legend& l) {
      iv::ImageLabels labels;
      labels.title = title;
      labels.legend = true;
      labels.scale_bar = true;
      return iv::annotate_image(im, labels, &l, mpp);
    };
    const iv::RgbImage figure =
        side_by_side({panel(iv::render_occupancy_band(plain, band, ppv), "plain map (Bayes)", lp),
                      panel(iv::render_explained_band(space, band, ppv), "explained free space", le),
                      panel(iv::render_truth_band(
                                g, band, [&](const iv::Key& k) { return w.scene.occupied(g, k); }, ppv),
                            "simulator's truth", lt)});
    iv::write_png((std::filesystem::path(o.out) / "final.png").string(), figure);
  }
  return 0;
}
}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{"Intervox: a scripted survey of a simulated world mapped with explained free space beside a plain\n"
               "grid, scored against the simulator's ground truth (beam classes by true path, lying objects'\n"
               "inside called free, explained floor, cost)."};
  app.add_option("--world", o.world,
                 "lab (the thesis' lab room), flat (two rooms, a doorway, a mirror-fronted\n"
                 "wardrobe and a black sofa) or symmetric (two mirror-symmetric rooms joined by a\n"
                 "doorway, a mirror panel beside it)")
      ->check(CLI::IsMember({"lab", "flat", "symmetric"}))
      ->capture_default_str();
  app.add_option("--closet", o.closet,
                 "material of the lab's closet, the flat's wardrobe front, or the symmetric rooms'\n"
                 "panel beside the doorway")
      ->check(examples::one_of(iv::sim::kMaterialNames))
      ->capture_default_str();
  app.add_option("--rig", o.rig, "eight (the thesis' base) or one (a single forward camera that turns on the spot)")
      ->check(CLI::IsMember({"eight", "one"}))
      ->capture_default_str();
  app.add_option("--order", o.order, "forward or reverse: the scripted poses in either order")
      ->check(CLI::IsMember({"forward", "reverse"}))
      ->capture_default_str();
  app.add_option("--resolution", o.resolution, "voxel edge [m]")
      ->check(examples::number_in(0.01, 1.0))
      ->capture_default_str();
  app.add_option("--max-range", o.max_range, "insertion max range [m]")
      ->check(examples::number_in(0.1, 100.0))
      ->capture_default_str();
  app.add_option("--seed", o.seed, "noise seed")
      ->check(examples::integer_in<std::uint64_t>(0, 1000000))
      ->capture_default_str();
  app.add_option("--ledger-mb", o.ledger_mb, "revision ledger budget [MiB] (0: beams keep their arrival class)")
      ->check(examples::number_in(0.0, 65536.0))
      ->capture_default_str();
  app.add_option("--revision-rounds", o.revision_rounds, "rounds of one revision at most")
      ->check(examples::integer_in<int>(1, 100))
      ->capture_default_str();
  app.add_option("--revision-interval", o.revision_interval,
                 "scans between two revisions (and one after the last scan)")
      ->check(examples::integer_in<int>(1, 1000))
      ->capture_default_str();
  app.add_flag("--inside-crossings", o.inside_crossings,
               "a returned beam's crossing counts only at a surface's inside met steeply, as a no-return beam's\n"
               "(ExplainOptions::returned_crossing_inside)");
  app.add_option("--out", o.out, "folder for per_scan.csv (none: print only)");
  app.add_flag("--annex", o.annex,
               "lab: an open doorway in the east wall to an annex room (scored apart; one more pose)");
  app.add_flag("--window", o.window,
               "lab: a window in the south wall, real things outside (scored apart; one more pose)");
  app.add_flag("--front-only", o.front_only, "lab: only the closet's front has --closet's material");
  app.add_flag("--glint", o.glint,
               "simulate the near-normal glint: within 3 degrees of a mirror's normal the camera\n"
               "measures the mirror itself (SimOptions::glint)");
  app.add_option("--max-inconsistent-share", o.max_inconsistent_share,
                 "the region analysis' opacity test (LyingSurfaceParams::max_inconsistent_share; 1: off, the default)")
      ->check(CLI::Range(0.0, 1.0));
  app.add_flag("--find-mirrors", o.find_mirrors,
               "after every scan, find the lying surfaces (analysis/lying_surfaces.hpp)\n"
               "and tell the channel of the mirrors found (resolve_mirrors())");
  app.add_flag("--body", o.body,
               "put the robot's body (0.6 x 0.4 x 0.6 m) in the scene at every pose: it appears in\n"
               "mirrors (SimOptions::body)");
  app.callback([&] {
    if (o.world != "lab" && (o.annex || o.window || o.front_only))
      throw CLI::ValidationError("--annex, --window and --front-only", "apply to --world lab only");
  });
  return examples::cli_main("explain_survey", app, argc, argv, [&] { return run(o); });
}
