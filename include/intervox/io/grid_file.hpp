#pragma once
/// \file
/// Intervox's own grid file format: save and load any VoxelGrid (every update policy with a
/// PolicyCodec, every storage) with its policy parameters, versioned, compressed and
/// checksummed. The layout and the loading rules are in io/grid_file_format.hpp; the codecs of
/// Intervox's policies in io/codec/ (io/policy_codec.hpp says how to add one for a policy of your
/// own).

#include <intervox/core/checked_math.hpp>
#include <intervox/core/error.hpp>
#include <intervox/grid/occupancy_grid.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/io/codec/bayes_log_odds.hpp>
#include <intervox/io/codec/dempster_shafer.hpp>
#include <intervox/io/codec/imprecise_dirichlet.hpp>
#include <intervox/io/codec/interval_update.hpp>
#include <intervox/io/detail/atomic_file.hpp>
#include <intervox/io/detail/binary.hpp>
#include <intervox/io/detail/text.hpp>
#include <intervox/io/detail/zstd.hpp>
#include <intervox/io/grid_file_format.hpp>
#include <intervox/io/policy_codec.hpp>

#include <algorithm>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace intervox {

/// Encodes \p grid in the grid file format (see the file comment).
/// \tparam U, H, S the grid's policies; U a GridFilePolicy (PolicyCodec<U> specialised).
/// \throws InvalidArgument for an unknown options.version or a compression level outside 0..19.
/// Thread safety: reads the grid only; safe concurrently with other const use.
template <GridFilePolicy U, class H, class S>
std::string save_grid_to_memory(const VoxelGrid<U, H, S>& grid, const GridSaveOptions& options = {}) {
  using Codec = PolicyCodec<U>;
  using Cell = typename U::Cell;
  if (options.version != 1 && options.version != 2) {
    ParamCheck("intervox::save_grid")
        .fail("format version " + std::to_string(options.version) + " cannot be written (1 or 2)");
  }
  if (options.compression_level < 0 || options.compression_level > 19) {
    ParamCheck("intervox::save_grid")
        .fail("compression level " + std::to_string(options.compression_level) + " outside 0..19");
  }
  detail::ByteWriter w;
  if (options.version == 1) {
    std::vector<std::pair<Key, Cell>> voxels;
    grid.for_each_observed([&](const Key& k, const Cell& c) { voxels.emplace_back(k, c); });
    std::sort(voxels.begin(), voxels.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    detail::write_grid_header(w, grid, 1, voxels.size());
    w.buffer().reserve(w.buffer().size() + voxels.size() * (12 + Codec::kCellBytes) + 4);
    for (const auto& [k, c] : voxels) {
      w.i32(k.x);
      w.i32(k.y);
      w.i32(k.z);
      Codec::write_cell(w, c);
    }
  } else {
    std::uint64_t blocks = 0;
    const std::string body = detail::encode_grid_body(grid, blocks);
    detail::write_grid_header(w, grid, 2, grid.observed_count());
    w.u64(blocks);
    const bool compress = options.compression_level > 0;
    const std::string stored = compress ? detail::zstd_compress(body, options.compression_level) : std::string();
    w.u8(compress ? 1 : 0);
    w.u64(body.size());
    w.u64(compress ? stored.size() : body.size());
    w.bytes(compress ? std::string_view(stored) : std::string_view(body));
  }
  w.u32(detail::crc32(w.buffer()));
  return std::move(w.buffer());
}

/// Saves \p grid to \p path atomically (detail::write_file_atomically: an exclusive temporary beside
/// the file the path names, following symbolic links, fsync, rename, the old permission bits
/// kept), so a failed save never leaves a half-written file in place of a good one.
/// \throws IoError if the file cannot be written; InvalidArgument for invalid options.
/// Thread safety: reads the grid only.
template <GridFilePolicy U, class H, class S>
void save_grid(const std::string& path, const VoxelGrid<U, H, S>& grid, const GridSaveOptions& options = {}) {
  const std::string bytes = save_grid_to_memory(grid, options);
  detail::write_file_atomically(path, [&](std::FILE* f) { detail::write_bytes(f, bytes.data(), bytes.size(), path); });
}

/// Reads the header of a grid file held in memory (no checksum check: the header only).
/// \throws IoError if it is not a grid file of a supported version or the header is corrupt.
inline GridFileInfo read_grid_file_info_from_memory(std::string_view bytes, const std::string& source = "<memory>") {
  detail::ByteReader r(bytes, source);
  return detail::parse_grid_header(r);
}

/// Reads the header of the grid file at \p path, e.g. to learn which grid type to load it into.
/// Reads at most the first detail::kMaxGridHeaderBytes bytes (1 KiB), never the body.
/// \throws IoError as read_grid_file_info_from_memory, or if the file cannot be read or is not a
///   regular file.
inline GridFileInfo read_grid_file_info(const std::string& path) {
  return read_grid_file_info_from_memory(detail::read_file_prefix(path, detail::kMaxGridHeaderBytes), path);
}

/// Decodes a grid file (version 1 or 2) held in memory into a grid of type \p Grid.
/// \tparam Grid a VoxelGrid whose update policy is a GridFilePolicy.
/// \param source names the data in error messages.
/// \param options the load budget (see GridLoadOptions).
/// \throws IoError naming \p source and the problem (see the loading rules in the file comment),
///         including a grid or body larger than options.max_bytes (checked before allocating)
///         and an allocation failure.
/// Thread safety: reentrant.
template <OccupancyGrid Grid>
requires GridFilePolicy<typename Grid::UpdateType> Grid load_grid_from_memory(std::string_view bytes,
                                                                              const std::string& source = "<memory>",
                                                                              const GridLoadOptions& options = {}) {
  using U = typename Grid::UpdateType;
  using Codec = PolicyCodec<U>;
  return detail::guard_allocation(source, [&]() -> Grid {
    detail::ByteReader r(bytes, source);
    const GridFileInfo info = detail::parse_grid_header(r);
    if (info.update_policy != U::kName) {
      r.fail("holds a grid of update policy '" + detail::quote_bytes(info.update_policy, 64) +
             "', cannot load it into a grid of policy '" + std::string(U::kName) + "'");
    }
    if (info.cell_bytes != Codec::kCellBytes) {
      r.fail("cell size " + std::to_string(info.cell_bytes) + " does not match policy '" + std::string(U::kName) +
             "' (" + std::to_string(Codec::kCellBytes) + " bytes; corrupt)");
    }
    const std::uint64_t available = r.remaining() >= 4 ? r.remaining() - 4 : 0;
    if (info.version == 1) {
      const std::uint64_t record = 12 + Codec::kCellBytes;
      if (r.remaining() < 4 || info.voxel_count > available / record || info.voxel_count * record != available) {
        r.fail("truncated or corrupt file: the header announces " + std::to_string(info.voxel_count) + " voxels (" +
               std::to_string(saturating_add(detail::saturating_mul(info.voxel_count, record), std::uint64_t{4})) +
               " more bytes) but " + std::to_string(r.remaining()) + " bytes follow");
      }
    } else if (r.remaining() < 4 || info.stored_bytes != available) {
      r.fail("truncated or corrupt file: the header announces a body of " + std::to_string(info.stored_bytes) +
             " bytes (and a 4-byte checksum) but " + std::to_string(r.remaining()) + " bytes follow");
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
    if (info.version == 1) return detail::load_grid_v1<Grid>(r, info, std::move(update), options);
    return detail::load_grid_v2<Grid>(r, info, std::move(update), options);
  });
}

/// Loads the grid file at \p path into a grid of type \p Grid (see the loading rules above).
/// The file is read in two steps: its 8-byte magic first (a foreign file is refused after reading
/// those bytes), then the rest, at most the larger of detail::kDefaultReadLimitBytes (1 GiB) and
/// options.max_bytes; directories, devices and FIFOs are refused before reading.
/// \throws IoError naming the path and the problem, including a file over the size limit, one that
///   is not a regular file, and an allocation failure while reading.
/// Thread safety: reentrant.
template <OccupancyGrid Grid>
requires GridFilePolicy<typename Grid::UpdateType> Grid load_grid(const std::string& path,
                                                                  const GridLoadOptions& options = {}) {
  const std::string bytes = detail::guard_allocation(path, [&] {
    return detail::read_file_bytes(path, std::max(detail::kDefaultReadLimitBytes, options.max_bytes),
                                   detail::kGridMagic.size(), [&](std::string_view magic) {
                                     if (magic != detail::kGridMagic) {
                                       throw IoError(path + ": not an Intervox grid file (bad magic)");
                                     }
                                   });
  });
  return load_grid_from_memory<Grid>(bytes, path, options);
}

}  // namespace intervox
