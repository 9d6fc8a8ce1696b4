#pragma once
// The 16UC1 depth images (millimetres, 0 = no measurement) the ROS tests publish and record.
#include "ros_conversions.hpp"

#include <cstdint>
#include <cstring>
#include <string>

namespace intervox_ros::test {

/// A 16UC1 image of \p width x \p height pixels in frame \p frame, pixel (u, v) = mm(u, v).
template <class F>
msg::Image depth_image_mm(const std::string& frame, int width, int height, F&& mm) {
  msg::Image image;
  image.header.frame_id = frame;
  image.width = static_cast<std::uint32_t>(width);
  image.height = static_cast<std::uint32_t>(height);
  image.encoding = "16UC1";
  image.step = static_cast<std::uint32_t>(2 * width);
  image.data.resize(image.step * image.height);
  for (int v = 0; v < height; ++v)
    for (int u = 0; u < width; ++u) {
      const std::uint16_t value = mm(u, v);
      std::memcpy(image.data.data() + image.step * static_cast<std::uint32_t>(v) + 2 * u, &value, 2);
    }
  return image;
}

}  // namespace intervox_ros::test
