#pragma once
/// \file
/// Moved to intervox/view/exploration_image.hpp; this forwarding header goes in the next release.

#include <intervox/view/exploration_image.hpp>
