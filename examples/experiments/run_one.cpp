// The one translation unit that instantiates the runs of every offered configuration (runs.hpp):
// the experiments program and the experiments tests link it instead of compiling them each.
#include "run_one.hpp"

#include "runs.hpp"

#include <algorithm>
#include <iterator>

namespace experiments {

namespace detail {
namespace {

/// The compile-time configurations, chosen at run time by name (examples/common/policies.hpp).
Runner mobile_runner(const std::string& update, const std::string& utility) {
  return examples::with_policies<MobileOffer, Runner>(update, utility, []<class U, class H>() -> Runner {
    return &run_mobile<MobileGrid<U, H>>;
  });
}

Runner arm_runner(const std::string& update, const std::string& utility) {
  return examples::with_policies<ArmOffer, Runner>(update, utility, []<class U, class H>() -> Runner {
    return &run_arm<ArmGrid<U, H>>;
  });
}

}  // namespace
}  // namespace detail

RunResult run_one(const RunConfig& c, const SweepOptions& o, const std::string& figure_stem) {
  const auto check = [&](const char* what, const std::string& value, std::initializer_list<const char*> allowed) {
    for (const char* v : allowed)
      if (value == v) return;
    throw iv::InvalidArgument("experiments: unknown " + std::string(what) + " '" + value + "'");
  };
  check("planner", c.planner, {"plain", "conflict-aware", "safe"});
  check("room", c.room, {"lab", "annex", "front-only"});
  check("rules", c.rules, {"thesis", "library"});
  if (std::ranges::find(kSensorConditions, c.sensor) == std::end(kSensorConditions))
    throw iv::InvalidArgument("experiments: unknown sensor '" + c.sensor + "'");
  if (c.platform == "arm" && (c.planner == "safe" || c.room != "lab" || c.rules != "thesis" || c.sensor != "plain"))
    throw iv::InvalidArgument("experiments: the safe planner, rooms, rules and sensor conditions are the mobile robot's, not the arm's (" +
                              c.key() + ")");
  if (c.platform == "mobile") return detail::mobile_runner(c.update, c.utility)(c, o, figure_stem);
  if (c.platform == "arm") return detail::arm_runner(c.update, c.utility)(c, o, figure_stem);
  throw iv::InvalidArgument("experiments: unknown platform '" + c.platform + "'");
}

}  // namespace experiments
