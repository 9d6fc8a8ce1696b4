#pragma once
/// \file
/// The grid-file codec (io/policy_codec.hpp) of the imprecise Dirichlet update (five parameters, two 16-bit counts a
/// cell).
///
/// Thread safety: stateless.

#include <intervox/core/error.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/io/policy_codec.hpp>
#include <intervox/update/imprecise_dirichlet.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace intervox {

template <StateRule Rule>
struct PolicyCodec<ImpreciseDirichletUpdate<Rule>> {
  static std::vector<double> encode(const ImpreciseDirichletUpdate<Rule>& u) {
    const DirichletParams& p = u.params();
    return {p.prior_strength, p.free_threshold, p.occupied_threshold, double(static_cast<int>(p.forgetting)),
            double(p.max_count)};
  }
  static ImpreciseDirichletUpdate<Rule> decode(std::span<const double> v) {
    const ParamCheck check("intervox::PolicyCodec<ImpreciseDirichletUpdate>::decode");
    if (v.size() != 5) check.fail("expected 5 Dirichlet parameters, got " + std::to_string(v.size()));
    if (v[3] != 0.0 && v[3] != 1.0) check.fail("forgetting mode must be 0 or 1");
    if (!(v[4] >= 2 && v[4] <= 65535 && v[4] == std::floor(v[4])))
      check.fail("max_count must be a whole number in [2, 65535]");
    return ImpreciseDirichletUpdate<Rule>(DirichletParams{v[0], v[1], v[2], static_cast<DirichletForgetting>(int(v[3])),
                                                          static_cast<std::uint32_t>(v[4])});
  }
  static constexpr std::size_t kCellBytes = 4;
  static void write_cell(detail::ByteWriter& w, const DirichletCell& c) {
    w.u16(c.hits);
    w.u16(c.misses);
  }
  static DirichletCell read_cell(detail::ByteReader& r) {
    const std::uint16_t hits = r.u16("cell hit count");
    return {hits, r.u16("cell miss count")};
  }
  /// Observed cells only: at least one count. (The counts' limit is a parameter of the file; a
  /// count above it is accepted and simply stops or halves at the next update.)
  static bool valid_cell(const DirichletCell& c) { return c.hits != 0 || c.misses != 0; }
};

}  // namespace intervox
