// Reading files (io/detail/binary.hpp and every loader on it): only regular files, bounded sizes,
// the magic checked before the rest is read, allocation failures as IoError.
#include <catch2/catch.hpp>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>

#include "grid_types.hpp"
#include <intervox/grid/named_grids.hpp>
#include <intervox/io/grid_file.hpp>
#include <intervox/io/octomap.hpp>
#include <intervox/io/point_cloud.hpp>
#include "io_test_util.hpp"

using namespace intervox;

namespace {

/// A sparse file of \p size bytes that starts with \p head (no disk space used for the rest).
void make_sparse_file(const std::string& path, const std::string& head, std::uint64_t size) {
  write_all(path, head);
  REQUIRE(::truncate(path.c_str(), static_cast<off_t>(size)) == 0);
}

template <class F>
double seconds_of(F&& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

TEST_CASE("devices, directories and FIFOs are refused before anything is read", "[io][read_limits]") {
  const TempDir dir;
  REQUIRE(::mkfifo(dir.file("pipe.ivx").c_str(), 0600) == 0);
  std::filesystem::create_directory(dir.file("folder.ply"));
  const double t = seconds_of([&] {
    CHECK_THROWS_WITH(load_grid<BayesGrid>("/dev/zero"),
                      Catch::Contains("/dev/zero") && Catch::Contains("character device"));
    CHECK_THROWS_WITH(read_point_cloud(dir.file("folder.ply")),
                      Catch::Contains("folder.ply") && Catch::Contains("a directory"));
    CHECK_THROWS_WITH(load_grid<BayesGrid>(dir.file("pipe.ivx")),
                      Catch::Contains("pipe.ivx") && Catch::Contains("FIFO"));
    CHECK_THROWS_WITH(read_grid_file_info("/dev/zero"), Catch::Contains("character device"));
    CHECK_THROWS_WITH(read_bt<BayesGrid>("/dev/zero"), Catch::Contains("character device"));
    CHECK_THROWS_WITH(detail::read_file_bytes("/dev/zero"), Catch::Contains("not a regular file"));
  });
  CHECK(t < 2.0);
}

TEST_CASE("a large file that is not a grid file is refused after its magic, without reading the rest",
          "[io][read_limits]") {
  const TempDir dir;
  // 900 MB (sparse): a loader reading it whole fails within 256 MiB of address space; checking the
  // magic first refuses it after 8 bytes.
  make_sparse_file(dir.file("big.ivx"), "not a grid file", std::uint64_t{900} << 20);
  make_sparse_file(dir.file("big.bt"), "not an octree", std::uint64_t{900} << 20);
  make_sparse_file(dir.file("big.ply"), "solid ascii", std::uint64_t{900} << 20);
  const std::uint64_t cap = std::uint64_t{256} << 20;
  CHECK(run_with_address_limit(cap, [&] {
          return classify_load([&] { (void)load_grid<BayesGrid>(dir.file("big.ivx")); }, "bad magic");
        }) == kExpectedError);
  CHECK(run_with_address_limit(cap, [&] {
          return classify_load([&] { (void)read_bt<BayesGrid>(dir.file("big.bt")); }, "not an OctoMap binary file");
        }) == kExpectedError);
  CHECK(run_with_address_limit(cap, [&] {
          return classify_load([&] { (void)read_point_cloud(dir.file("big.ply")); }, "not a PLY file");
        }) == kExpectedError);
  // The header alone is read for the file's information.
  BayesGrid grid(0.1);
  grid.update(Key{1, 2, 3}, Observation::Hit);
  std::string bytes = save_grid_to_memory(grid);
  write_all(dir.file("padded.ivx"), bytes);
  REQUIRE(::truncate(dir.file("padded.ivx").c_str(), static_cast<off_t>(std::uint64_t{900} << 20)) == 0);
  CHECK(run_with_address_limit(
            cap, [&] { return read_grid_file_info(dir.file("padded.ivx")).voxel_count == 1 ? 0 : 1; }) == 0);
}

TEST_CASE("a file over the read limit is refused from its size, and allocation failures are IoError",
          "[io][read_limits]") {
  const TempDir dir;
  make_sparse_file(dir.file("huge.xyz"), "1 2 3\n", detail::kDefaultReadLimitBytes + 1);
  const double t = seconds_of([&] {
    CHECK_THROWS_WITH(read_point_cloud(dir.file("huge.xyz")),
                      Catch::Contains("huge.xyz") && Catch::Contains("larger than the limit"));
  });
  CHECK(t < 2.0);
  write_all(dir.file("small.xyz"), "1 2 3\n4 5 6\n");
  CHECK_THROWS_WITH(detail::read_file_bytes(dir.file("small.xyz"), 5),
                    Catch::Contains("larger than the limit of 5 bytes"));
  CHECK(detail::read_file_bytes(dir.file("small.xyz"), 12).size() == 12);
#ifndef INTERVOX_TEST_SANITIZED
  // A 600 MB cloud under 256 MiB of address space: the read fails with IoError, not std::bad_alloc.
  make_sparse_file(dir.file("zeros.xyz"), "1 2 3\n", std::uint64_t{600} << 20);
  CHECK(run_with_address_limit(std::uint64_t{256} << 20, [&] {
          return classify_load([&] { (void)read_point_cloud(dir.file("zeros.xyz")); }, "out of memory");
        }) == kExpectedError);
  // ... and a grid file (its magic is right) the same.
  make_sparse_file(dir.file("zeros.ivx"), std::string(detail::kGridMagic), std::uint64_t{600} << 20);
  CHECK(run_with_address_limit(std::uint64_t{256} << 20, [&] {
          return classify_load([&] { (void)load_grid<BayesGrid>(dir.file("zeros.ivx")); }, "out of memory");
        }) == kExpectedError);
#endif
}

TEST_CASE("a path with a NUL byte is refused by loads and saves, and no shorter name is touched", "[io][paths]") {
  const TempDir dir;
  const std::string shorter = dir.file("a");
  const std::string with_nul = shorter + std::string(1, '\0') + "b.ivx";
  BayesGrid g(0.1);
  g.update(Point3(0.05, 0.05, 0.05), Observation::Hit);
  CHECK_THROWS_WITH(save_grid(with_nul, g), Catch::Contains("contains a NUL byte"));
  CHECK_FALSE(std::filesystem::exists(shorter));  // the save wrote nothing, not even "a"
  write_all(shorter, "not a grid");
  CHECK_THROWS_WITH(load_grid<BayesGrid>(with_nul), Catch::Contains("contains a NUL byte"));
  CHECK_THROWS_AS(read_point_cloud(shorter + std::string(1, '\0') + ".xyz"), InvalidArgument);
  CHECK_THROWS_AS(read_bt(shorter + std::string(1, '\0') + ".bt"), InvalidArgument);
  CHECK(read_all(shorter) == "not a grid");
}
