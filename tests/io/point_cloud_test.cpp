#include <catch2/catch.hpp>

#include <cstring>
#include <filesystem>
#include <map>
#include <string>

#include <intervox/grid/named_grids.hpp>
#include <intervox/io/grid_file.hpp>
#include <intervox/io/octomap.hpp>
#include <intervox/io/point_cloud.hpp>
#include "io_test_util.hpp"

using namespace intervox;

namespace {
std::string floats_le(std::initializer_list<float> values) {
  std::string out;
  for (const float v : values) {
    char b[4];
    std::memcpy(b, &v, 4);  // the test machine is little-endian (x86-64)
    out.append(b, 4);
  }
  return out;
}
}  // namespace

TEST_CASE("XYZ files give the first three numbers of each line", "[io][point_cloud]") {
  const PointCloud c = read_xyz_from_memory("# comment\n1 2 3\n\n4.5,5,6 255 0 0\r\n-1e-3\t2 nan\n");
  REQUIRE(c.points.size() == 2);
  CHECK(c.points[1] == Point3(4.5, 5, 6));
  CHECK(c.dropped == 1);
  CHECK_THROWS_WITH(read_xyz_from_memory("1 2 3\n1 2\n", "scan.xyz"),
                    Catch::Contains("scan.xyz") && Catch::Contains("line 2"));
}

TEST_CASE("ASCII and binary PCD files give their x, y, z fields", "[io][point_cloud]") {
  const std::string ascii =
      "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\nWIDTH 3\nHEIGHT 1\n"
      "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\nDATA ascii\n1 2 3 0\n4 5 6 0\nnan nan nan 0\n";
  const PointCloud a = read_pcd_from_memory(ascii);
  REQUIRE(a.points.size() == 2);
  CHECK(a.points[1] == Point3(4, 5, 6));
  CHECK(a.dropped == 1);

  const std::string header = "VERSION 0.7\nFIELDS intensity x y z\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\nWIDTH "
                             "2\nHEIGHT 1\nPOINTS 2\nDATA binary\n";
  const std::string binary = header + floats_le({9, 1, 2, 3, 9, -1, -2, -3});
  const PointCloud b = read_pcd_from_memory(binary);
  REQUIRE(b.points.size() == 2);
  CHECK(b.points[1] == Point3(-1, -2, -3));
  CHECK_THROWS_WITH(read_pcd_from_memory(binary.substr(0, binary.size() - 1)), Catch::Contains("truncated"));
  std::string compressed = header;
  compressed.replace(compressed.find("DATA binary"), 11, "DATA binary_compressed");
  CHECK_THROWS_WITH(read_pcd_from_memory(compressed), Catch::Contains("not supported"));
  std::string huge = header;
  huge.replace(huge.find("POINTS 2"), 8, "POINTS 99999999999");
  CHECK_THROWS_AS(read_pcd_from_memory(huge + floats_le({1, 2, 3, 4})), IoError);
}

TEST_CASE("PLY files in every encoding give their vertices", "[io][point_cloud]") {
  const std::string ascii =
      "ply\nformat ascii 1.0\ncomment x\nelement vertex 2\nproperty double x\nproperty double y\nproperty double z\n"
      "property uchar red\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n1 2 3 4\n5 6 7 8\n3 0 1 "
      "1\n";
  const PointCloud a = read_ply_points_from_memory(ascii);
  REQUIRE(a.points.size() == 2);
  CHECK(a.points[1] == Point3(5, 6, 7));
  // A face element before the vertices, big-endian shorts.
  std::string big = "ply\nformat binary_big_endian 1.0\nelement face 1\nproperty list uchar int vertex_indices\n"
                    "element vertex 1\nproperty short x\nproperty short y\nproperty short z\nend_header\n";
  big += std::string("\x02\x00\x00\x00\x01\x00\x00\x00\x02", 9);
  big += std::string("\xFF\xFE\x00\x03\x01\x00", 6);
  const PointCloud b = read_ply_points_from_memory(big);
  REQUIRE(b.points.size() == 1);
  CHECK(b.points[0] == Point3(-2, 3, 256));
  CHECK_THROWS_AS(read_ply_points_from_memory(big.substr(0, big.size() - 1)), IoError);
  CHECK_THROWS_AS(
      read_ply_points_from_memory("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n1\n"),
      IoError);
  CHECK_THROWS_AS(read_ply_points_from_memory("ply\nformat ascii 1.0\nelement vertex 99999999999\nend_header\n"),
                  IoError);
}

TEST_CASE("point clouds are read from files by extension", "[io][point_cloud]") {
  const TempDir dir;
  write_all(dir.file("a.XYZ"), "1 2 3\n");
  CHECK(read_point_cloud(dir.file("a.XYZ")).points.size() == 1);
  write_all(dir.file("a.obj"), "v 1 2 3\n");
  CHECK_THROWS_WITH(read_point_cloud(dir.file("a.obj")), Catch::Contains("extension"));
  CHECK_THROWS_AS(read_point_cloud(dir.file("missing.pcd")), IoError);
}

TEST_CASE("malformed and once-crashing inputs are rejected cleanly by every loader", "[io][fuzz]") {
  // Every file under tests/io/data/fuzz/<loader>/ (a seed corpus of malformed inputs, plus any
  // crashing input a fuzzer finds, plus the tiny files that once allocated gigabytes: budget_*)
  // must be read or rejected with an intervox::Error: no crash, no other exception, no runaway
  // allocation.
  const std::filesystem::path root = std::filesystem::path(INTERVOX_IO_TEST_DATA) / "fuzz";
  REQUIRE(std::filesystem::exists(root));
  auto probe = [](const std::string& loader, const std::string& bytes) {
    try {
      if (loader == "ply") read_ply_points_from_memory(bytes);
      if (loader == "pcd") read_pcd_from_memory(bytes);
      if (loader == "xyz") read_xyz_from_memory(bytes);
      if (loader == "grid") {
        (void)load_grid_from_memory<BayesGrid>(bytes);
        (void)load_grid_from_memory<DenseIntervalGrid>(bytes);
      }
      if (loader == "bt") {
        OctomapImportOptions options;
        options.max_voxels = 1 << 16;
        (void)read_bt_from_memory<BayesGrid>(bytes, "<corpus>", BayesLogOdds::octomap(), options);
        (void)read_bt_from_memory<DenseBayesGrid>(bytes, "<corpus>", BayesLogOdds::octomap(), options);
      }
    } catch (const Error&) {
    }
  };
  std::map<std::string, int> per_loader;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(root)) {
    if (!entry.is_regular_file()) continue;
    const std::string loader = entry.path().parent_path().filename().string();
    INFO(entry.path().string());
    CHECK_NOTHROW(probe(loader, read_all(entry.path().string())));
    ++per_loader[loader];
  }
  for (const char* loader : {"ply", "pcd", "xyz", "grid", "bt"}) {
    INFO(loader);
    CHECK(per_loader[loader] >= 2);
  }
}

TEST_CASE("a declared point count is checked against what the bytes after the header can hold",
          "[io][point_cloud][budget]") {
  // Binary: the exact record size (3 floats = 12 bytes per vertex).
  const std::string header =
      "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n";
  CHECK(read_ply_points_from_memory(header + floats_le({1, 2, 3, 4, 5, 6})).points.size() == 2);
  CHECK_THROWS_WITH(read_ply_points_from_memory(header + floats_le({1, 2, 3, 4, 5}), "short.ply"),
                    Catch::Contains("short.ply") && Catch::Contains("declares 2 items of at least 12 bytes"));
  // ASCII: at least 2 bytes per value. A 32 MB file declaring 32 M points would reserve 768 MB
  // for them: refused before allocating, within 512 MiB of address space.
  const std::size_t n = std::size_t{32} << 20;
  const std::string body(n, '1');
  const std::string ply = "ply\nformat ascii 1.0\nelement vertex " + std::to_string(n) +
                          "\nproperty float x\nproperty float y\nproperty float z\nend_header\n" + body;
  const std::string pcd = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH " + std::to_string(n) +
                          "\nHEIGHT 1\nPOINTS " + std::to_string(n) + "\nDATA ascii\n" + body;
  const std::uint64_t cap = std::uint64_t{512} << 20;
  CHECK(run_with_address_limit(cap, [&] {
          return classify_load([&] { (void)read_ply_points_from_memory(ply); }, "declares");
        }) == kExpectedError);
  CHECK(run_with_address_limit(cap, [&] {
          return classify_load([&] { (void)read_pcd_from_memory(pcd); }, "truncated data");
        }) == kExpectedError);
  CHECK_THROWS_WITH(read_pcd_from_memory("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 3\nDATA ascii\n1 2 3\n4 5 6"),
                    Catch::Contains("3 points of 3 values"));
}

TEST_CASE("numbers out of the range of double or with trailing garbage are refused in text clouds",
          "[io][point_cloud]") {
  CHECK_THROWS_WITH(read_xyz_from_memory("1 2 3\n1e400xyz 2 3\n", "a.xyz"), Catch::Contains("line 2"));
  CHECK_THROWS_WITH(read_xyz_from_memory("1e400 2 3\n", "a.xyz"), Catch::Contains("line 1"));
  CHECK_THROWS_WITH(read_xyz_from_memory("0x10 2 3\n", "a.xyz"), Catch::Contains("line 1"));
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  CHECK_THROWS_WITH(read_ply_points_from_memory(ply + "1e400xyz 2 3\n"), Catch::Contains("bad number '1e400xyz'"));
  CHECK_THROWS_WITH(read_ply_points_from_memory(ply + "1e400 2 3\n"), Catch::Contains("bad number '1e400'"));
  // Below the range reads as the nearest double; "inf" and "nan" are non-finite points, dropped.
  const PointCloud tiny = read_xyz_from_memory("1e-400 2 3\ninf 1 1\n");
  REQUIRE(tiny.points.size() == 1);
  CHECK(tiny.points[0].x() == 0.0);
  CHECK(tiny.dropped == 1);
  // Bytes of the file are quoted with control bytes escaped.
  CHECK_THROWS_WITH(read_ply_points_from_memory(ply + "\x1b[31m 2 3\n"), Catch::Contains("bad number '\\x1B[31m'"));
}
