#pragma once
/// \file
/// Moved to intervox/sim/beam_rng.hpp; this forwarding header goes in the next release.

#include <intervox/sim/beam_rng.hpp>
