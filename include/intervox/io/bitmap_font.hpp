#pragma once
/// \file
/// Moved to intervox/view/bitmap_font.hpp; this forwarding header goes in the next release.

#include <intervox/view/bitmap_font.hpp>
