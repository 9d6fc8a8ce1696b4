// libFuzzer target: the grid file loader, for a Bayes and an interval grid, sparse and dense.
// Every input is loaded twice: as it is, and with its last four bytes replaced by the CRC-32 of
// the rest, so that mutations reach the header fields and the body behind the checksum (a
// version 2 file with body encoding 0 holds its block runs uncompressed).
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include <intervox/grid/named_grids.hpp>
#include <intervox/io/grid_file.hpp>

namespace {

void load_all(std::string_view bytes) {
  intervox::GridLoadOptions options;
  options.max_bytes = std::uint64_t{1} << 20;  // 1 MiB: keeps every run fast (the budget logic is the same)
  try {
    (void)intervox::load_grid_from_memory<intervox::BayesGrid>(bytes, "<fuzz>", options);
  } catch (const intervox::Error&) {
  }
  try {
    (void)intervox::load_grid_from_memory<intervox::DenseIntervalGrid>(bytes, "<fuzz>", options);
  } catch (const intervox::Error&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  load_all(bytes);
  if (size >= 4) {
    std::string fixed(bytes);
    const std::uint32_t crc = intervox::detail::crc32(bytes.substr(0, size - 4));
    for (std::size_t i = 0; i < 4; ++i) fixed[size - 4 + i] = static_cast<char>((crc >> (8 * i)) & 0xFFu);
    if (fixed != bytes) load_all(fixed);
  }
  return 0;
}
