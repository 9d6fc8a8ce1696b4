#pragma once
/// \file
/// Intervox's own grid file format: save and load any VoxelGrid (every update policy and storage)
/// with its policy parameters, versioned and checksummed.
///
/// Layout (all numbers little-endian, version 1):
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
/// | voxels, sorted by key: x, y, z (i32) then the raw cell (floats as IEEE bits) | count × (12 + cell size) |
/// | CRC-32 of every byte above (u32) | 4 |
///
/// Loading rules:
///  - the file's update policy kName must equal the grid's (IoError naming both otherwise);
///    the storage may differ: any storage loads into any storage of the same policy;
///  - the loaded grid keeps the file's key box if it has one; a DenseStorage grid loaded from an
///    unbounded file gets the smallest box around the stored voxels (an empty unbounded file
///    cannot be loaded into a dense grid: IoError);
///  - the utility policy is recorded for information but not enforced (it holds no state);
///  - every count is checked against the file size before anything is allocated; truncated files,
///    checksum mismatches, unknown versions, invalid parameters, keys out of range or unsorted,
///    and cells the policy could not have produced (NaN, lower > upper) throw IoError naming the
///    file and the problem.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "intervox/core/error.hpp"
#include "intervox/grid/voxel_grid.hpp"
#include "intervox/io/detail/atomic_file.hpp"
#include "intervox/io/detail/binary.hpp"

namespace intervox {

/// Current version of the grid file format written by save_grid.
inline constexpr std::uint32_t kGridFormatVersion = 1;

/// Customisation point: how an update policy's parameters and cells are stored in a grid file.
/// Specialised for BayesLogOdds, IntervalUpdate<Rule> and CompactIntervalUpdate<Rule>; specialise it to save grids of your own
/// policies. Required members:
///  - `static std::vector<double> encode(const U&)` — every parameter as a double;
///  - `static U decode(std::span<const double>)` — the inverse; may throw InvalidArgument;
///  - `static constexpr std::size_t kCellBytes`, `static void write_cell(detail::ByteWriter&, const Cell&)`,
///    `static Cell read_cell(detail::ByteReader&)`;
///  - `static bool valid_cell(const Cell&)` — false for a value the policy could never produce.
/// \tparam U the update policy
template <class U>
struct PolicyCodec;

template <>
struct PolicyCodec<BayesLogOdds> {
  static std::vector<double> encode(const BayesLogOdds& u) {
    const BayesParams& p = u.params();
    return {p.p_hit, p.p_miss, p.clamp_min, p.clamp_max, p.free_threshold, p.occupied_threshold, p.prior,
            p.latch ? 1.0 : 0.0};
  }
  static BayesLogOdds decode(std::span<const double> v) {
    if (v.size() != 8) throw InvalidArgument("expected 8 Bayes parameters, got " + std::to_string(v.size()));
    if (v[7] != 0.0 && v[7] != 1.0) throw InvalidArgument("latch flag must be 0 or 1");
    return BayesLogOdds(BayesParams{v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7] == 1.0});
  }
  static constexpr std::size_t kCellBytes = 4;
  static void write_cell(detail::ByteWriter& w, float c) { w.f32(c); }
  static float read_cell(detail::ByteReader& r) { return r.f32("cell"); }
  static bool valid_cell(float c) { return !std::isnan(c); }
};

template <StateRule Rule>
struct PolicyCodec<IntervalUpdate<Rule>> {
  static std::vector<double> encode(const IntervalUpdate<Rule>& u) {
    const IntervalParams& p = u.params();
    return {p.p_hit,     p.p_miss,         p.initial_lower,      p.initial_upper, p.clamp_min,
            p.clamp_max, p.free_threshold, p.occupied_threshold, p.latch ? 1.0 : 0.0};
  }
  static IntervalUpdate<Rule> decode(std::span<const double> v) {
    if (v.size() != 9) throw InvalidArgument("expected 9 interval parameters, got " + std::to_string(v.size()));
    if (v[8] != 0.0 && v[8] != 1.0) throw InvalidArgument("latch flag must be 0 or 1");
    return IntervalUpdate<Rule>(IntervalParams{v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8] == 1.0});
  }
  static constexpr std::size_t kCellBytes = 8;
  static void write_cell(detail::ByteWriter& w, const IntervalCell& c) {
    w.f32(c.lower);
    w.f32(c.upper);
  }
  static IntervalCell read_cell(detail::ByteReader& r) {
    const float lower = r.f32("cell lower bound");
    return {lower, r.f32("cell upper bound")};
  }
  static bool valid_cell(const IntervalCell& c) {
    return !std::isnan(c.lower) && !std::isnan(c.upper) && c.lower <= c.upper;
  }
};

template <StateRule Rule>
struct PolicyCodec<CompactIntervalUpdate<Rule>> {
  static std::vector<double> encode(const CompactIntervalUpdate<Rule>& u) {
    return PolicyCodec<IntervalUpdate<Rule>>::encode(IntervalUpdate<Rule>(u.params()));
  }
  static CompactIntervalUpdate<Rule> decode(std::span<const double> v) {
    return CompactIntervalUpdate<Rule>(PolicyCodec<IntervalUpdate<Rule>>::decode(v).params());
  }
  static constexpr std::size_t kCellBytes = 4;
  static void write_cell(detail::ByteWriter& w, const CompactIntervalCell& c) {
    w.u16(static_cast<std::uint16_t>(c.lower));
    w.u16(static_cast<std::uint16_t>(c.upper));
  }
  static CompactIntervalCell read_cell(detail::ByteReader& r) {
    const auto lower = static_cast<std::int16_t>(r.u16("cell lower bound"));
    return {lower, static_cast<std::int16_t>(r.u16("cell upper bound"))};
  }
  static bool valid_cell(const CompactIntervalCell& c) {
    using U = CompactIntervalUpdate<Rule>;
    return c.lower != U::kUnobserved && c.upper != U::kUnobserved && c.lower <= c.upper;
  }
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
};

namespace detail {

inline constexpr std::string_view kGridMagic{"IVXGRID\0", 8};
inline constexpr std::uint32_t kMaxGridParams = 64;

/// Parses the header; leaves the reader at the first voxel. Checks only what the header itself
/// can show; the caller checks the voxel block and the checksum.
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
  return info;
}

}  // namespace detail

/// Encodes \p grid in the grid file format (see the file comment).
/// \tparam U, H, S the grid's policies; PolicyCodec<U> must be specialised.
/// Thread safety: reads the grid only; safe concurrently with other const use.
template <class U, class H, class S>
std::string save_grid_to_memory(const VoxelGrid<U, H, S>& grid) {
  using Codec = PolicyCodec<U>;
  using Cell = typename U::Cell;
  std::vector<std::pair<Key, Cell>> voxels;
  grid.for_each_observed([&](const Key& k, const Cell& c) { voxels.emplace_back(k, c); });
  std::sort(voxels.begin(), voxels.end(), [](const auto& a, const auto& b) { return a.first < b.first; });

  detail::ByteWriter w;
  w.bytes(detail::kGridMagic);
  w.u32(kGridFormatVersion);
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
  w.u64(voxels.size());
  w.buffer().reserve(w.buffer().size() + voxels.size() * (12 + Codec::kCellBytes) + 4);
  for (const auto& [k, c] : voxels) {
    w.i32(k.x);
    w.i32(k.y);
    w.i32(k.z);
    Codec::write_cell(w, c);
  }
  w.u32(detail::crc32(w.buffer()));
  return std::move(w.buffer());
}

/// Saves \p grid to \p path: written to a temporary file in the same directory, then renamed, so
/// a failed save never leaves a half-written file in place of a good one.
/// \throws IoError if the file cannot be written.
/// Thread safety: reads the grid only.
template <class U, class H, class S>
void save_grid(const std::string& path, const VoxelGrid<U, H, S>& grid) {
  const std::string bytes = save_grid_to_memory(grid);
  detail::write_file_atomically(path, [&](std::FILE* f) { detail::write_bytes(f, bytes.data(), bytes.size(), path); });
}

/// Reads the header of a grid file held in memory (no checksum check: the header only).
/// \throws IoError if it is not a grid file of a supported version or the header is corrupt.
inline GridFileInfo read_grid_file_info_from_memory(std::string_view bytes, const std::string& source = "<memory>") {
  detail::ByteReader r(bytes, source);
  return detail::parse_grid_header(r);
}

/// Reads the header of the grid file at \p path, e.g. to learn which grid type to load it into.
/// \throws IoError as read_grid_file_info_from_memory, or if the file cannot be read.
inline GridFileInfo read_grid_file_info(const std::string& path) {
  return read_grid_file_info_from_memory(detail::read_file_bytes(path), path);
}

/// Decodes a grid file held in memory into a grid of type \p Grid.
/// \tparam Grid a VoxelGrid whose update policy has a PolicyCodec.
/// \param source names the data in error messages.
/// \throws IoError naming \p source and the problem (see the loading rules in the file comment).
/// Thread safety: reentrant.
template <class Grid>
Grid load_grid_from_memory(std::string_view bytes, const std::string& source = "<memory>") {
  using U = typename Grid::UpdateType;
  using H = typename Grid::UtilityType;
  using S = typename Grid::StorageType;
  using Codec = PolicyCodec<U>;
  using Cell = typename U::Cell;

  detail::ByteReader r(bytes, source);
  const GridFileInfo info = detail::parse_grid_header(r);
  if (info.update_policy != U::kName) {
    r.fail("holds a grid of update policy '" + info.update_policy + "', cannot load it into a grid of policy '" +
           std::string(U::kName) + "'");
  }
  if (info.cell_bytes != Codec::kCellBytes) {
    r.fail("cell size " + std::to_string(info.cell_bytes) + " does not match policy '" + std::string(U::kName) +
           "' (" + std::to_string(Codec::kCellBytes) + " bytes; corrupt)");
  }
  const std::uint64_t record = 12 + Codec::kCellBytes;
  const std::uint64_t available = r.remaining() >= 4 ? r.remaining() - 4 : 0;
  if (r.remaining() < 4 || info.voxel_count > available / record || info.voxel_count * record != available) {
    r.fail("truncated or corrupt file: the header announces " + std::to_string(info.voxel_count) + " voxels (" +
           std::to_string(info.voxel_count * record + 4) + " more bytes) but " + std::to_string(r.remaining()) +
           " bytes follow");
  }
  const std::size_t crc_at = bytes.size() - 4;
  detail::ByteReader crc_reader(bytes.substr(crc_at), source);
  const std::uint32_t stored_crc = crc_reader.u32("checksum");
  if (detail::crc32(bytes.substr(0, crc_at)) != stored_crc) r.fail("checksum mismatch: the file is corrupt");

  U update = [&] {
    try {
      return Codec::decode(info.params);
    } catch (const InvalidArgument& e) {
      r.fail(std::string("invalid policy parameters: ") + e.what());
    }
  }();

  // Read and validate every voxel before building the grid.
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
  if (!box && S::kBounded) {
    if (voxels.empty()) r.fail("an empty unbounded grid cannot be loaded into a '" + std::string(S::kName) + "' grid");
    KeyBox b{voxels.front().first, voxels.front().first};
    for (const auto& [k, c] : voxels) {
      for (int a = 0; a < 3; ++a) {
        b.min[a] = std::min(b.min[a], k[a]);
        b.max[a] = std::max(b.max[a], k[a]);
      }
    }
    box = b;
  }
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
  for (const auto& [k, c] : voxels) {
    Cell* cell = grid->storage().touch(k);
    if (cell == nullptr) r.fail("voxel outside the grid");
    *cell = c;
  }
  return std::move(*grid);
}

/// Loads the grid file at \p path into a grid of type \p Grid (see the loading rules above).
/// \throws IoError naming the path and the problem.
/// Thread safety: reentrant.
template <class Grid>
Grid load_grid(const std::string& path) {
  return load_grid_from_memory<Grid>(detail::read_file_bytes(path), path);
}

}  // namespace intervox
