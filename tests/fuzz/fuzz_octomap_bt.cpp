// libFuzzer target: the OctoMap .bt importer into a sparse and a dense grid (with a small voxel
// limit and load budget to keep runs fast).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include <intervox/grid/named_grids.hpp>
#include <intervox/io/octomap.hpp>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  intervox::OctomapImportOptions options;
  options.max_voxels = 1 << 16;
  options.max_bytes = std::uint64_t{1} << 20;
  try {
    (void)intervox::read_bt_from_memory<intervox::BayesGrid>(bytes, "<fuzz>", intervox::BayesLogOdds::octomap(),
                                                             options);
  } catch (const intervox::Error&) {
  }
  try {
    (void)intervox::read_bt_from_memory<intervox::DenseBayesGrid>(bytes, "<fuzz>", intervox::BayesLogOdds::octomap(),
                                                                  options);
  } catch (const intervox::Error&) {
  }
  return 0;
}
