// libFuzzer target: the grid file loader, structure-aware. A custom mutator parses the header
// (see the layout in include/intervox/io/grid_file_format.hpp), mutates mostly the payload (a version 2
// body, decompressed first if it is a zstd frame, or the version 1 voxel records), then
// re-derives the length fields (body size, stored size; block and voxel counts from a scan of the
// body, most of the time), re-encodes the body (stored or recompressed with zstd) and recomputes
// the CRC-32, so that nearly every mutation reaches the body decoder, the grid construction and
// the cell checks instead of stopping at "checksum mismatch". A few mutations change one header
// field to an extreme value, or the whole file as bytes (then the checksum is fixed again).
// Every input is loaded into seven grid types: all five update policies, sparse and dense.
//
// The mutator is compiled only for libFuzzer; the corpus replay (corpus_replay.cpp, built with
// any compiler) defines INTERVOX_CORPUS_REPLAY and uses LLVMFuzzerTestOneInput alone.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <random>
#include <string>
#include <string_view>

#include <intervox/grid/named_grids.hpp>
#include <intervox/io/grid_file.hpp>

namespace {

template <class Grid>
void load_one(std::string_view bytes) {
  intervox::GridLoadOptions options;
  options.max_bytes = std::uint64_t{1} << 20;  // 1 MiB: keeps every run fast (the budget logic is the same)
  try {
    (void)intervox::load_grid_from_memory<Grid>(bytes, "<fuzz>", options);
  } catch (const intervox::Error&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  load_one<intervox::BayesGrid>(bytes);
  load_one<intervox::DenseBayesGrid>(bytes);
  load_one<intervox::IntervalGrid>(bytes);
  load_one<intervox::DenseIntervalGrid>(bytes);
  load_one<intervox::CompactIntervalGrid>(bytes);
  load_one<intervox::DirichletGrid>(bytes);
  load_one<intervox::BeliefGrid>(bytes);
  return 0;
}

#ifndef INTERVOX_CORPUS_REPLAY

#include <zstd.h>

extern "C" std::size_t LLVMFuzzerMutate(std::uint8_t* data, std::size_t size, std::size_t max_size);

namespace {

// Offsets of the header fields of a grid file, found without validating their values.
struct Layout {
  std::uint32_t version = 0;
  std::size_t fields[16] = {};  // offsets of the numeric header fields (see parse_layout)
  std::size_t field_bytes[16] = {};
  std::size_t field_count = 0;
  std::size_t voxel_count_at = 0;
  std::size_t block_count_at = 0;  // version 2 only, as the next three
  std::size_t encoding_at = 0;
  std::size_t body_size_at = 0;
  std::size_t stored_size_at = 0;
  std::size_t body_at = 0;  // first byte after the header
  std::uint32_t cell_bytes = 0;
};

std::uint64_t get_le(const std::string& s, std::size_t at, std::size_t n) {
  std::uint64_t v = 0;
  for (std::size_t i = 0; i < n; ++i) v |= std::uint64_t{static_cast<unsigned char>(s[at + i])} << (8 * i);
  return v;
}

void put_le(std::string& s, std::size_t at, std::size_t n, std::uint64_t v) {
  for (std::size_t i = 0; i < n; ++i) s[at + i] = static_cast<char>((v >> (8 * i)) & 0xFFu);
}

std::optional<Layout> parse_layout(const std::string& s) {
  Layout l;
  std::size_t at = 0;
  auto need = [&](std::size_t n) { return s.size() >= at && s.size() - at >= n; };
  auto field = [&](std::size_t n) {
    if (l.field_count < 16) {
      l.fields[l.field_count] = at;
      l.field_bytes[l.field_count] = n;
      ++l.field_count;
    }
    at += n;
  };
  if (!need(12) || std::memcmp(s.data(), "IVXGRID\0", 8) != 0) return std::nullopt;
  at = 8;
  l.version = static_cast<std::uint32_t>(get_le(s, at, 4));
  field(4);
  for (int i = 0; i < 3; ++i) {
    if (!need(2)) return std::nullopt;
    const std::size_t n = get_le(s, at, 2);
    at += 2;
    if (!need(n)) return std::nullopt;
    at += n;
  }
  if (!need(4)) return std::nullopt;
  const std::uint64_t params = get_le(s, at, 4);
  field(4);
  if (params > 64 || !need(8 * params + 33)) return std::nullopt;
  if (params > 0) field(8);  // the first parameter
  at = at - (params > 0 ? 8 : 0) + 8 * params;
  for (int i = 0; i < 4; ++i) field(8);  // resolution, origin
  const auto has_box = static_cast<unsigned char>(s[at]);
  field(1);
  if (has_box == 1) {
    if (!need(24)) return std::nullopt;
    for (int i = 0; i < 6; ++i) field(4);
  }
  if (!need(12)) return std::nullopt;
  l.cell_bytes = static_cast<std::uint32_t>(get_le(s, at, 4));
  field(4);
  l.voxel_count_at = at;
  field(8);
  if (l.version >= 2) {
    if (!need(25)) return std::nullopt;
    l.block_count_at = at;
    field(8);
    l.encoding_at = at;
    field(1);
    l.body_size_at = at;
    field(8);
    l.stored_size_at = at;
    field(8);
  }
  l.body_at = at;
  return l;
}

// Counts the blocks and voxels of a version 2 body the way decode_grid_body reads it, up to the
// first block it cannot parse; \p complete_bytes is the length of the complete blocks.
void scan_body(std::string_view body, std::uint32_t cell_bytes, std::uint64_t& blocks, std::uint64_t& voxels,
               std::size_t& complete_bytes) {
  std::size_t at = 0;
  blocks = voxels = 0;
  complete_bytes = 0;
  auto varint = [&](std::uint64_t& v) {
    v = 0;
    for (int shift = 0; shift < 64; shift += 7) {
      if (at >= body.size()) return false;
      const auto b = static_cast<unsigned char>(body[at++]);
      v |= std::uint64_t{b & 0x7Fu} << shift;
      if ((b & 0x80u) == 0) return true;
    }
    return false;
  };
  while (at < body.size()) {
    std::uint64_t v = 0;
    if (!varint(v) || !varint(v) || !varint(v)) return;
    std::uint64_t pos = 0, block_voxels = 0;
    while (pos < 512) {
      if (!varint(v)) return;
      const std::uint64_t len = (v >> 1) + 1;
      if (len > 512 - pos) return;
      if ((v & 1u) != 0) {
        if (body.size() - at < cell_bytes) return;
        at += cell_bytes;
        block_voxels += len;
      }
      pos += len;
    }
    ++blocks;
    voxels += block_voxels;
    complete_bytes = at;
  }
}

std::uint64_t extreme_value(std::mt19937_64& rng, std::size_t bytes) {
  static constexpr std::uint64_t kValues[] = {0,          1,          2,          7,          8,
                                              255,        256,        511,        512,        513,
                                              0x7FFFFFFF, 0x80000000, 0xFFFFFFFF, 0x3FFFFF,   0x400000,
                                              0xFFC00000, 0xFFC00001, 1u << 20,   0xFFF00000, 0x7FF0000000000000ull,
                                              ~0ull,      ~0ull >> 1, 1ull << 32, 1ull << 40, 0x3FF0000000000000ull};
  std::uint64_t v = kValues[rng() % (sizeof kValues / sizeof kValues[0])];
  if (rng() % 4 == 0) v = rng();
  if (rng() % 8 == 0) v = ~v;
  return bytes >= 8 ? v : v & ((std::uint64_t{1} << (8 * bytes)) - 1);
}

void fix_crc(std::string& s) {
  if (s.size() < 4) return;
  put_le(s, s.size() - 4, 4, intervox::detail::crc32(std::string_view(s).substr(0, s.size() - 4)));
}

std::size_t emit(const std::string& s, std::uint8_t* data, std::size_t max_size) {
  if (s.size() > max_size) return 0;
  std::memcpy(data, s.data(), s.size());
  return s.size();
}

// A whole-file byte mutation, then the checksum fixed (the old target's approach).
std::size_t mutate_bytes(std::uint8_t* data, std::size_t size, std::size_t max_size) {
  size = LLVMFuzzerMutate(data, size, max_size);
  if (size >= 4) {
    std::string s(reinterpret_cast<const char*>(data), size);
    fix_crc(s);
    std::memcpy(data, s.data(), size);
  }
  return size;
}

}  // namespace

extern "C" std::size_t LLVMFuzzerCustomMutator(std::uint8_t* data, std::size_t size, std::size_t max_size,
                                               unsigned int seed) {
  std::mt19937_64 rng(seed);
  std::string file(reinterpret_cast<const char*>(data), size);
  const std::optional<Layout> layout = parse_layout(file);
  const unsigned choice = static_cast<unsigned>(rng() % 100);
  if (!layout || choice < 10) return mutate_bytes(data, size, max_size);
  const Layout& l = *layout;
  std::string header = file.substr(0, l.body_at);
  std::string payload = file.substr(l.body_at, file.size() - l.body_at >= 4 ? file.size() - l.body_at - 4 : 0);

  if (choice < 25) {
    // One header field set to an extreme value (a box corner, a count, the resolution...).
    const std::size_t f = rng() % l.field_count;
    put_le(header, l.fields[f], l.field_bytes[f], extreme_value(rng, l.field_bytes[f]));
    std::string out = header + payload + "    ";
    fix_crc(out);
    return emit(out, data, max_size);
  }

  // The payload: decode a zstd body first (if it is one of a plausible size).
  bool compressed = false;
  if (l.version >= 2 && header[l.encoding_at] == 1) {
    const unsigned long long n = ZSTD_getFrameContentSize(payload.data(), payload.size());
    if (n != ZSTD_CONTENTSIZE_ERROR && n != ZSTD_CONTENTSIZE_UNKNOWN && n <= (1u << 20)) {
      std::string raw(static_cast<std::size_t>(n), '\0');
      const std::size_t got = ZSTD_decompress(raw.data(), raw.size(), payload.data(), payload.size());
      if (!ZSTD_isError(got) && got == n) {
        payload = std::move(raw);
        compressed = true;
      }
    }
  }
  const std::size_t room = max_size > header.size() + 4 ? max_size - header.size() - 4 : 0;
  const std::size_t limit = std::max<std::size_t>(room, payload.size() + 64);
  payload.resize(std::max<std::size_t>(payload.size(), 1));
  const std::size_t old_size = payload.size();
  payload.resize(limit);
  payload.resize(LLVMFuzzerMutate(reinterpret_cast<std::uint8_t*>(payload.data()), old_size, limit));

  if (l.version == 1) {
    // Whole voxel records; the count follows them (most of the time).
    const std::size_t record = 12 + std::size_t{l.cell_bytes};
    if (l.cell_bytes < 64 && rng() % 8 != 0) {
      payload.resize(payload.size() / record * record);
      put_le(header, l.voxel_count_at, 8, payload.size() / record);
    }
  } else {
    if (rng() % 8 != 0 && l.cell_bytes < 64) {
      std::uint64_t blocks = 0, voxels = 0;
      std::size_t complete = 0;
      scan_body(payload, l.cell_bytes, blocks, voxels, complete);
      if (rng() % 2 == 0) payload.resize(complete);  // drop an incomplete last block
      put_le(header, l.block_count_at, 8, blocks);
      put_le(header, l.voxel_count_at, 8, voxels);
    }
    put_le(header, l.body_size_at, 8, payload.size());
    const unsigned encode = static_cast<unsigned>(rng() % 10);
    const bool compress = compressed ? encode < 7 : encode < 2;
    if (compress) {
      std::string frame(ZSTD_compressBound(payload.size()), '\0');
      const std::size_t n = ZSTD_compress(frame.data(), frame.size(), payload.data(), payload.size(), 1);
      if (!ZSTD_isError(n)) {
        frame.resize(n);
        payload = std::move(frame);
        header[l.encoding_at] = 1;
      } else {
        header[l.encoding_at] = 0;
      }
    } else {
      header[l.encoding_at] = 0;
    }
    put_le(header, l.stored_size_at, 8, payload.size());
  }
  std::string out = header + payload + "    ";
  fix_crc(out);
  if (out.size() > max_size) return mutate_bytes(data, size, max_size);
  return emit(out, data, max_size);
}

#endif  // INTERVOX_CORPUS_REPLAY
