#pragma once
/// \file
/// Checks of file paths given as std::string, shared by every entry point that takes one.
/// Thread safety: stateless functions.

#include <intervox/core/error.hpp>
#include <intervox/core/validate.hpp>

#include <string>

namespace intervox::detail {

/// \throws InvalidArgument naming the path (each NUL byte shown as \0) if \p path contains a NUL
///         byte: the operating system would read it as a shorter name and open another file
///         ("a\0b.ivx" names "a").
inline void check_path(const std::string& path) {
  if (path.find('\0') == std::string::npos) return;
  std::string shown;
  shown.reserve(path.size() + 8);
  for (const char c : path) {
    if (c == '\0')
      shown += "\\0";
    else
      shown += c;
  }
  ParamCheck("intervox").fail("path \"" + shown + "\" contains a NUL byte (shown as \\0): a file name cannot hold one");
}

}  // namespace intervox::detail
