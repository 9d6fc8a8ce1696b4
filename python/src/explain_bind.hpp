#pragma once
/// \file
/// What python/src/explain.cpp and lying_surfaces.cpp share: ExplainedSpace is a guarded type
/// (guard.hpp), declared once here before guard.hpp is included.

#include "common.hpp"

#include <intervox/explain/explained_space.hpp>

namespace intervox::python {
template <>
inline constexpr const char* kGuardedName<ExplainedSpace> = "ExplainedSpace";
}  // namespace intervox::python

#include "guard.hpp"
