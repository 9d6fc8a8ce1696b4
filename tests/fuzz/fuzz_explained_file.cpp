// libFuzzer target: the explained-free-space file loader (io/explained_file.hpp). Every input is
// loaded twice: as it is, and with its last four bytes replaced by the CRC-32 of the rest, so that
// mutations reach the options, the extent and the embedded grid files behind the checksum. A file
// that loads must save again and load back with the same mirrors and evidence (what is written can
// be read), and its explained state is queried on and around every mirror (the mirror index).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include <intervox/io/explained_file.hpp>

#include "fuzz_check.hpp"

namespace {

void load(std::string_view bytes) {
  intervox::GridLoadOptions options;
  options.max_bytes = std::uint64_t{1} << 20;  // 1 MiB per grid: keeps every run fast
  std::optional<intervox::ExplainedSpace> space;
  try {
    space.emplace(intervox::load_explained_from_memory(bytes, "<fuzz>", options));
  } catch (const intervox::Error&) {
    return;
  }
  const std::string again = intervox::save_explained_to_memory(*space, intervox::GridSaveOptions{2, 0});
  std::optional<intervox::ExplainedSpace> back;
  try {
    back.emplace(intervox::load_explained_from_memory(again, "<fuzz: saved again>", options));
  } catch (const intervox::Error&) {
    fuzz_check_failed("a loaded explained file, saved again, does not load");
  }
  if (back->mirrors().size() != space->mirrors().size() || back->size() != space->size())
    fuzz_check_failed("a loaded explained file, saved again, loads with other mirrors or evidence");
  const intervox::GridGeometry& g = space->geometry();
  const std::size_t n = std::min<std::size_t>(space->mirrors().size(), 64);
  for (std::size_t i = 0; i < n; ++i) {
    const intervox::PlanePatch& m = space->mirrors()[i];
    if (const std::optional<intervox::Key> k = g.try_key(m.center)) {
      for (int d = -1; d <= 1; ++d) {
        const intervox::Key q{k->x + d, k->y - d, k->z + d};
        if (space->on_mirror(q) != back->on_mirror(q))
          fuzz_check_failed("a saved and loaded mirror holds other voxels");
        (void)space->state(q);
      }
    }
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
