// The credal update policies (imprecise Dirichlet counts, Dempster–Shafer belief) as rows of the
// experiments, with the conflict band counts, on a tiny configuration.
#include <catch2/catch.hpp>

#include "sweep.hpp"

#include <intervox/sim/scenes.hpp>

#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

namespace fs = std::filesystem;

namespace {
experiments::SweepOptions tiny_credal(const fs::path& out) {
  experiments::SweepOptions o;
  o.mobile_surfaces = {"mirror"};
  o.mobile_updates = {"dirichlet-mean", "belief-mean"};
  o.utilities = {"max-entropy"};
  o.planners = {"plain", "conflict-aware"};
  o.arm_objects = {"bottle"};
  o.arm_updates = {"dirichlet-mean", "belief-mean"};
  o.arm_resolution = 0.02;
  o.arm_max_views = 2;
  o.seeds = 1;
  o.resolution = 0.2;
  o.max_steps = 2;
  o.gain_stride = 8;
  o.workers = 2;
  o.figures = false;
  o.progress = false;
  o.out = out.string();
  return o;
}
}  // namespace

TEST_CASE("credal updates run as rows of the sweep, with both planners on both platforms", "[experiments][credal]") {
  const fs::path out = fs::temp_directory_path() / ("intervox_sweep_credal_" + std::to_string(::getpid()));
  fs::remove_all(out);
  const auto o = tiny_credal(out);
  const auto report = experiments::run_and_write(o);
  CHECK(report.failed.empty());
  const auto& results = report.results;
  // Each platform: 2 updates x 2 planners.
  REQUIRE(results.size() == 8);
  int mobile = 0, aware = 0, arm_aware = 0;
  for (const auto& r : results) {
    INFO(r.config.group());
    CHECK(r.steps >= 1);
    CHECK(r.known > 0.0);
    CHECK(r.conflicts >= 0);  // an interval, so the signature count is defined
    if (r.config.platform == "mobile") {
      ++mobile;
      aware += r.config.planner == "conflict-aware";
      REQUIRE(r.conflict_truth >= 0);
      CHECK(r.conflict_precision >= 0.0);
      CHECK(r.conflict_precision <= 1.0);
      CHECK(r.conflict_recall >= 0.0);
      CHECK(r.conflict_recall <= 1.0);
      // The band counts are parts of the totals; the detector's regions are signature voxels
      // without the surface fringe and the isolated ones.
      CHECK(r.signature_band >= 0);
      CHECK(r.signature_band <= r.signature_voxels);
      CHECK(r.flagged_band >= 0);
      CHECK(r.flagged_band <= r.flagged_voxels);
      CHECK(r.flagged_voxels <= r.signature_voxels);
      CHECK(r.flagged_band <= r.signature_band);
      CHECK(r.truth_band >= 0);
      CHECK(r.truth_band <= r.conflict_truth);
    } else {
      arm_aware += r.config.planner == "conflict-aware";
      // The arm has no simulator labels in the sweep: not computed.
      CHECK(r.conflict_truth == -1);
      CHECK(r.signature_voxels == -1);
      CHECK(r.flagged_band == -1);
      CHECK(r.truth_band == -1);
    }
  }
  CHECK(mobile == 4);
  CHECK(aware == 2);
  CHECK(arm_aware == 2);
  // The new columns survive the CSV.
  const auto back = experiments::read_csv((out / "results.csv").string());
  REQUIRE(back.size() == results.size());
  for (std::size_t i = 0; i < back.size(); ++i) {
    CHECK(back[i].config.update == results[i].config.update);
    CHECK(back[i].signature_voxels == results[i].signature_voxels);
    CHECK(back[i].signature_band == results[i].signature_band);
    CHECK(back[i].flagged_voxels == results[i].flagged_voxels);
    CHECK(back[i].flagged_band == results[i].flagged_band);
    CHECK(back[i].truth_band == results[i].truth_band);
  }
  fs::remove_all(out);
}

TEST_CASE("the conflict band spans the closet from behind the wall to half a metre in front", "[experiments][credal]") {
  const auto lab = intervox::sim::make_lab_room({});
  const intervox::Bounds closet = lab.scene.object_bounds(lab.closet);
  const intervox::Bounds band = experiments::detail::conflict_band(closet, 0.05);
  CHECK(band.min.x() == Approx(closet.min.x() - 1.0));
  CHECK(band.max.x() == Approx(closet.max.x() + 0.5));
  CHECK(band.min.y() == closet.min.y());
  CHECK(band.max.y() == closet.max.y());
  CHECK(band.min.z() > 0.05);  // above the floor layer
  CHECK(band.min.z() < 0.051);
  CHECK(band.max.z() == closet.max.z());
}

TEST_CASE("a band count below -1 in results.csv is rejected with its column", "[experiments][credal][csv]") {
  const fs::path out = fs::temp_directory_path() / ("intervox_sweep_credal_csv_" + std::to_string(::getpid()));
  fs::create_directories(out);
  experiments::RunResult r;
  r.config.update = "belief-mean";
  r.termination = "budget";
  r.flagged_band = -2;
  experiments::write_csv((out / "results.csv").string(), {r});
  try {
    experiments::read_csv((out / "results.csv").string());
    FAIL("no error");
  } catch (const intervox::IoError& e) {
    CHECK_THAT(e.what(), Catch::Contains("flagged_band is '-2'"));
  }
  r.flagged_band = 3;
  experiments::write_csv((out / "results.csv").string(), {r});
  CHECK(experiments::read_csv((out / "results.csv").string()).at(0).flagged_band == 3);
  fs::remove_all(out);
}
