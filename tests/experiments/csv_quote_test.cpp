// Messages about a malformed results.csv quote its bytes with control characters escaped
// (intervox::detail::quote_bytes), so a crafted file cannot send escape sequences to a terminal.
#include <catch2/catch.hpp>
#include "results.hpp"

#include <cstdio>
#include <filesystem>
#include <random>
#include <string>

TEST_CASE("a results file's unknown column is quoted with control bytes escaped", "[experiments][csv]") {
  namespace fs = std::filesystem;
  const fs::path path = fs::temp_directory_path() / ("intervox_csv_" + std::to_string(std::random_device{}()) + ".csv");
  std::FILE* f = std::fopen(path.c_str(), "w");
  REQUIRE(f != nullptr);
  std::fputs("platform,\x1b[2Jcolumn\n", f);
  std::fclose(f);
  try {
    (void)experiments::read_csv(path.string());
    FAIL("no error");
  } catch (const intervox::IoError& e) {
    const std::string m = e.what();
    CHECK(m.find('\x1b') == std::string::npos);
    CHECK_THAT(m, Catch::Contains("unknown column '\\x1B[2Jcolumn'"));
  }
  fs::remove(path);
}
