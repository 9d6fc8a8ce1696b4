#pragma once
/// \file
/// The grid-file codec (io/policy_codec.hpp) of the Dempster-Shafer update (six parameters, three float masses a cell).
///
/// Thread safety: stateless.

#include <intervox/core/error.hpp>
#include <intervox/core/validate.hpp>
#include <intervox/io/policy_codec.hpp>
#include <intervox/update/dempster_shafer.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace intervox {

template <StateRule Rule>
struct PolicyCodec<DempsterShaferUpdate<Rule>> {
  static std::vector<double> encode(const DempsterShaferUpdate<Rule>& u) {
    const BeliefParams& p = u.params();
    return {p.hit_support,    p.miss_support,       p.discount,
            p.free_threshold, p.occupied_threshold, double(static_cast<int>(p.combination))};
  }
  static DempsterShaferUpdate<Rule> decode(std::span<const double> v) {
    const ParamCheck check("intervox::PolicyCodec<DempsterShaferUpdate>::decode");
    if (v.size() != 6) check.fail("expected 6 belief parameters, got " + std::to_string(v.size()));
    if (v[5] != 0.0 && v[5] != 1.0) check.fail("combination rule must be 0 or 1");
    return DempsterShaferUpdate<Rule>(
        BeliefParams{v[0], v[1], v[2], v[3], v[4], static_cast<BeliefCombination>(int(v[5]))});
  }
  static constexpr std::size_t kCellBytes = 12;
  static void write_cell(detail::ByteWriter& w, const BeliefCell& c) {
    w.f32(c.occ);
    w.f32(c.free);
    w.f32(c.conflict);
  }
  static BeliefCell read_cell(detail::ByteReader& r) {
    const float occ = r.f32("cell mass occupied");
    const float free = r.f32("cell mass free");
    return {occ, free, r.f32("cell conflict mass")};
  }
  /// Masses finite, in [0, 1], occ + free <= 1 (within float rounding).
  static bool valid_cell(const BeliefCell& c) {
    const auto unit = [](float x) { return x >= 0.0f && x <= 1.0f; };  // false for NaN
    return unit(c.occ) && unit(c.free) && unit(c.conflict) && double(c.occ) + double(c.free) <= 1.0 + 1e-6;
  }
};

}  // namespace intervox
