#pragma once
/// \file
/// Moved to intervox/view/html_view.hpp; this forwarding header goes in the next release.

#include <intervox/view/html_view.hpp>
