#pragma once
/// \file
/// Saving and loading explained free space (explain/explained_space.hpp): the classing options,
/// the trusted extent, the three count grids, each an own-format grid file
/// (io/grid_file.hpp) of the hit-and-miss count policy (its codec: io/codec/hit_miss_count.hpp),
/// and the known mirrors (ExplainedSpace::add_mirror()), in one checksummed file. The ledger is
/// not saved: a loaded channel's saved evidence keeps its classes. Grid files of every other
/// policy are unchanged, and load as before.
///
/// Layout (little-endian):
/// | field | bytes |
/// |---|---|
/// | magic `"IVXEXPL\0"` | 8 |
/// | format version (u32, 2; version 1 files, written before mirrors were saved, load with none) | 4 |
/// | option count n (u32, 14; version 2 files written before returned_crossing_inside hold 13, version 1 files 12, or
/// 11 if written before no_return_crossing_angle, and load with the defaults of the options they lack) and n doubles:
/// hit_mass, miss_mass, trusted, suspect and no-return reliability, free and occupied threshold, min_surface_hits,
/// surface_hit_ratio, crossing_tolerance, mid_air_misses, no_return_crossing_angle, min_lying_misses,
/// returned_crossing_inside (0 or 1) | 4 + 8n | | has trusted extent (u8), then min x y z, max x y z (i32) if set | 1
/// (+24) | | three times (trusted, suspect, no-return): size s (u64) and s bytes of a grid file | 3 × (8 + s) | |
/// version 2: mirror count m (u32, at most 65536) and m times 11 doubles: centre x y z, normal x y z, axis_u x y z,
/// half_u, half_v | 4 + 88m | | CRC-32 of every byte above (u32) | 4 |
///
/// Loading checks the magic, the version, the checksum, every size against the bytes that follow,
/// the options (ExplainOptions::validate()), that the grids are unbounded count grids of one
/// geometry, every mirror (PlanePatch::validate()), and each grid against the load budget
/// (GridLoadOptions::max_bytes, per grid); any failure throws IoError naming the file and the problem. Saves are atomic
/// (a failed write leaves the previous file).

#include <intervox/core/error.hpp>
#include <intervox/core/plane_patch.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/explain/explained_space.hpp>
#include <intervox/io/codec/hit_miss_count.hpp>
#include <intervox/io/grid_file.hpp>
#include <intervox/update/hit_miss_count.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace intervox {

namespace detail {
inline constexpr std::string_view kExplainedMagic{"IVXEXPL\0", 8};
inline constexpr std::uint32_t kExplainedVersion = 2;
inline constexpr std::uint32_t kExplainedVersionNoMirrors = 1;  ///< files written before mirrors were saved
inline constexpr std::uint32_t kExplainedMaxMirrors = 65536;
inline constexpr std::uint32_t kExplainedOptionCount = 14;
inline constexpr std::uint32_t kExplainedOptionCountV2 =
    13;  ///< version 2 files written before returned_crossing_inside
inline constexpr std::uint32_t kExplainedOptionCountV1 = 12;  ///< version 1 files: no min_lying_misses
inline constexpr std::uint32_t kExplainedOptionCountBefore =
    11;  ///< version 1 files written before no_return_crossing_angle
}  // namespace detail

/// The file bytes of \p space (see the file comment).
/// \throws InvalidArgument for invalid save options, more than 65536 mirrors or a mirror that is not
///         a valid patch (the loader would refuse the file; ExplainedSpace keeps none such).
/// Thread safety: reads the channel only.
inline std::string save_explained_to_memory(const ExplainedSpace& space, const GridSaveOptions& options = {}) {
  detail::ByteWriter w;
  w.bytes(detail::kExplainedMagic);
  w.u32(detail::kExplainedVersion);
  const ExplainOptions& o = space.options();
  const double values[detail::kExplainedOptionCount] = {o.model.hit_mass,
                                                        o.model.miss_mass,
                                                        o.model.trusted_reliability,
                                                        o.model.suspect_reliability,
                                                        o.model.no_return_reliability,
                                                        o.model.free_threshold,
                                                        o.model.occupied_threshold,
                                                        double(o.min_surface_hits),
                                                        o.surface_hit_ratio,
                                                        o.crossing_tolerance,
                                                        double(o.mid_air_misses),
                                                        o.no_return_crossing_angle,
                                                        double(o.min_lying_misses),
                                                        o.returned_crossing_inside ? 1.0 : 0.0};
  w.u32(detail::kExplainedOptionCount);
  for (const double v : values) w.f64(v);
  const auto& extent = space.trusted_extent();
  w.u8(extent ? 1 : 0);
  if (extent)
    for (const Key& k : {extent->min, extent->max})
      for (int a = 0; a < 3; ++a) w.i32(k[a]);
  for (const BeamClass c : {BeamClass::Trusted, BeamClass::Suspect, BeamClass::NoReturn}) {
    const std::string g = save_grid_to_memory(space.counts(c), options);
    w.u64(g.size());
    w.bytes(g);
  }
  if (space.mirrors().size() > detail::kExplainedMaxMirrors)
    ParamCheck("intervox::save_explained")
        .fail(std::to_string(space.mirrors().size()) + " mirrors, at most " +
              std::to_string(detail::kExplainedMaxMirrors) + " are saved");
  // Never write what the loader refuses (it validates every mirror).
  for (std::size_t i = 0; i < space.mirrors().size(); ++i) {
    try {
      space.mirrors()[i].validate();
    } catch (const InvalidArgument& e) {
      ParamCheck("intervox::save_explained").fail("mirror " + std::to_string(i) + " cannot be saved: " + e.what());
    }
  }
  w.u32(static_cast<std::uint32_t>(space.mirrors().size()));
  for (const PlanePatch& m : space.mirrors()) {
    for (const Point3* p : {&m.center, &m.normal, &m.axis_u})
      for (int a = 0; a < 3; ++a) w.f64((*p)[a]);
    w.f64(m.half_u);
    w.f64(m.half_v);
  }
  w.u32(detail::crc32(w.buffer()));
  return std::move(w.buffer());
}

/// Saves \p space to \p path atomically (a failed save leaves the previous file).
/// \throws IoError if the file cannot be written (or \p path names no regular file); InvalidArgument
///         as save_explained_to_memory().
inline void save_explained(const std::string& path, const ExplainedSpace& space, const GridSaveOptions& options = {}) {
  const std::string bytes = save_explained_to_memory(space, options);
  detail::write_file_atomically(path, [&](std::FILE* f) { detail::write_bytes(f, bytes.data(), bytes.size(), path); });
}

namespace detail {

/// Reads the magic and the version of an explained-free-space file from \p r (at its start) and
/// checks the checksum of \p bytes, the whole file. Returns the version (1 or 2).
inline std::uint32_t read_explained_version(ByteReader& r, std::string_view bytes) {
  if (r.bytes(kExplainedMagic.size(), "magic") != kExplainedMagic)
    r.fail("not an Intervox explained-free-space file (bad magic)");
  const std::uint32_t version = r.u32("version");
  if (version != kExplainedVersion && version != kExplainedVersionNoMirrors)
    r.fail("unsupported explained-free-space file version " + std::to_string(version) + " (this build reads 1 and 2)");
  if (bytes.size() < 4) r.fail("truncated file");
  ByteReader crc_reader(bytes.substr(bytes.size() - 4), r.source());
  if (crc32(bytes.substr(0, bytes.size() - 4)) != crc_reader.u32("checksum"))
    r.fail("checksum mismatch: the file is corrupt");
  return version;
}

/// Reads the option count and the options of a file of \p version (the options a file lacks get
/// their defaults) and validates them.
inline ExplainOptions read_explained_options(ByteReader& r, std::uint32_t version) {
  const std::uint32_t n = r.u32("option count");
  if (version == kExplainedVersion && n != kExplainedOptionCount && n != kExplainedOptionCountV2)
    r.fail("expected " + std::to_string(kExplainedOptionCount) + " or " + std::to_string(kExplainedOptionCountV2) +
           " options, the file holds " + std::to_string(n));
  if (version == kExplainedVersionNoMirrors && n != kExplainedOptionCountV1 && n != kExplainedOptionCountBefore)
    r.fail("expected " + std::to_string(kExplainedOptionCountV1) + " or " +
           std::to_string(kExplainedOptionCountBefore) + " options in a version 1 file, the file holds " +
           std::to_string(n));
  double v[kExplainedOptionCount];
  v[11] = ExplainOptions{}.no_return_crossing_angle;
  v[12] = ExplainOptions{}.min_lying_misses;
  v[13] = ExplainOptions{}.returned_crossing_inside ? 1.0 : 0.0;
  for (std::uint32_t i = 0; i < n; ++i) v[i] = r.f64("option");
  const auto whole = [&](double x, const char* what) {
    if (!(std::isfinite(x) && x == std::floor(x) && x >= 1.0 && x <= 1e6))
      r.fail(std::string("invalid ") + what + " (corrupt)");
    return static_cast<int>(x);
  };
  ExplainOptions o;
  o.model = {v[0], v[1], v[2], v[3], v[4], v[5], v[6]};
  o.min_surface_hits = whole(v[7], "min_surface_hits");
  o.surface_hit_ratio = v[8];
  o.crossing_tolerance = v[9];
  o.mid_air_misses = whole(v[10], "mid_air_misses");
  o.no_return_crossing_angle = v[11];
  o.min_lying_misses = whole(v[12], "min_lying_misses");
  if (v[13] != 0.0 && v[13] != 1.0) r.fail("invalid returned_crossing_inside (corrupt)");
  o.returned_crossing_inside = v[13] == 1.0;
  try {
    o.validate();
  } catch (const InvalidArgument& e) {
    r.fail(std::string("invalid options: ") + e.what());
  }
  return o;
}

/// Reads the trusted extent (its flag, then the box if set).
inline std::optional<KeyBox> read_explained_extent(ByteReader& r) {
  std::optional<KeyBox> extent;
  const std::uint8_t has_extent = r.u8("extent flag");
  if (has_extent > 1) r.fail("invalid extent flag (corrupt)");
  if (has_extent) {
    KeyBox b;
    for (Key* k : {&b.min, &b.max})
      for (int a = 0; a < 3; ++a) (*k)[a] = r.i32("extent");
    if (!in_key_range(b.min) || !in_key_range(b.max)) r.fail("trusted extent outside the key range (corrupt)");
    extent = b;
  }
  return extent;
}

/// Reads the three count grids (trusted, suspect, no-return), each size checked against the bytes
/// that follow, and refuses a fourth grid file where the mirrors (or the checksum) belong.
inline std::array<std::optional<ExplainedSpace::CountGrid>, 3> read_explained_grids(ByteReader& r,
                                                                                    std::string_view bytes,
                                                                                    const GridLoadOptions& options) {
  using CountGrid = ExplainedSpace::CountGrid;
  std::array<std::optional<CountGrid>, 3> grids;
  const char* names[3] = {" (trusted counts)", " (suspect counts)", " (no-return counts)"};
  for (std::size_t i = 0; i < 3; ++i) {
    const std::uint64_t size = r.u64("grid size");
    if (size > r.remaining() || r.remaining() - size < 4)
      r.fail("truncated or corrupt file: a grid of " + std::to_string(size) + " bytes announced");
    grids[i].emplace(load_grid_from_memory<CountGrid>(r.bytes(static_cast<std::size_t>(size), "grid"),
                                                      r.source() + names[i], options));
  }
  // A grid file's size and magic where the mirrors (or the checksum) belong: more than three grids.
  if (r.remaining() >= 8 + kGridMagic.size() + 4 && bytes.substr(r.position() + 8, kGridMagic.size()) == kGridMagic)
    r.fail("a fourth count grid follows the three (an explained-free-space file holds exactly three: the trusted, "
           "suspect and no-return counts; corrupt)");
  return grids;
}

/// Reads the mirrors of a version 2 file (none in a version 1 file), their count checked against
/// the bytes before the checksum, each validated.
inline std::vector<PlanePatch> read_explained_mirrors(ByteReader& r, std::uint32_t version) {
  std::vector<PlanePatch> mirrors;
  if (version >= kExplainedVersion) {
    const std::uint32_t m = r.u32("mirror count");
    if (m > kExplainedMaxMirrors) r.fail(std::to_string(m) + " mirrors announced, at most 65536 (corrupt)");
    if (std::uint64_t{m} * 88 + 4 > r.remaining())
      r.fail("truncated file: " + std::to_string(m) + " mirrors announced (" + std::to_string(std::uint64_t{m} * 88) +
             " bytes), " + std::to_string(r.remaining() - std::min<std::size_t>(r.remaining(), 4)) +
             " bytes follow before the checksum");
    mirrors.resize(m);
    for (std::uint32_t i = 0; i < m; ++i) {
      PlanePatch& p = mirrors[i];
      for (Point3* q : {&p.center, &p.normal, &p.axis_u})
        for (int a = 0; a < 3; ++a) (*q)[a] = r.f64("mirror");
      p.half_u = r.f64("mirror");
      p.half_v = r.f64("mirror");
      try {
        p.validate();
      } catch (const InvalidArgument& e) {
        r.fail("invalid mirror " + std::to_string(i) + " (corrupt): " + e.what());
      }
    }
  }
  return mirrors;
}

}  // namespace detail

/// Decodes an explained-free-space file held in memory (see the file comment).
/// \param source names the data in error messages
/// \throws IoError naming \p source and the problem.
/// Thread safety: reentrant.
inline ExplainedSpace load_explained_from_memory(std::string_view bytes, const std::string& source = "<memory>",
                                                 const GridLoadOptions& options = {}) {
  return detail::guard_allocation(source, [&]() -> ExplainedSpace {
    detail::ByteReader r(bytes, source);
    const std::uint32_t version = detail::read_explained_version(r, bytes);
    const ExplainOptions o = detail::read_explained_options(r, version);
    const std::optional<KeyBox> extent = detail::read_explained_extent(r);
    std::array<std::optional<ExplainedSpace::CountGrid>, 3> grids = detail::read_explained_grids(r, bytes, options);
    std::vector<PlanePatch> mirrors = detail::read_explained_mirrors(r, version);
    if (r.remaining() != 4)
      r.fail(std::to_string(r.remaining() - 4) + " bytes after the " +
             (version >= detail::kExplainedVersion ? "mirrors" : "grids") + " (corrupt)");
    try {
      return ExplainedSpace(o, std::move(*grids[0]), std::move(*grids[1]), std::move(*grids[2]), extent,
                            std::move(mirrors));
    } catch (const InvalidArgument& e) {
      r.fail(e.what());
    }
  });
}

/// Loads the explained-free-space file at \p path (read after its magic checks; directories,
/// devices and FIFOs refused; at most the larger of 1 GiB and 3 x options.max_bytes read).
/// \throws IoError naming the path and the problem.
/// Thread safety: reentrant.
inline ExplainedSpace load_explained(const std::string& path, const GridLoadOptions& options = {}) {
  const std::string bytes = detail::guard_allocation(path, [&] {
    return detail::read_file_bytes(
        path, std::max(detail::kDefaultReadLimitBytes, saturating_mul(options.max_bytes, std::uint64_t{3})),
        detail::kExplainedMagic.size(), [&](std::string_view magic) {
          if (magic != detail::kExplainedMagic)
            throw IoError(path + ": not an Intervox explained-free-space file (bad magic)");
        });
  });
  return load_explained_from_memory(bytes, path, options);
}

}  // namespace intervox
