// sim_scan: one simulated scan of the mobile base's eight ToF cameras in the lab room, written as
// CSV with the simulator's ground truth of every beam, and the room's true occupancy at the
// cameras' height: the data behind docs/platforms.md's mirror figure (scripts/plot_scan.py).
//
//   sim_scan --closet mirror --x 1.6 --y 4.0 --yaw 0 --out scan
//   -> scan/beams.csv  (x,y,z of each beam's end, hit 0/1, path: direct|reflected|passed|no-return,
//                       sx,sy,sz: the true surface point that returned it, empty unless returned)
//      scan/truth.csv  (x,y of the occupied voxel centres of the layer z in [0.3, 0.4) at 5 cm)
//      scan/pose.csv   (the body pose x,y,yaw)
#include "common/cli.hpp"

#include <intervox/io/text_file.hpp>
#include <intervox/sim/sim.hpp>

#include <cmath>
#include <stdexcept>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace iv = intervox;

namespace {
struct Options {
  std::string closet = "mirror";
  std::string door = "diffuse";
  double x = 1.6, y = 4.0, yaw = 0.0;
  std::uint64_t seed = 1;
  int max_bounces = iv::sim::kDefaultMaxBounces;
  std::string out = "out/sim_scan";
};

/// Saves a whole CSV atomically (io/text_file.hpp): a full disk leaves the previous file, never a
/// truncated one.
void save(const std::ostringstream& f, const std::filesystem::path& p) {
  if (!f) throw iv::IoError("sim_scan: cannot format " + p.string());
  iv::write_text_file(p.string(), f.str());
}

int run(const Options& o) {
  iv::sim::LabRoomOptions ro;
  ro.closet_material = iv::sim::material_from_string(o.closet);
  ro.door_material = iv::sim::material_from_string(o.door);
  const iv::sim::LabRoom lab = iv::sim::make_lab_room(ro);
  const iv::Point3 at(o.x, o.y, 0.0);
  if (!lab.interior.contains(at)) throw iv::InvalidArgument("sim_scan: the body position lies outside the room");
  if (lab.scene.inside(at + iv::Point3(0, 0, 0.05)))
    throw iv::InvalidArgument("sim_scan: the body position lies inside an object");
  iv::Pose body = iv::Pose::Identity();
  body.linear() = Eigen::AngleAxisd(o.yaw, iv::Point3::UnitZ()).toRotationMatrix();
  body.translation() = at;
  iv::sim::SimOptions so;
  so.max_bounces = o.max_bounces;
  std::vector<iv::sim::BeamPath> paths;
  const iv::SensorRig rig = iv::SensorRig::mobile_base();
  // The surfaces behind each beam: trace again with the same streams (simulate() keeps only the
  // beams); identical by construction because every beam draws from its own stream.
  const std::vector<iv::Beam> beams = iv::sim::simulate(rig, lab.scene, body, o.seed, so, &paths);
  std::vector<iv::Point3> surfaces;
  surfaces.reserve(beams.size());
  for (const iv::SensorRay& r : rig.rays(body)) {
    iv::sim::BeamRng rng(o.seed, r.sensor, r.beam);
    const auto t =
        iv::sim::trace(lab.scene, r.ray.origin, r.ray.direction, r.min_range, r.ray.range, rng, so.max_bounces);
    if (t.path != iv::sim::BeamPath::Invalid) surfaces.push_back(t.surface);
  }
  if (surfaces.size() != beams.size()) throw std::logic_error("sim_scan: beams and traces disagree");

  const std::filesystem::path dir(o.out);
  std::filesystem::create_directories(dir);
  std::ostringstream b;
  b << "x,y,z,hit,path,sx,sy,sz\n";
  std::size_t counts[5] = {};
  for (std::size_t i = 0; i < beams.size(); ++i) {
    const auto& e = beams[i].end;
    b << e.x() << ',' << e.y() << ',' << e.z() << ',' << int(beams[i].hit) << ',' << iv::sim::to_string(paths[i]);
    if (beams[i].hit)
      b << ',' << surfaces[i].x() << ',' << surfaces[i].y() << ',' << surfaces[i].z();
    else
      b << ",,,";
    b << '\n';
    ++counts[static_cast<int>(paths[i])];
  }
  save(b, dir / "beams.csv");
  const iv::GridGeometry g(0.05);
  std::ostringstream t;
  t << "x,y\n";
  std::set<std::pair<int, int>> seen;
  const iv::Bounds layer{{lab.scene.bounds().min.x(), lab.scene.bounds().min.y(), 0.3},
                         {lab.scene.bounds().max.x(), lab.scene.bounds().max.y(), 0.4 - 1e-9}};
  for (const iv::Key& k : lab.scene.ground_truth(g, layer))
    if (seen.insert({k.x, k.y}).second) t << g.center(k).x() << ',' << g.center(k).y() << '\n';
  save(t, dir / "truth.csv");
  std::ostringstream p;
  p << "x,y,yaw\n" << o.x << ',' << o.y << ',' << o.yaw << '\n';
  save(p, dir / "pose.csv");
  std::printf("sim_scan: %zu beams: %zu direct, %zu reflected, %zu passed, %zu no return -> %s/\n", beams.size(),
              counts[0], counts[1], counts[2], counts[3], o.out.c_str());
  return 0;
}
}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{"Intervox: one simulated scan of the mobile base's eight ToF cameras in the lab room, as CSV with the\n"
               "simulator's ground truth of every beam (direct, reflected, passed, no return) and the room's true\n"
               "occupancy at the cameras' height."};
  app.add_option("--closet", o.closet, "material of the closet against the west wall")
      ->check(examples::one_of(iv::sim::kMaterialNames))
      ->capture_default_str();
  app.add_option("--door", o.door, "material of the door in the east wall (the thesis' reflective door: mirror)")
      ->check(examples::one_of(iv::sim::kMaterialNames))
      ->capture_default_str();
  app.add_option("--x", o.x, "body position x [m]")->check(examples::number_in(0.0, 8.0))->capture_default_str();
  app.add_option("--y", o.y, "body position y [m]")->check(examples::number_in(0.0, 6.0))->capture_default_str();
  app.add_option("--yaw", o.yaw, "body yaw [rad]")->check(examples::number_in(-10.0, 10.0))->capture_default_str();
  app.add_option("--seed", o.seed, "noise seed")->check(examples::integer_in<std::uint64_t>())->capture_default_str();
  app.add_option("--max-bounces", o.max_bounces, "reflections a beam may undergo")
      ->check(examples::integer_in(0, 255))
      ->capture_default_str();
  app.add_option("--out", o.out, "output folder (created as needed)")->capture_default_str();
  return examples::cli_main("sim_scan", app, argc, argv, [&] { return run(o); });
}
