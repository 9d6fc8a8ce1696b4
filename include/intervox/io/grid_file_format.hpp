#pragma once
/// \file
/// The grid file format of io/grid_file.hpp: its layout, the loading rules, the options and the
/// header's contents, and the version 1 and 2 encoders and decoders (detail) that save_grid and
/// load_grid use. Include io/grid_file.hpp to save and load.
///
/// Layout (all numbers little-endian; version 2 is written, versions 1 and 2 are read):
/// | field | bytes |
/// |---|---|
/// | magic `"IVXGRID\0"` | 8 |
/// | format version (u32) | 4 |
/// | update policy kName, storage kName, utility kName (u16 length + bytes each) | ... |
/// | policy parameter count n (u32) and n doubles (PolicyCodec<U>) | 4 + 8n |
/// | resolution, origin x, y, z (f64) | 32 |
/// | has key box (u8), then min x y z, max x y z (i32) if set | 1 (+24) |
/// | cell size in bytes (u32) | 4 |
/// | voxel count (u64) | 8 |
/// | version 1: voxels, sorted by key: x, y, z (i32) then the raw cell (floats as IEEE bits) | count × (12 + cell size)
/// | | version 2: block count (u64), body encoding (u8: 0 stored, 1 zstd), body size (u64), stored size (u64) | 25 | |
/// version 2: the body, stored or as one zstd frame | stored size | | CRC-32 of every byte above (u32) | 4 |
///
/// The version 2 body holds the 8x8x8 blocks (block coordinate = key >> 3) that contain observed
/// voxels, sorted by block z, y, x. Each block is its coordinate as three zigzag varints (x, y, z;
/// difference to the previous block's, the first to (0, 0, 0)), then runs covering its 512 cells
/// in x-fastest order (index x | y << 3 | z << 6): a varint t, the run being (t >> 1) + 1 cells;
/// if t is odd they are observed and hold one cell value (PolicyCodec<U>::write_cell) that follows
/// t, if even they are unobserved. Unobserved cells are therefore not stored, and runs of equal
/// cells (free space, clamped cells) take one value; zstd then compresses the rest.
///
/// Loading rules:
///  - the file's update policy kName must equal the grid's (IoError naming both otherwise);
///    the storage may differ: any storage loads into any storage of the same policy;
///  - the loaded grid keeps the file's key box if it has one; a DenseStorage grid loaded from an
///    unbounded file gets the smallest box around the stored voxels (an empty unbounded file
///    cannot be loaded into a dense grid: IoError);
///  - the utility policy is recorded for information but not enforced (it holds no state);
///  - every count is checked against the file size before anything is allocated, and the memory
///    the grid would take (and the decompressed body) against the load budget
///    (GridLoadOptions::max_bytes, see load_budget.hpp); truncated files, checksum mismatches,
///    unknown versions, invalid parameters, keys out of range or unsorted, malformed runs, cells
///    the policy could not have produced (NaN, lower > upper), files over the budget and
///    allocation failures throw IoError naming the file and the problem;
///  - sizes formed from header numbers (box volumes, counts times record sizes) are computed with
///    the checked arithmetic of core/checked_math.hpp, so a crafted header cannot make one wrap to
///    a small number (a box of 2^64 voxels is refused, never allocated as an empty array);
///  - names holding bytes outside printable ASCII are refused (corrupt), so that error messages
///    never echo terminal control bytes from a file.

#include <intervox/core/checked_math.hpp>
#include <intervox/core/error.hpp>
#include <intervox/grid/occupancy_grid.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/io/detail/atomic_file.hpp>
#include <intervox/io/detail/binary.hpp>
#include <intervox/io/detail/text.hpp>
#include <intervox/io/detail/zstd.hpp>
#include <intervox/io/load_budget.hpp>
#include <intervox/io/policy_codec.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

namespace intervox {

/// Current version of the grid file format written by save_grid.
inline constexpr std::uint32_t kGridFormatVersion = 2;

/// How save_grid writes a file.
struct GridSaveOptions {
  /// Format version to write: 2 (default, block runs + zstd) or 1 (the uncompressed voxel list,
  /// for readers of Intervox before version 2 of the format).
  std::uint32_t version = kGridFormatVersion;
  /// zstd level of a version 2 body, 1 (fastest) to 19 (smallest); 0 stores the body
  /// uncompressed. Ignored for version 1.
  int compression_level = 9;
};

/// Limits of load_grid.
struct GridLoadOptions {
  /// Load budget in bytes (see load_budget.hpp): the cells of the grid being built (the whole box
  /// of a dense grid, 8^3 cells per block of a sparse grid) and the decompressed body must fit,
  /// otherwise IoError before anything is allocated.
  std::uint64_t max_bytes = kDefaultLoadBudgetBytes;
};

/// What a grid file holds, read from its header (see read_grid_file_info).
struct GridFileInfo {
  std::uint32_t version = 0;
  std::string update_policy;   ///< the policy's kName, e.g. "bayes", "interval-mean"
  std::string storage;         ///< "sparse" or "dense"
  std::string utility;         ///< e.g. "entropy"
  std::vector<double> params;  ///< as PolicyCodec<U>::encode
  double resolution = 0;
  Point3 origin = Point3::Zero();
  std::optional<KeyBox> key_box;
  std::uint32_t cell_bytes = 0;
  std::uint64_t voxel_count = 0;
  std::uint64_t block_count = 0;   ///< version 2: 8^3 blocks holding the voxels (0 for version 1)
  std::uint8_t compression = 0;    ///< version 2: 0 stored body, 1 zstd
  std::uint64_t body_bytes = 0;    ///< version 2: size of the decoded body
  std::uint64_t stored_bytes = 0;  ///< version 2: size of the body in the file
};

namespace detail {

inline constexpr std::string_view kGridMagic{"IVXGRID\0", 8};
inline constexpr std::uint32_t kMaxGridParams = 64;
/// The longest header a grid file can have (three names of 64 bytes, 64 parameters, the box and
/// the counts: 820 bytes), rounded up; read_grid_file_info reads no more.
inline constexpr std::size_t kMaxGridHeaderBytes = 1024;
inline constexpr int kGridBlockLog2 = 3;
inline constexpr std::uint32_t kGridBlockCells = 512;

/// Saturating products of header counts (core/checked_math.hpp): sizes never wrap.
inline std::uint64_t saturating_mul(std::uint64_t a, std::uint64_t b) noexcept {
  return intervox::saturating_mul(a, b);
}

/// Parses the header; leaves the reader at the first voxel (version 1) or the body (version 2).
/// Checks only what the header itself can show; the caller checks the rest and the checksum.
inline GridFileInfo parse_grid_header(ByteReader& r) {
  GridFileInfo info;
  if (r.remaining() < kGridMagic.size() || r.bytes(kGridMagic.size(), "magic") != kGridMagic) {
    r.fail("not an Intervox grid file (bad magic)");
  }
  info.version = r.u32("format version");
  if (info.version == 0 || info.version > kGridFormatVersion) {
    r.fail("format version " + std::to_string(info.version) + " is not supported (this library reads 1.." +
           std::to_string(kGridFormatVersion) + ")");
  }
  info.update_policy = r.str(64, "update policy name");
  info.storage = r.str(64, "storage name");
  info.utility = r.str(64, "utility name");
  // Names are identifiers ("interval-mean"): printable ASCII only, so that no caller ever echoes
  // terminal control bytes of a crafted file.
  for (const std::string* name : {&info.update_policy, &info.storage, &info.utility}) {
    if (std::any_of(name->begin(), name->end(), [](char c) { return c < 0x20 || c > 0x7E; })) {
      r.fail("a policy or storage name holds non-printable bytes: '" + quote_bytes(*name, 64) + "' (corrupt)");
    }
  }
  const std::uint32_t n = r.u32("parameter count");
  if (n > kMaxGridParams) r.fail("parameter count " + std::to_string(n) + " is implausible (corrupt)");
  for (std::uint32_t i = 0; i < n; ++i) info.params.push_back(r.f64("policy parameter"));
  info.resolution = r.f64("resolution");
  for (int a = 0; a < 3; ++a) info.origin[a] = r.f64("origin");
  if (!(std::isfinite(info.resolution) && info.resolution > 0.0) || !is_finite(info.origin)) {
    r.fail("invalid resolution or origin (corrupt)");
  }
  const std::uint8_t has_box = r.u8("key box flag");
  if (has_box > 1) r.fail("invalid key box flag (corrupt)");
  if (has_box == 1) {
    KeyBox b;
    for (int a = 0; a < 3; ++a) b.min[a] = r.i32("key box");
    for (int a = 0; a < 3; ++a) b.max[a] = r.i32("key box");
    for (int a = 0; a < 3; ++a) {
      if (b.min[a] > b.max[a]) r.fail("empty key box (corrupt)");
    }
    if (!in_key_range(b.min) || !in_key_range(b.max)) r.fail("key box outside the key range (corrupt)");
    info.key_box = b;
  }
  info.cell_bytes = r.u32("cell size");
  info.voxel_count = r.u64("voxel count");
  if (info.version >= 2) {
    info.block_count = r.u64("block count");
    info.compression = r.u8("body encoding");
    if (info.compression > 1) r.fail("unknown body encoding " + std::to_string(info.compression) + " (corrupt)");
    info.body_bytes = r.u64("body size");
    info.stored_bytes = r.u64("stored body size");
    if (info.voxel_count < info.block_count || info.voxel_count > saturating_mul(info.block_count, kGridBlockCells)) {
      r.fail(std::to_string(info.voxel_count) + " voxels cannot fill " + std::to_string(info.block_count) +
             " blocks (corrupt)");
    }
    if (info.compression == 0 && info.body_bytes != info.stored_bytes) r.fail("stored body size mismatch (corrupt)");
  }
  return info;
}

/// Sort code of the block holding \p k: block z, y, x (21 bits each, offset to be non-negative).
inline std::uint64_t grid_block_code(const Key& k) noexcept {
  auto c = [](std::int32_t v) {
    return static_cast<std::uint64_t>(static_cast<std::uint32_t>((v >> kGridBlockLog2) + (1 << 20)) & 0x1FFFFFu);
  };
  return (c(k.z) << 42) | (c(k.y) << 21) | c(k.x);
}

/// Index of \p k inside its block, x fastest.
inline std::uint32_t grid_cell_index(const Key& k) noexcept {
  constexpr std::int32_t m = (1 << kGridBlockLog2) - 1;
  return static_cast<std::uint32_t>((k.x & m) | ((k.y & m) << kGridBlockLog2) | ((k.z & m) << (2 * kGridBlockLog2)));
}

template <class Cell>
bool same_cell_bits(const Cell& a, const Cell& b) noexcept {
  return std::memcmp(&a, &b, sizeof(Cell)) == 0;
}

/// Appends one block of the version 2 body: its coordinate (relative to \p prev, updated) and
/// the runs of its 512 \p cells (x fastest). \returns false (and writes nothing) if no cell is
/// observed.
template <class U>
bool encode_grid_block(ByteWriter& w, const U& update, const Key& origin, const typename U::Cell* cells,
                       std::int64_t (&prev)[3]) {
  using Codec = PolicyCodec<U>;
  std::uint32_t first = 0;
  while (first < kGridBlockCells && !update.is_observed(cells[first])) ++first;
  if (first == kGridBlockCells) return false;
  for (int a = 0; a < 3; ++a) {
    const std::int64_t b = origin[a] >> kGridBlockLog2;
    w.svarint(b - prev[a]);
    prev[a] = b;
  }
  for (std::uint32_t pos = 0; pos < kGridBlockCells;) {
    std::uint32_t end = pos + 1;
    if (!update.is_observed(cells[pos])) {
      while (end < kGridBlockCells && !update.is_observed(cells[end])) ++end;
      w.varint(std::uint64_t{end - pos - 1} << 1);
    } else {
      while (end < kGridBlockCells && same_cell_bits(cells[end], cells[pos])) ++end;
      w.varint((std::uint64_t{end - pos - 1} << 1) | 1u);
      Codec::write_cell(w, cells[pos]);
    }
    pos = end;
  }
  return true;
}

/// The version 2 body of \p grid (see the file comment); counts its blocks into \p blocks.
template <class U, class H, class S>
std::string encode_grid_body(const VoxelGrid<U, H, S>& grid, std::uint64_t& blocks) {
  using Cell = typename U::Cell;
  const U& update = grid.update_policy();
  ByteWriter w;
  std::int64_t prev[3] = {0, 0, 0};
  blocks = 0;
  using Container = typename VoxelGrid<U, H, S>::Container;
  if constexpr (std::is_same_v<Container, SparseBlocks<Cell>>) {
    // Sparse storage: its blocks are the file's blocks. for_each visits each block's 512 cells in
    // a row, x fastest from the block's minimum key, so the first cell of every 512 starts one.
    static_assert(SparseBlocks<Cell>::kBlockCells == kGridBlockCells);
    struct BlockRef {
      std::uint64_t code;
      Key origin;
      const Cell* cells;
    };
    std::vector<BlockRef> refs;
    refs.reserve(grid.storage().block_count());
    std::size_t i = 0;
    grid.storage().for_each([&](const Key& k, const Cell& c) {
      if ((i++ % kGridBlockCells) == 0) refs.push_back({grid_block_code(k), k, &c});
    });
    std::sort(refs.begin(), refs.end(), [](const BlockRef& a, const BlockRef& b) { return a.code < b.code; });
    for (const BlockRef& b : refs) blocks += encode_grid_block(w, update, b.origin, b.cells, prev) ? 1 : 0;
  } else {
    // Any other storage: gather the observed voxels, sort them by block and index.
    struct Entry {
      std::uint64_t block;
      std::uint32_t index;
      Key key;
      Cell cell;
    };
    std::vector<Entry> entries;
    entries.reserve(grid.observed_count());
    grid.for_each_observed([&](const Key& k, const Cell& c) {
      entries.push_back({grid_block_code(k), grid_cell_index(k), k, c});
    });
    std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
      return a.block != b.block ? a.block < b.block : a.index < b.index;
    });
    std::vector<Cell> cells(kGridBlockCells, update.unobserved());
    for (std::size_t i = 0; i < entries.size();) {
      std::size_t end = i;
      while (end < entries.size() && entries[end].block == entries[i].block) ++end;
      for (std::size_t k = i; k < end; ++k) cells[entries[k].index] = entries[k].cell;
      constexpr std::int32_t m = ~((1 << kGridBlockLog2) - 1);
      const Key origin{entries[i].key.x & m, entries[i].key.y & m, entries[i].key.z & m};
      blocks += encode_grid_block(w, update, origin, cells.data(), prev) ? 1 : 0;
      for (std::size_t k = i; k < end; ++k) cells[entries[k].index] = update.unobserved();
      i = end;
    }
  }
  return std::move(w.buffer());
}

/// Decodes a version 2 body, checking everything it can (coordinates in range and sorted, runs
/// covering each block exactly, valid observed cells inside the key box, the header's counts),
/// and calls f(key, cell) for every observed voxel.
template <class U, class F>
void decode_grid_body(std::string_view body, const std::string& source, const GridFileInfo& info, const U& update,
                      F&& f) {
  using Codec = PolicyCodec<U>;
  using Cell = typename U::Cell;
  ByteReader r(body, source);
  std::int64_t prev[3] = {0, 0, 0};
  std::uint64_t blocks = 0;
  std::uint64_t voxels = 0;
  std::uint64_t last_code = 0;
  while (r.remaining() > 0) {
    if (++blocks > info.block_count)
      r.fail("the body holds more blocks than the header's " + std::to_string(info.block_count) + " (corrupt)");
    Key origin;
    for (int a = 0; a < 3; ++a) {
      // prev is within the key range, the difference is any 64-bit value: add without overflow.
      const std::optional<std::int64_t> sum = checked_add(prev[a], r.svarint("block coordinate"));
      const std::int64_t b = sum ? *sum : std::numeric_limits<std::int64_t>::max();
      if (b < -(std::int64_t{kKeyLimit} >> kGridBlockLog2) || b >= (std::int64_t{kKeyLimit} >> kGridBlockLog2)) {
        r.fail("block " + std::to_string(blocks - 1) + " lies outside the key range (corrupt)");
      }
      prev[a] = b;
      origin[a] = static_cast<std::int32_t>(b * (1 << kGridBlockLog2));
    }
    const std::uint64_t code = grid_block_code(origin);
    if (blocks > 1 && code <= last_code) r.fail("blocks are not strictly sorted (corrupt)");
    last_code = code;
    std::uint32_t pos = 0;
    std::uint32_t observed = 0;
    while (pos < kGridBlockCells) {
      const std::uint64_t t = r.varint("cell run");
      if ((t >> 1) >= kGridBlockCells - pos) r.fail("a cell run overruns its block (corrupt)");
      const auto len = static_cast<std::uint32_t>(t >> 1) + 1;
      if ((t & 1u) != 0) {
        const Cell c = Codec::read_cell(r);
        if (!Codec::valid_cell(c) || !update.is_observed(c)) {
          r.fail("voxel " + std::to_string(voxels) + " holds an invalid cell value");
        }
        for (std::uint32_t i = pos; i < pos + len; ++i) {
          constexpr std::uint32_t m = (1u << kGridBlockLog2) - 1;
          const Key k{origin.x + static_cast<std::int32_t>(i & m),
                      origin.y + static_cast<std::int32_t>((i >> kGridBlockLog2) & m),
                      origin.z + static_cast<std::int32_t>(i >> (2 * kGridBlockLog2))};
          if (info.key_box && !info.key_box->contains(k)) {
            r.fail("voxel " + std::to_string(voxels) + " lies outside the key box");
          }
          f(k, c);
          ++voxels;
        }
        observed += len;
      }
      pos += len;
    }
    if (observed == 0) r.fail("block " + std::to_string(blocks - 1) + " holds no observed voxel (corrupt)");
  }
  if (blocks != info.block_count || voxels != info.voxel_count) {
    r.fail("the body holds " + std::to_string(blocks) + " blocks and " + std::to_string(voxels) +
           " voxels, the header announces " + std::to_string(info.block_count) + " and " +
           std::to_string(info.voxel_count) + " (corrupt)");
  }
}

/// Writes the header fields shared by every version.
template <class U, class H, class S>
void write_grid_header(ByteWriter& w, const VoxelGrid<U, H, S>& grid, std::uint32_t version, std::uint64_t voxels) {
  using Codec = PolicyCodec<U>;
  w.bytes(kGridMagic);
  w.u32(version);
  w.str(U::kName);
  w.str(S::kName);
  w.str(H::kName);
  const std::vector<double> params = Codec::encode(grid.update_policy());
  w.u32(static_cast<std::uint32_t>(params.size()));
  for (const double v : params) w.f64(v);
  w.f64(grid.geometry().resolution());
  for (int a = 0; a < 3; ++a) w.f64(grid.geometry().origin()[a]);
  const auto& box = grid.key_box();
  w.u8(box ? 1 : 0);
  if (box) {
    for (int a = 0; a < 3; ++a) w.i32(box->min[a]);
    for (int a = 0; a < 3; ++a) w.i32(box->max[a]);
  }
  w.u32(static_cast<std::uint32_t>(Codec::kCellBytes));
  w.u64(voxels);
}

/// Builds a grid of type Grid with \p box (or none) and the file's geometry and policy.
template <class Grid>
Grid make_loaded_grid(const GridFileInfo& info, const std::optional<KeyBox>& box, typename Grid::UpdateType update,
                      const ByteReader& r) {
  using H = typename Grid::UtilityType;
  const GridGeometry geometry(info.resolution, info.origin);
  std::optional<Grid> grid;
  try {
    if (box) {
      // VoxelGrid takes metric bounds; pass the box's voxel centres so that key_box() equals *box.
      const Bounds bounds{geometry.center(box->min), geometry.center(box->max)};
      grid.emplace(geometry, bounds, std::move(update), H{});
    } else {
      grid.emplace(geometry, std::nullopt, std::move(update), H{});
    }
  } catch (const Error& e) {
    r.fail(std::string("cannot create the grid: ") + e.what());
  }
  if (grid->key_box() != box) r.fail("the key box cannot be represented by this grid geometry");
  return std::move(*grid);
}

inline constexpr const char* kGridBudgetOption = "GridLoadOptions::max_bytes";

/// Loads a version 1 file (the reader stands at the first voxel; the checksum is checked).
template <class Grid>
Grid load_grid_v1(ByteReader& r, const GridFileInfo& info, typename Grid::UpdateType update,
                  const GridLoadOptions& options) {
  using U = typename Grid::UpdateType;
  using S = typename Grid::StorageType;
  using Codec = PolicyCodec<U>;
  using Cell = typename U::Cell;
  // Read and validate every voxel before building the grid (the count was checked against the file size).
  std::vector<std::pair<Key, Cell>> voxels;
  voxels.reserve(static_cast<std::size_t>(info.voxel_count));
  for (std::uint64_t i = 0; i < info.voxel_count; ++i) {
    Key k;
    k.x = r.i32("voxel key");
    k.y = r.i32("voxel key");
    k.z = r.i32("voxel key");
    const Cell c = Codec::read_cell(r);
    if (!in_key_range(k)) r.fail("voxel " + std::to_string(i) + " has a key outside the key range");
    if (info.key_box && !info.key_box->contains(k)) r.fail("voxel " + std::to_string(i) + " lies outside the key box");
    if (!voxels.empty() && !(voxels.back().first < k)) r.fail("voxel keys are not strictly sorted (corrupt)");
    if (!Codec::valid_cell(c)) r.fail("voxel " + std::to_string(i) + " holds an invalid cell value");
    voxels.emplace_back(k, c);
  }

  std::optional<KeyBox> box = info.key_box;
  std::uint64_t blocks = 0;
  if constexpr (S::kBounded) {
    if (!box) {
      if (voxels.empty())
        r.fail("an empty unbounded grid cannot be loaded into a '" + std::string(S::kName) + "' grid");
      KeyBox b{voxels.front().first, voxels.front().first};
      for (const auto& [k, c] : voxels) {
        for (int a = 0; a < 3; ++a) {
          b.min[a] = std::min(b.min[a], k[a]);
          b.max[a] = std::max(b.max[a], k[a]);
        }
      }
      box = b;
    }
  } else {
    std::vector<std::uint64_t> codes;
    codes.reserve(voxels.size());
    for (const auto& [k, c] : voxels) codes.push_back(grid_block_code(k));
    std::sort(codes.begin(), codes.end());
    blocks = static_cast<std::uint64_t>(std::unique(codes.begin(), codes.end()) - codes.begin());
  }
  check_load_budget(grid_cell_bytes<Grid>(box, blocks), options.max_bytes, r.source(),
                    "a '" + std::string(S::kName) + "' grid of these voxels", kGridBudgetOption);
  Grid grid = make_loaded_grid<Grid>(info, box, std::move(update), r);
  for (const auto& [k, c] : voxels) {
    Cell* cell = grid.storage().touch(k);
    if (cell == nullptr) r.fail("voxel outside the grid");
    *cell = c;
  }
  return grid;
}

/// Loads a version 2 file (the reader stands at the body; the checksum is checked).
template <class Grid>
Grid load_grid_v2(ByteReader& r, const GridFileInfo& info, typename Grid::UpdateType update,
                  const GridLoadOptions& options) {
  using U = typename Grid::UpdateType;
  using S = typename Grid::StorageType;
  using Codec = PolicyCodec<U>;
  using Cell = typename U::Cell;
  const std::string grid_what = "a '" + std::string(S::kName) + "' grid of these voxels";
  // Budgets first, from the header alone: every voxel needs a cell, a sparse grid a block per
  // block, a dense grid its box; the decoded body is bounded by its blocks and voxels.
  check_load_budget(saturating_mul(info.voxel_count, sizeof(Cell)), options.max_bytes, r.source(),
                    std::to_string(info.voxel_count) + " voxels", kGridBudgetOption);
  if constexpr (S::kBounded) {
    if (info.key_box)
      check_load_budget(grid_cell_bytes<Grid>(info.key_box, 0), options.max_bytes, r.source(), grid_what,
                        kGridBudgetOption);
  } else {
    check_load_budget(grid_cell_bytes<Grid>(std::nullopt, info.block_count), options.max_bytes, r.source(), grid_what,
                      kGridBudgetOption);
  }
  const std::uint64_t body_limit =
      saturating_add(saturating_mul(info.block_count, std::uint64_t{16}),
                     saturating_mul(info.voxel_count, std::uint64_t{4 + Codec::kCellBytes}));
  if (info.body_bytes > body_limit)
    r.fail("body size " + std::to_string(info.body_bytes) + " is implausible (corrupt)");
  check_load_budget(info.body_bytes, options.max_bytes, r.source(), "the decoded body", kGridBudgetOption);

  const std::string_view stored = r.bytes(static_cast<std::size_t>(info.stored_bytes), "body");
  std::string decompressed;
  std::string_view body = stored;
  if (info.compression == 1) {
    decompressed = zstd_decompress(stored, info.body_bytes, r);
    body = decompressed;
  }

  // Pass 1: validate everything and find the box of the voxels; pass 2: fill the grid.
  std::optional<KeyBox> box = info.key_box;
  std::optional<KeyBox> voxel_box;
  decode_grid_body(body, r.source(), info, update, [&](const Key& k, const Cell&) {
    if (!voxel_box) {
      voxel_box = KeyBox{k, k};
      return;
    }
    for (int a = 0; a < 3; ++a) {
      voxel_box->min[a] = std::min(voxel_box->min[a], k[a]);
      voxel_box->max[a] = std::max(voxel_box->max[a], k[a]);
    }
  });
  if constexpr (S::kBounded) {
    if (!box) {
      if (!voxel_box) r.fail("an empty unbounded grid cannot be loaded into a '" + std::string(S::kName) + "' grid");
      box = voxel_box;
      check_load_budget(grid_cell_bytes<Grid>(box, 0), options.max_bytes, r.source(), grid_what, kGridBudgetOption);
    }
  }
  Grid grid = make_loaded_grid<Grid>(info, box, update, r);
  decode_grid_body(body, r.source(), info, update, [&](const Key& k, const Cell& c) {
    Cell* cell = grid.storage().touch(k);
    if (cell == nullptr) r.fail("voxel outside the grid");
    *cell = c;
  });
  return grid;
}

}  // namespace detail

}  // namespace intervox
