#pragma once
/// \file
/// PLY export of a grid's voxels as coloured points or cubes, for MeshLab and CloudCompare.

#include <intervox/core/error.hpp>
#include <intervox/grid/voxel_grid.hpp>
#include <intervox/io/color.hpp>
#include <intervox/io/detail/atomic_file.hpp>
#include <intervox/io/detail/binary.hpp>

#include <array>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

namespace intervox {

/// What a PLY export holds.
struct PlyExportOptions {
  enum class Geometry : std::uint8_t {
    Points,  ///< one vertex per voxel, at its centre
    Cubes,   ///< an axis-aligned cube per voxel: 8 vertices, 6 quads
  };
  enum class Voxels : std::uint8_t {
    Occupied,  ///< only voxels the grid classifies as occupied
    Observed,  ///< every observed voxel
  };
  Geometry geometry = Geometry::Points;
  Voxels voxels = Voxels::Occupied;
  ColorBy color = ColorBy::State;
  bool binary = true;  ///< binary_little_endian (compact) or ascii (readable)
  /// Adds the voxel's `float probability` (the state), `float lower`, `float upper` (its interval;
  /// both the state for Bayes grids) and `uchar class` (Occupancy: 0 unknown, 1 free, 2 occupied)
  /// to every vertex, for colouring and filtering in MeshLab, CloudCompare or Open3D.
  bool voxel_properties = true;
  /// If set, only the selected voxels for which it returns true are exported (e.g. a model's
  /// voxels: the explained-occupied ones, or those of a region). Called from the exporting
  /// thread, once per selected voxel.
  std::function<bool(const Key&)> keep;
};

namespace detail {

/// A voxel selected for the PLY export: its centre, colour and vertex properties.
struct PlyVoxel {
  Point3 center;
  Rgb rgb;
  float probability, lower, upper;
  std::uint8_t cls;
};

/// The voxels of \p grid that options.voxels and options.keep select, in the grid's order.
template <class U, class H, class S>
std::vector<PlyVoxel> collect_ply_voxels(const VoxelGrid<U, H, S>& grid, const PlyExportOptions& options) {
  std::vector<PlyVoxel> items;
  const auto& u = grid.update_policy();
  grid.for_each_observed([&](const Key& k, const typename U::Cell& c) {
    const Occupancy o = u.occupancy(c);
    if (options.voxels == PlyExportOptions::Voxels::Occupied && o != Occupancy::Occupied) return;
    if (options.keep && !options.keep(k)) return;
    const Interval i = u.interval(c);
    items.push_back({grid.center(k), cell_color(grid, c, options.color), static_cast<float>(u.state(c)),
                     static_cast<float>(i.lower), static_cast<float>(i.upper), static_cast<std::uint8_t>(o)});
  });
  return items;
}

/// The PLY header of an export of \p voxels voxels of a grid of update policy \p policy_name.
inline std::string ply_export_header(const PlyExportOptions& options, const std::string& policy_name,
                                     std::size_t voxels) {
  const bool cubes = options.geometry == PlyExportOptions::Geometry::Cubes;
  const std::size_t vertices = voxels * (cubes ? 8 : 1);
  std::string out = "ply\nformat ";
  out += options.binary ? "binary_little_endian" : "ascii";
  out += " 1.0\ncomment Intervox voxel export (" + policy_name + ")\nelement vertex " + std::to_string(vertices) +
         "\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\n"
         "property uchar blue\n";
  if (options.voxel_properties) {
    out += "property float probability\nproperty float lower\nproperty float upper\nproperty uchar class\n";
  }
  if (cubes) out += "element face " + std::to_string(voxels * 6) + "\nproperty list uchar int vertex_indices\n";
  out += "end_header\n";
  return out;
}

/// Appends the vertex at \p p with the colour and properties of \p it, in the export's format.
inline void append_ply_vertex(ByteWriter& w, const Point3& p, const PlyVoxel& it, const PlyExportOptions& options) {
  const Rgb& c = it.rgb;
  if (options.binary) {
    w.f32(static_cast<float>(p.x()));
    w.f32(static_cast<float>(p.y()));
    w.f32(static_cast<float>(p.z()));
    w.u8(c.r);
    w.u8(c.g);
    w.u8(c.b);
    if (options.voxel_properties) {
      w.f32(it.probability);
      w.f32(it.lower);
      w.f32(it.upper);
      w.u8(it.cls);
    }
  } else {
    char line[256];
    int n = std::snprintf(line, sizeof line, "%.9g %.9g %.9g %u %u %u", static_cast<float>(p.x()),
                          static_cast<float>(p.y()), static_cast<float>(p.z()), unsigned{c.r}, unsigned{c.g},
                          unsigned{c.b});
    if (options.voxel_properties) {
      n += std::snprintf(line + n, sizeof line - static_cast<std::size_t>(n), " %.9g %.9g %.9g %u",
                         double{it.probability}, double{it.lower}, double{it.upper}, unsigned{it.cls});
    }
    line[n++] = '\n';
    w.bytes(std::string_view(line, static_cast<std::size_t>(n)));
  }
}

/// Appends the six quads of each of \p cubes cubes (8 vertices each, in order), binary or ASCII.
inline void append_ply_cube_faces(ByteWriter& w, std::size_t cubes, bool binary) {
  // Quads over corner bits (x = 1, y = 2, z = 4), counter-clockwise seen from outside.
  static constexpr std::array<std::array<int, 4>, 6> kFaces{
      {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}}};
  char line[256];
  for (std::size_t i = 0; i < cubes; ++i) {
    const auto base = static_cast<std::int64_t>(i * 8);
    for (const auto& f : kFaces) {
      if (binary) {
        w.u8(4);
        for (const int v : f) w.i32(static_cast<std::int32_t>(base + v));
      } else {
        const int n = std::snprintf(line, sizeof line, "4 %lld %lld %lld %lld\n", static_cast<long long>(base + f[0]),
                                    static_cast<long long>(base + f[1]), static_cast<long long>(base + f[2]),
                                    static_cast<long long>(base + f[3]));
        w.bytes(std::string_view(line, static_cast<std::size_t>(n)));
      }
    }
  }
}

}  // namespace detail

/// Encodes the selected voxels of \p grid as PLY: vertices with `float x, y, z`,
/// `uchar red, green, blue` and (PlyExportOptions::voxel_properties) `float probability, lower,
/// upper`, `uchar class`, plus `face` quads for cubes.
/// Thread safety: reads the grid only.
template <class U, class H, class S>
std::string write_ply_to_memory(const VoxelGrid<U, H, S>& grid, const PlyExportOptions& options = {}) {
  const std::vector<detail::PlyVoxel> items = detail::collect_ply_voxels(grid, options);
  const bool cubes = options.geometry == PlyExportOptions::Geometry::Cubes;
  std::string out = detail::ply_export_header(options, std::string(U::kName), items.size());
  const double h = grid.resolution() / 2;
  detail::ByteWriter w;
  for (const detail::PlyVoxel& it : items) {
    if (!cubes) {
      detail::append_ply_vertex(w, it.center, it, options);
      continue;
    }
    for (int v = 0; v < 8; ++v) {
      detail::append_ply_vertex(w, it.center + Point3((v & 1) ? h : -h, (v & 2) ? h : -h, (v & 4) ? h : -h), it,
                                options);
    }
  }
  if (cubes) detail::append_ply_cube_faces(w, items.size(), options.binary);
  out += w.buffer();
  return out;
}

/// Writes the PLY export of \p grid to \p path (temporary file, then rename).
/// \throws IoError if the file cannot be written.
template <class U, class H, class S>
void write_ply(const std::string& path, const VoxelGrid<U, H, S>& grid, const PlyExportOptions& options = {}) {
  const std::string bytes = write_ply_to_memory(grid, options);
  detail::write_file_atomically(path, [&](std::FILE* f) { detail::write_bytes(f, bytes.data(), bytes.size(), path); });
}

}  // namespace intervox
