#pragma once
/// \file
/// Moved to intervox/io/ply_writer.hpp; this forwarding header goes in the next release.

#include <intervox/io/ply_writer.hpp>
