#pragma once
/// \file
/// The grid-file codec (io/policy_codec.hpp) of the interval updates (nine or ten parameters; two floats a cell, or two
/// 16-bit log-odds in the compact cell).
///
/// Thread safety: stateless.

#include <intervox/core/error.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/io/policy_codec.hpp>
#include <intervox/update/interval_update.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace intervox {

template <StateRule Rule>
struct PolicyCodec<IntervalUpdate<Rule>> {
  static std::vector<double> encode(const IntervalUpdate<Rule>& u) {
    const IntervalParams& p = u.params();
    std::vector<double> v{p.p_hit,     p.p_miss,         p.initial_lower,      p.initial_upper,    p.clamp_min,
                          p.clamp_max, p.free_threshold, p.occupied_threshold, p.latch ? 1.0 : 0.0};
    // The tenth parameter only when set, so that files of the default classification stay
    // readable by earlier versions (which expect nine).
    if (p.classify_unobserved) v.push_back(1.0);
    return v;
  }
  /// Nine parameters (classify_unobserved false) or ten (the tenth: classify_unobserved, 0 or 1).
  static IntervalUpdate<Rule> decode(std::span<const double> v) {
    const ParamCheck check("intervox::PolicyCodec<IntervalUpdate>::decode");
    if (v.size() != 9 && v.size() != 10)
      check.fail("expected 9 or 10 interval parameters, got " + std::to_string(v.size()));
    if (v[8] != 0.0 && v[8] != 1.0) check.fail("latch flag must be 0 or 1");
    if (v.size() == 10 && v[9] != 0.0 && v[9] != 1.0) check.fail("classify_unobserved flag must be 0 or 1");
    IntervalParams p{v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8] == 1.0};
    p.classify_unobserved = v.size() == 10 && v[9] == 1.0;
    return IntervalUpdate<Rule>(p);
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

}  // namespace intervox
