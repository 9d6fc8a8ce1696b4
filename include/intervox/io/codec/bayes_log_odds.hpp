#pragma once
/// \file
/// The grid-file codec (io/policy_codec.hpp) of the Bayes log-odds update (eight parameters, the log-odds as one float
/// a cell).
///
/// Thread safety: stateless.

#include <intervox/core/error.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/io/policy_codec.hpp>
#include <intervox/update/bayes_log_odds.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace intervox {

template <>
struct PolicyCodec<BayesLogOdds> {
  static std::vector<double> encode(const BayesLogOdds& u) {
    const BayesParams& p = u.params();
    return {p.p_hit, p.p_miss,           p.clamp_min, p.clamp_max, p.free_threshold, p.occupied_threshold,
            p.prior, p.latch ? 1.0 : 0.0};
  }
  static BayesLogOdds decode(std::span<const double> v) {
    const ParamCheck check("intervox::PolicyCodec<BayesLogOdds>::decode");
    if (v.size() != 8) check.fail("expected 8 Bayes parameters, got " + std::to_string(v.size()));
    if (v[7] != 0.0 && v[7] != 1.0) check.fail("latch flag must be 0 or 1");
    return BayesLogOdds(BayesParams{v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7] == 1.0});
  }
  static constexpr std::size_t kCellBytes = 4;
  static void write_cell(detail::ByteWriter& w, float c) { w.f32(c); }
  static float read_cell(detail::ByteReader& r) { return r.f32("cell"); }
  static bool valid_cell(float c) { return !std::isnan(c); }
};

}  // namespace intervox
