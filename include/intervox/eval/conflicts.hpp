#pragma once
/// \file
/// Moved to intervox/eval/conflict_scoring.hpp; this forwarding header goes in the next release.

#include <intervox/eval/conflict_scoring.hpp>
