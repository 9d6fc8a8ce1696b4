#pragma once
/// \file
/// Explained free space: beam classes, the evidence channel and its belief (docs/concepts.md,
/// "Explained free space").

#include <intervox/explain/evidence.hpp>
#include <intervox/explain/explained_space.hpp>
