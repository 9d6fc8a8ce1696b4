#pragma once
/// \file
/// OctoMap interoperability without linking OctoMap: export any grid to OctoMap's binary `.bt`
/// format (a maximum-likelihood tree, as `OcTree::writeBinary` writes it) and import a `.bt` file
/// into a Bayes log-odds grid.
///
/// Key mapping: OctoMap's tree has depth 16 and keys `floor(coordinate / resolution) + 32768`;
/// an Intervox key k of a grid with origin o maps to `k + round(o / resolution) + 32768`, which
/// must lie in [0, 65535] on each axis (about +-1.6 km at 5 cm around the origin): an exported
/// voxel beyond that is left out of the tree and counted (OctomapExportSummary::out_of_range).
/// Imported grids have origin 0.

#include <intervox/core/checked_math.hpp>
#include <intervox/core/error.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/grid/occupancy_grid.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/update/bayes_log_odds.hpp>
#include <intervox/io/detail/atomic_file.hpp>
#include <intervox/io/detail/binary.hpp>
#include <intervox/io/detail/text.hpp>
#include <intervox/io/load_budget.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace intervox {

/// How voxels become OctoMap leaves on export.
struct OctomapExportOptions {
  /// Maximum-likelihood rule: an observed voxel whose state is at or above this probability is
  /// written occupied, otherwise free (OctoMap's default occupancy threshold is 0.5).
  double occupied_threshold = 0.5;
  /// If false, observed voxels the grid classifies as Occupancy::Unknown (state between its
  /// thresholds) are left out of the tree (unknown in OctoMap) instead of being rounded by the
  /// maximum-likelihood rule.
  bool include_unknown = true;
};

/// What an export wrote.
struct OctomapExportSummary {
  std::uint64_t voxels = 0;        ///< observed voxels written (as leaves, before pruning)
  std::uint64_t out_of_range = 0;  ///< observed voxels left out: beyond OctoMap's 16-bit key range
};

/// Limits of the `.bt` importer.
struct OctomapImportOptions {
  /// Largest number of voxels a file may expand to (pruned inner leaves expand to 8^levels voxels);
  /// a larger file throws IoError before anything is allocated.
  std::uint64_t max_voxels = std::uint64_t{1} << 27;
  /// Load budget in bytes (see load_budget.hpp): the cells of the grid being built — the box
  /// around the leaves for a dense grid, 8^3 cells per block touched by the (expanded) leaves for
  /// a sparse grid — must fit, otherwise IoError before the grid is allocated.
  std::uint64_t max_bytes = kDefaultLoadBudgetBytes;
};

namespace detail {

inline constexpr std::string_view kBtHeader = "# Octomap OcTree binary file";
inline constexpr int kOctoDepth = 16;
inline constexpr std::int64_t kOctoCenter = 32768;

/// Interleaves three 16-bit keys so that sorting by the code groups octree children; at each
/// level the child index is x | y << 1 | z << 2 (OctoMap's computeChildIdx).
inline std::uint64_t octo_morton(std::uint32_t x, std::uint32_t y, std::uint32_t z) noexcept {
  std::uint64_t code = 0;
  for (int bit = kOctoDepth - 1; bit >= 0; --bit) {
    code = (code << 3) | ((x >> bit) & 1u) | (((y >> bit) & 1u) << 1) | (((z >> bit) & 1u) << 2);
  }
  return code;
}

struct BtLeaf {
  std::uint64_t code;
  bool occupied;
};

/// A subtree being serialised: a (possibly pruned) leaf or an inner node with its bytes.
struct BtNode {
  enum Kind : std::uint8_t { kOccupied = 1, kFree = 2, kInner = 3 } kind;
  std::string bytes;        // inner nodes: this node's two child bytes, then its inner children
  std::uint64_t count = 1;  // nodes in the subtree
};

/// Builds the subtree of leaves[lo, hi) at `level` (levels of voxels below it; 16 = root).
inline BtNode build_bt(const std::vector<BtLeaf>& leaves, std::size_t lo, std::size_t hi, int level) {
  if (level == 0) return {leaves[lo].occupied ? BtNode::kOccupied : BtNode::kFree, {}, 1};
  std::optional<BtNode> children[8];
  const int shift = 3 * (level - 1);
  for (std::size_t i = lo; i < hi;) {
    const auto idx = static_cast<unsigned>((leaves[i].code >> shift) & 7u);
    std::size_t j = i;
    while (j < hi && ((leaves[j].code >> shift) & 7u) == idx) ++j;
    children[idx] = build_bt(leaves, i, j, level - 1);
    i = j;
  }
  // Prune eight equal leaves into one, as OcTree::prune does (never at the root).
  if (level < kOctoDepth) {
    bool uniform = children[0] && children[0]->kind != BtNode::kInner;
    for (int i = 1; i < 8 && uniform; ++i) uniform = children[i] && children[i]->kind == children[0]->kind;
    if (uniform) return {children[0]->kind, {}, 1};
  }
  BtNode node{BtNode::kInner, std::string(2, '\0'), 1};
  for (int i = 0; i < 8; ++i) {
    if (!children[i]) continue;
    const unsigned bits = children[i]->kind == BtNode::kInner ? 3u : (children[i]->kind == BtNode::kOccupied ? 2u : 1u);
    // bit 2i = 1 for free and inner, bit 2i+1 = 1 for occupied and inner
    node.bytes[static_cast<std::size_t>(i / 4)] = static_cast<char>(
        static_cast<unsigned char>(node.bytes[static_cast<std::size_t>(i / 4)]) | (bits << (2 * (i % 4))));
    node.count += children[i]->count;
  }
  for (int i = 0; i < 8; ++i) {
    if (children[i] && children[i]->kind == BtNode::kInner) node.bytes += children[i]->bytes;
  }
  return node;
}

/// Offset from Intervox keys to OctoMap keys for a geometry.
/// \throws InvalidArgument if the origin is not a whole number of voxels.
inline Key octomap_key_offset(const GridGeometry& g) {
  Key off;
  for (int a = 0; a < 3; ++a) {
    const double v = g.origin()[a] / g.resolution();
    const double r = std::round(v);
    if (std::abs(v - r) > 1e-6 || std::abs(r) > 65536.0) {
      ParamCheck("intervox::write_bt")
          .fail("the grid origin must be a whole number of voxels from 0 for an OctoMap export");
    }
    off[a] = static_cast<std::int32_t>(r);
  }
  return off;
}

}  // namespace detail

/// Encodes \p grid as an OctoMap `.bt` file (maximum-likelihood, pruned, as OcTree::writeBinary).
/// Works for every policy: the voxel's state is compared with options.occupied_threshold. A map
/// that reaches beyond OctoMap's key range (see the file comment) is exported without the voxels
/// that lie beyond it: they are left out and counted in \p summary (if given), which also counts
/// the voxels written.
/// \throws InvalidArgument if the grid origin is not a whole number of voxels or the threshold is not in (0, 1).
/// Thread safety: reads the grid only.
template <class U, class H, class S>
std::string write_bt_to_memory(const VoxelGrid<U, H, S>& grid, const OctomapExportOptions& options = {},
                               OctomapExportSummary* summary = nullptr) {
  ParamCheck("intervox::write_bt").in_range("occupied_threshold", options.occupied_threshold, 0, 1, RangeEnds::Open);
  const Key off = detail::octomap_key_offset(grid.geometry());
  std::vector<detail::BtLeaf> leaves;
  std::uint64_t out_of_range = 0;
  const auto& policy = grid.update_policy();
  grid.for_each_observed([&](const Key& k, const typename U::Cell& c) {
    if (!options.include_unknown && policy.occupancy(c) == Occupancy::Unknown) return;
    std::uint32_t ok[3];
    for (int a = 0; a < 3; ++a) {
      const std::int64_t v = std::int64_t{k[a]} + off[a] + detail::kOctoCenter;
      if (v < 0 || v > 65535) {
        ++out_of_range;
        return;
      }
      ok[a] = static_cast<std::uint32_t>(v);
    }
    leaves.push_back({detail::octo_morton(ok[0], ok[1], ok[2]), policy.state(c) >= options.occupied_threshold});
  });
  if (summary) *summary = {leaves.size(), out_of_range};
  std::sort(leaves.begin(), leaves.end(), [](const auto& a, const auto& b) { return a.code < b.code; });
  std::string out(detail::kBtHeader);
  out += "\n# (feel free to add / change comments, but leave the first line as it is!)\n#\n";
  detail::BtNode root{detail::BtNode::kInner, {}, 0};
  if (!leaves.empty()) root = detail::build_bt(leaves, 0, leaves.size(), detail::kOctoDepth);
  char res[64];
  std::snprintf(res, sizeof res, "%.17g", grid.geometry().resolution());
  out += "id OcTree\nsize " + std::to_string(root.count) + "\nres " + res + "\ndata\n";
  out += root.bytes;
  return out;
}

/// Writes \p grid to \p path as OctoMap `.bt` (see write_bt_to_memory), atomically as save_grid
/// (an exclusive temporary beside the file the path names, fsync, rename). Returns the voxels
/// written and those left out beyond OctoMap's key range.
/// \throws as write_bt_to_memory, and IoError if the file cannot be written.
template <class U, class H, class S>
OctomapExportSummary write_bt(const std::string& path, const VoxelGrid<U, H, S>& grid,
                              const OctomapExportOptions& options = {}) {
  OctomapExportSummary summary;
  const std::string bytes = write_bt_to_memory(grid, options, &summary);
  detail::write_file_atomically(path, [&](std::FILE* f) { detail::write_bytes(f, bytes.data(), bytes.size(), path); });
  return summary;
}

namespace detail {

/// Throws the IoError of the `.bt` importer: \p source, then \p what.
[[noreturn]] inline void bt_fail(const std::string& source, const std::string& what) {
  throw IoError(source + ": " + what);
}

/// The header of a `.bt` file: the tree's node count and resolution, and where the tree begins.
struct BtHeader {
  std::uint64_t size = 0;
  double res = 0;
  std::size_t data_pos = 0;  ///< the first byte after the 'data' line
};

/// Parses the header lines up to 'data' (at most 1000 after the first).
/// \throws IoError for a first line that is not the `.bt` header, an unsupported tree type, a bad
///         size or resolution, no 'data' line, no size or resolution, or a size the file cannot hold.
inline BtHeader parse_bt_header(std::string_view bytes, const std::string& source) {
  std::size_t pos = 0;
  auto next_line = [&]() -> std::optional<std::string_view> {
    if (pos >= bytes.size()) return std::nullopt;
    std::size_t end = bytes.find('\n', pos);
    if (end == std::string_view::npos) end = bytes.size();
    std::string_view line = bytes.substr(pos, end - pos);
    pos = std::min(bytes.size(), end + 1);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    return line;
  };
  const auto first = next_line();
  if (!first || first->substr(0, detail::kBtHeader.size()) != detail::kBtHeader) {
    bt_fail(source, "not an OctoMap binary file (first line must be '" + std::string(detail::kBtHeader) + "')");
  }
  std::optional<std::uint64_t> size;
  std::optional<double> res;
  bool data = false;
  for (int lines = 0; lines < 1000 && !data; ++lines) {
    const auto line = next_line();
    if (!line) break;
    if (line->empty() || line->front() == '#') continue;
    const std::size_t space = line->find(' ');
    const std::string_view word = line->substr(0, space);
    const std::string_view value = space == std::string_view::npos ? std::string_view{} : line->substr(space + 1);
    if (word == "data") {
      data = true;
    } else if (word == "id") {
      if (value != "OcTree")
        bt_fail(source, "tree type '" + quote_bytes(value, 40) + "' is not supported (only OcTree)");
    } else if (word == "size") {
      std::uint64_t v = 0;
      const auto [p, ec] = std::from_chars(value.data(), value.data() + value.size(), v);
      if (ec != std::errc{} || p != value.data() + value.size())
        bt_fail(source, "invalid size '" + quote_bytes(value, 40) + "'");
      size = v;
    } else if (word == "res") {
      const std::string text(value);
      char* end = nullptr;
      const double v = std::strtod(text.c_str(), &end);
      if (text.empty() || end != text.c_str() + text.size() || !(std::isfinite(v) && v > 0.0)) {
        bt_fail(source, "invalid resolution '" + quote_bytes(text, 40) + "'");
      }
      res = v;
    }
  }
  if (!data) bt_fail(source, "truncated header: no 'data' line");
  if (!size || !res) bt_fail(source, "header lacks 'size' or 'res'");
  if (*size > saturating_add(saturating_mul(std::uint64_t{bytes.size()}, std::uint64_t{4}), std::uint64_t{1}))
    bt_fail(source, "size " + std::to_string(*size) + " exceeds what the file can hold (corrupt)");
  return {*size, *res, pos};
}

/// A leaf of an imported tree: its prefix key (OctoMap keys), its level (a voxel: 0) and its state.
struct BtImportLeaf {
  std::uint32_t key[3];
  int level;
  bool occupied;
};

/// Reads the tree after the header into its leaves, without expanding them: the nodes are counted
/// against the header's size and the voxels the leaves expand to against options.max_voxels.
/// \throws IoError for a truncated tree, more nodes than the size (or fewer), a voxel with
///         children, or more voxels than options.max_voxels.
inline std::vector<BtImportLeaf> read_bt_leaves(std::string_view bytes, const BtHeader& header,
                                                const std::string& source, const OctomapImportOptions& options) {
  std::size_t pos = header.data_pos;
  std::vector<BtImportLeaf> leaves;
  std::uint64_t nodes = 0;
  std::uint64_t voxels = 0;
  struct Frame {
    std::uint32_t key[3];
    int level;  // levels of voxels below this node (16 = root)
  };
  if (header.size > 0) {
    std::vector<Frame> stack{{{0, 0, 0}, detail::kOctoDepth}};
    nodes = 1;
    // OctoMap writes depth-first, children in index order: a stack visited in reverse order.
    while (!stack.empty()) {
      const Frame f = stack.back();
      stack.pop_back();
      if (bytes.size() - pos < 2) bt_fail(source, "truncated tree data after " + std::to_string(nodes) + " nodes");
      const auto b0 = static_cast<unsigned char>(bytes[pos]);
      const auto b1 = static_cast<unsigned char>(bytes[pos + 1]);
      pos += 2;
      std::vector<Frame> inner;
      for (int i = 0; i < 8; ++i) {
        const unsigned bits = ((i < 4 ? b0 : b1) >> (2 * (i % 4))) & 3u;
        if (bits == 0) continue;
        if (++nodes > header.size)
          bt_fail(source, "the tree holds more nodes than its size " + std::to_string(header.size) + " (corrupt)");
        const int level = f.level - 1;
        Frame c{{f.key[0] | (static_cast<std::uint32_t>(i & 1) << level),
                 f.key[1] | (static_cast<std::uint32_t>((i >> 1) & 1) << level),
                 f.key[2] | (static_cast<std::uint32_t>((i >> 2) & 1) << level)},
                level};
        if (bits == 3) {
          if (level == 0) bt_fail(source, "a voxel at depth 16 claims children (corrupt)");
          inner.push_back(c);
        } else {
          voxels = saturating_add(voxels, std::uint64_t{1} << (3 * level));
          if (voxels > options.max_voxels) {
            bt_fail(source, "the tree expands to more than " + std::to_string(options.max_voxels) + " voxels");
          }
          leaves.push_back({{c.key[0], c.key[1], c.key[2]}, level, bits == 2});
        }
      }
      for (auto it = inner.rbegin(); it != inner.rend(); ++it) stack.push_back(*it);
    }
  }
  if (nodes != header.size) {
    bt_fail(source,
            "tree size mismatch: read " + std::to_string(nodes) + " nodes, header says " + std::to_string(header.size));
  }
  return leaves;
}

/// The Intervox key of OctoMap key \p k moved by (dx, dy, dz).
inline Key bt_import_key(const std::uint32_t* k, std::uint32_t dx, std::uint32_t dy, std::uint32_t dz) {
  return Key{static_cast<std::int32_t>(k[0] + dx) - static_cast<std::int32_t>(detail::kOctoCenter),
             static_cast<std::int32_t>(k[1] + dy) - static_cast<std::int32_t>(detail::kOctoCenter),
             static_cast<std::int32_t>(k[2] + dz) - static_cast<std::int32_t>(detail::kOctoCenter)};
}

/// The smallest key box around the (expanded) leaves; \p leaves is not empty.
inline KeyBox bt_leaf_box(const std::vector<BtImportLeaf>& leaves) {
  KeyBox box{bt_import_key(leaves[0].key, 0, 0, 0), bt_import_key(leaves[0].key, 0, 0, 0)};
  for (const BtImportLeaf& l : leaves) {
    const std::uint32_t n = (1u << l.level) - 1;
    const Key lo = bt_import_key(l.key, 0, 0, 0);
    const Key hi = bt_import_key(l.key, n, n, n);
    for (int a = 0; a < 3; ++a) {
      box.min[a] = std::min(box.min[a], lo[a]);
      box.max[a] = std::max(box.max[a], hi[a]);
    }
  }
  return box;
}

/// Blocks of 8^3 voxels the leaves touch: a leaf of level >= 3 covers 8^(level - 3) whole blocks of
/// its own (keys are offset by 32768, a multiple of 8); smaller leaves share blocks.
inline std::uint64_t bt_leaf_blocks(const std::vector<BtImportLeaf>& leaves) {
  std::uint64_t blocks = 0;
  std::vector<std::uint64_t> small;
  for (const BtImportLeaf& l : leaves) {
    if (l.level >= 3) {
      blocks = saturating_add(blocks, std::uint64_t{1} << (3 * (l.level - 3)));
    } else {
      small.push_back(std::uint64_t{l.key[0] >> 3} | (std::uint64_t{l.key[1] >> 3} << 13) |
                      (std::uint64_t{l.key[2] >> 3} << 26));
    }
  }
  std::sort(small.begin(), small.end());
  blocks += static_cast<std::uint64_t>(std::unique(small.begin(), small.end()) - small.begin());
  return blocks;
}

/// Creates the empty grid the leaves are loaded into, after checking it against the load budget:
/// for a bounded grid the box around the leaves, for a sparse one the blocks they touch.
/// \throws IoError for an empty tree and a bounded grid, a grid over options.max_bytes, or a
///         bounded grid that cannot be created.
template <class Grid>
Grid create_bt_grid(const std::vector<BtImportLeaf>& leaves, double res, const std::string& source, BayesLogOdds policy,
                    const OctomapImportOptions& options) {
  const GridGeometry geometry(res);
  std::optional<Grid> grid;
  const char* budget_option = "OctomapImportOptions::max_bytes";
  if constexpr (Grid::StorageType::kBounded) {
    if (leaves.empty()) bt_fail(source, "an empty tree cannot be loaded into a bounded grid");
    const KeyBox box = bt_leaf_box(leaves);
    check_load_budget(grid_cell_bytes<Grid>(box, 0), options.max_bytes, source,
                      "a '" + std::string(Grid::StorageType::kName) + "' grid around the tree's leaves", budget_option);
    try {
      grid.emplace(geometry, Bounds{geometry.center(box.min), geometry.center(box.max)}, policy);
    } catch (const Error& e) {
      bt_fail(source, std::string("cannot create the grid: ") + e.what());
    }
  } else {
    const std::uint64_t blocks = bt_leaf_blocks(leaves);
    check_load_budget(grid_cell_bytes<Grid>(std::nullopt, blocks), options.max_bytes, source,
                      "a '" + std::string(Grid::StorageType::kName) + "' grid of the expanded tree", budget_option);
    grid.emplace(geometry, std::nullopt, policy);
  }
  return std::move(*grid);
}

/// Sets every voxel of the (expanded) leaves: occupied leaves to the policy's upper clamp, free
/// leaves to its lower clamp.
template <class Grid>
void fill_bt_leaves(Grid& grid, const std::vector<BtImportLeaf>& leaves) {
  const float occupied = grid.update_policy().clamp_max_log_odds();
  const float free = grid.update_policy().clamp_min_log_odds();
  for (const BtImportLeaf& l : leaves) {
    const std::uint32_t n = 1u << l.level;
    for (std::uint32_t dz = 0; dz < n; ++dz)
      for (std::uint32_t dy = 0; dy < n; ++dy)
        for (std::uint32_t dx = 0; dx < n; ++dx) {
          if (float* c = grid.storage().touch(bt_import_key(l.key, dx, dy, dz))) *c = l.occupied ? occupied : free;
        }
  }
}

/// read_bt_from_memory without the conversion of allocation failures.
template <class Grid>
Grid read_bt_unguarded(std::string_view bytes, const std::string& source, BayesLogOdds policy,
                       const OctomapImportOptions& options) {
  const BtHeader header = parse_bt_header(bytes, source);
  const std::vector<BtImportLeaf> leaves = read_bt_leaves(bytes, header, source, options);
  Grid grid = create_bt_grid<Grid>(leaves, header.res, source, std::move(policy), options);
  fill_bt_leaves(grid, leaves);
  return grid;
}

}  // namespace detail

/// Decodes an OctoMap `.bt` file held in memory into a Bayes grid, as OctoMap reads it: occupied
/// leaves get the policy's upper clamp in log-odds, free leaves the lower clamp (±inf for a
/// latching policy); pruned inner leaves are expanded to voxels. The grid has origin 0 and the
/// file's resolution; a bounded (dense) grid gets the smallest box around the leaves.
/// \tparam Grid a VoxelGrid with the BayesLogOdds update policy (by default BayesGrid).
/// \throws IoError naming \p source and the problem for a malformed header, a tree that is
///         truncated, deeper than 16 levels or inconsistent with its `size`, larger than
///         options.max_voxels or options.max_bytes (checked before the grid is allocated), and
///         for an allocation failure.
/// Thread safety: reentrant.
template <OccupancyGrid Grid = VoxelGrid<BayesLogOdds>>
Grid read_bt_from_memory(std::string_view bytes, const std::string& source = "<memory>",
                         BayesLogOdds policy = BayesLogOdds::octomap(), const OctomapImportOptions& options = {}) {
  static_assert(std::is_same_v<typename Grid::UpdateType, BayesLogOdds>,
                "read_bt loads into grids with the BayesLogOdds policy");
  return detail::guard_allocation(
      source, [&]() -> Grid { return detail::read_bt_unguarded<Grid>(bytes, source, std::move(policy), options); });
}

/// Reads the OctoMap `.bt` file at \p path (see read_bt_from_memory).
/// \throws IoError naming the path and the problem.
/// The file must be a regular file of at most detail::kDefaultReadLimitBytes (1 GiB); a file whose
/// first bytes are not the `.bt` header line is refused after reading those bytes.
template <OccupancyGrid Grid = VoxelGrid<BayesLogOdds>>
Grid read_bt(const std::string& path, BayesLogOdds policy = BayesLogOdds::octomap(),
             const OctomapImportOptions& options = {}) {
  const std::string bytes = detail::guard_allocation(path, [&] {
    return detail::read_file_bytes(path, detail::kDefaultReadLimitBytes, detail::kBtHeader.size(),
                                   [&](std::string_view head) {
                                     if (head != detail::kBtHeader) {
                                       throw IoError(path + ": not an OctoMap binary file (first line must be '" +
                                                     std::string(detail::kBtHeader) + "')");
                                     }
                                   });
  });
  return read_bt_from_memory<Grid>(bytes, path, std::move(policy), options);
}

}  // namespace intervox
