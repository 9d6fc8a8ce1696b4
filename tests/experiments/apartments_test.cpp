// The apartments benchmark (examples/apartments): collisions scored on hand-made trajectories,
// the rows' round trip, resumption and worker or thread counts that leave results.csv unchanged.
#include <catch2/catch.hpp>

#include "apartments/benchmark.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <utility>
#include <string>
#include <vector>

namespace {

namespace ap = apartments;

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// A fresh folder below the system's temporary folder.
std::string fresh(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("intervox_apartments_" + name);
  std::filesystem::remove_all(dir);
  return dir.string();
}

/// The first world with a wall mirror that has free space before it, and that mirror's index.
std::pair<intervox::sim::Apartment, std::size_t> mirror_world() {
  intervox::sim::ApartmentOptions o;
  o.mix.fill(0.0);
  o.mix[static_cast<std::size_t>(intervox::sim::FixtureKind::WallMirror)] = 1.0;
  for (std::uint64_t seed = 1; seed < 100; ++seed) {
    intervox::sim::Apartment a = intervox::sim::make_apartment(seed, o);
    for (std::size_t i = 0; i < a.fixtures.size(); ++i) {
      const intervox::PlanePatch& m = *a.fixtures[i].plane;
      const intervox::Point3 front = m.center + 1.0 * m.normal;
      if (!a.scene.overlaps({front + intervox::Point3(-0.4, -0.4, 0.1), front + intervox::Point3(0.4, 0.4, 0.9)}))
        return {std::move(a), i};
    }
  }
  throw intervox::Error("no world with a free wall mirror in seeds 1..99");
}

}  // namespace

TEST_CASE(
    "the benchmark counts the poses and segments of a hand-made path through a wall mirror and names the mirror first",
    "[apartments]") {
  const auto [a, index] = mirror_world();
  const intervox::PlanePatch& m = *a.fixtures[index].plane;
  const intervox::Point3 n = m.normal;
  const intervox::Point3 base(m.center.x(), m.center.y(), 0.0);
  // 1 m in front of the mirror (free), 0.8 m in front (free: the robot's radius is 0.35 m), then
  // 0.3 m behind it, inside the wall and beyond (into the phantom room): one pose meets the
  // true world and so do the two segments around it.
  std::vector<intervox::Pose> path{intervox::planar_pose(base + 1.0 * n, 0.0),
                                   intervox::planar_pose(base + 0.8 * n, 0.0),
                                   intervox::planar_pose(base - 0.3 * n, 0.0)};
  ap::Run run;
  const intervox::MobilePlannerParams p = ap::planner_params(run, ap::Options{});
  ap::Result r;
  ap::score_collisions(a, a.scene, intervox::GridGeometry(0.1), path, p, r);
  CHECK(r.collision_poses == 1);
  CHECK(r.collision_segments == 1);
  CHECK(r.first_collision == 2);
  CHECK(r.met_lying);
  CHECK(r.met.find(":wall-mirror") != std::string::npos);
  // Back in front of the mirror: no collision.
  ap::Result clear;
  ap::score_collisions(a, a.scene, intervox::GridGeometry(0.1), {path[0], path[1]}, p, clear);
  CHECK(clear.collision_poses == 0);
  CHECK(clear.collision_segments == 0);
  CHECK(clear.first_collision == -1);
  CHECK(clear.met == "-");
}

TEST_CASE("the benchmark's rows read back as written", "[apartments]") {
  ap::Result r;
  r.run = {10007, "honest", "safe", "one", "bayes"};
  r.rooms = 3;
  r.kinds = "wall-mirror;glass-door";
  r.floor_area = 31.25;
  r.termination = "no reachable frontier";
  r.completed = true;
  r.steps = 17;
  r.distance = 23.4567;
  r.known = 0.987654;
  r.collision_poses = 4;
  r.collision_segments = 5;
  r.first_collision = 12;
  r.met = "wall_mirror_0:wall-mirror;wall_south:wall";
  r.met_lying = true;
  r.seconds_per_plan = 0.25;
  r.seconds_per_insert = 0.5;
  r.seconds_total = 12.5;
  const std::string dir = fresh("rows");
  std::filesystem::create_directories(dir);
  ap::write_results(dir, {r});
  const std::vector<ap::Result> back = ap::read_results(dir + "/results.csv", dir + "/timings.csv");
  REQUIRE(back.size() == 1);
  CHECK(ap::results_row(back[0]) == ap::results_row(r));
  CHECK(ap::timings_row(back[0]) == ap::timings_row(r));
  // A file of another program is refused by name.
  intervox::write_text_file(dir + "/other.csv", "a,b\n1,2\n");
  CHECK_THROWS_WITH(ap::read_results(dir + "/other.csv"), Catch::Contains("other.csv"));
}

TEST_CASE("an unknown planner, rig, update or world is refused before anything runs", "[apartments]") {
  CHECK_THROWS_AS(ap::run_one({1, "lying", "careful", "eight", "bayes"}, ap::Options{}), intervox::InvalidArgument);
  CHECK_THROWS_AS(ap::run_one({1, "lying", "plain", "three", "bayes"}, ap::Options{}), intervox::InvalidArgument);
  CHECK_THROWS_AS(ap::run_one({1, "lying", "plain", "eight", "lower"}, ap::Options{}), intervox::InvalidArgument);
  CHECK_THROWS_AS(ap::run_one({1, "mirrored", "plain", "eight", "bayes"}, ap::Options{}), intervox::InvalidArgument);
}

TEST_CASE("the benchmark's results are the same on one worker and thread and on two, and a resumed run adds only what "
          "is missing",
          "[apartments][slow][threaded]") {
  ap::Options o;
  o.first_seed = 3;
  o.worlds = 1;
  o.planners = {"plain", "oracle"};
  o.rigs = {"eight"};
  o.updates = {"interval-mean"};
  o.max_steps = 2;
  o.figure_worlds = 1;
  o.progress = false;
  o.workers = 1;
  o.out = fresh("one");
  const ap::Report one = ap::run_benchmark(o);
  CHECK(one.ran == 3);  // plain and oracle in the apartment, plain in its honest twin
  CHECK(one.failed.empty());
  CHECK(std::filesystem::exists(o.out + "/figures/lying_plain_eight_interval-mean_3.png"));

  ap::Options two = o;
  two.workers = 2;
  two.threads = 2;
  two.out = fresh("two");
  two.figure_worlds = 0;
  ap::run_benchmark(two);
  CHECK(slurp(two.out + "/results.csv") == slurp(o.out + "/results.csv"));

  // The plain runs first, then the oracle's with --resume: the same rows, the plain ones kept.
  ap::Options part = two;
  part.out = fresh("resumed");
  part.planners = {"plain"};
  CHECK(ap::run_benchmark(part).ran == 2);
  part.planners = {"plain", "oracle"};
  part.resume = true;
  const ap::Report rest = ap::run_benchmark(part);
  CHECK(rest.resumed == 2);
  CHECK(rest.ran == 1);
  CHECK(slurp(part.out + "/results.csv") == slurp(o.out + "/results.csv"));
}
