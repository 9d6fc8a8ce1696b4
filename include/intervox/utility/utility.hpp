#pragma once
/// \file
/// Moved to intervox/utility/utility_policies.hpp; this forwarding header goes in the next release.

#include <intervox/utility/utility_policies.hpp>
