// Depth PNGs are read as the raw 16-bit samples they hold (io/depth_sequence.hpp): ancillary
// chunks (gAMA, sRGB, tRNS) change nothing, any other format is refused naming it, and sizes are
// checked from the header before anything is decoded.
#include <catch2/catch.hpp>
#include <intervox/io/depth_sequence.hpp>

#include <png.h>

#include <cmath>
#include <csetjmp>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "io_test_util.hpp"

namespace iv = intervox;

namespace {

/// A PNG to write with libpng's low-level API: samples in row order, channel by channel.
struct PngSpec {
  int width = 2;
  int height = 2;
  int bit_depth = 16;
  int color_type = PNG_COLOR_TYPE_GRAY;
  std::vector<std::uint16_t> samples;
  bool gama = false;
  bool srgb = false;
  bool trns = false;
  std::uint16_t trns_gray = 0;
  bool interlace = false;
};

int channels(int color_type) {
  switch (color_type) {
    case PNG_COLOR_TYPE_GRAY_ALPHA:
      return 2;
    case PNG_COLOR_TYPE_RGB:
      return 3;
    case PNG_COLOR_TYPE_RGB_ALPHA:
      return 4;
    default:
      return 1;
  }
}

/// Writes \p spec to \p path; false if libpng failed. Only trivially destructible locals behind setjmp.
bool write_png_raw(const char* path, const PngSpec& spec, const std::vector<png_bytep>& rows) {
  std::FILE* f = std::fopen(path, "wb");
  if (f == nullptr) return false;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    std::fclose(f);
    return false;
  }
  png_init_io(png, f);
  png_set_IHDR(png, info, static_cast<png_uint_32>(spec.width), static_cast<png_uint_32>(spec.height), spec.bit_depth,
               spec.color_type, spec.interlace ? PNG_INTERLACE_ADAM7 : PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  if (spec.color_type == PNG_COLOR_TYPE_PALETTE) {
    png_color palette[2] = {{0, 0, 0}, {255, 255, 255}};
    png_set_PLTE(png, info, palette, 2);
  }
  if (spec.gama) png_set_gAMA(png, info, 0.45455);
  if (spec.srgb) png_set_sRGB(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
  if (spec.trns) {
    png_color_16 c{};
    c.gray = spec.trns_gray;
    png_set_tRNS(png, info, nullptr, 0, &c);
  }
  png_write_info(png, info);
  png_write_image(png, const_cast<png_bytepp>(rows.data()));
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return std::fclose(f) == 0;
}

void write_png(const std::string& path, const PngSpec& spec) {
  const int n = channels(spec.color_type);
  const int bytes = spec.bit_depth == 16 ? 2 : 1;
  const std::size_t row_bytes = static_cast<std::size_t>(spec.width) * static_cast<std::size_t>(n * bytes);
  std::vector<unsigned char> data(row_bytes * static_cast<std::size_t>(spec.height));
  REQUIRE(spec.samples.size() == static_cast<std::size_t>(spec.width * spec.height * n));
  for (std::size_t i = 0; i < spec.samples.size(); ++i) {
    if (bytes == 2) {
      data[2 * i] = static_cast<unsigned char>(spec.samples[i] >> 8);  // PNG is big-endian
      data[2 * i + 1] = static_cast<unsigned char>(spec.samples[i] & 0xFF);
    } else {
      data[i] = static_cast<unsigned char>(spec.samples[i]);
    }
  }
  std::vector<png_bytep> rows(static_cast<std::size_t>(spec.height));
  for (std::size_t y = 0; y < rows.size(); ++y) rows[y] = data.data() + y * row_bytes;
  REQUIRE(write_png_raw(path.c_str(), spec, rows));
}

// 1.9422 m, 1 m, no measurement, the largest value.
const std::vector<std::uint16_t> kDepthSamples{9711, 5000, 0, 65535};

void require_raw_depths(const iv::DepthImage& d) {
  REQUIRE(d.width == 2);
  REQUIRE(d.height == 2);
  CHECK(d.depth[0] == static_cast<float>(9711 / 5000.0));
  CHECK(d.depth[1] == 1.0f);
  CHECK(std::isnan(d.depth[2]));
  CHECK(d.depth[3] == static_cast<float>(65535 / 5000.0));
}

std::string error_of(const std::string& path) {
  try {
    (void)iv::read_depth_png(path);
  } catch (const iv::IoError& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace

TEST_CASE("a depth PNG with gAMA, sRGB or tRNS chunks reads as its raw samples", "[io][depth_png]") {
  const TempDir dir;
  for (const char* chunk : {"none", "gAMA", "sRGB", "tRNS", "all", "interlaced"}) {
    INFO("chunk " << chunk);
    PngSpec spec;
    spec.samples = kDepthSamples;
    const std::string c = chunk;
    spec.gama = c == "gAMA" || c == "all";
    spec.srgb = c == "sRGB" || c == "all";
    spec.trns = c == "tRNS" || c == "all";
    spec.trns_gray = 9711;  // the "transparent" gray value is a depth like any other
    spec.interlace = c == "interlaced";
    const std::string path = dir.file(c + ".png");
    write_png(path, spec);
    require_raw_depths(iv::read_depth_png(path));
    const iv::DepthPngInfo info = iv::read_depth_png_info(path);
    CHECK(info.is_depth());
    CHECK(info.width == 2);
  }
}

TEST_CASE("a PNG that is not single-channel 16-bit gray is refused naming the file and its format", "[io][depth_png]") {
  const TempDir dir;
  struct Case {
    const char* name;
    int color_type;
    int bit_depth;
    const char* format;
  };
  for (const Case& c :
       {Case{"ga16", PNG_COLOR_TYPE_GRAY_ALPHA, 16, "gray+alpha 16-bit"},
        Case{"gray8", PNG_COLOR_TYPE_GRAY, 8, "gray 8-bit"}, Case{"rgb16", PNG_COLOR_TYPE_RGB, 16, "RGB 16-bit"},
        Case{"rgb8", PNG_COLOR_TYPE_RGB, 8, "RGB 8-bit"}, Case{"rgba8", PNG_COLOR_TYPE_RGB_ALPHA, 8, "RGBA 8-bit"},
        Case{"palette", PNG_COLOR_TYPE_PALETTE, 8, "palette 8-bit"}}) {
    INFO(c.name);
    PngSpec spec;
    spec.color_type = c.color_type;
    spec.bit_depth = c.bit_depth;
    const std::size_t n = static_cast<std::size_t>(4 * channels(c.color_type));
    for (std::size_t i = 0; i < n; ++i)
      spec.samples.push_back(static_cast<std::uint16_t>(c.bit_depth == 16 ? 5000 : 1));
    const std::string path = dir.file(std::string(c.name) + ".png");
    write_png(path, spec);
    CHECK_THAT(error_of(path), Catch::Contains(std::string(c.name) + ".png") && Catch::Contains(c.format));
  }
}

TEST_CASE("a depth PNG's size is checked from its header before it is decoded", "[io][depth_png][sequence]") {
  const TempDir dir;
  std::filesystem::create_directories(dir.file("depth"));
  PngSpec spec;
  spec.samples = kDepthSamples;
  write_png(dir.file("depth/small.png"), spec);
  // The same file claiming 16384 x 16384 pixels (1.6 GB decoded): patch IHDR and its CRC.
  std::string bytes = read_all(dir.file("depth/small.png"));
  REQUIRE(bytes.substr(12, 4) == "IHDR");
  for (const std::size_t at : {16u, 20u}) {
    bytes[at] = 0;
    bytes[at + 1] = 0;
    bytes[at + 2] = 0x40;
    bytes[at + 3] = 0;
  }
  const std::uint32_t crc = iv::detail::crc32(std::string_view(bytes).substr(12, 17));
  for (int i = 0; i < 4; ++i) bytes[29 + static_cast<std::size_t>(i)] = static_cast<char>((crc >> (24 - 8 * i)) & 0xFF);
  write_all(dir.file("depth/huge.png"), bytes);
  CHECK(iv::read_depth_png_info(dir.file("depth/huge.png")).width == 16384);
  // read_depth_png: above the pixel limit, refused before allocating.
  CHECK_THAT(error_of(dir.file("depth/huge.png")),
             Catch::Contains("huge.png") && Catch::Contains("larger than the limit"));
  // DepthSequence::depth: the size is compared with the intrinsics first, within 1 GiB.
  write_all(dir.file("depth.txt"), "1.0 depth/huge.png\n");
  write_all(dir.file("groundtruth.txt"), "1.0 0 0 0 0 0 0 1\n");
  const iv::DepthSequence s =
      iv::DepthSequence::open(dir.path().string(), iv::PinholeIntrinsics::from_fov(2, 2, 1.0, 1.0));
  const int outcome = run_with_address_limit(std::uint64_t{1} << 30, [&] {
    return classify_load([&] { (void)s.depth(0); }, "is 16384x16384, the intrinsics say 2x2");
  });
  CHECK(outcome == kExpectedError);
}
