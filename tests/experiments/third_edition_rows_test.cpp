// The rows the third edition of docs/experiments.md adds to the sweep: the safe planner, the annex
// and front-only rooms, the library's start and map rules, the near-normal glint, and the
// measures that come with them (the annex's floor, the closet band's free share at every step).
#include <catch2/catch.hpp>

#include "beam_class_score.hpp"
#include "runs.hpp"
#include "sweep.hpp"

#include <intervox/explain/explained_space.hpp>
#include <intervox/grid/named_grids.hpp>

#include <filesystem>
#include <fstream>
#include <deque>
#include <set>
#include <unistd.h>

namespace fs = std::filesystem;

TEST_CASE("rooms, rules and sensor conditions are conditions of the mobile runs, with keys of their own",
          "[experiments][third]") {
  experiments::SweepOptions o;
  o.mobile_surfaces = {"specular"};
  o.mobile_updates = {"bayes", "interval-mean"};
  o.utilities = {"max-entropy"};
  o.planners = {"plain", "conflict-aware", "safe"};
  o.rooms = {"lab", "annex"};
  o.rules = {"thesis", "library"};
  o.sensors = {"plain", "glint"};
  o.arm_objects = {"part"};
  o.arm_updates = {"interval-mean"};
  o.seeds = 1;
  const auto runs = experiments::sweep_configs(o);
  // Mobile: bayes plain + safe, interval-mean plain + conflict-aware + safe: 5 × 2 rooms × 2 rules
  // × 2 sensors; the arm: plain and conflict-aware, never safe, in no room, rule or sensor.
  REQUIRE(runs.size() == 5 * 8 + 2);
  std::set<std::string> groups;
  for (const auto& c : runs) {
    INFO(c.key());
    CHECK(groups.insert(c.group()).second);
    if (c.platform == "arm") {
      CHECK(c.planner != "safe");
      CHECK(c.room == "lab");
      CHECK(c.rules == "thesis");
      CHECK(c.sensor == "plain");
    }
  }
  // The defaults add nothing to the key, so that the second edition's keys and figure names stay.
  CHECK(runs.front().group() == "mobile/specular/bayes/max-entropy/thesis/removed/unknown/plain");
  CHECK(runs[7].group() ==
        "mobile/specular/bayes/max-entropy/thesis/removed/unknown/plain/room-annex/rules-library/sensor-glint");
}

TEST_CASE("the closet's free share counts the grid's free voxels, and with a channel only the explained ones",
          "[experiments][third]") {
  intervox::BayesGrid grid(1.0);
  std::vector<intervox::Key> band;  // 2 × 2 × 2 voxels
  for (const intervox::Point3& p :
       {intervox::Point3(0.5, 0.5, 0.5), intervox::Point3(1.5, 0.5, 0.5), intervox::Point3(0.5, 1.5, 0.5),
        intervox::Point3(1.5, 1.5, 0.5), intervox::Point3(0.5, 0.5, 1.5), intervox::Point3(1.5, 0.5, 1.5),
        intervox::Point3(0.5, 1.5, 1.5), intervox::Point3(1.5, 1.5, 1.5)})
    band.push_back(grid.geometry().key(p));
  for (const intervox::Point3& p :
       {intervox::Point3(0.5, 0.5, 0.5), intervox::Point3(1.5, 0.5, 0.5), intervox::Point3(1.5, 1.5, 1.5)})
    for (int i = 0; i < 10; ++i) grid.update(p, intervox::Observation::Miss);
  for (int i = 0; i < 10; ++i) grid.update(intervox::Point3(0.5, 1.5, 0.5), intervox::Observation::Hit);
  CHECK(experiments::detail::free_share(grid, nullptr, band) == Approx(3.0 / 8.0));
  // A channel that has seen nothing explains nothing free.
  const intervox::ExplainedSpace nothing(grid.geometry());
  CHECK(experiments::detail::free_share(grid, &nothing, band) == 0.0);
  CHECK(experiments::detail::free_share(grid, nullptr, {}) == 0.0);
}

TEST_CASE("the explained share counts the grid's free voxels of a box that the channel also explains free",
          "[experiments][third]") {
  intervox::BayesGrid grid(1.0);
  intervox::ExplainedSpace space(grid.geometry());
  intervox::InsertOptions io;
  io.max_range = 10.0;
  intervox::ScanInserter inserter(io);
  // A trusted beam along y = 0.5 frees voxels x = 0, 1, 2 in both and ends in x = 3.
  const std::vector<intervox::Beam> beam{{{0.5, 0.5, 0.5}, {3.5, 0.5, 0.5}, true}};
  for (int i = 0; i < 5; ++i) space.insert_beams(inserter, grid, std::span<const intervox::Beam>(beam));
  // Free in the grid only: misses the channel never saw.
  for (int i = 0; i < 10; ++i) grid.update(intervox::Point3(1.5, 1.5, 0.5), intervox::Observation::Miss);
  const intervox::Bounds box{{1.0, 0.0, 0.0}, {2.999, 1.999, 0.999}};  // x in {1, 2}, y in {0, 1}
  REQUIRE(grid.occupancy(grid.geometry().key({1.5, 0.5, 0.5})) == intervox::Occupancy::Free);
  CHECK(experiments::detail::explained_free_share(grid, space, box) == Approx(2.0 / 3.0));
  // No free voxel: -1.
  CHECK(experiments::detail::explained_free_share(grid, space, intervox::Bounds{{5.0, 5.0, 5.0}, {5.5, 5.5, 5.5}}) ==
        -1.0);
}

TEST_CASE("a wall gap is the doorway's if its floor segment comes within a quarter metre of the doorway",
          "[experiments][third]") {
  const intervox::Bounds door{{8.0, 4.7, 0.0}, {8.1, 5.9, 2.1}};  // the lab room's doorway to the annex
  const auto gap = [](intervox::Point3 c, intervox::Point3 u, double half) {
    intervox::WallGap g;
    g.surface.center = c;
    g.surface.axis_u = u;
    g.surface.normal = intervox::Point3::UnitZ().cross(u);
    g.surface.half_u = half;
    g.surface.half_v = 1.0;
    return g;
  };
  CHECK(experiments::detail::gap_at(gap({8.05, 5.3, 1.0}, intervox::Point3::UnitY(), 0.6), door));
  CHECK_FALSE(
      experiments::detail::gap_at(gap({8.05, 3.0, 1.0}, intervox::Point3::UnitY(), 0.5), door));    // y 2.5 .. 3.5
  CHECK(experiments::detail::gap_at(gap({8.05, 3.0, 1.0}, intervox::Point3::UnitY(), 1.5), door));  // reaches 4.5
  CHECK_FALSE(
      experiments::detail::gap_at(gap({8.05, 3.0, 1.0}, intervox::Point3::UnitY(), 1.4), door));  // 4.4: 0.3 short
  CHECK_FALSE(
      experiments::detail::gap_at(gap({4.0, 6.0, 1.0}, intervox::Point3::UnitX(), 1.0), door));  // the north wall
}

TEST_CASE("the safe planner runs with Bayes in the annex room and records the annex's floor and the band at every step",
          "[experiments][third]") {
  const fs::path out = fs::temp_directory_path() / ("intervox_third_" + std::to_string(::getpid()));
  fs::remove_all(out);
  experiments::SweepOptions o;
  o.mobile_surfaces = {"specular"};
  o.mobile_updates = {"bayes"};
  o.utilities = {"max-entropy"};
  o.planners = {"plain", "safe"};
  o.rooms = {"annex"};
  o.rules = {"library"};
  o.arm_objects = {};
  o.seeds = 1;
  o.resolution = 0.2;
  o.max_steps = 2;
  o.gain_stride = 8;
  o.workers = 2;
  o.figures = false;
  o.progress = false;
  o.out = out.string();
  const auto report = experiments::run_and_write(o);
  REQUIRE(report.failed.empty());
  REQUIRE(report.results.size() == 2);
  for (const auto& r : report.results) {
    INFO(r.config.key());
    CHECK(r.distance >= 0.0);
    CHECK(r.annex_known >= 0.0);
    CHECK(r.annex_known <= 1.0);
    // The look-around, then every step that scanned.
    REQUIRE_FALSE(r.closet_free_curve.empty());
    CHECK(r.closet_free_curve.size() <= static_cast<std::size_t>(r.steps) + 1);
    for (const double f : r.closet_free_curve) {
      CHECK(f >= 0.0);
      CHECK(f <= 1.0);
    }
    // Only the safe planner keeps a channel whose beam classes are scored.
    if (r.config.planner == "safe") {
      // The doorway's gap: counted in the plans that close wall gaps.
      CHECK(r.door_plans >= 0);
      CHECK(r.door_opening_plans >= 0);
      CHECK(r.door_opening_plans <= r.door_plans);
      CHECK((r.door_plans == 0) == (r.door_last_opening == -1));
      CHECK(r.explained_free_share <= 1.0);
      CHECK(r.annex_explained_free_share <= 1.0);
      CHECK(r.direct_suspect >= 0.0);
      CHECK(r.direct_suspect <= 1.0);
      CHECK(r.reflected_suspect <= 1.0);  // -1 if no reflected return is kept (two steps at 20 cm)
      CHECK(r.suspect_precision <= 1.0);
    } else {
      CHECK(r.direct_suspect == -1.0);
      CHECK(r.suspect_recall == -1.0);
      CHECK(r.explained_free_share == -1.0);
      CHECK(r.door_plans == -1);
      CHECK(r.door_last_opening == -1);
    }
  }
  // The rows and their new columns come back from results.csv as they were written.
  const auto back = experiments::read_csv((out / "results.csv").string());
  REQUIRE(back.size() == 2);
  for (std::size_t i = 0; i < 2; ++i) {
    CHECK(back[i].config.key() == report.results[i].config.key());
    CHECK(back[i].config.room == "annex");
    CHECK(back[i].config.rules == "library");
    CHECK(back[i].annex_known == report.results[i].annex_known);
    CHECK(back[i].distance == report.results[i].distance);
    CHECK(back[i].closet_free_curve == report.results[i].closet_free_curve);
    CHECK(back[i].direct_suspect == report.results[i].direct_suspect);
    CHECK(back[i].suspect_precision == report.results[i].suspect_precision);
    CHECK(back[i].explained_free_share == report.results[i].explained_free_share);
    CHECK(back[i].annex_explained_free_share == report.results[i].annex_explained_free_share);
    CHECK(back[i].door_plans == report.results[i].door_plans);
    CHECK(back[i].door_opening_plans == report.results[i].door_opening_plans);
    CHECK(back[i].door_last_opening == report.results[i].door_last_opening);
  }
  CHECK(back[1].config.planner == "safe");
  fs::remove_all(out);
}

TEST_CASE("the second edition's results.csv loads with the lab room, the thesis' rules and no glint",
          "[experiments][third][csv]") {
  const auto second = experiments::read_csv(INTERVOX_SOURCE_DIR "/docs/experiments/results.csv");
  REQUIRE(second.size() == 450);
  for (const auto& r : second) {
    CHECK(r.config.room == "lab");
    CHECK(r.config.rules == "thesis");
    CHECK(r.config.sensor == "plain");
    CHECK(r.annex_known == -1.0);
    CHECK(r.distance == -1.0);
    CHECK(r.closet_free_curve.empty());
  }
}

TEST_CASE("a results.csv room, rule or sensor the sweep does not know is rejected with its column",
          "[experiments][third][csv]") {
  const fs::path path = fs::temp_directory_path() / ("intervox_third_bad_" + std::to_string(::getpid()) + ".csv");
  const std::string header =
      "platform,surface,update,utility,seed,steps,termination,completed,known,area_m2,wrongly_occupied,"
      "wrongly_free,true_occupied,conflicts,seconds_per_step,seconds_total,room,rules,sensor\n";
  const std::string row = "mobile,diffuse,bayes,entropy,1,3,explored,1,0.99,20,1,1,1,-1,0.1,0.3,";
  for (const auto& [tail, column] : {std::pair{"basement,thesis,plain", "room"}, std::pair{"lab,ours,plain", "rules"},
                                     std::pair{"lab,thesis,sonar", "sensor"}}) {
    {
      std::ofstream f(path);
      f << header << row << tail << "\n";
    }
    INFO(tail);
    CHECK_THROWS_WITH(experiments::read_csv(path.string()), Catch::Contains(std::string(column) + " is '"));
  }
  {
    std::ofstream f(path);
    f << header << row << "annex,library,glint\n"
      << row << "lab,library,body\n"
      << row << "front-only,library,one-camera\n";
  }
  const auto ok = experiments::read_csv(path.string());
  REQUIRE(ok.size() == 3);
  CHECK(ok[0].config.group() ==
        "mobile/diffuse/bayes/entropy/clamped/kept/all/plain/room-annex/rules-library/sensor-glint");
  CHECK(ok[1].config.sensor == "body");
  CHECK(ok[2].config.group() ==
        "mobile/diffuse/bayes/entropy/clamped/kept/all/plain/room-front-only/rules-library/sensor-one-camera");
  fs::remove(path);
}

TEST_CASE(
    "the one-camera condition plans for one forward camera with the exact start rule and the frames its update needs",
    "[experiments][third]") {
  experiments::SweepOptions o;
  experiments::RunConfig c;  // mobile, diffuse, Bayes, the thesis' eight cameras
  CHECK(experiments::detail::mobile_rig(c).size() == 8);
  CHECK_FALSE(experiments::detail::mobile_params(c, o).exact_blind_zone);
  CHECK(experiments::detail::mobile_params(c, o).frames_per_scan == 1);
  for (const char* sensor : {"glint", "body"}) {
    c.sensor = sensor;
    CHECK(experiments::detail::mobile_rig(c).size() == 8);
    CHECK(experiments::detail::mobile_params(c, o).frames_per_scan == 1);
  }
  c.sensor = "one-camera";
  const intervox::SensorRig one = experiments::detail::mobile_rig(c);
  REQUIRE(one.size() == 1);
  // At the front of the base, knee height, looking along the body's x axis.
  const intervox::Pose mount = one.sensor_pose(0, intervox::Pose::Identity());
  CHECK(mount.translation().isApprox(intervox::Point3(0.3, 0.0, 0.5)));
  CHECK(one.sees(intervox::Pose::Identity(), {3.0, 0.0, 0.5}));
  CHECK_FALSE(one.sees(intervox::Pose::Identity(), {-3.0, 0.0, 0.5}));
  CHECK(experiments::detail::mobile_params(c, o).exact_blind_zone);
  CHECK(experiments::detail::mobile_params(c, o).frames_per_scan == 3);  // Bayes: three misses free a voxel
  c.update = "interval-mean";
  CHECK(experiments::detail::mobile_params(c, o).frames_per_scan == 5);  // interval-mean: five
}

TEST_CASE("with the body condition the mirror closet shows the robot: the same seed maps otherwise than without it",
          "[experiments][third]") {
  experiments::SweepOptions o;
  o.resolution = 0.1;
  o.max_steps = 4;  // from the start the mirror lies beyond half the cameras' range: the look-around sees no body
  o.figures = false;
  experiments::RunConfig c{"mobile", "specular", "bayes", "entropy", "clamped", "kept", "all", "plain", 1, "unknown"};
  c.rules = "library";
  const experiments::RunResult plain = experiments::run_one(c, o);
  c.sensor = "body";
  const experiments::RunResult body = experiments::run_one(c, o);
  // Reflected beams that meet the body return from it: their phantom points differ from the
  // plain run's, so the map does (the first segment of a beam never meets the body, so a room
  // without a mirror maps alike; the sim's own tests check both).
  CHECK((body.wrongly_occupied != plain.wrongly_occupied || body.wrongly_free != plain.wrongly_free));
  c.surface = "diffuse";
  c.sensor = "plain";
  const experiments::RunResult diffuse_plain = experiments::run_one(c, o);
  c.sensor = "body";
  const experiments::RunResult diffuse_body = experiments::run_one(c, o);
  CHECK(diffuse_body.wrongly_occupied == diffuse_plain.wrongly_occupied);
  CHECK(diffuse_body.wrongly_free == diffuse_plain.wrongly_free);
}

TEST_CASE(
    "beam classes are scored against the true paths of the batches the ledger keeps, skipped beams and refused batches "
    "passed over",
    "[experiments][third]") {
  namespace ex = experiments;
  using P = intervox::sim::BeamPath;
  using C = intervox::BeamClass;
  const intervox::Point3 o(0, 0, 0.5);
  const auto beam = [&](double x, bool hit = true) { return intervox::Beam{o, intervox::Point3(x, 1.0, 0.5), hit}; };
  std::deque<ex::LabelledBatch> log;
  log.push_back({{beam(1), beam(2), beam(3, false)}, {P::Direct, P::Reflected, P::NoReturn}});
  log.push_back({{beam(4), beam(5)}, {P::Direct, P::Direct}});  // refused by the ledger
  log.push_back({{beam(6), beam(7), beam(8), beam(9)}, {P::Direct, P::Passed, P::Reflected, P::Direct}});
  const intervox::InsertOptions insert;
  std::deque<intervox::LedgerScan> scans;
  {
    const std::vector<intervox::Beam> b = log[0].beams;
    const std::vector<C> c{C::Trusted, C::Suspect, C::NoReturn};
    scans.emplace_back(b, c, insert);
  }
  {
    const std::vector<intervox::Beam> b = log[2].beams;
    const std::vector<C> c{C::Skipped, C::Suspect, C::Trusted, C::Suspect};  // the first beam leaves no evidence
    scans.emplace_back(b, c, insert);
  }
  const ex::BeamClassScore s = ex::score_beam_classes(scans, log);
  CHECK(s.scans == 2);
  CHECK(s.direct == 2);  // beams 1 and 9 (6 was skipped)
  CHECK(s.direct_suspect == 1);
  CHECK(s.reflected == 2);
  CHECK(s.reflected_suspect == 1);
  CHECK(s.passed == 1);
  CHECK(s.passed_suspect == 1);
  CHECK(s.precision() == Approx(2.0 / 3.0));  // suspect: 9 (direct), 2 (reflected), 7 (passed)
  CHECK(s.recall() == Approx(2.0 / 3.0));     // lying: 2, 7 suspect; 8 trusted
  CHECK(s.direct_share() == Approx(0.5));
  CHECK(s.reflected_share() == Approx(0.5));

  // Nothing suspect, nothing lying: no score.
  CHECK(ex::BeamClassScore{}.precision() == -1.0);
  CHECK(ex::BeamClassScore{}.recall() == -1.0);

  // A ledger scan of beams the log does not hold, and a batch whose paths are missing, are refused.
  std::deque<intervox::LedgerScan> stranger;
  {
    const std::vector<intervox::Beam> b{beam(42)};
    const std::vector<C> c{C::Trusted};
    stranger.emplace_back(b, c, insert);
  }
  CHECK_THROWS_AS(ex::score_beam_classes(stranger, log), intervox::InvalidArgument);
  std::deque<ex::LabelledBatch> short_paths{{{beam(1)}, {}}};
  CHECK_THROWS_AS(ex::score_beam_classes(scans, short_paths), intervox::InvalidArgument);
}

TEST_CASE("an unknown planner, room, rule or sensor, and the mobile robot's rows on the arm, are refused",
          "[experiments][third]") {
  experiments::SweepOptions o;
  o.resolution = 0.2;
  o.max_steps = 1;
  experiments::RunConfig c;  // mobile, diffuse, Bayes
  for (auto change :
       {+[](experiments::RunConfig& r) { r.planner = "greedy"; },
        +[](experiments::RunConfig& r) { r.room = "basement"; }, +[](experiments::RunConfig& r) { r.rules = "ours"; },
        +[](experiments::RunConfig& r) { r.sensor = "sonar"; },
        +[](experiments::RunConfig& r) { r.sensor = "one camera"; }}) {
    experiments::RunConfig bad = c;
    change(bad);
    CHECK_THROWS_AS(experiments::run_one(bad, o), intervox::InvalidArgument);
  }
  experiments::RunConfig arm{"arm",  "part", "interval-mean", "max-entropy", "thesis", "kept", "unknown",
                             "safe", 1,      "unknown"};
  CHECK_THROWS_WITH(experiments::run_one(arm, o), Catch::Contains("the mobile robot's, not the arm's"));
  arm.planner = "plain";
  arm.room = "annex";
  CHECK_THROWS_AS(experiments::run_one(arm, o), intervox::InvalidArgument);
}
