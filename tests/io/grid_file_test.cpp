#include <catch2/catch.hpp>

#include <cstdint>
#include <filesystem>
#include <string>

#include "grid_types.hpp"
#include <intervox/io/grid_file.hpp>
#include <intervox/update/bayes_log_odds.hpp>
#include <intervox/update/interval_update.hpp>
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
using DenseMean = VoxelGrid<IntervalUpdate<MeanState>, Entropy, DenseStorage>;

constexpr std::uint64_t kGiB = std::uint64_t{1} << 30;

/// A sparse interval grid bounded to keys [0, 1624]^3 (nothing allocated) with one voxel: as a
/// dense grid its box holds 1625^3 cells, 32 GiB.
SparseMean huge_box_grid() {
  const GridGeometry g(0.1);
  SparseMean grid(g, Bounds{g.center(Key{0, 0, 0}), g.center(Key{1624, 1624, 1624})});
  grid.update(Key{3, 4, 5}, Observation::Hit);
  REQUIRE(grid.key_box()->volume() == std::int64_t{1625} * 1625 * 1625);
  return grid;
}

/// An unbounded interval grid with two voxels 1,624 apart on every axis: the smallest dense box
/// around them is again 32 GiB.
SparseMean far_apart_grid() {
  SparseMean grid(0.1);
  grid.update(Key{-812, -812, -812}, Observation::Hit);
  grid.update(Key{812, 812, 812}, Observation::Miss);
  return grid;
}

/// Loads \p bytes into a dense interval grid in a child limited to 1 GiB of address space.
int load_dense_capped(const std::string& bytes, const GridLoadOptions& options, const std::string& expected) {
  return run_with_address_limit(kGiB, [&] {
    return classify_load([&] { (void)load_grid_from_memory<DenseMean>(bytes, "crafted.ivx", options); }, expected);
  });
}

}  // namespace

TEMPLATE_TEST_CASE("a saved grid loads back with the same voxels, parameters and geometry", "[io][grid_file]",
                   INTERVOX_TEST_GRIDS) {
  using G = TestType;
  const TempDir dir;
  auto params = typename G::UpdateType{}.params();
  const bool variant = GENERATE(false, true);
  // Parameters other than the defaults, so that the file must carry them.
  if constexpr (requires { params.latch; }) {
    params.p_hit = 0.8;
    params.latch = variant;
    if constexpr (requires { params.classify_unobserved; }) params.classify_unobserved = !variant;
  } else if constexpr (requires { params.prior_strength; }) {  // imprecise Dirichlet
    params.prior_strength = 3.5;
    params.forgetting = variant ? intervox::DirichletForgetting::HalveAtMax : intervox::DirichletForgetting::Saturate;
  } else {  // Dempster–Shafer
    params.hit_support = 0.7;
    params.combination = variant ? intervox::BeliefCombination::Conjunctive : intervox::BeliefCombination::Dempster;
  }
  G grid = make_test_grid<G>(typename G::UpdateType(params));
  fill_randomly(grid, 600, 7);
  REQUIRE(grid.observed_count() > 100);

  const std::string path = dir.file("map.ivx");
  save_grid(path, grid);
  const G back = load_grid<G>(path);
  CHECK(back.update_policy() == grid.update_policy());
  CHECK(back.geometry() == grid.geometry());
  CHECK(back.key_box() == grid.key_box());
  CHECK(back.key_box().has_value() == test::kConstructBounded<G>);
  require_same_voxels(grid, back);
  CHECK(back.counts().occupied == grid.counts().occupied);

  const GridFileInfo info = read_grid_file_info(path);
  CHECK(info.update_policy == G::UpdateType::kName);
  CHECK(info.storage == G::StorageType::kName);
  CHECK(info.voxel_count == grid.observed_count());
}

TEMPLATE_TEST_CASE("a grid with a shifted origin and no observations round-trips", "[io][grid_file]",
                   INTERVOX_TEST_GRIDS) {
  using G = TestType;
  const GridGeometry geometry(0.05, Point3(0.3, -2.0, 1.25));
  const Bounds b{Point3(0, -2, 1), Point3(1, -1, 2)};
  const G grid(geometry, test::kConstructBounded<G> ? std::optional<Bounds>(b) : std::nullopt);
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
  // Version 1: the voxel count is the 8 bytes before the 4-byte checksum of an empty grid.
  std::string bytes = save_grid_to_memory(grid, GridSaveOptions{1, 0});
  std::size_t at = bytes.size() - 12;
  for (int i = 0; i < 8; ++i) bytes[at + static_cast<std::size_t>(i)] = static_cast<char>(0xFF);
  CHECK_THROWS_WITH(load_grid_from_memory<SparseBayes>(bytes), Catch::Contains("announces"));
  // Version 2: the voxel count precedes the 25 bytes of block count, encoding and body sizes.
  bytes = save_grid_to_memory(grid);
  at = bytes.size() - 4 - 25 - 8;
  for (int i = 0; i < 8; ++i) bytes[at + static_cast<std::size_t>(i)] = static_cast<char>(0xFF);
  CHECK_THROWS_WITH(load_grid_from_memory<SparseBayes>(bytes), Catch::Contains("corrupt"));
  // ... and the body size: more than the file holds.
  bytes = save_grid_to_memory(grid);
  at = bytes.size() - 4 - read_grid_file_info_from_memory(bytes).stored_bytes - 8;
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

TEST_CASE("a tiny grid file whose key box needs gigabytes as a dense grid is refused by the load budget",
          "[io][grid_file][budget]") {
  for (const std::uint32_t version : {1u, 2u}) {
    INFO("format version " << version);
    const std::string bytes = save_grid_to_memory(huge_box_grid(), GridSaveOptions{version, 9});
    CHECK(bytes.size() < 300);
    const int outcome = load_dense_capped(bytes, {}, "load budget");
    CHECK(outcome == kExpectedError);
    if (outcome == kExpectedError) {  // safe to load in this process: refused before allocating
      CHECK_THROWS_WITH(load_grid_from_memory<DenseMean>(bytes, "crafted.ivx"),
                        Catch::Contains("crafted.ivx") && Catch::Contains("34328125000 bytes") &&
                            Catch::Contains("GridLoadOptions::max_bytes"));
    }
    // Into a sparse grid the same file costs one block.
    CHECK(load_grid_from_memory<SparseMean>(bytes).observed_count() == 1);
  }
}

TEST_CASE("a tiny grid file whose key box volume wraps 64 bits is refused as a dense grid, never overruns it",
          "[io][grid_file][budget]") {
  // Keys [-2^23, 2^23) x [-2^23, 2^23) x [0, 2^16): 2^64 voxels, which a 64-bit product wraps to 0,
  // so an unchecked loader builds an empty dense array and writes the voxel past its end.
  const GridGeometry g(0.1);
  const Key lo{-kKeyLimit, -kKeyLimit, 0}, hi{kKeyLimit - 1, kKeyLimit - 1, (1 << 16) - 1};
  SparseBayes grid(g, Bounds{g.center(lo), g.center(hi)});
  REQUIRE(grid.key_box() == KeyBox{lo, hi});
  grid.update(Key{3, 4, 5}, Observation::Hit);
  for (const std::uint32_t version : {1u, 2u}) {
    INFO("format version " << version);
    const std::string bytes = save_grid_to_memory(grid, GridSaveOptions{version, 9});
    CHECK(bytes.size() < 300);
    const int outcome = run_with_address_limit(kGiB, [&] {
      return classify_load([&] { (void)load_grid_from_memory<DenseBayes>(bytes, "wraps.ivx"); }, "load budget");
    });
    REQUIRE(outcome == kExpectedError);
    CHECK_THROWS_AS(load_grid_from_memory<DenseBayes>(bytes, "wraps.ivx"), IoError);
    // Even with the budget lifted the dense grid is refused (IoError, not a crash).
    CHECK_THROWS_WITH(load_grid_from_memory<DenseBayes>(bytes, "wraps.ivx", GridLoadOptions{~std::uint64_t{0}}),
                      Catch::Contains("wraps.ivx") && Catch::Contains("cannot create the grid"));
    CHECK(load_grid_from_memory<SparseBayes>(bytes).observed_count() == 1);
  }
}

TEST_CASE("a tiny unbounded grid file whose voxels lie far apart is refused as a dense grid by the load budget",
          "[io][grid_file][budget]") {
  for (const std::uint32_t version : {1u, 2u}) {
    INFO("format version " << version);
    const std::string bytes = save_grid_to_memory(far_apart_grid(), GridSaveOptions{version, 9});
    CHECK(bytes.size() < 300);
    CHECK(load_dense_capped(bytes, {}, "load budget") == kExpectedError);
    CHECK(load_grid_from_memory<SparseMean>(bytes).observed_count() == 2);
  }
}

TEST_CASE("the load budget can be lowered and raised through the load options", "[io][grid_file][budget]") {
  SparseBayes grid(0.1);
  for (int i = 0; i < 4; ++i) grid.update(Key{i * 8, 0, 0}, Observation::Hit);  // four blocks
  for (const std::uint32_t version : {1u, 2u}) {
    INFO("format version " << version);
    const std::string bytes = save_grid_to_memory(grid, GridSaveOptions{version, 9});
    const std::uint64_t four_blocks = 4 * detail::sparse_block_bytes<float>();
    CHECK_THROWS_WITH(load_grid_from_memory<SparseBayes>(bytes, "m.ivx", GridLoadOptions{four_blocks - 1}),
                      Catch::Contains("load budget"));
    CHECK(load_grid_from_memory<SparseBayes>(bytes, "m.ivx", GridLoadOptions{four_blocks}).observed_count() == 4);
    // As a dense grid: a box of 25 x 1 x 1 voxels of 4 bytes.
    CHECK_THROWS_WITH(load_grid_from_memory<DenseBayes>(bytes, "m.ivx", GridLoadOptions{99}),
                      Catch::Contains("load budget"));
    CHECK(load_grid_from_memory<DenseBayes>(bytes, "m.ivx", GridLoadOptions{100}).observed_count() == 4);
  }
}

#ifndef INTERVOX_TEST_SANITIZED
TEST_CASE("an allocation failure while loading is reported as IoError", "[io][grid_file][budget]") {
  // With the budget lifted, the 32 GiB dense box cannot be allocated under a 1 GiB address space.
  const std::string bytes = save_grid_to_memory(huge_box_grid());
  CHECK(load_dense_capped(bytes, GridLoadOptions{~std::uint64_t{0}}, "out of memory") == kExpectedError);
}
#endif

TEST_CASE("a version 1 file written before the format change loads to the same grid", "[io][grid_file]") {
  const std::string dir = std::string(INTERVOX_IO_TEST_DATA) + "/grid_v1/";
  // The files were written by the version 1 writer from these grids (see tests/io/data/grid_v1/README).
  auto bayes = make_test_grid<SparseBayes>();
  fill_randomly(bayes, 600, 7);
  auto mean = make_test_grid<DenseMean>();
  fill_randomly(mean, 600, 8);

  CHECK(read_grid_file_info(dir + "v1_bayes_sparse.ivx").version == 1);
  const auto bayes_back = load_grid<SparseBayes>(dir + "v1_bayes_sparse.ivx");
  require_same_voxels(bayes, bayes_back);
  CHECK(bayes_back.update_policy() == bayes.update_policy());
  const auto mean_back = load_grid<DenseMean>(dir + "v1_interval_mean_dense.ivx");
  require_same_voxels(mean, mean_back);
  CHECK(mean_back.key_box() == mean.key_box());
  // The version 1 writer is kept: it still writes these bytes.
  CHECK(save_grid_to_memory(bayes, GridSaveOptions{1, 0}) == read_all(dir + "v1_bayes_sparse.ivx"));
  CHECK(save_grid_to_memory(mean, GridSaveOptions{1, 0}) == read_all(dir + "v1_interval_mean_dense.ivx"));
}

TEST_CASE("version 2 stores runs of equal cells once and compresses them", "[io][grid_file]") {
  SparseBayes grid(0.05, BayesLogOdds::octomap());
  // A 40^3 free room (clamped cells) with a few hundred noisy voxels.
  for (int z = 0; z < 40; ++z)
    for (int y = 0; y < 40; ++y)
      for (int x = 0; x < 40; ++x)
        for (int i = 0; i < 30; ++i) grid.update(Key{x, y, z}, Observation::Miss);
  fill_randomly(grid, 400, 3);
  const std::string v1 = save_grid_to_memory(grid, GridSaveOptions{1, 0});
  const std::string stored = save_grid_to_memory(grid, GridSaveOptions{2, 0});
  const std::string packed = save_grid_to_memory(grid);
  CHECK(read_grid_file_info_from_memory(packed).version == 2);
  CHECK(read_grid_file_info_from_memory(packed).compression == 1);
  CHECK(read_grid_file_info_from_memory(stored).compression == 0);
  CHECK(stored.size() * 5 < v1.size());
  CHECK(packed.size() * 50 < v1.size());
  require_same_voxels(grid, load_grid_from_memory<SparseBayes>(stored));
  require_same_voxels(grid, load_grid_from_memory<SparseBayes>(packed));
  CHECK_THROWS_AS(save_grid_to_memory(grid, GridSaveOptions{3, 9}), InvalidArgument);
  CHECK_THROWS_AS(save_grid_to_memory(grid, GridSaveOptions{2, 20}), InvalidArgument);
}

TEST_CASE("a corrupt body behind a valid checksum is reported, never crashes", "[io][grid_file]") {
  SparseMean grid(0.1);
  fill_randomly(grid, 60, 12);
  for (const int level : {0, 3}) {
    INFO("compression level " << level);
    const std::string bytes = save_grid_to_memory(grid, GridSaveOptions{2, level});
    const std::size_t body_at = bytes.size() - 4 - read_grid_file_info_from_memory(bytes).stored_bytes;
    std::size_t rejected = 0;
    for (std::size_t i = body_at; i + 4 < bytes.size(); ++i) {
      for (const int bit : {0, 3, 7}) {
        std::string bad = bytes;
        bad[i] = static_cast<char>(bad[i] ^ (1 << bit));
        fix_grid_checksum(bad);
        INFO("byte " << i << " bit " << bit);
        try {
          (void)load_grid_from_memory<SparseMean>(bad);  // a changed cell value can still be valid
        } catch (const IoError&) {
          ++rejected;
        }
      }
    }
    CHECK(rejected > 0);
  }
  // Header counts that disagree with the body.
  std::string bytes = save_grid_to_memory(grid, GridSaveOptions{2, 0});
  const GridFileInfo info = read_grid_file_info_from_memory(bytes);
  const std::size_t voxel_count_at = bytes.size() - 4 - info.stored_bytes - 25 - 8;
  bytes[voxel_count_at] = static_cast<char>(bytes[voxel_count_at] + 1);
  fix_grid_checksum(bytes);
  CHECK_THROWS_WITH(load_grid_from_memory<SparseMean>(bytes), Catch::Contains("announces"));
}

TEST_CASE("interval parameters are stored as nine values, ten when never-observed space is classified",
          "[io][grid_file]") {
  using Codec = PolicyCodec<IntervalUpdate<LowerState>>;
  IntervalParams p;
  // The default classification writes the nine values earlier versions read.
  CHECK(Codec::encode(IntervalUpdate<LowerState>(p)).size() == 9);
  CHECK_FALSE(Codec::decode(Codec::encode(IntervalUpdate<LowerState>(p))).params().classify_unobserved);
  p.classify_unobserved = true;
  std::vector<double> v = Codec::encode(IntervalUpdate<LowerState>(p));
  REQUIRE(v.size() == 10);
  CHECK(v[9] == 1.0);
  CHECK(Codec::decode(v) == IntervalUpdate<LowerState>(p));
  v[9] = 0.5;
  CHECK_THROWS_WITH(Codec::decode(v), Catch::Contains("classify_unobserved flag must be 0 or 1"));
  v.push_back(1.0);
  CHECK_THROWS_WITH(Codec::decode(v), Catch::Contains("expected 9 or 10 interval parameters, got 11"));
}
