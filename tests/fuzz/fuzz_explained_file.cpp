// libFuzzer target: the explained-free-space file loader (io/explained_file.hpp). Every input is
// loaded twice: as it is, and with its last four bytes replaced by the CRC-32 of the rest, so that
// mutations reach the options, the extent and the embedded grid files behind the checksum.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include <intervox/io/explained_file.hpp>

namespace {

void load(std::string_view bytes) {
  intervox::GridLoadOptions options;
  options.max_bytes = std::uint64_t{1} << 20;  // 1 MiB per grid: keeps every run fast
  try {
    (void)intervox::load_explained_from_memory(bytes, "<fuzz>", options);
  } catch (const intervox::Error&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  load(bytes);
  if (size >= 4) {
    std::string fixed(bytes);
    const std::uint32_t crc = intervox::detail::crc32(bytes.substr(0, size - 4));
    for (std::size_t i = 0; i < 4; ++i) fixed[size - 4 + i] = static_cast<char>((crc >> (8 * i)) & 0xFFu);
    if (fixed != bytes) load(fixed);
  }
  return 0;
}
