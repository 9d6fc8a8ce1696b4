#pragma once
/// \file
/// Moved to intervox/view/slice.hpp; this forwarding header goes in the next release.

#include <intervox/view/slice.hpp>
