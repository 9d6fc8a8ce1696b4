// libFuzzer target: the PLY point cloud reader.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include <intervox/io/point_cloud.hpp>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    (void)intervox::read_ply_points_from_memory(std::string_view(reinterpret_cast<const char*>(data), size));
  } catch (const intervox::Error&) {
  }
  return 0;
}
