#pragma once
// A header the param-style check must reject (tests/layering/check_param_style.cmake): it
// validates a parameter by hand instead of with ParamCheck.
#include <intervox/core/error.hpp>

namespace intervox {
inline void hand_check(double v) {
  if (!(v > 0)) throw InvalidArgument("intervox::hand_check: v must be > 0");
}
}  // namespace intervox
