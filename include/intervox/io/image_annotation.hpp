#pragma once
/// \file
/// Moved to intervox/view/image_annotation.hpp; this forwarding header goes in the next release.

#include <intervox/view/image_annotation.hpp>
