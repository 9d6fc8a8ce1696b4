// The experiment pipeline on a tiny configuration: every metric computed, every file written.
#include <catch2/catch.hpp>

#include "sweep.hpp"

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <unistd.h>

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
  const auto results = experiments::run_and_write(o);
  REQUIRE(results.size() == 5);
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
    CHECK(r.seconds_total > 0.0);
    CHECK(r.seconds_per_step > 0.0);
    // Conflicts are counted for interval policies only.
    CHECK((r.conflicts >= 0) == (r.config.update != "bayes"));
    if (mobile)
      CHECK(r.completed == (r.known >= experiments::kCompleteFraction && r.termination != "budget" && r.termination != "blocked"));
  }
  CHECK(results.back().config.platform == "arm");
  CHECK(lines(out / "results.csv") == 1 + results.size());
  std::ifstream jf(out / "results.json");
  const auto j = nlohmann::json::parse(jf);
  CHECK(j["runs"].size() == results.size());
  CHECK(j["summary"].size() == 5);
  CHECK(j["summary"][0]["steps"]["n"] == 1);
  CHECK(lines(out / "tables.md") >= 2 * 3 + 5);
  for (const char* group : {"mobile_diffuse_bayes_max-entropy", "mobile_specular_interval-mean_max-entropy"})
    for (const char* kind : {"_map.png", "_state.png", "_width.png", "_table52.png"}) {
      INFO(group << kind);
      CHECK(fs::file_size(out / "figures" / (std::string(group) + kind)) > 100);
    }
  for (const char* kind : {"_state.png", "_width.png", "_table52.png"})
    CHECK(fs::file_size(out / "figures" / (std::string("arm_bottle_interval-mean_max-entropy") + kind)) > 100);
  fs::remove_all(out);
}

TEST_CASE("a sweep gives the same results whatever the number of workers", "[experiments]") {
  const fs::path out = fs::temp_directory_path() / ("intervox_sweep_w_" + std::to_string(::getpid()));
  auto o = tiny(out);
  o.figures = false;
  o.mobile_surfaces = {"specular"};
  o.arm_objects = {};
  o.workers = 1;
  const auto a = experiments::run_sweep(o);
  o.workers = 2;
  const auto b = experiments::run_sweep(o);
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
  const auto results = experiments::run_and_write(o);
  const auto back = experiments::read_csv((out / "results.csv").string());
  REQUIRE(back.size() == results.size());
  CHECK(experiments::tables_markdown(back) == experiments::tables_markdown(results));
  CHECK(back[0].config.group() == results[0].config.group());
  CHECK(back[0].wrongly_free == results[0].wrongly_free);
  std::ofstream(out / "bad.csv") << "header\nmobile,diffuse,bayes\n";
  CHECK_THROWS_AS(experiments::read_csv((out / "bad.csv").string()), intervox::IoError);
  fs::remove_all(out);
}
