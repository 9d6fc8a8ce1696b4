#pragma once
/// \file
/// RgbImage: a plain 8-bit RGB raster, produced by the slice renderer and written by io/png.hpp.
/// This header needs no library; only writing PNG files (io/png.hpp) needs libpng.

#include <intervox/core/error.hpp>
#include <intervox/core/validate.hpp>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace intervox {

/// An 8-bit RGB image, row-major from the top-left, 3 bytes (r, g, b) per pixel.
/// Invariant expected by write_png: `rgb.size() == 3 * width * height`, width and height > 0.
/// Thread safety: a plain value type.
struct RgbImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;

  /// A width × height image filled with one colour.
  /// \throws InvalidArgument if width or height is not positive or the image exceeds 2^28 pixels.
  static RgbImage filled(int width, int height, std::uint8_t r, std::uint8_t g, std::uint8_t b) {
    if (width <= 0 || height <= 0 || static_cast<long long>(width) * height > (1LL << 28)) {
      ParamCheck("intervox::RgbImage::filled")
          .fail("invalid size " + std::to_string(width) + "x" + std::to_string(height));
    }
    RgbImage image{width, height, {}};
    image.rgb.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3u);
    for (std::size_t i = 0; i < image.rgb.size(); i += 3) {
      image.rgb[i] = r;
      image.rgb[i + 1] = g;
      image.rgb[i + 2] = b;
    }
    return image;
  }

  /// Sets pixel (x, y), y counted from the top. Unchecked apart from an assertion-free bounds test:
  /// pixels outside the image are ignored.
  void set(int x, int y, std::uint8_t r, std::uint8_t g, std::uint8_t b) {
    if (x < 0 || y < 0 || x >= width || y >= height) return;
    const std::size_t i =
        (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)) * 3u;
    rgb[i] = r;
    rgb[i + 1] = g;
    rgb[i + 2] = b;
  }
};

}  // namespace intervox
