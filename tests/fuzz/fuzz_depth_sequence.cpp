// libFuzzer target: DepthSequence (include/intervox/io/depth_sequence.hpp), the TUM RGB-D index
// files. The input is split at its first NUL byte: the part before it becomes depth.txt, the part
// after it groundtruth.txt (without a NUL, groundtruth.txt is a fixed three-pose file). Both are
// written into a per-process folder under the temporary folder that also holds a few fixed depth
// images: depth/a.png (4x3, the intrinsics' size), depth/b.png (5x3), depth/c.png (8-bit) and
// depth/d.png (truncated). Every associated frame is then read, as long as its file name stays
// inside that folder (names with "..", absolute names and odd characters are skipped, so that
// the harness never opens a device or another file of the machine).
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <unistd.h>

#include "fuzz_check.hpp"

#include <intervox/io/depth_sequence.hpp>

namespace {

namespace fs = std::filesystem;

bool write_file(const std::string& path, std::string_view bytes) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) return false;
  const bool ok = bytes.empty() || std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
  return std::fclose(f) == 0 && ok;
}

std::string read_file(const std::string& path) {
  std::string out;
  if (std::FILE* f = std::fopen(path.c_str(), "rb")) {
    char buf[4096];
    for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0;) out.append(buf, n);
    std::fclose(f);
  }
  return out;
}

intervox::DepthImage test_image(int w, int h) {
  intervox::DepthImage img(w, h);
  for (std::size_t i = 0; i < img.depth.size(); ++i)
    img.depth[i] = i % 5 == 0 ? 0.0f : 0.5f + 0.25f * static_cast<float>(i);
  return img;
}

// The folder with the fixed images, made once per process (removed at exit).
const std::string& folder() {
  static const std::string dir = [] {
    static std::string d = (fs::temp_directory_path() / ("intervox-fuzz-seq-" + std::to_string(::getpid()))).string();
    fs::create_directories(d + "/depth");
    intervox::write_depth_png(d + "/depth/a.png", test_image(4, 3));
    intervox::write_depth_png(d + "/depth/b.png", test_image(5, 3));
    png_image png{};
    png.version = PNG_IMAGE_VERSION;
    png.width = 4;
    png.height = 3;
    png.format = PNG_FORMAT_GRAY;
    const unsigned char gray[12] = {0, 10, 20, 30, 40, 50, 60, 70, 80, 90, 100, 110};
    if (png_image_write_to_file(&png, (d + "/depth/c.png").c_str(), 0, gray, 0, nullptr) == 0)
      fuzz_check_failed("cannot write depth/c.png");
    const std::string a = read_file(d + "/depth/a.png");
    if (a.size() < 40 || !write_file(d + "/depth/d.png", std::string_view(a).substr(0, a.size() / 2)))
      fuzz_check_failed("cannot write depth/d.png");
    std::atexit([] {
      std::error_code ec;
      fs::remove_all(d, ec);
    });
    return d;
  }();
  return dir;
}

constexpr std::string_view kDefaultTruth = "# timestamp tx ty tz qx qy qz qw\n"
                                           "1.0 0 0 0 0 0 0 1\n"
                                           "2.0 1 2 3 0 0 0.70710678 0.70710678\n"
                                           "3.0 -1 0.5 2 0.5 0.5 0.5 0.5\n";

bool inside_folder(std::string_view name) {
  if (name.empty() || name.front() == '/' || name.find("..") != std::string_view::npos) return false;
  for (const char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '/' ||
                    c == '.' || c == '_' || c == '-';
    if (!ok) return false;
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string& dir = folder();
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  const std::size_t nul = input.find('\0');
  const std::string_view depth_txt = input.substr(0, nul);
  const std::string_view truth_txt = nul == std::string_view::npos ? kDefaultTruth : input.substr(nul + 1);
  if (!write_file(dir + "/depth.txt", depth_txt) || !write_file(dir + "/groundtruth.txt", truth_txt))
    fuzz_check_failed("cannot write the index files");

  intervox::PinholeIntrinsics k;
  k.width = 4;
  k.height = 3;
  k.fx = k.fy = 2.0;
  k.cx = 1.5;
  k.cy = 1.0;
  intervox::DepthSequenceOptions options;
  options.max_time_difference = 0.05;
  try {
    const intervox::DepthSequence seq = intervox::DepthSequence::open(dir, k, options);
    if (seq.size() > seq.depth_frames()) fuzz_check_failed("more frames associated than listed");
    const std::string prefix = dir + "/";
    for (std::size_t i = 0; i < seq.size() && i < 16; ++i) {
      const std::string& path = seq.frames()[i].depth_path;
      if (path.compare(0, prefix.size(), prefix) != 0) fuzz_check_failed("a frame path outside its folder");
      if (!inside_folder(std::string_view(path).substr(prefix.size()))) continue;
      try {
        const intervox::DepthFrame f = seq.frame(i);
        if (f.image.width != 4 || f.image.height != 3 || !f.image.consistent())
          fuzz_check_failed("a frame of another size than the intrinsics'");
      } catch (const intervox::Error&) {
      }
    }
  } catch (const intervox::Error&) {
  }
  return 0;
}
