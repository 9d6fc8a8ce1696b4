#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <string>

#include <intervox/io/png.hpp>
#include "io_test_util.hpp"

using intervox::RgbImage;

TEST_CASE("a PNG written and read back has the same pixels", "[io][png]") {
  const TempDir dir;
  RgbImage image = RgbImage::filled(7, 3, 10, 20, 30);
  image.set(0, 0, 255, 0, 0);
  image.set(6, 2, 0, 255, 128);
  const std::string path = dir.file("a.png");
  intervox::write_png(path, image);
  const RgbImage back = intervox::read_png(path);
  CHECK(back.width == 7);
  CHECK(back.height == 3);
  CHECK(back.rgb == image.rgb);
}

TEST_CASE("an image whose buffer does not match its size is refused", "[io][png]") {
  const TempDir dir;
  RgbImage image{4, 4, std::vector<std::uint8_t>(10)};
  CHECK_THROWS_AS(intervox::write_png(dir.file("bad.png"), image), intervox::InvalidArgument);
  CHECK_FALSE(std::filesystem::exists(dir.file("bad.png")));
}

TEST_CASE("a failed PNG write leaves the previous file in place", "[io][png]") {
  const TempDir dir;
  const std::string path = dir.file("keep.png");
  intervox::write_png(path, RgbImage::filled(2, 2, 1, 2, 3));
  const RgbImage bad{0, 0, {}};
  CHECK_THROWS(intervox::write_png(path, bad));
  CHECK(intervox::read_png(path).rgb == RgbImage::filled(2, 2, 1, 2, 3).rgb);
  CHECK(count_files(dir.path()) == 1);  // no temporary file left behind
  CHECK_THROWS_AS(intervox::write_png(dir.file("no/such/dir/x.png"), RgbImage::filled(1, 1, 0, 0, 0)),
                  intervox::IoError);
}

TEST_CASE("reading a missing, truncated or non-PNG file throws IoError", "[io][png]") {
  const TempDir dir;
  CHECK_THROWS_AS(intervox::read_png(dir.file("missing.png")), intervox::IoError);
  const std::string path = dir.file("t.png");
  intervox::write_png(path, RgbImage::filled(64, 64, 9, 9, 9));
  const std::string bytes = read_all(path);
  write_all(path, bytes.substr(0, bytes.size() / 2));
  CHECK_THROWS_AS(intervox::read_png(path), intervox::IoError);
  write_all(path, "not a png at all");
  CHECK_THROWS_AS(intervox::read_png(path), intervox::IoError);
}
