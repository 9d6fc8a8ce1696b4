#pragma once
// A file-format header that breaks the layering on purpose: the check must reject this folder
// (ctest layering.io_includes_detects_view).
#include <intervox/view/slice.hpp>
