#pragma once
/// \file
/// The grid-file codec (io/policy_codec.hpp) of the hit-and-miss count policy
/// (update/hit_miss_count.hpp, the count grids of explained free space): no parameters, two
/// 16-bit counts a cell.
///
/// Thread safety: stateless.

#include <intervox/core/error.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/io/policy_codec.hpp>
#include <intervox/update/hit_miss_count.hpp>

#include <cstddef>
#include <span>
#include <string>
#include <vector>

namespace intervox {

template <>
struct PolicyCodec<HitMissCount> {
  static std::vector<double> encode(const HitMissCount&) { return {}; }
  static HitMissCount decode(std::span<const double> v) {
    const ParamCheck check("intervox::PolicyCodec<HitMissCount>::decode");
    if (!v.empty()) check.fail("expected no hit-miss-count parameters, got " + std::to_string(v.size()));
    return {};
  }
  static constexpr std::size_t kCellBytes = 4;
  static void write_cell(detail::ByteWriter& w, const HitMissCount::Cell& c) {
    w.u16(c.hits);
    w.u16(c.misses);
  }
  static HitMissCount::Cell read_cell(detail::ByteReader& r) {
    HitMissCount::Cell c;
    c.hits = r.u16("cell hits");
    c.misses = r.u16("cell misses");
    return c;
  }
  /// A stored cell is an observed one: at least one count.
  static bool valid_cell(const HitMissCount::Cell& c) { return (c.hits | c.misses) != 0; }
};

}  // namespace intervox
