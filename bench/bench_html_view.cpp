// The viewer page of a large map (docs/viewing.md, "Large maps"): the room-frame map of
// bench_raycast.cpp (bench/room_frame.hpp: 5,057,644 observed voxels at 2 cm), all observed voxels
// in the page. Times packing (selection, surface rule, merges) and the whole page (packing, base64,
// file), and writes the pages bench_html_view_<case>.html into the working folder, to be opened
// in a browser (docs/viewing.md gives the Chromium command that times the page until it is ready).
#include <benchmark/benchmark.h>

#include <intervox/intervox.hpp>
#include <intervox/raycast/raycast.hpp>
#include <intervox/view/html_view.hpp>

#include "room_frame.hpp"

#include <cstdio>
#include "bench_main.hpp"

namespace iv = intervox;

namespace {

const iv::BayesGrid& room_map() {
  static const iv::BayesGrid grid = [] {
    iv::BayesGrid g(room_frame::kResolution);
    iv::ScanInserter ins({.max_range = room_frame::kMaxRange, .min_range = 0.0, .threads = 1});
    for (const auto& f : room_frame::frames()) ins.insert_depth_image(g, f.image, room_frame::camera(), f.pose);
    return g;
  }();
  return grid;
}

iv::HtmlViewOptions options(std::size_t max_voxels) {
  iv::HtmlViewOptions o;
  o.voxels = iv::HtmlViewOptions::Voxels::Observed;
  o.max_voxels = max_voxels;
  o.title = "room frame, " + std::to_string(max_voxels) + " voxels at most";
  return o;
}

// Arg: max_voxels (the default 2,000,000, and 6,000,000 so that all 5 M voxels are drawn).
void BM_PackViewVoxels(benchmark::State& state) {
  const auto& grid = room_map();
  const auto o = options(static_cast<std::size_t>(state.range(0)));
  std::size_t drawn = 0;
  for (auto _ : state) {
    const iv::ViewVoxels v = iv::pack_view_voxels(grid, o);
    drawn = v.size_drawn();
    benchmark::DoNotOptimize(v.offsets.data());
  }
  state.counters["observed"] = static_cast<double>(grid.observed_count());
  state.counters["drawn"] = static_cast<double>(drawn);
}

void BM_WriteHtmlView(benchmark::State& state) {
  const auto& grid = room_map();
  const auto o = options(static_cast<std::size_t>(state.range(0)));
  const std::string path = "bench_html_view_" + std::to_string(state.range(0)) + ".html";
  iv::HtmlViewSummary s;
  for (auto _ : state) s = iv::write_html_view(path, grid, o);
  state.counters["drawn"] = static_cast<double>(s.drawn);
  state.counters["MB"] = static_cast<double>(s.bytes) / 1e6;
  state.counters["surface_only"] = s.surface_only;
  state.counters["level"] = s.level;
}

}  // namespace

int main(int argc, char** argv) {
  // A smoke run draws the map of one frame, once per row; otherwise ten frames, three times.
  const bool smoke = bench::has_smoke_flag(argc, argv);
  if (smoke) room_frame::frame_count() = 1;
  const int iterations = smoke ? 1 : 3;
  benchmark::RegisterBenchmark("BM_PackViewVoxels", BM_PackViewVoxels)
      ->Arg(2'000'000)
      ->Arg(6'000'000)
      ->Unit(benchmark::kMillisecond)
      ->Iterations(iterations);
  benchmark::RegisterBenchmark("BM_WriteHtmlView", BM_WriteHtmlView)
      ->Arg(2'000'000)
      ->Arg(6'000'000)
      ->Unit(benchmark::kMillisecond)
      ->Iterations(iterations);
  return bench::run_main(argc, argv);
}
