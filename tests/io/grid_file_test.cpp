#include <catch2/catch.hpp>

#include <filesystem>
#include <string>

#include "grid_types.hpp"
#include "intervox/io/grid_file.hpp"
#include "io_test_util.hpp"

using namespace intervox;

namespace {

template <class A, class B>
void require_same_voxels(const A& a, const B& b) {
  std::size_t n = 0;
  a.for_each_observed([&](const Key& k, const typename A::Cell& c) {
    ++n;
    REQUIRE(same_bits(c, b.cell(k)));
  });
  REQUIRE(n == b.observed_count());
}

using SparseBayes = VoxelGrid<BayesLogOdds, Entropy, SparseStorage>;
using DenseBayes = VoxelGrid<BayesLogOdds, Entropy, DenseStorage>;
using SparseMean = VoxelGrid<IntervalUpdate<MeanState>, MaxEntropy, SparseStorage>;

}  // namespace

TEMPLATE_TEST_CASE("a saved grid loads back with the same voxels, parameters and geometry", "[io][grid_file]",
                   IO_ALL_GRIDS) {
  using G = TestType;
  const TempDir dir;
  auto params = typename G::UpdateType{}.params();
  params.p_hit = 0.8;
  params.latch = GENERATE(false, true);
  G grid = make_test_grid<G>(typename G::UpdateType(params));
  fill_randomly(grid, 600, 7);
  REQUIRE(grid.observed_count() > 100);

  const std::string path = dir.file("map.ivx");
  save_grid(path, grid);
  const G back = load_grid<G>(path);
  CHECK(back.update_policy() == grid.update_policy());
  CHECK(back.geometry() == grid.geometry());
  CHECK(back.key_box() == grid.key_box());
  require_same_voxels(grid, back);
  CHECK(back.counts().occupied == grid.counts().occupied);

  const GridFileInfo info = read_grid_file_info(path);
  CHECK(info.update_policy == G::UpdateType::kName);
  CHECK(info.storage == G::StorageType::kName);
  CHECK(info.voxel_count == grid.observed_count());
}

TEMPLATE_TEST_CASE("a grid with a shifted origin and no observations round-trips", "[io][grid_file]", IO_ALL_GRIDS) {
  using G = TestType;
  const GridGeometry geometry(0.05, Point3(0.3, -2.0, 1.25));
  const Bounds b{Point3(0, -2, 1), Point3(1, -1, 2)};
  const G grid(geometry, G::StorageType::kBounded ? std::optional<Bounds>(b) : std::nullopt);
  const G back = load_grid_from_memory<G>(save_grid_to_memory(grid));
  CHECK(back.geometry() == geometry);
  CHECK(back.key_box() == grid.key_box());
  CHECK(back.observed_count() == 0);
}

TEST_CASE("a sparse grid loads into a dense grid of the same policy and back", "[io][grid_file]") {
  SparseBayes sparse(0.1);
  fill_randomly(sparse, 300, 3);
  const DenseBayes dense = load_grid_from_memory<DenseBayes>(save_grid_to_memory(sparse));
  require_same_voxels(sparse, dense);
  // The dense grid covers exactly the stored voxels.
  KeyBox b{Key{10, 10, 10}, Key{-10, -10, -10}};
  sparse.for_each_observed([&](const Key& k, float) {
    for (int a = 0; a < 3; ++a) {
      b.min[a] = std::min(b.min[a], k[a]);
      b.max[a] = std::max(b.max[a], k[a]);
    }
  });
  CHECK(dense.key_box() == b);
  const SparseBayes again = load_grid_from_memory<SparseBayes>(save_grid_to_memory(dense));
  require_same_voxels(dense, again);
  CHECK(again.key_box() == b);  // the dense grid's bounds travel with the file
}

TEST_CASE("an empty unbounded grid cannot be loaded into a dense grid", "[io][grid_file]") {
  const SparseBayes empty(0.1);
  CHECK_THROWS_AS(load_grid_from_memory<DenseBayes>(save_grid_to_memory(empty)), IoError);
}

TEST_CASE("loading a file of another policy names both policies", "[io][grid_file]") {
  SparseBayes bayes(0.1);
  fill_randomly(bayes, 20, 1);
  const std::string bytes = save_grid_to_memory(bayes);
  CHECK_THROWS_WITH(load_grid_from_memory<SparseMean>(bytes, "map.ivx"),
                    Catch::Contains("'bayes'") && Catch::Contains("'interval-mean'") && Catch::Contains("map.ivx"));
  using SparseLower = VoxelGrid<IntervalUpdate<LowerState>, MaxEntropy, SparseStorage>;
  SparseMean mean(0.1);
  CHECK_THROWS_AS(load_grid_from_memory<SparseLower>(save_grid_to_memory(mean)), IoError);
}

TEST_CASE("every truncation of a grid file is reported as an error", "[io][grid_file]") {
  SparseMean grid(0.1);
  fill_randomly(grid, 40, 5);
  const std::string bytes = save_grid_to_memory(grid);
  for (std::size_t n = 0; n < bytes.size(); ++n) {
    INFO("length " << n);
    CHECK_THROWS_AS(load_grid_from_memory<SparseMean>(std::string_view(bytes).substr(0, n)), IoError);
  }
  CHECK_THROWS_WITH(load_grid_from_memory<SparseMean>(std::string_view(bytes).substr(0, bytes.size() - 13)),
                    Catch::Contains("truncated"));
}

TEST_CASE("any flipped bit in a grid file is reported as an error", "[io][grid_file]") {
  SparseBayes grid(0.1);
  fill_randomly(grid, 30, 9);
  const std::string bytes = save_grid_to_memory(grid);
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    std::string bad = bytes;
    bad[i] = static_cast<char>(bad[i] ^ (1 << (i % 8)));
    INFO("byte " << i);
    CHECK_THROWS_AS(load_grid_from_memory<SparseBayes>(bad), IoError);
  }
  std::string bad = bytes;
  bad[bytes.size() / 2] = static_cast<char>(bad[bytes.size() / 2] ^ 0x10);
  CHECK_THROWS_WITH(load_grid_from_memory<SparseBayes>(bad), Catch::Contains("checksum"));
}

TEST_CASE("a corrupt voxel count is refused before anything is allocated", "[io][grid_file]") {
  const SparseBayes grid(0.1);
  std::string bytes = save_grid_to_memory(grid);
  // The voxel count is the 8 bytes before the 4-byte checksum of an empty grid.
  const std::size_t at = bytes.size() - 12;
  for (int i = 0; i < 8; ++i) bytes[at + static_cast<std::size_t>(i)] = static_cast<char>(0xFF);
  CHECK_THROWS_WITH(load_grid_from_memory<SparseBayes>(bytes), Catch::Contains("announces"));
}

TEST_CASE("a newer format version and a foreign file are named as such", "[io][grid_file]") {
  const SparseBayes grid(0.1);
  std::string bytes = save_grid_to_memory(grid);
  bytes[8] = 9;
  CHECK_THROWS_WITH(load_grid_from_memory<SparseBayes>(bytes), Catch::Contains("version 9"));
  CHECK_THROWS_WITH(load_grid_from_memory<SparseBayes>("# Octomap OcTree binary file\n"),
                    Catch::Contains("not an Intervox grid file"));
  CHECK_THROWS_AS(load_grid<SparseBayes>("/nonexistent/dir/map.ivx"), IoError);
}

TEST_CASE("a failed save leaves the previous file in place", "[io][grid_file]") {
  const TempDir dir;
  SparseBayes grid(0.1);
  fill_randomly(grid, 50, 2);
  const std::string path = dir.file("map.ivx");
  save_grid(path, grid);
  const std::string good = read_all(path);
  CHECK_THROWS(detail::write_file_atomically(path, [](std::FILE* f) {
    std::fputs("half a file", f);
    throw IoError("simulated failure in the middle of a write");
  }));
  CHECK(read_all(path) == good);
  CHECK(count_files(dir.path()) == 1);
  // A path whose target is a directory cannot be replaced: error, directory untouched.
  std::filesystem::create_directory(dir.file("adir"));
  CHECK_THROWS_AS(save_grid(dir.file("adir"), grid), IoError);
  CHECK(std::filesystem::is_directory(dir.file("adir")));
  CHECK(count_files(dir.path()) == 2);
}
