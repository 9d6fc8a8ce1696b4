// Explained free space in a file: a round trip keeps every count, the options, the extent and
// what later beams are classed as; corrupt files are refused with a reason; saves are atomic.
#include <intervox/explain/explained_space.hpp>
#include <intervox/grid/named_grids.hpp>
#include <intervox/io/explained_file.hpp>

#include "../common/explained_evidence.hpp"

#include <catch2/catch.hpp>

#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <map>
#include <random>
#include <string>
#include <vector>

namespace iv = intervox;

namespace {
using test::evidence_map;

iv::ExplainedSpace surveyed(std::vector<iv::Beam>* probe) {
  iv::ExplainOptions o;
  o.crossing_tolerance = 0.2;
  o.model.suspect_reliability = 0.05;
  o.no_return_crossing_angle = 35.0;
  iv::VoxelGrid<iv::BayesLogOdds> grid(0.05);
  iv::ExplainedSpace space(grid.geometry(), o);
  iv::InsertOptions io;
  io.max_range = 3.0;
  iv::ScanInserter ins(io);
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int s = 0; s < 5; ++s) {
    std::vector<iv::Beam> beams;
    for (int i = 0; i < 3000; ++i) {
      // Returns on a wall at x = 2, every third one 3 m farther (cut at max range), every
      // eleventh without a return.
      const iv::Point3 on_wall(2.0, 1.2 * u(rng), 0.6 * u(rng));
      const iv::Point3 end = i % 3 == 0 ? iv::Point3(on_wall * 2.5) : on_wall;
      beams.push_back({{0.1 * s, 0.0, 0.0}, end, i % 11 != 0});
    }
    space.insert_beams(ins, grid, std::span<const iv::Beam>(beams));
    if (probe && s == 4) *probe = beams;
  }
  return space;
}
}  // namespace

TEST_CASE("a saved channel loads with every count, its options and its extent, and classes beams alike",
          "[explain][io]") {
  std::vector<iv::Beam> probe;
  const iv::ExplainedSpace a = surveyed(&probe);
  const std::string bytes = iv::save_explained_to_memory(a);
  const iv::ExplainedSpace b = iv::load_explained_from_memory(bytes, "<test>");
  CHECK(evidence_map(a) == evidence_map(b));
  REQUIRE(a.trusted_extent());
  REQUIRE(b.trusted_extent());
  CHECK(a.trusted_extent()->min == b.trusted_extent()->min);
  CHECK(a.trusted_extent()->max == b.trusted_extent()->max);
  CHECK(b.options().crossing_tolerance == 0.2);
  CHECK(b.options().model.suspect_reliability == 0.05);
  CHECK(b.options().no_return_crossing_angle == 35.0);
  iv::InsertOptions io;
  io.max_range = 3.0;
  const auto ca = a.classify(std::span<const iv::Beam>(probe), io);
  const auto cb = b.classify(std::span<const iv::Beam>(probe), io);
  CHECK(ca == cb);
  CHECK(std::count(ca.begin(), ca.end(), iv::BeamClass::NoReturn) > 0);

  const auto dir = std::filesystem::temp_directory_path() / ("intervox_explained_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "space.ivx").string();
  iv::save_explained(path, a);
  CHECK(evidence_map(iv::load_explained(path)) == evidence_map(a));
  std::filesystem::remove_all(dir);
}

TEST_CASE("a file written before the no-return crossing angle existed loads with its default", "[explain][io]") {
  const iv::ExplainedSpace a = surveyed(nullptr);
  const std::string now = iv::save_explained_to_memory(a);
  // The older layout: 11 options (the last, no_return_crossing_angle, left out), a new checksum.
  const std::size_t at = 8 + 4;
  std::string old = now.substr(0, at);
  const std::uint32_t eleven = 11;
  old.append(reinterpret_cast<const char*>(&eleven), 4);
  old += now.substr(at + 4, 11 * 8);
  old += now.substr(at + 4 + 12 * 8, now.size() - 4 - (at + 4 + 12 * 8));
  const std::uint32_t crc = iv::detail::crc32(old);
  for (int i = 0; i < 4; ++i) old.push_back(static_cast<char>((crc >> (8 * i)) & 0xFF));
  const iv::ExplainedSpace b = iv::load_explained_from_memory(old, "<older>");
  CHECK(b.options().no_return_crossing_angle == iv::ExplainOptions{}.no_return_crossing_angle);
  CHECK(b.options().crossing_tolerance == 0.2);
  CHECK(evidence_map(a) == evidence_map(b));
  // Any other count is refused.
  std::string ten = old.substr(0, old.size() - 4);
  const std::uint32_t n10 = 10;
  std::memcpy(&ten[at], &n10, 4);
  const std::uint32_t crc10 = iv::detail::crc32(ten);
  for (int i = 0; i < 4; ++i) ten.push_back(static_cast<char>((crc10 >> (8 * i)) & 0xFF));
  CHECK_THROWS_WITH(iv::load_explained_from_memory(ten, "f"), Catch::Contains("the file holds 10"));
}

TEST_CASE("a corrupt or foreign explained-free-space file is refused with the reason", "[explain][io][errors]") {
  const std::string good = iv::save_explained_to_memory(surveyed(nullptr));
  CHECK_THROWS_WITH(iv::load_explained_from_memory(good.substr(0, 7), "f"), Catch::Contains("f: "));
  CHECK_THROWS_WITH(iv::load_explained_from_memory("IVXGRID" + std::string(1, '\0') + good.substr(8), "f"),
                    Catch::Contains("bad magic"));
  std::string flipped = good;
  flipped[good.size() / 2] = static_cast<char>(flipped[good.size() / 2] ^ 0x40);
  CHECK_THROWS_WITH(iv::load_explained_from_memory(flipped, "f"), Catch::Contains("checksum"));
  CHECK_THROWS_AS(iv::load_explained_from_memory(good.substr(0, good.size() - 9), "f"), iv::IoError);
  // A version this build does not read.
  std::string v2 = good;
  v2[8] = 2;
  CHECK_THROWS_WITH(iv::load_explained_from_memory(v2, "f"), Catch::Contains("version 2"));
  // Invalid options behind a correct checksum.
  std::string bad = good.substr(0, good.size() - 4);
  const double neg = -1.0;
  std::memcpy(&bad[8 + 4 + 4 + 9 * 8], &neg, 8);  // crossing_tolerance
  const std::uint32_t crc = iv::detail::crc32(bad);
  for (int i = 0; i < 4; ++i) bad.push_back(static_cast<char>((crc >> (8 * i)) & 0xFF));
  CHECK_THROWS_WITH(iv::load_explained_from_memory(bad, "f"), Catch::Contains("crossing_tolerance"));
  CHECK_THROWS_AS(iv::load_explained("/nonexistent/intervox/space.ivx"), iv::IoError);
  // A grid file is no explained-free-space file.
  CHECK_THROWS_WITH(iv::load_explained_from_memory(iv::save_grid_to_memory(iv::BayesGrid(0.1)), "g"), Catch::Contains("bad magic"));
}

TEST_CASE("count grids of different geometries or with bounds do not make a channel", "[explain][io][errors]") {
  using CG = iv::ExplainedSpace::CountGrid;
  CHECK_THROWS_WITH(iv::ExplainedSpace(iv::ExplainOptions{}, CG(0.05), CG(0.1), CG(0.05)), Catch::Contains("geometries"));
  CHECK_THROWS_WITH(iv::ExplainedSpace(iv::ExplainOptions{}, CG(0.05), CG(0.05, iv::Bounds{{0, 0, 0}, {1, 1, 1}}), CG(0.05)),
                    Catch::Contains("unbounded"));
  const iv::ExplainedSpace empty(iv::ExplainOptions{}, CG(0.05), CG(0.05), CG(0.05));
  CHECK(!empty.trusted_extent());
  CHECK(empty.size() == 0);
}
