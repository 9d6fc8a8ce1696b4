// libFuzzer target: the grid file loader, for a Bayes and an interval grid, sparse and dense.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "intervox/io/grid_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  try {
    (void)intervox::load_grid_from_memory<intervox::BayesGrid>(bytes);
  } catch (const intervox::Error&) {
  }
  try {
    (void)intervox::load_grid_from_memory<intervox::DenseIntervalGrid>(bytes);
  } catch (const intervox::Error&) {
  }
  return 0;
}
