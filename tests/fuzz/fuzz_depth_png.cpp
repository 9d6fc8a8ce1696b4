// libFuzzer target: read_depth_png (include/intervox/io/depth_sequence.hpp). The reader takes a
// path, so every input is written to a per-process file under the temporary folder and read
// from there. Every input is read twice: as it is and, if it starts with the PNG signature, with
// the CRC of every chunk recomputed (libpng refuses a critical chunk with a bad CRC, so without
// this most mutations of IHDR and IDAT would stop there).
//
// Value check (the rule of issue 30: a depth image is read as the raw 16-bit samples it holds,
// whatever its ancillary chunks say): when read_depth_png returns an image, the harness decodes
// the same bytes with libpng's low-level API and no transformation; the file must be a
// single-channel 16-bit image and every pixel must equal sample / depth_factor (0: NaN). The
// reader of main before the fix (libpng's simplified API) fails this check on gAMA, sRGB, tRNS
// and gray+alpha images; INTERVOX_FUZZ_NO_VALUE_CHECK=1 in the environment turns the check off
// to fuzz that reader for crashes alone.
#include <cmath>
#include <csetjmp>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <unistd.h>
#include <zlib.h>

#include "fuzz_check.hpp"

#include <intervox/io/depth_sequence.hpp>

namespace {

const std::string& temp_png() {
  static const std::string path = [] {
    static std::string p =
        (std::filesystem::temp_directory_path() / ("intervox-fuzz-depth-" + std::to_string(::getpid()) + ".png"))
            .string();
    std::atexit([] { std::remove(p.c_str()); });
    return p;
  }();
  return path;
}

bool write_file(const std::string& path, std::string_view bytes) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) return false;
  const bool ok = bytes.empty() || std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
  return std::fclose(f) == 0 && ok;
}

constexpr std::string_view kSignature{"\x89PNG\r\n\x1a\n", 8};

std::uint32_t be32(const std::string& s, std::size_t at) {
  return (std::uint32_t{static_cast<unsigned char>(s[at])} << 24) |
         (std::uint32_t{static_cast<unsigned char>(s[at + 1])} << 16) |
         (std::uint32_t{static_cast<unsigned char>(s[at + 2])} << 8) |
         std::uint32_t{static_cast<unsigned char>(s[at + 3])};
}

// \p png with the CRC of every complete chunk recomputed.
std::string fix_chunk_crcs(std::string png) {
  std::size_t at = kSignature.size();
  while (png.size() - at >= 12) {
    const std::uint32_t len = be32(png, at);
    if (len > png.size() - at - 12) break;
    const auto* p = reinterpret_cast<const Bytef*>(png.data() + at + 4);
    const uLong crc = crc32(crc32(0L, Z_NULL, 0), p, static_cast<uInt>(len + 4));
    for (int i = 0; i < 4; ++i)
      png[at + 8 + len + static_cast<std::size_t>(i)] = static_cast<char>((crc >> (24 - 8 * i)) & 0xFFu);
    at += 12 + std::size_t{len};
  }
  return png;
}

// The raw samples of a PNG, decoded by libpng's low-level API without any transformation.
struct RawImage {
  bool ok = false;
  png_uint_32 width = 0, height = 0;
  int bit_depth = 0, color_type = 0, channels = 0;
  std::vector<unsigned char> bytes;  // rows, as stored (16-bit samples big-endian)
};

struct MemoryReader {
  const unsigned char* data;
  std::size_t size, at;
};

void read_from_memory(png_structp png, png_bytep out, png_size_t n) {
  auto* m = static_cast<MemoryReader*>(png_get_io_ptr(png));
  if (n > m->size - m->at) png_error(png, "read past the end");
  std::memcpy(out, m->data + m->at, n);
  m->at += n;
}

void ignore_warning(png_structp, png_const_charp) {}

// Between setjmp and a png_error's longjmp only plain pointers change (the row pointers live on
// the heap, owned by a pointer set before setjmp), so the jump skips no destructor.
void decode_raw(const std::string& file, RawImage& out) {
  MemoryReader reader{reinterpret_cast<const unsigned char*>(file.data()), file.size(), 0};
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, ignore_warning);
  if (png == nullptr) return;
  png_infop info = png_create_info_struct(png);
  std::vector<png_bytep>* rows = new std::vector<png_bytep>();
  if (info == nullptr || setjmp(png_jmpbuf(png))) {
    out.ok = false;
    delete rows;
    png_destroy_read_struct(&png, &info, nullptr);
    return;
  }
  png_set_read_fn(png, &reader, read_from_memory);
  png_read_info(png, info);
  out.width = png_get_image_width(png, info);
  out.height = png_get_image_height(png, info);
  out.bit_depth = png_get_bit_depth(png, info);
  out.color_type = png_get_color_type(png, info);
  out.channels = png_get_channels(png, info);
  if (std::uint64_t{out.width} * out.height > (1u << 20)) png_error(png, "too large for the value check");
  (void)png_set_interlace_handling(png);
  png_read_update_info(png, info);
  const std::size_t row_bytes = png_get_rowbytes(png, info);
  out.bytes.resize(row_bytes * out.height);
  rows->resize(out.height);
  for (png_uint_32 y = 0; y < out.height; ++y) (*rows)[y] = out.bytes.data() + row_bytes * y;
  png_read_image(png, rows->data());
  out.ok = true;
  delete rows;
  png_destroy_read_struct(&png, &info, nullptr);
}

void check_values(const std::string& file, const intervox::DepthImage& img, double factor) {
  RawImage raw;
  decode_raw(file, raw);
  if (!raw.ok) return;  // libpng's own decoder refuses it: no reference to compare with
  // Read as a depth image: it must be one channel of 16 bits, of that size...
  if (raw.bit_depth != 16 || raw.color_type != PNG_COLOR_TYPE_GRAY)
    fuzz_check_failed("read_depth_png accepted an image that is not single-channel 16-bit");
  if (static_cast<png_uint_32>(img.width) != raw.width || static_cast<png_uint_32>(img.height) != raw.height)
    fuzz_check_failed("read_depth_png returned another size than the IHDR's");
  // ...and every pixel its raw sample / depth factor.
  for (std::size_t i = 0; i < img.depth.size(); ++i) {
    const unsigned v = (unsigned{raw.bytes[2 * i]} << 8) | raw.bytes[2 * i + 1];
    const float want = v == 0 ? std::nanf("") : static_cast<float>(v / factor);
    const float got = img.depth[i];
    if (v == 0 ? !std::isnan(got) : got != want)
      fuzz_check_failed("a depth differs from its raw 16-bit sample / depth_factor");
  }
}

// True if the IHDR announces more than 2^22 pixels (8 MiB of samples). Such inputs are skipped:
// the reader of main allocates the whole image before decoding (issue 30, item 5), seconds per
// input under ASan, which would leave no time for anything else.
bool too_large(const std::string& file) {
  if (file.size() < 24 || std::string_view(file).substr(12, 4) != "IHDR") return false;
  return std::uint64_t{be32(file, 16)} * be32(file, 20) > (std::uint64_t{1} << 22);
}

void read_one(const std::string& file, bool check) {
  if (too_large(file)) return;
  const std::string& path = temp_png();
  if (!write_file(path, file)) fuzz_check_failed("cannot write the temporary PNG");
  for (const double factor : {5000.0, 1.0}) {
    try {
      const intervox::DepthImage img = intervox::read_depth_png(path, factor);
      if (!img.consistent() || img.width <= 0 || img.height <= 0)
        fuzz_check_failed("read_depth_png returned an inconsistent image");
      if (check) check_values(file, img, factor);
    } catch (const intervox::Error&) {
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const bool check = [] {
    const char* v = std::getenv("INTERVOX_FUZZ_NO_VALUE_CHECK");
    return v == nullptr || std::string_view(v) != "1";
  }();
  const std::string file(reinterpret_cast<const char*>(data), size);
  read_one(file, check);
  if (file.size() > kSignature.size() && std::string_view(file).substr(0, kSignature.size()) == kSignature) {
    const std::string fixed = fix_chunk_crcs(file);
    if (fixed != file) read_one(fixed, check);
  }
  return 0;
}
