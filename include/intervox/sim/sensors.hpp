#pragma once
/// \file
/// Moved to intervox/sim/sensor_aliases.hpp; this forwarding header goes in the next release.

#include <intervox/sim/sensor_aliases.hpp>
