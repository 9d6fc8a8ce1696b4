// The experiment pipeline on a tiny configuration: every metric computed, every file written.
#include <catch2/catch.hpp>

#include "sweep.hpp"

#include <filesystem>
#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>
#include <unistd.h>
#include <intervox/update/interval_update.hpp>

namespace fs = std::filesystem;

namespace {
experiments::SweepOptions tiny(const fs::path& out) {
  experiments::SweepOptions o;
  o.mobile_surfaces = {"diffuse", "specular"};
  o.mobile_updates = {"bayes", "interval-mean"};
  o.utilities = {"max-entropy"};
  o.arm_objects = {"bottle"};
  o.arm_updates = {"interval-mean"};
  o.arm_resolution = 0.02;
  o.arm_max_views = 2;
  o.seeds = 1;
  o.resolution = 0.2;
  o.max_steps = 2;
  o.gain_stride = 8;
  o.workers = 2;
  o.out = out.string();
  o.progress = false;
  return o;
}
std::size_t lines(const fs::path& p) {
  std::ifstream f(p);
  std::size_t n = 0;
  for (std::string s; std::getline(f, s);) ++n;
  return n;
}
}  // namespace

TEST_CASE("a tiny sweep computes every metric and writes every file", "[experiments]") {
  const fs::path out = fs::temp_directory_path() / ("intervox_sweep_" + std::to_string(::getpid()));
  fs::remove_all(out);
  const auto o = tiny(out);
  const auto report = experiments::run_and_write(o);
  const auto& results = report.results;
  REQUIRE(results.size() == 5);
  CHECK(report.ran == 5);
  CHECK(report.failed.empty());
  for (const auto& r : results) {
    INFO(r.config.group());
    const bool mobile = r.config.platform == "mobile";
    CHECK(r.steps >= 1);
    CHECK(r.steps <= (mobile ? o.max_steps : o.arm_max_views));
    CHECK_FALSE(r.termination.empty());
    CHECK(r.termination != "running");
    CHECK(r.known > 0.0);
    CHECK(r.known <= 1.0);
    if (mobile) CHECK(r.area > 1.0);
    CHECK(r.true_occupied > 0);
    CHECK(r.region_voxels > r.true_occupied);
    CHECK(r.config.policies == "thesis");
    if (mobile) {
      CHECK(r.config.floor == "removed");
      CHECK(r.config.gain == "unknown");
      // The detector is scored against the simulator's labels for interval updates only.
      CHECK((r.conflict_truth >= 0) == (r.config.update != "bayes"));
      if (r.conflict_truth >= 0) {
        CHECK(r.conflict_precision >= 0.0);
        CHECK(r.conflict_precision <= 1.0);
        CHECK(r.conflict_recall >= 0.0);
        CHECK(r.conflict_recall <= 1.0);
      }
      CHECK(r.band_voxels > 0);
      CHECK(r.band_voxels < r.region_voxels);
      CHECK(r.band_wrongly_occupied <= r.wrongly_occupied);
      CHECK(r.band_wrongly_free <= r.wrongly_free);
      // Every pose or segment in collision meets some object, and no object more often than that.
      std::size_t most_poses = 0, most_segments = 0, sum_poses = 0, sum_segments = 0;
      for (const auto& c : r.collision_objects) {
        most_poses = std::max(most_poses, c.poses);
        most_segments = std::max(most_segments, c.segments);
        sum_poses += c.poses;
        sum_segments += c.segments;
      }
      CHECK(most_poses <= r.collision_poses);
      CHECK(most_segments <= r.collision_segments);
      CHECK(sum_poses >= r.collision_poses);
      CHECK(sum_segments >= r.collision_segments);
    } else {
      CHECK(r.collision_objects.empty());
      CHECK(r.coverage_curve.size() == static_cast<std::size_t>(r.steps));  // one value per view
      CHECK(r.coverage_curve.back() == Approx(r.known));
    }
    CHECK(r.seconds_total > 0.0);
    CHECK(r.seconds_per_step > 0.0);
    // Conflicts are counted for interval policies only.
    CHECK((r.conflicts >= 0) == (r.config.update != "bayes"));
    if (mobile)
      CHECK(r.completed ==
            (r.known >= experiments::kCompleteFraction && r.termination != "budget" && r.termination != "blocked"));
  }
  CHECK(results.back().config.platform == "arm");
  CHECK(lines(out / "results.csv") == 1 + results.size());
  std::ifstream jf(out / "results.json");
  const auto j = nlohmann::json::parse(jf);
  CHECK(j["runs"].size() == results.size());
  CHECK(j["summary"].size() == 5);
  CHECK(j["summary"][0]["steps"]["n"] == 1);
  CHECK(lines(out / "tables.md") >= 2 * 3 + 5);
  for (const char* group : {"mobile_diffuse_bayes_max-entropy_thesis_removed_unknown_plain",
                            "mobile_specular_interval-mean_max-entropy_thesis_removed_unknown_plain"})
    for (const char* kind : {"_map.png", "_lookaround_map.png", "_state.png", "_width.png", "_table52.png"}) {
      INFO(group << kind);
      CHECK(fs::file_size(out / "figures" / (std::string(group) + kind)) > 100);
    }
  for (const char* kind : {"_state.png", "_width.png", "_table52.png"})
    CHECK(fs::file_size(out / "figures" /
                        (std::string("arm_bottle_interval-mean_max-entropy_thesis_kept_unknown_plain") + kind)) > 100);
  fs::remove_all(out);
}

TEST_CASE("a sweep gives the same results whatever the number of workers", "[experiments]") {
  const fs::path out = fs::temp_directory_path() / ("intervox_sweep_w_" + std::to_string(::getpid()));
  auto o = tiny(out);
  o.figures = false;
  o.mobile_surfaces = {"specular"};
  o.arm_objects = {};
  o.workers = 1;
  const auto a = experiments::run_sweep(o).results;
  o.workers = 2;
  const auto b = experiments::run_sweep(o).results;
  REQUIRE(a.size() == b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    CHECK(a[i].steps == b[i].steps);
    CHECK(a[i].known == b[i].known);
    CHECK(a[i].wrongly_occupied == b[i].wrongly_occupied);
    CHECK(a[i].wrongly_free == b[i].wrongly_free);
    CHECK(a[i].conflicts == b[i].conflicts);
  }
  fs::remove_all(out);
}

TEST_CASE("summaries give the mean and sample standard deviation", "[experiments]") {
  const auto s = experiments::stat({2.0, 4.0, 4.0, 4.0, 5.0, 5.0, 7.0, 9.0});
  CHECK(s.mean == Approx(5.0));
  CHECK(s.sd == Approx(2.138089935));
  CHECK(s.n == 8);
  CHECK(experiments::stat({3.0}).sd == 0.0);
}

TEST_CASE("results read back from the CSV give the same tables", "[experiments]") {
  const fs::path out = fs::temp_directory_path() / ("intervox_sweep_csv_" + std::to_string(::getpid()));
  auto o = tiny(out);
  o.figures = false;
  o.mobile_surfaces = {"diffuse"};
  o.mobile_updates = {"interval-mean"};
  o.arm_objects = {};
  const auto results = experiments::run_and_write(o).results;
  const auto back = experiments::read_csv((out / "results.csv").string());
  REQUIRE(back.size() == results.size());
  CHECK(experiments::tables_markdown(back) == experiments::tables_markdown(results));
  CHECK(back[0].config.group() == results[0].config.group());
  CHECK(back[0].wrongly_free == results[0].wrongly_free);
  std::ofstream(out / "bad.csv") << "header\nmobile,diffuse,bayes\n";
  CHECK_THROWS_AS(experiments::read_csv((out / "bad.csv").string()), intervox::IoError);
  fs::remove_all(out);
}

namespace {
/// The measured columns of a run, without the timing (which differs between runs).
std::string measured(const experiments::RunResult& r) {
  auto copy = r;
  copy.seconds_per_step = copy.seconds_total = 0;
  return experiments::csv_row(copy);
}
}  // namespace

TEST_CASE("shards partition the sweep and their merged results equal one process's", "[experiments][shard]") {
  const fs::path out = fs::temp_directory_path() / ("intervox_sweep_shard_" + std::to_string(::getpid()));
  auto o = tiny(out);
  o.figures = false;
  o.mobile_surfaces = {"specular"};
  o.seeds = 2;
  o.workers = 1;
  const auto all = experiments::sweep_configs(o);
  std::vector<std::string> keys;
  std::vector<experiments::RunResult> merged;
  for (int k = 1; k <= 3; ++k) {
    auto s = o;
    s.shard_index = k;
    s.shard_count = 3;
    s.out = (out / ("shard" + std::to_string(k))).string();
    for (const auto& c : experiments::shard_configs(s)) keys.push_back(c.key());
    const auto part = experiments::run_and_write(s).results;
    const auto back = experiments::read_csv((fs::path(s.out) / "results.csv").string());
    CHECK(back.size() == part.size());
    merged.insert(merged.end(), back.begin(), back.end());
  }
  std::vector<std::string> expected;
  for (const auto& c : all) expected.push_back(c.key());
  std::sort(keys.begin(), keys.end());
  std::sort(expected.begin(), expected.end());
  CHECK(keys == expected);  // every run in exactly one shard
  auto single = o;
  single.out = (out / "single").string();
  experiments::run_and_write(single);
  auto merged_options = o;
  merged_options.out = (out / "merged").string();
  experiments::write_results(merged_options, merged);
  const auto a = experiments::read_csv((out / "single" / "results.csv").string());
  const auto b = experiments::read_csv((out / "merged" / "results.csv").string());
  REQUIRE(a.size() == all.size());
  REQUIRE(b.size() == a.size());
  for (std::size_t i = 0; i < a.size(); ++i) CHECK(measured(a[i]) == measured(b[i]));
  CHECK_THROWS_AS(experiments::parse_shard("0/3", o.shard_index, o.shard_count), intervox::InvalidArgument);
  CHECK_THROWS_AS(experiments::parse_shard("4/3", o.shard_index, o.shard_count), intervox::InvalidArgument);
  CHECK_THROWS_AS(experiments::parse_shard("1-3", o.shard_index, o.shard_count), intervox::InvalidArgument);
  fs::remove_all(out);
}

TEST_CASE("a resumed sweep runs only what is missing and a failed run does not stop the others",
          "[experiments][resume]") {
  const fs::path out = fs::temp_directory_path() / ("intervox_sweep_resume_" + std::to_string(::getpid()));
  fs::remove_all(out);
  auto o = tiny(out);
  o.figures = false;
  o.mobile_surfaces = {"diffuse"};
  o.mobile_updates = {"bayes", "no-such-update", "interval-mean"};
  o.arm_objects = {};
  o.workers = 1;
  const auto first = experiments::run_sweep(o);
  CHECK(first.ran == 2);
  REQUIRE(first.failed.size() == 1);
  CHECK(first.failed[0].find("no-such-update") != std::string::npos);
  // Every finished run is already in results.csv, appended as it finished.
  CHECK(experiments::read_csv((out / "results.csv").string()).size() == 2);
  o.mobile_updates = {"bayes", "interval-mean", "interval-upper"};
  o.resume = true;
  const auto second = experiments::run_sweep(o);
  CHECK(second.resumed == 2);
  CHECK(second.ran == 1);
  REQUIRE(second.results.size() == 3);
  CHECK(second.results[0].config.update == "bayes");
  CHECK(second.results[2].config.update == "interval-upper");
  CHECK(measured(second.results[0]) == measured(first.results[0]));
  // Without resume the old file is kept aside, not lost.
  o.resume = false;
  o.mobile_updates = {"bayes"};
  experiments::run_sweep(o);
  CHECK(experiments::read_csv((out / "results.csv.previous").string()).size() == 3);
  fs::remove_all(out);
}

TEST_CASE("the conflict-aware planner is a condition of its own and skipped for bayes", "[experiments]") {
  experiments::SweepOptions o;
  o.mobile_surfaces = {"specular"};
  o.mobile_updates = {"bayes", "interval-mean"};
  o.utilities = {"max-entropy"};
  o.planners = {"plain", "conflict-aware"};
  o.gains = {"unknown", "all"};
  o.arm_objects = {"part"};
  o.arm_updates = {"bayes", "interval-mean"};
  o.seeds = 1;
  const auto runs = experiments::sweep_configs(o);
  // Each platform: bayes 2 gains x plain; interval-mean 2 gains x 2 planners.
  REQUIRE(runs.size() == 12);
  for (const auto& c : runs) CHECK_FALSE((c.update == "bayes" && c.planner == "conflict-aware"));
  CHECK(runs[5].platform == "mobile");
  CHECK(runs[5].planner == "conflict-aware");
  CHECK(runs.back().platform == "arm");
  CHECK(runs.back().planner == "conflict-aware");
  CHECK(runs.back().group() != runs[runs.size() - 2].group());
}

TEST_CASE("the conflict-aware arm planner is run, and refused for bayes", "[experiments]") {
  const fs::path out = fs::temp_directory_path() / ("intervox_arm_ca_" + std::to_string(::getpid()));
  fs::remove_all(out);
  auto o = tiny(out);
  o.figures = false;
  o.mobile_surfaces = {};
  o.arm_objects = {"part"};
  o.arm_updates = {"interval-mean"};
  o.planners = {"plain", "conflict-aware"};
  const auto report = experiments::run_and_write(o);
  REQUIRE(report.results.size() == 2);
  CHECK(report.failed.empty());
  for (const auto& r : report.results) {
    CHECK(r.config.platform == "arm");
    CHECK(r.coverage_curve.size() == static_cast<std::size_t>(r.steps));
  }
  CHECK(report.results[1].config.planner == "conflict-aware");
  experiments::RunConfig bayes{"arm",     "part",           "bayes", "max-entropy", "thesis", "kept",
                               "unknown", "conflict-aware", 1,       "unknown"};
  CHECK_THROWS_AS(experiments::run_one(bayes, o), intervox::InvalidArgument);
  fs::remove_all(out);
}

TEST_CASE("the first edition's results.csv still loads, with its conditions as defaults", "[experiments][csv]") {
  const auto old = experiments::read_csv(INTERVOX_SOURCE_DIR "/docs/experiments/first-edition/results.csv");
  REQUIRE(old.size() == 400);  // the first edition: 400 runs
  for (const auto& r : old) {
    CHECK(r.config.policies == "clamped");
    CHECK(r.config.floor == "kept");
    CHECK(r.config.gain == "all");
    CHECK(r.config.planner == "plain");
    CHECK(r.config.unobserved == "unknown");
    CHECK(r.conflict_truth == -1);
    CHECK(r.views_to_80 == -1);
    CHECK(r.coverage_curve.empty());
  }
}

TEST_CASE("classifying never-observed space by rule is a condition of the lower and upper rules only",
          "[experiments]") {
  experiments::SweepOptions o;
  o.mobile_surfaces = {"diffuse"};
  o.mobile_updates = {"bayes", "interval-lower", "interval-mean", "interval-upper"};
  o.utilities = {"max-entropy"};
  o.arm_objects = {"part"};
  o.arm_updates = {"bayes", "interval-mean"};
  o.unobserved = {"unknown", "by-rule"};
  o.seeds = 1;
  const auto runs = experiments::sweep_configs(o);
  // mobile: 4 updates "unknown" + lower and upper "by-rule"; arm: 2 updates "unknown" only.
  REQUIRE(runs.size() == 8);
  for (const auto& c : runs)
    if (c.unobserved == "by-rule") CHECK((c.update == "interval-lower" || c.update == "interval-upper"));
  CHECK(runs[1].group() != runs[2].group());  // lower "unknown" and lower "by-rule" are two groups
}

TEST_CASE("with never-observed space classified by rule, the lower rule calls unseen floor free and its errors stay",
          "[experiments]") {
  // The policy a "by-rule" run builds: the preset's parameters with the thesis' classification.
  const auto u = experiments::detail::make_policy<intervox::IntervalUpdate<intervox::LowerState>>("thesis", "by-rule");
  CHECK(u.params().classify_unobserved);
  CHECK(u.params().latch);
  CHECK_FALSE(experiments::detail::make_policy<intervox::IntervalUpdate<intervox::LowerState>>("thesis", "unknown")
                  .params()
                  .classify_unobserved);
  const fs::path out = fs::temp_directory_path() / ("intervox_unobserved_" + std::to_string(::getpid()));
  fs::remove_all(out);
  auto o = tiny(out);
  o.mobile_surfaces = {"diffuse"};
  o.mobile_updates = {"interval-lower"};
  o.arm_objects = {};
  o.max_steps = 0;  // the look-around only: both runs insert the same scans
  o.unobserved = {"unknown", "by-rule"};
  const auto results = experiments::run_and_write(o).results;
  REQUIRE(results.size() == 2);
  const auto& ours = results[0].config.unobserved == "unknown" ? results[0] : results[1];
  const auto& thesis = results[0].config.unobserved == "unknown" ? results[1] : results[0];
  REQUIRE(thesis.config.unobserved == "by-rule");
  INFO("wrongly free: ours " << ours.wrongly_free << ", by rule " << thesis.wrongly_free << "; known: ours "
                             << ours.known << ", by rule " << thesis.known);
  CHECK(thesis.steps == ours.steps);
  // Same observed voxels, and the errors are counted over observed voxels (evaluate_voxels), so
  // they are equal; the never-observed floor columns turn free, so more of the floor is known.
  CHECK(thesis.wrongly_occupied == ours.wrongly_occupied);
  CHECK(thesis.wrongly_free == ours.wrongly_free);
  CHECK(thesis.known > ours.known);
  // The condition survives the CSV.
  const auto back = experiments::read_csv((out / "results.csv").string());
  REQUIRE(back.size() == 2);
  CHECK(back[0].config.unobserved == results[0].config.unobserved);
  CHECK(back[1].config.unobserved == results[1].config.unobserved);
  fs::remove_all(out);
}

TEST_CASE("a floor cut keeps floor returns out of the map and hands them on as confirmed returns", "[experiments]") {
  const auto lab = intervox::sim::make_lab_room();
  const auto rig = intervox::SensorRig::mobile_base();
  const intervox::Pose pose = intervox::planar_pose(lab.start, 0.3);
  const std::vector<intervox::Beam> all = intervox::sim::SimulatedRig(lab.scene, rig, 3)(pose);
  std::vector<intervox::Beam> confirmed;
  experiments::FloorCutSource src{intervox::sim::SimulatedRig(lab.scene, rig, 3), true, 0.05, nullptr,
                                  [&](std::span<const intervox::Beam> b) { confirmed.assign(b.begin(), b.end()); }};
  const std::vector<intervox::Beam> kept = src(pose);
  REQUIRE_FALSE(confirmed.empty());  // knee-height cameras see the floor
  CHECK(kept.size() + confirmed.size() == all.size());
  for (const auto& b : confirmed) CHECK((b.hit && b.end.z() <= 0.05));
  for (const auto& b : kept) CHECK_FALSE((b.hit && b.end.z() <= 0.05));
  // Kept beams are the scan's other beams, in order.
  std::size_t j = 0;
  for (const auto& b : all)
    if (j < kept.size() && b.end == kept[j].end && b.origin == kept[j].origin) ++j;
  CHECK(j == kept.size());
}

TEST_CASE("collisions by object survive results.csv and a malformed field is named", "[experiments][csv]") {
  const fs::path out = fs::temp_directory_path() / ("intervox_sweep_collision_csv_" + std::to_string(::getpid()));
  fs::create_directories(out);
  experiments::RunResult r;
  r.termination = "budget";
  r.collision_poses = 3;
  r.collision_segments = 2;
  r.collision_objects = {{"closet", 3, 1}, {"wall_west", 0, 2}};
  const std::string csv = (out / "results.csv").string();
  experiments::write_csv(csv, {r});
  CHECK(experiments::read_csv(csv).at(0).collision_objects == r.collision_objects);
  r.collision_objects.clear();
  experiments::write_csv(csv, {r});
  CHECK(experiments::read_csv(csv).at(0).collision_objects.empty());
  for (const char* bad : {"closet=3", "closet=3/x", "=1/2", "clo set=1/2", "closet=1/2;", "closet=-1/2"}) {
    std::string text = experiments::csv_row(r);
    const std::string marker = ",3,2,,";  // collision_poses, collision_segments, empty collision_objects
    const std::size_t at = text.find(marker);
    REQUIRE(at != std::string::npos);
    text.replace(at, marker.size(), std::string(",3,2,") + bad + ",");
    {
      std::ofstream f(csv);
      f << experiments::kCsvHeader << "\n" << text << "\n";
    }
    INFO(bad);
    try {
      experiments::read_csv(csv);
      FAIL("no error");
    } catch (const intervox::IoError& e) {
      CHECK_THAT(e.what(), Catch::Contains("collision_objects is '"));
    }
  }
  fs::remove_all(out);
}
