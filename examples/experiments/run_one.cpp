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
  return examples::with_policies<MobileOffer, Runner>(
      update, utility, []<class U, class H>() -> Runner { return &run_mobile<MobileGrid<U, H>>; });
}

Runner arm_runner(const std::string& update, const std::string& utility) {
  return examples::with_policies<ArmOffer, Runner>(
      update, utility, []<class U, class H>() -> Runner { return &run_arm<ArmGrid<U, H>>; });
}

}  // namespace
}  // namespace detail

RunResult run_one(const RunConfig& c, const SweepOptions& o, const std::string& figure_stem) {
  const auto check = [&](const char* what, const std::string& value, const auto& allowed) {
    if (std::ranges::find(allowed, value) == std::end(allowed))
      throw iv::InvalidArgument("experiments: unknown " + std::string(what) + " '" + value + "'");
  };
  check("planner", c.planner, kPlanners);
  check("room", c.room, kRooms);
  check("rules", c.rules, kRules);
  check("sensor", c.sensor, kSensorConditions);
  if (c.platform == "arm" && (c.planner == "safe" || c.room != "lab" || c.rules != "thesis" || c.sensor != "plain"))
    throw iv::InvalidArgument(
        "experiments: the safe planner, rooms, rules and sensor conditions are the mobile robot's, not the arm's (" +
        c.key() + ")");
  if (c.platform == "mobile") return detail::mobile_runner(c.update, c.utility)(c, o, figure_stem);
  if (c.platform == "arm") return detail::arm_runner(c.update, c.utility)(c, o, figure_stem);
  throw iv::InvalidArgument("experiments: unknown platform '" + c.platform + "'");
}

}  // namespace experiments
