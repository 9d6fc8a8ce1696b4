#pragma once
/// \file
/// Recorded depth sequences in the TUM RGB-D layout (the de-facto format of depth-camera data
/// sets): a folder with `depth/*.png` (16-bit grayscale, depth = value / depth_factor metres, 0 =
/// no measurement), `depth.txt` (lines `timestamp filename`) and `groundtruth.txt` (lines
/// `timestamp tx ty tz qx qy qz qw`, the camera's optical frame to the world); `#` starts a
/// comment line; lines end at LF, CR LF or a lone CR, and every number must be a whole decimal
/// token ("0x3e8" is refused). Each depth frame takes the ground-truth pose with the nearest timestamp, if it
/// lies within a tolerance; frames without one are skipped. The intrinsics are the user's (see
/// docs/io.md for the common cameras). Needs the CMake target `intervox::png`.

#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "intervox/core/error.hpp"
#include "intervox/core/sensor_data.hpp"
#include "intervox/core/validate.hpp"
#include "intervox/io/detail/atomic_file.hpp"
#include "intervox/io/detail/binary.hpp"
#include "intervox/io/detail/text.hpp"

namespace intervox {

/// Options of reading a sequence.
struct DepthSequenceOptions {
  double depth_factor = 5000.0;       ///< PNG value per metre (TUM: 5000, i.e. 0.2 mm steps), > 0
  double max_time_difference = 0.02;  ///< s; a depth frame without a pose this close is skipped, >= 0
};

/// One frame of a sequence: when, which file, and the camera pose (optical frame to world).
struct DepthSequenceFrame {
  double time = 0;
  std::string depth_path;  ///< full path of the PNG
  Pose pose = Pose::Identity();
};

/// Largest depth image read_depth_png decodes: 2^26 pixels (e.g. 8192 x 8192; depth cameras give
/// at most a few million). Checked from the PNG header before anything is allocated.
inline constexpr std::uint64_t kMaxDepthPngPixels = std::uint64_t{1} << 26;

/// What the header (IHDR) of a PNG says (see read_depth_png_info).
struct DepthPngInfo {
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  int bit_depth = 0;   ///< bits per sample: 1, 2, 4, 8 or 16
  int color_type = 0;  ///< PNG_COLOR_TYPE_GRAY, _GRAY_ALPHA, _RGB, _RGB_ALPHA or _PALETTE
  bool interlaced = false;
  /// True for what read_depth_png decodes: one 16-bit gray channel.
  bool is_depth() const noexcept { return color_type == PNG_COLOR_TYPE_GRAY && bit_depth == 16; }
  /// The format in words, e.g. "gray 16-bit", "gray+alpha 16-bit", "RGB 8-bit", "palette 8-bit".
  std::string format() const {
    const char* kind = color_type == PNG_COLOR_TYPE_GRAY         ? "gray"
                       : color_type == PNG_COLOR_TYPE_GRAY_ALPHA ? "gray+alpha"
                       : color_type == PNG_COLOR_TYPE_RGB        ? "RGB"
                       : color_type == PNG_COLOR_TYPE_RGB_ALPHA  ? "RGBA"
                       : color_type == PNG_COLOR_TYPE_PALETTE    ? "palette"
                                                                 : "unknown colour type";
    return std::string(kind) + " " + std::to_string(bit_depth) + "-bit" + (interlaced ? " interlaced" : "");
  }
};

namespace detail {

/// libpng's low-level reader over an open regular file. libpng reports errors by longjmp: every
/// call that can fail runs in a function of this struct with only trivially destructible locals,
/// behind setjmp, and reports failure by its return value with libpng's message in `error`.
/// Warnings (e.g. a bad CRC in an ancillary chunk, which libpng then skips) are ignored.
struct PngDepthReader {
  png_structp png = nullptr;
  png_infop info = nullptr;
  char error[256] = {};

  PngDepthReader() {
    png = png_create_read_struct(PNG_LIBPNG_VER_STRING, this, &on_error, &on_warning);
    if (png != nullptr) info = png_create_info_struct(png);
  }
  ~PngDepthReader() { png_destroy_read_struct(&png, info != nullptr ? &info : nullptr, nullptr); }
  PngDepthReader(const PngDepthReader&) = delete;
  PngDepthReader& operator=(const PngDepthReader&) = delete;

  static void on_error(png_structp p, png_const_charp message) {
    auto* self = static_cast<PngDepthReader*>(png_get_error_ptr(p));
    std::snprintf(self->error, sizeof self->error, "%s", message);
    png_longjmp(p, 1);
  }
  static void on_warning(png_structp, png_const_charp) {}

  /// Reads the signature's remainder and every chunk up to the image data; fills \p h.
  bool read_header(std::FILE* file, DepthPngInfo& h) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_init_io(png, file);
    png_set_sig_bytes(png, 8);
    // No limit of libpng's below ours: dimensions are checked against kMaxDepthPngPixels.
    png_set_user_limits(png, 0x7fffffffu, 0x7fffffffu);
    png_read_info(png, info);
    png_uint_32 w = 0, hgt = 0;
    int depth = 0, color = 0, interlace = 0;
    png_get_IHDR(png, info, &w, &hgt, &depth, &color, &interlace, nullptr, nullptr);
    h.width = w;
    h.height = hgt;
    h.bit_depth = depth;
    h.color_type = color;
    h.interlaced = interlace != PNG_INTERLACE_NONE;
    return true;
  }
  /// Reads the image into \p rows (one pointer per row of width * 2 bytes). No transformation is
  /// requested except de-interlacing: samples arrive as stored, big-endian, whatever gAMA, sRGB,
  /// iCCP or tRNS chunks say.
  bool read_rows(png_bytepp rows) {
    if (setjmp(png_jmpbuf(png))) return false;
    (void)png_set_interlace_handling(png);
    png_read_update_info(png, info);
    png_read_image(png, rows);
    png_read_end(png, nullptr);
    return true;
  }
};

/// Opens \p path, checks the PNG signature and reads the header into \p reader.
inline DepthPngInfo open_depth_png(const std::string& path, InputFile& file, PngDepthReader& reader) {
  const std::string where = "read_depth_png('" + path + "'): ";
  unsigned char sig[8] = {};
  if (std::fread(sig, 1, 8, file.get()) != 8 || png_sig_cmp(sig, 0, 8) != 0) throw IoError(where + "not a PNG file");
  if (reader.png == nullptr || reader.info == nullptr) throw IoError(where + "out of memory");
  DepthPngInfo h;
  if (!reader.read_header(file.get(), h)) throw IoError(where + "corrupt PNG header: " + reader.error);
  return h;
}

}  // namespace detail

/// Reads the header of the PNG at \p path (its size and format) without decoding the image.
/// \throws IoError naming the file if it cannot be read, is not a regular file, or is not a PNG.
inline DepthPngInfo read_depth_png_info(const std::string& path) {
  detail::InputFile file(path);
  detail::PngDepthReader reader;
  return detail::open_depth_png(path, file, reader);
}

namespace detail {

/// read_depth_png, calling check(info) after the header is read (and its format checked), before
/// the size limit is checked and anything is allocated or decoded.
template <class Check>
DepthImage read_depth_png_checked(const std::string& path, double depth_factor, Check&& check) {
  const std::string where = "read_depth_png('" + path + "'): ";
  InputFile file(path);
  PngDepthReader reader;
  const DepthPngInfo h = open_depth_png(path, file, reader);
  if (!h.is_depth()) {
    throw IoError(where + "the image is " + h.format() +
                  "; a depth image must be single-channel 16-bit gray (raw depth samples)");
  }
  check(h);
  const std::uint64_t pixels = std::uint64_t{h.width} * h.height;  // two 32-bit factors: no overflow
  if (h.width == 0 || h.height == 0 || h.width > 0x7fffffffu || h.height > 0x7fffffffu || pixels > kMaxDepthPngPixels) {
    throw IoError(where + "image of " + std::to_string(h.width) + " x " + std::to_string(h.height) +
                  " pixels is larger than the limit of " + std::to_string(kMaxDepthPngPixels) + " pixels");
  }
  const std::size_t row_bytes = std::size_t{h.width} * 2;
  if (png_get_rowbytes(reader.png, reader.info) != row_bytes) throw IoError(where + "unexpected row size (corrupt)");
  std::vector<unsigned char> raw(static_cast<std::size_t>(pixels) * 2);
  std::vector<png_bytep> rows(h.height);
  for (std::size_t y = 0; y < h.height; ++y) rows[y] = raw.data() + y * row_bytes;
  if (!reader.read_rows(rows.data())) throw IoError(where + "corrupt or truncated: " + reader.error);
  DepthImage img(static_cast<int>(h.width), static_cast<int>(h.height));
  for (std::size_t i = 0; i < static_cast<std::size_t>(pixels); ++i) {
    const unsigned v = (unsigned{raw[2 * i]} << 8) | raw[2 * i + 1];  // PNG samples are big-endian
    img.depth[i] = v == 0 ? std::numeric_limits<float>::quiet_NaN() : static_cast<float>(v / depth_factor);
  }
  return img;
}

}  // namespace detail

/// Reads a 16-bit grayscale PNG of depths: value / \p depth_factor metres, 0 = invalid (NaN).
/// The samples are read raw through libpng's low-level API: gAMA, sRGB, cHRM and iCCP chunks
/// (colour management, meaningless for depth) and a tRNS chunk (a "transparent" gray value) are
/// ignored, so a depth is always the stored sample. Interlaced images are de-interlaced.
/// \throws IoError naming the file if it is missing, not a regular file, not a PNG, not
///   single-channel 16-bit gray (the message names the format found, e.g. "gray+alpha 16-bit",
///   "gray 8-bit", "RGB 16-bit"), larger than kMaxDepthPngPixels (checked from the header, before
///   allocating), or corrupt or truncated.
inline DepthImage read_depth_png(const std::string& path, double depth_factor = 5000.0) {
  return detail::read_depth_png_checked(path, depth_factor, [](const DepthPngInfo&) {});
}

/// The PNG value a depth is stored as: round(depth * depth_factor), 0 for invalid or no-return
/// pixels and for depths beyond 65535 / depth_factor (the format has no "no return").
inline std::uint16_t depth_png_value(float depth, double depth_factor = 5000.0) noexcept {
  if (!(std::isfinite(depth) && depth > 0)) return 0;
  const double v = std::round(double(depth) * depth_factor);
  return v >= 1 && v <= 65535 ? static_cast<std::uint16_t>(v) : 0;
}

/// Writes \p image as a 16-bit grayscale PNG (see depth_png_value()), atomically (see
/// detail::write_file_atomically and docs/io.md, "Saving safely"): a failed write leaves any
/// previous file in place.
/// \throws IoError if the file cannot be written; InvalidArgument for an inconsistent image.
inline void write_depth_png(const std::string& path, const DepthImage& image, double depth_factor = 5000.0) {
  if (!image.consistent() || image.width == 0 || image.height == 0)
    ParamCheck("intervox::write_depth_png").fail("image size does not match its buffer");
  std::vector<std::uint16_t> raw(image.depth.size());
  for (std::size_t i = 0; i < raw.size(); ++i) raw[i] = depth_png_value(image.depth[i], depth_factor);
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(image.width);
  png.height = static_cast<png_uint_32>(image.height);
  png.format = PNG_FORMAT_LINEAR_Y;
  detail::write_file_atomically(path, [&](std::FILE* file) {
    const int ok = png_image_write_to_stdio(&png, file, 0, raw.data(), 0, nullptr);
    const std::string message = png.message;
    png_image_free(&png);
    if (ok == 0) throw IoError("write_depth_png('" + path + "'): " + message);
  });
}

/// A recorded sequence in the TUM RGB-D layout (see the file comment).
///
/// Thread safety: immutable after open(); depth() may be called concurrently.
class DepthSequence {
 public:
  /// Reads `depth.txt` and `groundtruth.txt` of \p folder and associates every depth frame with
  /// the nearest ground-truth pose (frames without a pose within the tolerance are skipped).
  /// \throws IoError naming the file (and line) for a missing file or a malformed line;
  ///         InvalidArgument for invalid intrinsics or options.
  static DepthSequence open(const std::string& folder, const PinholeIntrinsics& intrinsics,
                            const DepthSequenceOptions& options = {}) {
    intrinsics.validate();
    const ParamCheck check("intervox::DepthSequence");
    check.positive("depth_factor", options.depth_factor);
    check.nonnegative("max_time_difference", options.max_time_difference);
    struct Stamp {
      double time;
      Pose pose;
    };
    std::vector<Stamp> poses;
    for_each_line(folder + "/groundtruth.txt", [&](const std::vector<std::string_view>& words,
                                                   const std::string& where) {
      double v[8];
      if (words.size() < 8) throw IoError(where + ": expected 'timestamp tx ty tz qx qy qz qw'");
      for (int i = 0; i < 8; ++i) v[i] = number(words[static_cast<std::size_t>(i)], where);
      const double t = v[0], x = v[1], y = v[2], z = v[3], qx = v[4], qy = v[5], qz = v[6], qw = v[7];
      const Eigen::Quaterniond q(qw, qx, qy, qz);
      if (!(std::isfinite(t) && std::isfinite(x) && std::isfinite(y) && std::isfinite(z) && std::isfinite(q.norm())) ||
          std::abs(q.norm() - 1.0) > 1e-3)
        throw IoError(where + ": pose is not finite or its quaternion is not of unit length");
      Pose p = Pose::Identity();
      p.linear() = q.normalized().toRotationMatrix();
      p.translation() = Point3(x, y, z);
      poses.push_back({t, p});
    });
    std::stable_sort(poses.begin(), poses.end(), [](const Stamp& a, const Stamp& b) { return a.time < b.time; });
    DepthSequence s;
    s.intrinsics_ = intrinsics;
    s.options_ = options;
    for_each_line(folder + "/depth.txt", [&](const std::vector<std::string_view>& words, const std::string& where) {
      if (words.size() < 2) throw IoError(where + ": expected 'timestamp filename'");
      const double t = number(words[0], where);
      if (!std::isfinite(t)) throw IoError(where + ": the timestamp is not finite");
      const std::string file(words[1]);
      // A name from the file is echoed in messages and opened: no control bytes (UTF-8 is fine).
      if (std::any_of(file.begin(), file.end(),
                      [](char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7F; }))
        throw IoError(where + ": the file name '" + detail::quote_bytes(file, 80) + "' holds control bytes");
      ++s.depth_frames_;
      const auto it =
          std::lower_bound(poses.begin(), poses.end(), t, [](const Stamp& a, double v) { return a.time < v; });
      const Stamp* best = nullptr;
      if (it != poses.end()) best = &*it;
      if (it != poses.begin() && (!best || t - std::prev(it)->time <= best->time - t)) best = &*std::prev(it);
      if (!best || std::abs(best->time - t) > options.max_time_difference) return;
      s.frames_.push_back({t, folder + "/" + file, best->pose});
    });
    if (s.depth_frames_ == 0)
      throw IoError("intervox::DepthSequence: '" + folder + "/depth.txt' lists no depth frames");
    return s;
  }

  /// The associated frames, in the order of depth.txt.
  const std::vector<DepthSequenceFrame>& frames() const noexcept { return frames_; }
  std::size_t size() const noexcept { return frames_.size(); }
  /// Depth frames listed in depth.txt (associated or not).
  std::size_t depth_frames() const noexcept { return depth_frames_; }
  const PinholeIntrinsics& intrinsics() const noexcept { return intrinsics_; }
  const DepthSequenceOptions& options() const noexcept { return options_; }

  /// The depth image of frame \p i. Its size is read from the PNG header and compared with the
  /// intrinsics' before the image is decoded.
  /// \throws IoError as read_depth_png, or if its size differs from the intrinsics'; OutOfRange
  ///   for i >= size().
  DepthImage depth(std::size_t i) const {
    if (i >= frames_.size())
      throw OutOfRange("intervox::DepthSequence::depth: frame " + std::to_string(i) + " of " +
                       std::to_string(frames_.size()));
    const std::string& path = frames_[i].depth_path;
    return detail::read_depth_png_checked(path, options_.depth_factor, [&](const DepthPngInfo& h) {
      if (std::int64_t{h.width} != intrinsics_.width || std::int64_t{h.height} != intrinsics_.height)
        throw IoError("intervox::DepthSequence: '" + path + "' is " + std::to_string(h.width) + "x" +
                      std::to_string(h.height) + ", the intrinsics say " + std::to_string(intrinsics_.width) + "x" +
                      std::to_string(intrinsics_.height));
    });
  }

  /// Frame \p i as a DepthFrame (its depth image, the sequence's intrinsics, its ground-truth
  /// pose), ready for `insert_depth_image(grid, frame, options)`. Its max_range is +inf: the
  /// format has no "no return" (see depth_png_value()), so only InsertOptions::max_range applies.
  /// \throws as depth().
  DepthFrame frame(std::size_t i) const {
    DepthFrame f;
    f.image = depth(i);
    f.intrinsics = intrinsics_;
    f.pose = frames_[i].pose;
    return f;
  }

 private:
  /// Largest depth.txt or groundtruth.txt read: 256 MiB (millions of lines).
  static constexpr std::uint64_t kMaxListBytes = std::uint64_t{1} << 28;

  /// A whole token as a decimal number (detail::parse_double: "0x3e8" and "1.0s" are not).
  static double number(std::string_view token, const std::string& where) {
    double v = 0;
    if (!detail::parse_double(token, v))
      throw IoError(where + ": '" + detail::quote_bytes(token, 40) + "' is not a decimal number");
    return v;
  }

  /// Calls f(words, where) for every line of \p path that is not blank or a comment. Lines end at
  /// LF, CR LF or a lone CR (old Mac files); words are separated by spaces and tabs.
  /// \throws IoError if the file cannot be read, is not a regular file or exceeds kMaxListBytes.
  template <class F>
  static void for_each_line(const std::string& path, F&& f) {
    std::string text;
    try {
      text = detail::read_file_bytes(path, kMaxListBytes);
    } catch (const IoError& e) {
      throw IoError(std::string("intervox::DepthSequence: ") + e.what());
    }
    std::size_t pos = 0;
    for (int n = 1; pos < text.size(); ++n) {
      std::size_t end = text.find_first_of("\r\n", pos);
      if (end == std::string::npos) end = text.size();
      const std::string_view line = std::string_view(text).substr(pos, end - pos);
      pos = end + ((end + 1 < text.size() && text[end] == '\r' && text[end + 1] == '\n') ? 2 : 1);
      std::vector<std::string_view> words;
      for (std::size_t i = 0; i < line.size();) {
        while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
        const std::size_t start = i;
        while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
        if (i > start) words.push_back(line.substr(start, i - start));
      }
      if (words.empty() || words[0].front() == '#') continue;
      f(words, "'" + path + "' line " + std::to_string(n));
    }
  }

  PinholeIntrinsics intrinsics_;
  DepthSequenceOptions options_;
  std::vector<DepthSequenceFrame> frames_;
  std::size_t depth_frames_ = 0;
};

/// Writes a sequence in the TUM RGB-D layout into \p folder (created by the caller): one
/// `depth/<index>.png` per image, `depth.txt` and `groundtruth.txt` with the given times and
/// poses (17 significant digits). For tools and tests. Every file is written atomically (see
/// detail::write_file_atomically): the images first, then the two lists, so that a failure (a full
/// disk) never leaves a truncated list in place of a complete one.
/// \throws IoError if a file cannot be written; InvalidArgument if the lists differ in length.
inline void write_depth_sequence(const std::string& folder, const std::vector<double>& times,
                                 const std::vector<DepthImage>& images, const std::vector<Pose>& poses,
                                 double depth_factor = 5000.0) {
  if (times.size() != images.size() || times.size() != poses.size())
    ParamCheck("intervox::write_depth_sequence").fail("times, images and poses differ in length");
  std::string depth = "# depth maps\n# timestamp filename\n";
  std::string truth = "# ground truth trajectory\n# timestamp tx ty tz qx qy qz qw\n";
  char line[512];
  for (std::size_t i = 0; i < times.size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "depth/%04zu.png", i);
    write_depth_png(folder + "/" + name, images[i], depth_factor);
    std::snprintf(line, sizeof line, "%.6f %s\n", times[i], name);
    depth += line;
    const Eigen::Quaterniond q(poses[i].linear());
    const Point3 t = poses[i].translation();
    std::snprintf(line, sizeof line, "%.6f %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", times[i], t.x(), t.y(), t.z(),
                  q.x(), q.y(), q.z(), q.w());
    truth += line;
  }
  const auto save = [&](const std::string& path, const std::string& text) {
    detail::write_file_atomically(path, [&](std::FILE* f) { detail::write_bytes(f, text.data(), text.size(), path); });
  };
  save(folder + "/depth.txt", depth);
  save(folder + "/groundtruth.txt", truth);
}

}  // namespace intervox
