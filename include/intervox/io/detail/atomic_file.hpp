#pragma once
/// \file
/// Internal: write a file through a temporary sibling and an atomic rename, so a failed write never
/// replaces a good file. Not part of the public API.

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <string>
#include <system_error>
#include <thread>

#include "intervox/core/error.hpp"

namespace intervox::detail {

/// A unique temporary name beside `path` (same directory, so the rename stays atomic).
inline std::string temporary_sibling(const std::string& path) {
  static std::atomic<unsigned long long> counter{0};
  const auto thread = std::hash<std::thread::id>{}(std::this_thread::get_id());
  return path + ".tmp-" + std::to_string(thread % 1000003u) + "-" + std::to_string(counter.fetch_add(1));
}

/// Opens a temporary sibling of `path`, calls `write(FILE*)`, flushes, closes and renames it onto
/// `path`. On any failure (an exception from `write`, a short write, a failing close or rename) the
/// temporary file is removed, `path` is left untouched and IoError is thrown naming the path.
template <class Write>
void write_file_atomically(const std::string& path, Write&& write) {
  if (path.empty()) throw IoError("cannot write a file with an empty path");
  const std::string tmp = temporary_sibling(path);
  std::FILE* file = std::fopen(tmp.c_str(), "wb");
  if (file == nullptr) {
    throw IoError("cannot open '" + tmp + "' for writing (for '" + path + "'): " + std::strerror(errno));
  }
  auto discard = [&] {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
  };
  try {
    write(file);
  } catch (...) {
    std::fclose(file);
    discard();
    throw;
  }
  const bool write_failed = std::ferror(file) != 0 || std::fflush(file) != 0;
  const bool close_failed = std::fclose(file) != 0;
  if (write_failed || close_failed) {
    discard();
    throw IoError("writing '" + path + "' failed (disk full or I/O error)");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    discard();
    throw IoError("cannot move the written file onto '" + path + "': " + ec.message());
  }
}

/// Writes `size` bytes or throws IoError naming `path`.
inline void write_bytes(std::FILE* file, const void* data, std::size_t size, const std::string& path) {
  if (size != 0 && std::fwrite(data, 1, size, file) != size) {
    throw IoError("writing '" + path + "' failed (disk full or I/O error)");
  }
}

}  // namespace intervox::detail
