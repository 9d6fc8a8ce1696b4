// Explained free space in a file: a round trip keeps every count, the options, the extent, the
// mirrors and what later beams are classed as; corrupt files are refused with a reason; saves are atomic.
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
  o.returned_crossing_inside = true;
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

// A file's bytes without their checksum, sealed with a new one.
std::string resealed(std::string body) {
  const std::uint32_t c = iv::detail::crc32(body);
  for (int i = 0; i < 4; ++i) body.push_back(static_cast<char>((c >> (8 * i)) & 0xFF));
  return body;
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
  CHECK(b.options().returned_crossing_inside);
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

TEST_CASE("a saved channel keeps its mirrors, and beams through them stay suspect after loading", "[explain][io]") {
  std::vector<iv::Beam> probe;
  iv::ExplainedSpace a = surveyed(&probe);
  iv::InsertOptions io;
  io.max_range = 3.0;
  const auto before = a.classify(std::span<const iv::Beam>(probe), io);
  // Two mirrors in different planes across the beams to the wall at x = 2 (origins x <= 0.4).
  iv::PlanePatch m1;
  m1.center = {1.0, 0.3, 0.0};
  m1.normal = iv::Point3::UnitX();
  m1.axis_u = iv::Point3::UnitY();
  m1.half_u = m1.half_v = 0.25;
  iv::PlanePatch m2 = m1;
  m2.center = {1.5, -0.5, 0.1};
  m2.normal = iv::Point3(1, 1, 0).normalized();
  m2.axis_u = iv::PlanePatch::floor_axis(m2.normal);
  m2.half_u = 0.2;
  m2.half_v = 0.15;
  a.add_mirror(m1);
  a.add_mirror(m2);
  REQUIRE(a.mirrors().size() == 2);
  const iv::ExplainedSpace b = iv::load_explained_from_memory(iv::save_explained_to_memory(a), "<test>");
  REQUIRE(b.mirrors().size() == 2);
  for (std::size_t i = 0; i < 2; ++i) {
    CHECK(b.mirrors()[i].center == a.mirrors()[i].center);
    CHECK(b.mirrors()[i].normal == a.mirrors()[i].normal);
    CHECK(b.mirrors()[i].axis_u == a.mirrors()[i].axis_u);
    CHECK(b.mirrors()[i].half_u == a.mirrors()[i].half_u);
    CHECK(b.mirrors()[i].half_v == a.mirrors()[i].half_v);
  }
  CHECK(evidence_map(a) == evidence_map(b));
  const auto ca = a.classify(std::span<const iv::Beam>(probe), io);
  const auto cb = b.classify(std::span<const iv::Beam>(probe), io);
  CHECK(ca == cb);
  // The mirrors matter: more of the probe's beams are suspect with them than before.
  CHECK(std::count(ca.begin(), ca.end(), iv::BeamClass::Suspect) >
        std::count(before.begin(), before.end(), iv::BeamClass::Suspect));
  const iv::Key on = a.geometry().key(iv::Point3(1.0, 0.3, 0.0));
  CHECK(a.on_mirror(on));
  CHECK(b.on_mirror(on));
  CHECK(b.state(on) == iv::ExplainedState::Occupied);
}

TEST_CASE("a file written before the no-return crossing angle existed loads with its default", "[explain][io]") {
  const iv::ExplainedSpace a = surveyed(nullptr);
  const std::string now = iv::save_explained_to_memory(a);
  // The oldest layout: version 1 (no mirrors), 11 options (the last, no_return_crossing_angle,
  // left out), a new checksum.
  const std::size_t at = 8 + 4;
  std::string old = now.substr(0, 8);
  const std::uint32_t one = 1, eleven = 11;
  old.append(reinterpret_cast<const char*>(&one), 4);
  old.append(reinterpret_cast<const char*>(&eleven), 4);
  old += now.substr(at + 4, 11 * 8);
  old += now.substr(at + 4 + 14 * 8,
                    now.size() - 8 - (at + 4 + 14 * 8));  // without min_lying_misses and the mirror count (0)
  old = resealed(old);
  const iv::ExplainedSpace b = iv::load_explained_from_memory(old, "<older>");
  CHECK(b.options().no_return_crossing_angle == iv::ExplainOptions{}.no_return_crossing_angle);
  CHECK(b.options().crossing_tolerance == 0.2);
  CHECK(evidence_map(a) == evidence_map(b));
  CHECK(b.mirrors().empty());
  // Any other count is refused.
  std::string ten = old.substr(0, old.size() - 4);
  const std::uint32_t n10 = 10;
  std::memcpy(&ten[at], &n10, 4);
  CHECK_THROWS_WITH(iv::load_explained_from_memory(resealed(ten), "f"), Catch::Contains("the file holds 10"));
}

TEST_CASE("a file written before the inside rule for returned beams existed loads with its default", "[explain][io]") {
  const iv::ExplainedSpace a = surveyed(nullptr);
  const std::string now = iv::save_explained_to_memory(a);
  // Version 2 with 13 options (the last, returned_crossing_inside, left out), a new checksum.
  const std::size_t at = 8 + 4;
  std::string old = now.substr(0, at);
  const std::uint32_t thirteen = 13;
  old.append(reinterpret_cast<const char*>(&thirteen), 4);
  old += now.substr(at + 4, 13 * 8);
  old += now.substr(at + 4 + 14 * 8, now.size() - 4 - (at + 4 + 14 * 8));
  old = resealed(old);
  const iv::ExplainedSpace b = iv::load_explained_from_memory(old, "<older>");
  CHECK(b.options().returned_crossing_inside == iv::ExplainOptions{}.returned_crossing_inside);
  CHECK(b.options().no_return_crossing_angle == 35.0);
  CHECK(evidence_map(a) == evidence_map(b));
  // A value other than 0 or 1 is refused.
  std::string bad = now.substr(0, now.size() - 4);
  const double half = 0.5;
  std::memcpy(&bad[at + 4 + 13 * 8], &half, 8);
  CHECK_THROWS_WITH(iv::load_explained_from_memory(resealed(bad), "f"), Catch::Contains("returned_crossing_inside"));
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
  std::string v3 = good;
  v3[8] = 3;
  CHECK_THROWS_WITH(iv::load_explained_from_memory(v3, "f"), Catch::Contains("version 3"));
  // A mirror that is no rectangle in a plane, and a mirror count beyond the bytes, behind a
  // correct checksum.
  {
    iv::ExplainedSpace with = surveyed(nullptr);
    iv::PlanePatch m;
    m.center = {1.0, 0.0, 0.0};
    m.half_u = m.half_v = 0.1;
    with.add_mirror(m);
    const std::string bytes = iv::save_explained_to_memory(with);
    std::string body = bytes.substr(0, bytes.size() - 4);
    const double longer = 2.0;
    std::memcpy(&body[body.size() - 88 + 3 * 8], &longer, 8);  // the normal's x: (2, 0, 0)
    CHECK_THROWS_WITH(iv::load_explained_from_memory(resealed(body), "f"), Catch::Contains("invalid mirror 0"));
    body = bytes.substr(0, bytes.size() - 4);
    const std::uint32_t many = 1000;
    std::memcpy(&body[body.size() - 88 - 4], &many, 4);
    CHECK_THROWS_WITH(iv::load_explained_from_memory(resealed(body), "f"), Catch::Contains("1000 mirrors announced"));
  }
  // Invalid options behind a correct checksum.
  std::string bad = good.substr(0, good.size() - 4);
  const double neg = -1.0;
  std::memcpy(&bad[8 + 4 + 4 + 9 * 8], &neg, 8);  // crossing_tolerance
  CHECK_THROWS_WITH(iv::load_explained_from_memory(resealed(bad), "f"), Catch::Contains("crossing_tolerance"));
  CHECK_THROWS_AS(iv::load_explained("/nonexistent/intervox/space.ivx"), iv::IoError);
  // A grid file is no explained-free-space file.
  CHECK_THROWS_WITH(iv::load_explained_from_memory(iv::save_grid_to_memory(iv::BayesGrid(0.1)), "g"),
                    Catch::Contains("bad magic"));
}

TEST_CASE("a file with a fourth count grid is refused as one, not read as a count of mirrors",
          "[explain][io][errors]") {
  const std::string good = iv::save_explained_to_memory(surveyed(nullptr));
  // magic, version, option count and 14 options, the extent (flag and six i32), three grids.
  std::size_t at = 8 + 4 + 4 + 14 * 8;
  REQUIRE(good[at] == 1);
  at += 1 + 24;
  std::size_t last = at;
  for (int g = 0; g < 3; ++g) {
    std::uint64_t size = 0;
    std::memcpy(&size, &good[at], 8);
    last = at;
    at += 8 + size;
  }
  const std::string fourth = good.substr(last, at - last);  // the no-return grid again, with its size
  const std::string body = good.substr(0, at) + fourth + good.substr(at, good.size() - 4 - at);
  CHECK_THROWS_WITH(iv::load_explained_from_memory(resealed(body), "f"), Catch::Contains("f: ") &&
                                                                             Catch::Contains("a fourth count grid") &&
                                                                             !Catch::Contains("mirrors announced"));
  // Fewer mirror bytes than the count says is still named by the count.
  std::string cut = good.substr(0, good.size() - 4);
  const std::uint32_t two = 2;
  std::memcpy(&cut[at], &two, 4);
  CHECK_THROWS_WITH(iv::load_explained_from_memory(resealed(cut), "f"), Catch::Contains("2 mirrors announced") &&
                                                                            Catch::Contains("176 bytes") &&
                                                                            Catch::Contains("0 bytes"));
}

TEST_CASE("count grids of different geometries or with bounds do not make a channel", "[explain][io][errors]") {
  using CG = iv::ExplainedSpace::CountGrid;
  CHECK_THROWS_WITH(iv::ExplainedSpace(iv::ExplainOptions{}, CG(0.05), CG(0.1), CG(0.05)),
                    Catch::Contains("geometries"));
  CHECK_THROWS_WITH(
      iv::ExplainedSpace(iv::ExplainOptions{}, CG(0.05), CG(0.05, iv::Bounds{{0, 0, 0}, {1, 1, 1}}), CG(0.05)),
      Catch::Contains("unbounded"));
  const iv::ExplainedSpace empty(iv::ExplainOptions{}, CG(0.05), CG(0.05), CG(0.05));
  CHECK(!empty.trusted_extent());
  CHECK(empty.size() == 0);
}
