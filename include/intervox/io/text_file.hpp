#pragma once
/// \file
/// Writing a whole text (CSV, JSON, Markdown, reports) to a file, atomically.

#include <intervox/io/detail/atomic_file.hpp>

#include <string>
#include <string_view>

namespace intervox {

/// Writes \p content to \p path through a temporary sibling file and an atomic rename: a failed
/// write leaves an existing file at \p path untouched.
/// \throws IoError naming the path if the file cannot be written or renamed.
/// Thread safety: safe to call concurrently for different paths.
inline void write_text_file(const std::string& path, std::string_view content) {
  detail::write_file_atomically(
      path, [&](std::FILE* file) { detail::write_bytes(file, content.data(), content.size(), path); });
}

}  // namespace intervox
