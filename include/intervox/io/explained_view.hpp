#pragma once
/// \file
/// Moved to intervox/view/explained_page_options.hpp; this forwarding header goes in the next release.

#include <intervox/view/explained_page_options.hpp>
