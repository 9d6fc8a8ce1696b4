#pragma once
/// \file
/// Recorded depth sequences in the TUM RGB-D layout (the de-facto format of depth-camera data
/// sets): a folder with `depth/*.png` (16-bit grayscale, depth = value / depth_factor metres, 0 =
/// no measurement), `depth.txt` (lines `timestamp filename`) and `groundtruth.txt` (lines
/// `timestamp tx ty tz qx qy qz qw`, the camera's optical frame to the world); `#` starts a
/// comment line. Each depth frame takes the ground-truth pose with the nearest timestamp, if it
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
#include <vector>

#include "intervox/core/error.hpp"
#include "intervox/core/sensor_data.hpp"

namespace intervox {

/// Options of reading a sequence.
struct DepthSequenceOptions {
  double depth_factor = 5000.0;        ///< PNG value per metre (TUM: 5000, i.e. 0.2 mm steps), > 0
  double max_time_difference = 0.02;  ///< s; a depth frame without a pose this close is skipped, >= 0
};

/// One frame of a sequence: when, which file, and the camera pose (optical frame to world).
struct DepthSequenceFrame {
  double time = 0;
  std::string depth_path;         ///< full path of the PNG
  Pose pose = Pose::Identity();
};

/// Reads a 16-bit grayscale PNG of depths: value / \p depth_factor metres, 0 = invalid (NaN).
/// \throws IoError naming the file if it is missing, not a 16-bit one-channel PNG, or corrupt.
inline DepthImage read_depth_png(const std::string& path, double depth_factor = 5000.0) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  if (png_image_begin_read_from_file(&png, path.c_str()) == 0) {
    const std::string message = png.message;
    png_image_free(&png);
    throw IoError("read_depth_png('" + path + "'): " + message);
  }
  if ((png.format & PNG_FORMAT_FLAG_LINEAR) == 0 || (png.format & PNG_FORMAT_FLAG_COLOR) != 0 ||
      png.width == 0 || png.height == 0 || static_cast<unsigned long long>(png.width) * png.height > (1ULL << 28)) {
    png_image_free(&png);
    throw IoError("read_depth_png('" + path + "'): not a 16-bit grayscale depth image");
  }
  png.format = PNG_FORMAT_LINEAR_Y;
  std::vector<std::uint16_t> raw(PNG_IMAGE_SIZE(png) / 2);
  if (png_image_finish_read(&png, nullptr, raw.data(), 0, nullptr) == 0) {
    const std::string message = png.message;
    png_image_free(&png);
    throw IoError("read_depth_png('" + path + "'): corrupt or truncated: " + message);
  }
  DepthImage img(static_cast<int>(png.width), static_cast<int>(png.height));
  for (std::size_t i = 0; i < raw.size(); ++i)
    img.depth[i] = raw[i] == 0 ? std::numeric_limits<float>::quiet_NaN() : static_cast<float>(raw[i] / depth_factor);
  return img;
}

/// The PNG value a depth is stored as: round(depth * depth_factor), 0 for invalid or no-return
/// pixels and for depths beyond 65535 / depth_factor (the format has no "no return").
inline std::uint16_t depth_png_value(float depth, double depth_factor = 5000.0) noexcept {
  if (!(std::isfinite(depth) && depth > 0)) return 0;
  const double v = std::round(double(depth) * depth_factor);
  return v >= 1 && v <= 65535 ? static_cast<std::uint16_t>(v) : 0;
}

/// Writes \p image as a 16-bit grayscale PNG (see depth_png_value()).
/// \throws IoError if the file cannot be written; InvalidArgument for an inconsistent image.
inline void write_depth_png(const std::string& path, const DepthImage& image, double depth_factor = 5000.0) {
  if (!image.consistent() || image.width == 0 || image.height == 0)
    throw InvalidArgument("intervox::write_depth_png: image size does not match its buffer");
  std::vector<std::uint16_t> raw(image.depth.size());
  for (std::size_t i = 0; i < raw.size(); ++i) raw[i] = depth_png_value(image.depth[i], depth_factor);
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(image.width);
  png.height = static_cast<png_uint_32>(image.height);
  png.format = PNG_FORMAT_LINEAR_Y;
  if (png_image_write_to_file(&png, path.c_str(), 0, raw.data(), 0, nullptr) == 0) {
    const std::string message = png.message;
    png_image_free(&png);
    throw IoError("write_depth_png('" + path + "'): " + message);
  }
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
  static DepthSequence open(const std::string& folder, const PinholeIntrinsics& intrinsics, const DepthSequenceOptions& options = {}) {
    intrinsics.validate();
    if (!(std::isfinite(options.depth_factor) && options.depth_factor > 0 && std::isfinite(options.max_time_difference) &&
          options.max_time_difference >= 0))
      throw InvalidArgument("intervox::DepthSequence: need finite depth_factor > 0 and max_time_difference >= 0");
    struct Stamp {
      double time;
      Pose pose;
    };
    std::vector<Stamp> poses;
    for_each_line(folder + "/groundtruth.txt", [&](std::istringstream& in, const std::string& where) {
      double t, x, y, z, qx, qy, qz, qw;
      if (!(in >> t >> x >> y >> z >> qx >> qy >> qz >> qw))
        throw IoError(where + ": expected 'timestamp tx ty tz qx qy qz qw'");
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
    for_each_line(folder + "/depth.txt", [&](std::istringstream& in, const std::string& where) {
      double t;
      std::string file;
      if (!(in >> t >> file) || !std::isfinite(t)) throw IoError(where + ": expected 'timestamp filename'");
      ++s.depth_frames_;
      const auto it = std::lower_bound(poses.begin(), poses.end(), t, [](const Stamp& a, double v) { return a.time < v; });
      const Stamp* best = nullptr;
      if (it != poses.end()) best = &*it;
      if (it != poses.begin() && (!best || t - std::prev(it)->time <= best->time - t)) best = &*std::prev(it);
      if (!best || std::abs(best->time - t) > options.max_time_difference) return;
      s.frames_.push_back({t, folder + "/" + file, best->pose});
    });
    return s;
  }

  /// The associated frames, in the order of depth.txt.
  const std::vector<DepthSequenceFrame>& frames() const noexcept { return frames_; }
  std::size_t size() const noexcept { return frames_.size(); }
  /// Depth frames listed in depth.txt (associated or not).
  std::size_t depth_frames() const noexcept { return depth_frames_; }
  const PinholeIntrinsics& intrinsics() const noexcept { return intrinsics_; }
  const DepthSequenceOptions& options() const noexcept { return options_; }

  /// The depth image of frame \p i. \throws IoError as read_depth_png, or if its size differs
  /// from the intrinsics'; OutOfRange for i >= size().
  DepthImage depth(std::size_t i) const {
    if (i >= frames_.size()) throw OutOfRange("intervox::DepthSequence::depth: frame " + std::to_string(i) + " of " + std::to_string(frames_.size()));
    DepthImage img = read_depth_png(frames_[i].depth_path, options_.depth_factor);
    if (img.width != intrinsics_.width || img.height != intrinsics_.height)
      throw IoError("intervox::DepthSequence: '" + frames_[i].depth_path + "' is " + std::to_string(img.width) + "x" +
                    std::to_string(img.height) + ", the intrinsics say " + std::to_string(intrinsics_.width) + "x" +
                    std::to_string(intrinsics_.height));
    return img;
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
  template <class F>
  static void for_each_line(const std::string& path, F&& f) {
    std::ifstream file(path);
    if (!file) throw IoError("intervox::DepthSequence: cannot open '" + path + "'");
    std::string line;
    for (int n = 1; std::getline(file, line); ++n) {
      const auto first = line.find_first_not_of(" \t\r");
      if (first == std::string::npos || line[first] == '#') continue;
      std::istringstream in(line);
      f(in, "'" + path + "' line " + std::to_string(n));
    }
  }

  PinholeIntrinsics intrinsics_;
  DepthSequenceOptions options_;
  std::vector<DepthSequenceFrame> frames_;
  std::size_t depth_frames_ = 0;
};

/// Writes a sequence in the TUM RGB-D layout into \p folder (created by the caller): one
/// `depth/<index>.png` per image, `depth.txt` and `groundtruth.txt` with the given times and
/// poses (17 significant digits). For tools and tests.
/// \throws IoError if a file cannot be written; InvalidArgument if the lists differ in length.
inline void write_depth_sequence(const std::string& folder, const std::vector<double>& times, const std::vector<DepthImage>& images,
                                 const std::vector<Pose>& poses, double depth_factor = 5000.0) {
  if (times.size() != images.size() || times.size() != poses.size())
    throw InvalidArgument("intervox::write_depth_sequence: times, images and poses differ in length");
  std::ofstream depth(folder + "/depth.txt"), truth(folder + "/groundtruth.txt");
  if (!depth || !truth) throw IoError("intervox::write_depth_sequence: cannot write into '" + folder + "'");
  depth << "# depth maps\n# timestamp filename\n";
  truth << "# ground truth trajectory\n# timestamp tx ty tz qx qy qz qw\n";
  char line[512];
  for (std::size_t i = 0; i < times.size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "depth/%04zu.png", i);
    write_depth_png(folder + "/" + name, images[i], depth_factor);
    std::snprintf(line, sizeof line, "%.6f %s\n", times[i], name);
    depth << line;
    const Eigen::Quaterniond q(poses[i].linear());
    const Point3 t = poses[i].translation();
    std::snprintf(line, sizeof line, "%.6f %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", times[i], t.x(), t.y(), t.z(), q.x(),
                  q.y(), q.z(), q.w());
    truth << line;
  }
  if (!depth.flush() || !truth.flush()) throw IoError("intervox::write_depth_sequence: writing into '" + folder + "' failed");
}

}  // namespace intervox
