#include <catch2/catch.hpp>

#include <map>
#include <random>
#include <sstream>
#include <string>

#include "grid_types.hpp"
#include <intervox/io/octomap.hpp>
#include <intervox/update/bayes_log_odds.hpp>
#include "io_test_util.hpp"

#ifdef INTERVOX_HAVE_OCTOMAP
#include <octomap/OcTree.h>
#endif

using namespace intervox;

namespace {

using SparseBayes = VoxelGrid<BayesLogOdds, Entropy, SparseStorage>;
using DenseBayes = VoxelGrid<BayesLogOdds, Entropy, DenseStorage>;

/// Occupancy of every voxel a .bt export should hold, by the maximum-likelihood rule.
template <class G>
std::map<Key, bool> expected_ml(const G& grid) {
  std::map<Key, bool> out;
  grid.for_each_observed(
      [&](const Key& k, const typename G::Cell& c) { out[k] = grid.update_policy().state(c) >= 0.5; });
  return out;
}

std::string bt_data(const std::string& bt) { return bt.substr(bt.find("\ndata\n") + 6); }
std::string bt_size(const std::string& bt) {
  const auto at = bt.find("\nsize ") + 6;
  return bt.substr(at, bt.find('\n', at) - at);
}

}  // namespace

TEST_CASE("a .bt export read back by our importer keeps every voxel's maximum-likelihood state", "[io][octomap]") {
  SparseBayes grid(0.1, BayesLogOdds::octomap());
  fill_randomly(grid, 500, 11);
  // An aligned 4x4x4 occupied block and 2x2x2 free block so that pruning happens.
  for (int x = 0; x < 4; ++x)
    for (int y = 0; y < 4; ++y)
      for (int z = 0; z < 4; ++z) {
        for (int i = 0; i < 5; ++i) grid.update(Key{x + 20, y, z}, Observation::Hit);
        if (x < 2 && y < 2 && z < 2) grid.update(Key{x - 30, y, z}, Observation::Miss);
      }
  const std::string bt = write_bt_to_memory(grid);
  const SparseBayes back = read_bt_from_memory<SparseBayes>(bt);
  const auto expected = expected_ml(grid);
  CHECK(back.observed_count() == expected.size());
  for (const auto& [k, occupied] : expected) {
    REQUIRE(back.is_observed(k));
    CHECK((back.occupancy(k) == Occupancy::Occupied) == occupied);
    CHECK(back.cell(k) ==
          (occupied ? back.update_policy().clamp_max_log_odds() : back.update_policy().clamp_min_log_odds()));
  }
  const DenseBayes dense = read_bt_from_memory<DenseBayes>(bt);
  CHECK(dense.observed_count() == expected.size());
}

TEST_CASE("an empty grid exports as an empty tree", "[io][octomap]") {
  const SparseBayes grid(0.2);
  const std::string bt = write_bt_to_memory(grid);
  CHECK(bt_size(bt) == "0");
  CHECK(read_bt_from_memory<SparseBayes>(bt).observed_count() == 0);
  CHECK_THROWS_AS(read_bt_from_memory<DenseBayes>(bt), IoError);
}

TEST_CASE("voxels beyond OctoMap's 16-bit key range are left out of the export and counted", "[io][octomap]") {
  // A map reaching 4 km at 0.1 m: two voxels OctoMap can hold, two it cannot (keys 40000 and -40000
  // lie beyond 32767 voxels from the origin).
  SparseBayes grid(0.1);
  grid.update(Key{40000, 0, 0}, Observation::Hit);
  grid.update(Key{1, 2, 3}, Observation::Hit);
  grid.update(Key{-5, 0, 0}, Observation::Miss);
  grid.update(Key{0, -40000, 7}, Observation::Miss);
  OctomapExportSummary summary;
  const std::string bt = write_bt_to_memory(grid, {}, &summary);
  CHECK(summary.voxels == 2);
  CHECK(summary.out_of_range == 2);
  const SparseBayes back = read_bt_from_memory<SparseBayes>(bt);
  CHECK(back.observed_count() == 2);
  CHECK(back.is_observed(Key{1, 2, 3}));
  CHECK(back.is_observed(Key{-5, 0, 0}));
  // The same through a file: the summary is returned, and the file is the bytes above.
  const TempDir dir;
  const OctomapExportSummary written = write_bt(dir.file("far.bt"), grid);
  CHECK(written.out_of_range == 2);
  CHECK(read_all(dir.file("far.bt")) == bt);
  // An origin that is not a whole number of voxels is still refused before anything is written.
  SparseBayes shifted(GridGeometry(0.1, Point3(0.05, 0, 0)), std::nullopt);
  CHECK_THROWS_AS(write_bt_to_memory(shifted), InvalidArgument);
}

TEST_CASE("unknown-class voxels can be left out of a .bt export", "[io][octomap]") {
  VoxelGrid<BayesLogOdds> grid(0.1);  // thresholds 0.05 / 0.95: one hit is still unknown
  grid.update(Key{1, 1, 1}, Observation::Hit);
  for (int i = 0; i < 10; ++i) grid.update(Key{2, 2, 2}, Observation::Hit);
  CHECK(read_bt_from_memory<SparseBayes>(write_bt_to_memory(grid)).observed_count() == 2);
  OctomapExportOptions options;
  options.include_unknown = false;
  const auto back = read_bt_from_memory<SparseBayes>(write_bt_to_memory(grid, options));
  CHECK(back.observed_count() == 1);
  CHECK(back.is_observed(Key{2, 2, 2}));
}

TEST_CASE("malformed .bt files are reported, never crash", "[io][octomap]") {
  SparseBayes grid(0.1);
  fill_randomly(grid, 200, 4);
  const std::string bt = write_bt_to_memory(grid);
  const std::size_t data_at = bt.find("\ndata\n") + 6;
  for (std::size_t n = 0; n < bt.size(); n += (n < data_at ? 7 : 1)) {
    INFO("length " << n);
    CHECK_THROWS_AS(read_bt_from_memory<SparseBayes>(std::string_view(bt).substr(0, n)), IoError);
  }
  CHECK_THROWS_WITH(read_bt_from_memory<SparseBayes>("hello"), Catch::Contains("not an OctoMap binary file"));
  std::string wrong_size = bt;
  wrong_size.replace(wrong_size.find("\nsize ") + 6, bt_size(bt).size(), "7");
  CHECK_THROWS_WITH(read_bt_from_memory<SparseBayes>(wrong_size), Catch::Contains("size"));
  // A root whose eight children are all occupied leaves at depth 1 expands to 2^45 voxels.
  const std::string huge = "# Octomap OcTree binary file\nid OcTree\nsize 9\nres 0.1\ndata\n\xAA\xAA";
  CHECK_THROWS_WITH(read_bt_from_memory<SparseBayes>(huge), Catch::Contains("voxels"));
  CHECK_THROWS_AS(
      read_bt_from_memory<SparseBayes>("# Octomap OcTree binary file\nid ColorOcTree\nsize 0\nres 0.1\ndata\n"),
      IoError);
  CHECK_THROWS_AS(read_bt_from_memory<SparseBayes>("# Octomap OcTree binary file\nsize 0\nres -1\ndata\n"), IoError);
}

namespace {

/// A .bt holding one occupied leaf of `level` (pruned: 8^level voxels) at the tree's key origin.
std::string bt_with_one_leaf(int level) {
  std::string data;
  for (int l = 16; l > level + 1; --l) data += std::string("\x03\x00", 2);  // child 0 is inner
  data += std::string("\x02\x00", 2);                                       // child 0 is occupied
  return "# Octomap OcTree binary file\nid OcTree\nsize " + std::to_string(16 - level + 1) + "\nres 0.1\ndata\n" + data;
}

}  // namespace

TEST_CASE("a tiny .bt whose leaves lie far apart is refused as a dense grid by the load budget",
          "[io][octomap][budget]") {
  SparseBayes grid(0.1);
  grid.update(Key{-812, -812, -812}, Observation::Hit);
  grid.update(Key{812, 812, 812}, Observation::Hit);
  const std::string bt = write_bt_to_memory(grid);
  CHECK(bt.size() < 250);
  const int outcome = run_with_address_limit(std::uint64_t{1} << 30, [&] {
    return classify_load([&] { (void)read_bt_from_memory<DenseBayes>(bt, "crafted.bt"); }, "load budget");
  });
  CHECK(outcome == kExpectedError);
  if (outcome == kExpectedError) {  // safe to load in this process: refused before allocating
    CHECK_THROWS_WITH(read_bt_from_memory<DenseBayes>(bt, "crafted.bt"),
                      Catch::Contains("crafted.bt") && Catch::Contains("OctomapImportOptions::max_bytes"));
  }
  CHECK(read_bt_from_memory<SparseBayes>(bt).observed_count() == 2);
}

TEST_CASE("a tiny .bt whose pruned leaf expands to half a gigabyte is refused by the load budget",
          "[io][octomap][budget]") {
  const std::string bt = bt_with_one_leaf(9);  // 8^9 = 134 M voxels, 512 MiB of cells
  CHECK(bt.size() < 80);
  const int outcome = run_with_address_limit(std::uint64_t{1} << 30, [&] {
    return classify_load([&] { (void)read_bt_from_memory<SparseBayes>(bt, "crafted.bt"); }, "load budget");
  });
  CHECK(outcome == kExpectedError);
}

TEST_CASE("the .bt load budget counts the blocks of expanded leaves and can be changed", "[io][octomap][budget]") {
  const std::string bt = bt_with_one_leaf(5);  // 32^3 voxels = 64 blocks
  const std::uint64_t blocks = 64 * detail::sparse_block_bytes<float>();
  OctomapImportOptions options;
  options.max_bytes = blocks - 1;
  CHECK_THROWS_WITH(read_bt_from_memory<SparseBayes>(bt, "b.bt", BayesLogOdds::octomap(), options),
                    Catch::Contains("load budget"));
  options.max_bytes = blocks;
  CHECK(read_bt_from_memory<SparseBayes>(bt, "b.bt", BayesLogOdds::octomap(), options).observed_count() == 32768);
  options.max_bytes = 32768 * 4 - 1;
  CHECK_THROWS_WITH(read_bt_from_memory<DenseBayes>(bt, "b.bt", BayesLogOdds::octomap(), options),
                    Catch::Contains("load budget"));
  options.max_bytes = 32768 * 4;
  CHECK(read_bt_from_memory<DenseBayes>(bt, "b.bt", BayesLogOdds::octomap(), options).observed_count() == 32768);
  // Small leaves in one block count once.
  SparseBayes grid(0.1);
  for (int x = 0; x < 8; x += 2) grid.update(Key{x, 0, 0}, Observation::Hit);
  options.max_bytes = detail::sparse_block_bytes<float>();
  CHECK(read_bt_from_memory<SparseBayes>(write_bt_to_memory(grid), "c.bt", BayesLogOdds::octomap(), options)
            .observed_count() == 4);
}

#ifndef INTERVOX_TEST_SANITIZED
TEST_CASE("an allocation failure while importing a .bt is reported as IoError", "[io][octomap][budget]") {
  SparseBayes grid(0.1);
  grid.update(Key{-812, -812, -812}, Observation::Hit);
  grid.update(Key{812, 812, 812}, Observation::Hit);
  const std::string bt = write_bt_to_memory(grid);
  OctomapImportOptions options;
  options.max_bytes = ~std::uint64_t{0};
  const int outcome = run_with_address_limit(std::uint64_t{1} << 30, [&] {
    return classify_load([&] { (void)read_bt_from_memory<DenseBayes>(bt, "c.bt", BayesLogOdds::octomap(), options); },
                         "out of memory");
  });
  CHECK(outcome == kExpectedError);
}
#endif

#ifdef INTERVOX_HAVE_OCTOMAP

namespace {

/// Every voxel of an OctoMap tree (pruned leaves expanded) with its ML occupancy.
std::map<Key, bool> octomap_voxels(octomap::OcTree tree) {
  tree.expand();
  std::map<Key, bool> out;
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    REQUIRE(it.getDepth() == 16);
    const octomap::OcTreeKey k = it.getKey();
    out[Key{k[0] - 32768, k[1] - 32768, k[2] - 32768}] = tree.isNodeOccupied(*it);
  }
  return out;
}

}  // namespace

TEMPLATE_TEST_CASE("liboctomap reads our .bt export voxel by voxel", "[io][octomap]", INTERVOX_TEST_GRIDS) {
  using G = TestType;
  const TempDir dir;
  G grid = make_test_grid<G>();
  fill_randomly(grid, 800, 21);
  const std::string path = dir.file("map.bt");
  write_bt(path, grid);
  octomap::OcTree tree(path);
  CHECK(tree.getResolution() == Approx(0.1));
  CHECK(std::to_string(tree.size()) == bt_size(read_all(path)));
  CHECK(octomap_voxels(tree) == expected_ml(grid));
}

TEST_CASE("our .bt export is byte-identical to OcTree::writeBinary of the same voxels", "[io][octomap]") {
  SparseBayes grid(0.05, BayesLogOdds::octomap());
  fill_randomly(grid, 1500, 5);
  for (int x = 0; x < 8; ++x)
    for (int y = 0; y < 8; ++y)
      for (int z = 0; z < 8; ++z) grid.update(Key{x - 8, y + 8, z - 16}, Observation::Miss);
  octomap::OcTree tree(0.05);
  grid.for_each_observed([&](const Key& k, float c) {
    tree.setNodeValue(
        octomap::OcTreeKey(static_cast<octomap::key_type>(k.x + 32768), static_cast<octomap::key_type>(k.y + 32768),
                           static_cast<octomap::key_type>(k.z + 32768)),
        c);
  });
  std::stringstream theirs;
  tree.writeBinary(theirs);
  const std::string ours = write_bt_to_memory(grid);
  CHECK(bt_size(ours) == bt_size(theirs.str()));
  CHECK(bt_data(ours) == bt_data(theirs.str()));
}

TEST_CASE("a .bt written by liboctomap imports voxel by voxel", "[io][octomap]") {
  const TempDir dir;
  octomap::OcTree tree(0.1);
  std::mt19937 rng(17);
  std::uniform_int_distribution<int> coord(32700, 32830);
  for (int i = 0; i < 3000; ++i) {
    const octomap::OcTreeKey k(static_cast<octomap::key_type>(coord(rng)), static_cast<octomap::key_type>(coord(rng)),
                               static_cast<octomap::key_type>(coord(rng)));
    tree.updateNode(k, rng() % 3 == 0);
  }
  for (int x = 0; x < 16; ++x)  // a 16^3 aligned occupied cube: pruned to one leaf at depth 12
    for (int y = 0; y < 16; ++y)
      for (int z = 0; z < 16; ++z)
        tree.updateNode(
            octomap::OcTreeKey(static_cast<octomap::key_type>(32768 + 64 + x),
                               static_cast<octomap::key_type>(32768 + y), static_cast<octomap::key_type>(32768 + z)),
            true);
  const std::string path = dir.file("theirs.bt");
  REQUIRE(tree.writeBinary(path));  // converts to maximum likelihood and prunes, as on disk
  const auto expected = octomap_voxels(tree);
  const SparseBayes grid = read_bt<SparseBayes>(path);
  CHECK(grid.resolution() == Approx(0.1));
  CHECK(grid.observed_count() == expected.size());
  std::size_t mismatches = 0;
  for (const auto& [k, occupied] : expected) {
    if (!grid.is_observed(k) || (grid.occupancy(k) == Occupancy::Occupied) != occupied) ++mismatches;
  }
  CHECK(mismatches == 0);
  CHECK(grid.occupancy(Key{64 + 15, 15, 15}) == Occupancy::Occupied);
}

#endif  // INTERVOX_HAVE_OCTOMAP
