#pragma once
// Helpers shared by the io tests: a self-removing temporary directory, whole-file reads/writes,
// and loads run under a capped address space.

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <sstream>
#include <string>

#include <intervox/core/error.hpp>
#include <intervox/io/detail/binary.hpp>

class TempDir {
 public:
  TempDir() {
    static std::atomic<int> counter{0};
    std::random_device rd;
    path_ = std::filesystem::temp_directory_path() /
            ("intervox_io_" + std::to_string(rd()) + "_" + std::to_string(counter++));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

inline std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

inline void write_all(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

inline std::size_t count_files(const std::filesystem::path& dir) {
  std::size_t n = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir)) ++n;
  return n;
}

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define INTERVOX_TEST_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define INTERVOX_TEST_SANITIZED 1
#endif
#endif

/// Runs \p f (returning an int in 0..125) in a forked child whose address space is capped at
/// \p limit bytes, so that a loader that tries to allocate gigabytes fails there instead of
/// swapping the machine; returns f's result, or 126 if the child died (signal, abort). Under a
/// sanitizer (which reserves terabytes of address space) f runs in this process, uncapped.
template <class F>
int run_with_address_limit(std::uint64_t limit, F f) {
#ifdef INTERVOX_TEST_SANITIZED
  (void)limit;
  return f();
#else
  std::fflush(nullptr);
  const pid_t pid = fork();
  if (pid < 0) return 127;
  if (pid == 0) {
    rlimit r{static_cast<rlim_t>(limit), static_cast<rlim_t>(limit)};
    setrlimit(RLIMIT_AS, &r);
    _exit(f());
  }
  int status = 0;
  if (waitpid(pid, &status, 0) != pid) return 127;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 126;
#endif
}

/// Outcome codes for run_with_address_limit.
enum LoadOutcome : int { kExpectedError = 0, kOtherError = 1, kOtherException = 2, kNoError = 3 };

/// Calls \p load and classifies the outcome: an intervox::Error whose message contains \p expected,
/// another intervox::Error, another exception (std::bad_alloc), or none.
template <class F>
int classify_load(F&& load, const std::string& expected) {
  try {
    load();
  } catch (const std::exception& e) {
    const bool ours = dynamic_cast<const intervox::Error*>(&e) != nullptr;
    if (!ours) return kOtherException;
    return std::string(e.what()).find(expected) != std::string::npos ? kExpectedError : kOtherError;
  }
  return kNoError;
}

/// Replaces the last four bytes of \p bytes by the CRC-32 of the rest (as the grid fuzzer does).
inline void fix_grid_checksum(std::string& bytes) {
  if (bytes.size() < 4) return;
  const std::uint32_t crc = intervox::detail::crc32(std::string_view(bytes).substr(0, bytes.size() - 4));
  for (int i = 0; i < 4; ++i)
    bytes[bytes.size() - 4 + static_cast<std::size_t>(i)] = static_cast<char>((crc >> (8 * i)) & 0xFFu);
}
