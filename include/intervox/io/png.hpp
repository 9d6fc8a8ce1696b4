#pragma once
/// \file
/// PNG images through libpng. Link the CMake target `intervox::png` (created when libpng is found)
/// to use this header; everything else in Intervox works with `intervox::intervox` alone.

#include <intervox/core/error.hpp>
#include <intervox/core/path.hpp>
#include <intervox/io/detail/atomic_file.hpp>
#include <intervox/io/rgb_image.hpp>

#include <png.h>

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace intervox {

/// Writes `image` as an 8-bit RGB PNG. The file is written to a temporary sibling and renamed onto
/// `path`, so a failed write never replaces an existing good file.
/// \throws InvalidArgument if the image size does not match its pixel buffer.
/// \throws IoError if the file cannot be written (the message names the path).
/// Thread safety: safe to call concurrently for different paths.
inline void write_png(const std::string& path, const RgbImage& image) {
  if (image.width <= 0 || image.height <= 0 ||
      image.rgb.size() != static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height) * 3u) {
    ParamCheck("intervox::write_png")
        .fail("image of " + std::to_string(image.width) + "x" + std::to_string(image.height) + " pixels has " +
              std::to_string(image.rgb.size()) + " bytes, expected width*height*3 (writing '" + path + "')");
  }
  detail::write_file_atomically(path, [&](std::FILE* file) {
    png_image png{};
    png.version = PNG_IMAGE_VERSION;
    png.width = static_cast<png_uint_32>(image.width);
    png.height = static_cast<png_uint_32>(image.height);
    png.format = PNG_FORMAT_RGB;
    const int ok = png_image_write_to_stdio(&png, file, 0, image.rgb.data(), 0, nullptr);
    const std::string message = png.message;
    png_image_free(&png);
    if (ok == 0) throw IoError("write_png('" + path + "'): libpng: " + message);
  });
}

/// Reads any PNG (grayscale, palette, alpha, 16-bit are converted) into 8-bit RGB.
/// Meant for tests and tools. Images above 2^28 pixels are refused before allocation.
/// \throws IoError if the file is missing, not a PNG, truncated or corrupt (the message names the path
///         and libpng's reason).
/// Thread safety: safe to call concurrently.
inline RgbImage read_png(const std::string& path) {
  detail::check_path(path);
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  if (png_image_begin_read_from_file(&png, path.c_str()) == 0) {
    const std::string message = png.message;
    png_image_free(&png);
    throw IoError("read_png('" + path + "'): " + message);
  }
  if (png.width == 0 || png.height == 0 || static_cast<unsigned long long>(png.width) * png.height > (1ULL << 28)) {
    png_image_free(&png);
    throw IoError("read_png('" + path + "'): unsupported image size");
  }
  png.format = PNG_FORMAT_RGB;
  RgbImage image{static_cast<int>(png.width), static_cast<int>(png.height), {}};
  image.rgb.resize(PNG_IMAGE_SIZE(png));
  if (png_image_finish_read(&png, nullptr, image.rgb.data(), 0, nullptr) == 0) {
    const std::string message = png.message;
    png_image_free(&png);
    throw IoError("read_png('" + path + "'): corrupt or truncated: " + message);
  }
  return image;
}

}  // namespace intervox
